"""mbot_gazebo: the course's worlds and build_world, a floor-plan tool in place of Gazebo's Building Editor."""
