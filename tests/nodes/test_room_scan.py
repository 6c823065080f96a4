#!/usr/bin/env python3
"""In room.world the lidar reads the walls where the SDF puts them, within 2 cm.

The expected ranges come from the world file alone: each beam is intersected, in the laser's horizontal
plane, with the footprints of the collision shapes that reach that height.
"""
import math
import sys
import unittest

import numpy
import rospy
import rostest
from mbot_gazebo.footprints import footprint
from mbot_sim_bridge.core.description.sdf_world import parse_world
from sensor_msgs.msg import LaserScan

from sim_support import Simulator, wait_for

LASER_POSITION = (0.08, 0.0, 0.072)  # laser_link with the mbot at the origin, facing +x
SCANS_AVERAGED = 10  # averages the tutorial's 1 cm noise down to about 3 mm
TOLERANCE = 0.02
EDGE_STEP = 0.002  # rad: beams whose expected range jumps within this are grazing an edge


def ray_polygon_distance(origin, direction, polygon):
    """Distance along the ray to the nearest crossing of the polygon's edges (inf if none)."""
    nearest = math.inf
    for (ax, ay), (bx, by) in zip(polygon, polygon[1:] + polygon[:1]):
        ex, ey = bx - ax, by - ay
        denominator = direction[0] * ey - direction[1] * ex
        if abs(denominator) < 1e-12:
            continue
        wx, wy = ax - origin[0], ay - origin[1]
        distance = (wx * ey - wy * ex) / denominator
        along_edge = (wx * direction[1] - wy * direction[0]) / denominator
        if distance > 0 and 0 <= along_edge <= 1:
            nearest = min(nearest, distance)
    return nearest


def expected_range(polygons, angle, range_min, range_max):
    direction = (math.cos(angle), math.sin(angle))
    start = (LASER_POSITION[0] + range_min * direction[0], LASER_POSITION[1] + range_min * direction[1])
    distance = min((ray_polygon_distance(start, direction, polygon) for polygon in polygons), default=math.inf)
    return range_min + distance if range_min + distance < range_max else math.inf


class RoomScan(unittest.TestCase):
    def test_ranges_match_the_sdf_walls(self):
        rospy.init_node("room_scan_test")
        Simulator()
        world = parse_world(rospy.get_param("~world"))
        polygons = [list(footprint(shape)) for shape in world.shapes if shape.kind != "plane"
                    and shape.bounds()[0][2] <= LASER_POSITION[2] <= shape.bounds()[1][2]]
        scans = []
        subscriber = rospy.Subscriber("/scan", LaserScan, scans.append)
        wait_for(lambda: len(scans) >= SCANS_AVERAGED, what=f"{SCANS_AVERAGED} scans")
        subscriber.unregister()
        scan = scans[0]
        measured = numpy.array([s.ranges for s in scans[:SCANS_AVERAGED]])
        checked, errors = 0, []
        for beam in range(len(scan.ranges)):
            angle = scan.angle_min + beam * scan.angle_increment
            expected = [expected_range(polygons, angle + offset, scan.range_min, scan.range_max)
                        for offset in (-EDGE_STEP, 0.0, EDGE_STEP)]
            if not all(math.isfinite(e) for e in expected) or max(expected) - min(expected) > 0.01:
                continue
            checked += 1
            errors.append(measured[:, beam].mean() - expected[1])
        errors = numpy.abs(numpy.array(errors))
        print(f"figure: room.world: {checked} beams on walls, |measured - SDF| mean {errors.mean():.4f} m, max "
              f"{errors.max():.4f} m", file=sys.stderr)
        self.assertGreater(checked, 200, "most beams should see a wall in the room")
        self.assertLess(errors.max(), TOLERANCE)


if __name__ == "__main__":
    rostest.rosrun("mbot_tests", "room_scan", RoomScan)
