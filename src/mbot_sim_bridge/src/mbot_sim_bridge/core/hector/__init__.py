"""hector_gazebo_plugins: the sensor error model, IMU, GPS and magnetometer."""
