# Sourced by devel/setup.bash. roslaunch imports distutils (through rosclean), and setuptools' distutils shim
# then imports all of setuptools and pkg_resources first: about 0.2 s of every roslaunch start. Python's own
# distutils (python3-distutils, which rosclean depends on) has all rosclean uses. A value set before wins.
export SETUPTOOLS_USE_DISTUTILS="${SETUPTOOLS_USE_DISTUTILS:-stdlib}"
