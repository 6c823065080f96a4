"""mbot_sim_bridge: a PyBullet stand-in for gzserver and the gazebo_ros plugins the mbot course uses."""
