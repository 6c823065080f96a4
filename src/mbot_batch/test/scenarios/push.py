#!/usr/bin/env python3
"""The batch tests' cheap scenario: the simulator alone (no robot to describe, spawn and publish), a box spawned
on its ground plane and set sliding at the run's speed through gazebo_msgs, stepped for half a second of sim time
in lockstep; reports where it came to rest."""
import rospy
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import GetModelState, SetModelState, SpawnModel
from geometry_msgs.msg import Pose
from mbot_batch import scenario
from mbot_sim_bridge.lockstep import LockstepClient

HALF_SIZE = 0.05
BOX = (f"<sdf version='1.6'><model name='box'><link name='link'><inertial><mass>1.0</mass></inertial>"
       f"<collision name='collision'><geometry><box><size>{2 * HALF_SIZE} {2 * HALF_SIZE} {2 * HALF_SIZE}</size>"
       "</box></geometry></collision></link></model></sdf>")


def service(name, kind, timeout):
    rospy.wait_for_service(name, timeout=timeout)
    return rospy.ServiceProxy(name, kind)


if __name__ == "__main__":
    rospy.init_node("push_scenario", disable_signals=True)
    sim = LockstepClient(timeout=60)
    resting = Pose()
    resting.position.z = HALF_SIZE
    resting.orientation.w = 1.0
    if not service("/gazebo/spawn_sdf_model", SpawnModel, sim.timeout)("box", BOX, "", resting, "world").success:
        raise SystemExit("the box was not spawned")
    push = ModelState(model_name="box", pose=resting, reference_frame="world")
    push.twist.linear.x = scenario.parameters().get("speed", 0.2)
    if not service("/gazebo/set_model_state", SetModelState, sim.timeout)(push).success:
        raise SystemExit("the box was not set moving")
    sim_time = sim.step(500)
    state = service("/gazebo/get_model_state", GetModelState, sim.timeout)("box", "world")
    scenario.metric("slide", state.pose.position.x)
    scenario.metric("z", state.pose.position.z)
    scenario.metric("sim_time", sim_time)
