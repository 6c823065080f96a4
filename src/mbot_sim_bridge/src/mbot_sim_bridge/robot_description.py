"""A robot_description as a launch file's ``xacro FILE name:=value`` makes it, for what builds robots without
roslaunch: the tests, the benches and the demo."""


def expand_xacro(path: str, **arguments: str) -> str:
    """``path`` through the workspace's Noetic-compatible xacro; ``arguments`` are its xacro:arg values, the
    others keep their defaults."""
    import xacro_noetic as xacro  # imported on first use: the simulator itself never needs it
    # xacro's Python API wants the map of arguments even when it is empty.
    return xacro.process_file(path, mappings=arguments).toxml()
