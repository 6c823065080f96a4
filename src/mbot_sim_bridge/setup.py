from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=["mbot_sim_bridge", "mbot_sim_bridge.core", "mbot_sim_bridge.core.cameras",
              "mbot_sim_bridge.core.description", "mbot_sim_bridge.core.drives", "mbot_sim_bridge.core.hector",
              "mbot_sim_bridge.core.joints", "mbot_sim_bridge.core.ros_control", "mbot_sim_bridge.core.sensors",
              "mbot_sim_bridge.plugins"],
    package_dir={"": "src"},
))
