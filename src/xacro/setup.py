from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["ament_index_python", "xacro_noetic"], package_dir={"": "src"}))
