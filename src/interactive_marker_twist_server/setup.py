from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=['interactive_marker_twist_server'],
    package_dir={'': 'src'},
))
