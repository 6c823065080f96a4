from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=["mbot_sim_bridge", "mbot_sim_bridge.core", "mbot_sim_bridge.core.ros_control", "mbot_sim_bridge.plugins"],
    package_dir={"": "src"},
))
