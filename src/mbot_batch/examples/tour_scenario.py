"""The example's scenario: the lidar mbot drives ./mbot demo's tour of the play ground from the run's start pose
(the launch file's x, y, Y), steering on /odom as the demo does, and reports the distance it drove, the smallest
lidar range it saw (its clearance to the nearest obstacle, with the run's lidar noise), whether it finished the
tour and the sim time it took.

A tour leg not done within 15 s of sim time (the robot pushed against an obstacle) ends the tour early."""
import math

import numpy
import rospy
from mbot_batch import scenario
from mbot_gazebo.tour import Recorder, Tour
from mbot_sim_bridge.lockstep import LockstepClient
from sensor_msgs.msg import LaserScan

STEP_SIZE = 0.001  # the play ground's max_step_size
LEG_SIM_TIMEOUT = 15.0

rospy.init_node("tour_scenario", disable_signals=True)
sim = LockstepClient(timeout=120)
recorder = Recorder(sim, scan_points=False)
scans = sim.recorder(["/scan"])
tour = Tour(sim, recorder, STEP_SIZE, on_terminal=False, segment_sim_timeout=LEG_SIM_TIMEOUT)
try:
    tour.run()
    completed = 1.0
except RuntimeError as error:
    print(f"tour ended early: {error}", flush=True)
    completed = 0.0
sim_time = tour.pose[0]
sim.settle()
clearance = math.inf
for data in scans.messages("/scan", "/gazebo")[("/scan", "/gazebo")]:
    scan = LaserScan()
    scan.deserialize(data)
    ranges = numpy.asarray(scan.ranges)
    seen = ranges[numpy.isfinite(ranges) & (ranges >= scan.range_min)]
    if seen.size:
        clearance = min(clearance, float(seen.min()))
scenario.metric("distance", recorder.distance(sim_time))
scenario.metric("min_clearance", clearance)
scenario.metric("completed", completed)
scenario.metric("sim_time", sim_time)
sim.close()
