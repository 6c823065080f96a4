"""The simulation core: model and world loading, physics, diff drive and sensors.

Nothing in this package imports rospy or ROS message modules, so it runs under plain pytest.
"""
