"""twist_mux: Twist inputs multiplexed by priority, silenced by Bool locks (``mux``: the selection, without
rospy; ``node``: the ROS node; ``joystick_relay`` and ``twist_marker``: upstream's two companion nodes)."""
