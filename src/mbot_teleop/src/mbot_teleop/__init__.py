"""Keyboard teleop for the mbot, after the course's mbot_teleop.py; the logic is free of ROS."""
