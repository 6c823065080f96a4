"""The joint plugins: the joint state publisher and the mimic joint."""
