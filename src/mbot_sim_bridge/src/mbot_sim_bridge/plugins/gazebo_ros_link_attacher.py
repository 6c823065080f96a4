"""``libgazebo_ros_link_attacher.so``: the ``attach`` and ``detach`` services (gazebo_ros_link_attacher/Attach)
of upstream's ``link_attacher_node`` node handle, with upstream's log lines. The core's work runs in the loop's
thread (the only one touching the engine), paused or not, as upstream's callbacks run while Gazebo is paused."""
import rospy
from gazebo_ros_link_attacher.srv import Attach, AttachResponse

from ..core.errors import BridgeError
from ..core.manipulation.link_attacher import LinkAttacher
from . import RosPlugin


class GazeboRosLinkAttacher(RosPlugin, LinkAttacher):
    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        for verb, action in (("attach", self.attach), ("detach", self.detach)):
            service = self.topics.service(f"link_attacher_node/{verb}", Attach,
                                          lambda request, verb=verb, action=action: self._serve(request, verb, action))
            rospy.loginfo(f"{verb.capitalize()} service at: {service.resolved_name}")
        rospy.loginfo("Link attacher node initialized.")

    def _serve(self, request, verb: str, action) -> AttachResponse:
        names = (request.model_name_1, request.link_name_1, request.model_name_2, request.link_name_2)
        rospy.loginfo(f"Received request to {verb} model: '{names[0]}' using link: '{names[1]}' with model: "
                      f"'{names[2]}' using link: '{names[3]}'")
        try:
            ok, said = self.context.simulation.call_in_loop(lambda: action(names))
        except BridgeError as error:  # the loop did not take it (LoopBusy): not carried out
            ok, said = False, str(error)
        if said:
            (rospy.loginfo if ok else rospy.logerr)(said)
        (rospy.loginfo if ok else rospy.logerr)(f"{verb.capitalize()} was succesful" if ok
                                                 else f"Could not make the {verb}.")
        return AttachResponse(ok)
