"""interactive_marker_twist_server: an interactive marker around the robot whose feedback becomes a Twist."""
