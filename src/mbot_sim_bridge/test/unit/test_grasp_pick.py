"""Pick and place with the workspace's arm (arm_pick.py): the friction grasp holds the 0.2 kg box through a
0.2 m lift and a 0.3 m carry with less than 5 mm of slip in the fingers, and sets it down on its target."""
from arm_pick import arm_with_box, pick, placement_error

from mbot_sim_bridge.core.ros_control.gripper_action_controller import ABORTED

MAX_SLIP = 0.005  # m


def test_a_friction_grasp_lifts_carries_and_sets_down_the_box_without_slipping(tmp_path):
    sim, spawned, arm, gripper = arm_with_box(tmp_path)
    try:
        record = pick(sim, spawned, arm, gripper)
        closing = record.outcomes["close"]
        # The fingers stop on the 4 cm box (2 cm from the centre line each) and the goal ends stalled.
        assert (closing.status, closing.stalled) == (ABORTED, True) and abs(closing.position - 0.02) < 0.002
        print(f"figure: friction grasp: slip {record.slip * 1000:.2f} mm, placed "
              f"{placement_error(sim, record) * 1000:.1f} mm from the target")
        assert record.slip < MAX_SLIP
        assert placement_error(sim, record) < 0.01
    finally:
        sim.close()
