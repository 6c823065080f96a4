"""Pick and place with the workspace's arm (arm_pick.py): the 0.2 kg box is lifted 0.2 m, carried 0.3 m and set
down on its target with less than 5 mm of slip in the fingers, held by friction alone, then with
libgazebo_ros_link_attacher.so (in the pick world) attaching it while the fingers hold it, then with
libgazebo_grasp_fix.so in the arm's description attaching it when the fingers grip and releasing it when they
open. Once attached, the fingers open off the box for the carry: the attachment alone must hold it."""
from arm_pick import arm_with_box, pick, placement_error, step_until
from ros_control_fixtures import run_until_ended

from mbot_sim_bridge.core.manipulation.grasp_fix import GraspFix
from mbot_sim_bridge.core.manipulation.link_attacher import LinkAttacher
from mbot_sim_bridge.core.ros_control.gripper_action_controller import ABORTED, SUCCEEDED, GripperGoal

MAX_SLIP = 0.005  # m
# The gripper's Gazebo link: gripper_base_link hangs on tool0 and wrist_3_link by fixed joints, lumped into it.
GRIPPER_LINK = ("robot", "wrist_3_link", "box", "link")
# As a user adds it to the arm: the palm is that same link, the fingers are the two finger links. Checked 20 times
# a second, it attaches after 5 gripped checks (a quarter of a second) and releases 4 checks after the fingers open.
GRASP_FIX = """<gazebo><plugin name="gazebo_grasp_fix" filename="libgazebo_grasp_fix.so">
  <arm><arm_name>arm</arm_name><palm_link>wrist_3_link</palm_link>
    <gripper_link>left_finger_link</gripper_link><gripper_link>right_finger_link</gripper_link></arm>
  <forces_angle_tolerance>100</forces_angle_tolerance><update_rate>20</update_rate>
  <grip_count_threshold>4</grip_count_threshold><max_grip_count>8</max_grip_count>
  <release_tolerance>0.005</release_tolerance><disable_collisions_on_attach>false</disable_collisions_on_attach>
</plugin></gazebo>"""


# Each finger 3 mm off the 4 cm box's face: no contact, so no friction, yet less than the grasp fix's
# release_tolerance (5 mm), which would release the box.
LOOSENED = 0.023  # m from the centre line


def loosen_fingers(sim, gripper):
    assert gripper.accept_goal(GripperGoal(LOOSENED, 20.0))
    outcome = run_until_ended(sim, gripper)
    assert (outcome.status, outcome.reached_goal) == (SUCCEEDED, True), outcome


def assert_held_and_placed(sim, record, grasp: str):
    error = placement_error(sim, record)
    print(f"figure: {grasp}: slip {record.slip * 1000:.2f} mm, placed {error * 1000:.1f} mm from the target")
    assert record.slip < MAX_SLIP
    assert error < 0.01


def test_a_friction_grasp_lifts_carries_and_sets_down_the_box_without_slipping():
    sim, spawned, arm, gripper = arm_with_box()
    try:
        record = pick(sim, spawned, arm, gripper)
        closing = record.outcomes["close"]
        # The fingers stop on the 4 cm box (2 cm from the centre line each) and the goal ends stalled.
        assert (closing.status, closing.stalled) == (ABORTED, True) and abs(closing.position - 0.02) < 0.002
        assert_held_and_placed(sim, record, "friction grasp")
    finally:
        sim.close()


def test_the_link_attacher_holds_the_box_from_closing_to_opening():
    sim, spawned, arm, gripper = arm_with_box()
    try:
        attacher, = sim.world_plugins.plugins
        assert isinstance(attacher, LinkAttacher)
        answers = []

        def attach():
            answers.append(attacher.attach(GRIPPER_LINK))
            loosen_fingers(sim, gripper)
        record = pick(sim, spawned, arm, gripper, after_close=attach,
                      before_release=lambda: answers.append(attacher.detach(GRIPPER_LINK)))
        assert answers == [(True, "Attach finished."), (True, "")]
        assert_held_and_placed(sim, record, "link attacher grasp")
        assert not attacher.joints.holds(GRIPPER_LINK)
    finally:
        sim.close()


def test_the_grasp_fix_attaches_the_gripped_box_and_releases_it_when_the_fingers_open():
    sim, spawned, arm, gripper = arm_with_box(GRASP_FIX)
    try:
        fix = next(plugin for plugin in spawned.plugins if isinstance(plugin, GraspFix))
        holders = []

        def attached():
            step_until(sim, lambda: fix.attached, 1.0, "the grasp fix's attachment")
            loosen_fingers(sim, gripper)
        record = pick(sim, spawned, arm, gripper, after_close=attached,
                      before_release=lambda: holders.append({box: holder for box, (holder, _) in fix.attached.items()}),
                      after_release=lambda: step_until(sim, lambda: not fix.attached, 1.0, "its release"))
        assert holders == [{("box", "link"): "arm"}]  # held all the way
        assert_held_and_placed(sim, record, "grasp fix grasp")
    finally:
        sim.close()
