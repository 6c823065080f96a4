"""The one lookup PyPI's xacro 2.x makes through ROS 2's ament index, answered from ROS 1's package path.

xacro 2.x (the maintained line, a superset of Noetic's 1.14) resolves ``$(find pkg)`` with
``ament_index_python.packages.get_package_share_directory``. ROS 1 has no ament index: this package gives that
function over rospkg, which searches ROS_PACKAGE_PATH as ``rospack find`` does, so Noetic-style descriptions
resolve their packages unchanged.
"""
