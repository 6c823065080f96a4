"""The plugin blocks the simulator adds to a robot by itself, written as a Gazebo user would add them, so that
they are read, checked and built like the robot's own (beside ``plugin_table``, whose file names they use):

- a roboticsgroup mimic joint plugin for each URDF ``<mimic>`` joint no such plugin of the robot covers;
- a joint state publisher for the movable joints no plugin publishes.
"""
from typing import List, Sequence
from xml.etree import ElementTree

from .description.robot_model import RobotModel
from .joints.joint_states import JointStatePublisher
from .joints.mimic_joint import MimicJoint
from .plugin import Plugin
from .plugin_table import filename_of

JOINT_STATE_PLUGIN = filename_of(JointStatePublisher)
# Hz of sim time for the joints no plugin publishes (casters, passive joints): joint_state_publisher's default rate,
# at which the course's Gazebo launch files published them. robot_state_publisher asks the master for tf_prefix
# three times per transform set it sends, so at 100 Hz this second stream cost the master a quarter of its calls.
ADDED_JOINT_STATE_RATE = 10.0
MIMIC_PLUGIN = filename_of(MimicJoint)


def mimic_blocks(model: RobotModel, plugins: Sequence[Plugin]) -> List[ElementTree.Element]:
    """A mimic joint plugin block for each ``<mimic>`` joint of ``model`` that none of ``plugins`` drives."""
    mimicked = {plugin.follower for plugin in plugins if isinstance(plugin, MimicJoint)}
    blocks = []
    for joint in model.joints.values():
        if joint.mimic is not None and joint.name not in mimicked:
            leader, multiplier, offset = joint.mimic
            blocks.append(MimicJoint.plugin_element(MIMIC_PLUGIN, f"{joint.name}_mimic", joint=leader,
                                                    mimicJoint=joint.name, multiplier=repr(multiplier),
                                                    offset=repr(offset)))
    return blocks


def joint_state_blocks(movable_joints: Sequence[str], plugins: Sequence[Plugin], namespace: str,
                       rate: float) -> List[ElementTree.Element]:
    """The joint state publisher block for the ``movable_joints`` none of ``plugins`` publishes, if any."""
    published = {joint for plugin in plugins for joint in plugin.joint_states_published}
    remaining = [joint for joint in movable_joints if joint not in published]
    if not remaining:
        return []
    return [JointStatePublisher.plugin_element(JOINT_STATE_PLUGIN, "bridge_joint_state_publisher",
                                               robotNamespace=namespace, jointName=", ".join(remaining),
                                               updateRate=repr(rate))]
