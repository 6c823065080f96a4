"""Every control_msgs message, service and action type generated here carries control_msgs 1.5's (Noetic) md5 sum,
computed from upstream's definitions, so actionlib clients and MoveIt built against upstream talk to the
simulator's controllers."""
import inspect

import control_msgs.msg as msg
import control_msgs.srv as srv
import pytest

UPSTREAM_MD5 = {
    msg.FollowJointTrajectoryAction: "bc4f9b743838566551c0390c65f1a248",
    msg.FollowJointTrajectoryActionFeedback: "d8920dc4eae9fc107e00999cce4be641",
    msg.FollowJointTrajectoryActionGoal: "cff5c1d533bf2f82dd0138d57f4304bb",
    msg.FollowJointTrajectoryActionResult: "c4fb3b000dc9da4fd99699380efcc5d9",
    msg.FollowJointTrajectoryFeedback: "10817c60c2486ef6b33e97dcd87f4474",
    msg.FollowJointTrajectoryGoal: "69636787b6ecbde4d61d711979bc7ecb",
    msg.FollowJointTrajectoryResult: "493383b18409bfb604b4e26c676401d2",
    msg.GripperCommand: "680acaff79486f017132a7f198d40f08",
    msg.GripperCommandAction: "950b2a6ebe831f5d4f4ceaba3d8be01e",
    msg.GripperCommandActionFeedback: "653dff30c045f5e6ff3feb3409f4558d",
    msg.GripperCommandActionGoal: "aa581f648a35ed681db2ec0bf7a82bea",
    msg.GripperCommandActionResult: "143702cb2df0f163c5283cedc5efc6b6",
    msg.GripperCommandFeedback: "e4cbff56d3562bcf113da5a5adeef91f",
    msg.GripperCommandGoal: "86fd82f4ddc48a4cb6856cfa69217e43",
    msg.GripperCommandResult: "e4cbff56d3562bcf113da5a5adeef91f",
    msg.JointControllerState: "987ad85e4756f3aef7f1e5e7fe0595d1",
    msg.JointJog: "1685da700c8c2e1254afc92a5fb89c96",
    msg.JointTolerance: "f544fe9c16cf04547e135dd6063ff5be",
    msg.JointTrajectoryAction: "a04ba3ee8f6a2d0985a6aeaf23d9d7ad",
    msg.JointTrajectoryActionFeedback: "aae20e09065c3809e8a8e87c4c8953fd",
    msg.JointTrajectoryActionGoal: "a99e83ef6185f9fdd7693efe99623a86",
    msg.JointTrajectoryActionResult: "1eb06eeff08fa7ea874431638cb52332",
    msg.JointTrajectoryControllerState: "10817c60c2486ef6b33e97dcd87f4474",
    msg.JointTrajectoryFeedback: "d41d8cd98f00b204e9800998ecf8427e",
    msg.JointTrajectoryGoal: "2a0eff76c870e8595636c2a562ca298e",
    msg.JointTrajectoryResult: "d41d8cd98f00b204e9800998ecf8427e",
    msg.PidState: "b138ec00e886c10e73f27e8712252ea6",
    msg.PointHeadAction: "7252920f1243de1b741f14f214125371",
    msg.PointHeadActionFeedback: "33c9244957176bbba97dd641119e8460",
    msg.PointHeadActionGoal: "b53a8323d0ba7b310ba17a2d3a82a6b8",
    msg.PointHeadActionResult: "1eb06eeff08fa7ea874431638cb52332",
    msg.PointHeadFeedback: "cce80d27fd763682da8805a73316cab4",
    msg.PointHeadGoal: "8b92b1cd5e06c8a94c917dc3209a4c1d",
    msg.PointHeadResult: "d41d8cd98f00b204e9800998ecf8427e",
    msg.SingleJointPositionAction: "c4a786b7d53e5d0983decf967a5a779e",
    msg.SingleJointPositionActionFeedback: "3503b7cf8972f90d245850a5d8796cfa",
    msg.SingleJointPositionActionGoal: "4b0d3d091471663e17749c1d0db90f61",
    msg.SingleJointPositionActionResult: "1eb06eeff08fa7ea874431638cb52332",
    msg.SingleJointPositionFeedback: "8cee65610a3d08e0a1bded82f146f1fd",
    msg.SingleJointPositionGoal: "fbaaa562a23a013fd5053e5f72cbb35c",
    msg.SingleJointPositionResult: "d41d8cd98f00b204e9800998ecf8427e",
    srv.QueryCalibrationState: "28af3beedcb84986b8e470dc5470507d",
    srv.QueryCalibrationStateRequest: "d41d8cd98f00b204e9800998ecf8427e",
    srv.QueryCalibrationStateResponse: "28af3beedcb84986b8e470dc5470507d",
    srv.QueryTrajectoryState: "ec93cdecbd8062d761aa52b7c90cd44b",
    srv.QueryTrajectoryStateRequest: "556a4fb76023a469987922359d08a844",
    srv.QueryTrajectoryStateResponse: "1f1a6554ad060f44d013e71868403c1a",
}


def generated_types():
    return [cls for module in (msg, srv) for _, cls in inspect.getmembers(module, inspect.isclass)
            if hasattr(cls, "_md5sum")]


def test_every_generated_type_is_compared():
    assert set(generated_types()) == set(UPSTREAM_MD5)


@pytest.mark.parametrize("message_type", list(UPSTREAM_MD5), ids=lambda t: t._type)
def test_md5_matches_upstream(message_type):
    assert message_type._md5sum == UPSTREAM_MD5[message_type]
