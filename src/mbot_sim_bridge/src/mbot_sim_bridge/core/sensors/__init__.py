"""The sensor plugins over physics and ray casts: IMU, p3d, f3d, force-torque, lidar and its range, Velodyne and
block lasers, the bumper; ``sensor_elements`` reads a ``<sensor>`` one way for all of them."""
