"""``unspawner NAME ...``: stops the named running controllers until it is killed, then starts them again."""
import sys

import rospy
from controller_manager_msgs.srv import ListControllers, SwitchController, SwitchControllerRequest

from mbot_sim_bridge.processes import stop_on_signals

HELP = """./unspawner name1 name2 name3

\tStops a set of controllers until killed.
\tUseful in roslaunch files to temporarily stop controllers"""


def main():
    names = rospy.myargv()[1:]
    if not names or names[0] in ("-h", "--help"):
        print(HELP)
        sys.exit(1)
    stop = stop_on_signals()
    rospy.init_node("unspawner", anonymous=True, disable_signals=True)
    switch = rospy.ServiceProxy("controller_manager/switch_controller", SwitchController)
    list_controllers = rospy.ServiceProxy("controller_manager/list_controllers", ListControllers)
    switch.wait_for_service()
    list_controllers.wait_for_service()
    wanted, inhibited = set(names), set()
    # Upstream checks every 3 s (wall time) whether a spawner has started them again.
    while not stop.is_set():
        running = {state.name for state in list_controllers().controller if state.state == "running"}
        to_stop = wanted & running
        if to_stop:
            rospy.loginfo(f"Inhibiting controllers: {', '.join(sorted(to_stop))}")
            switch(strictness=SwitchControllerRequest.BEST_EFFORT, stop_controllers=sorted(to_stop))
            inhibited.update(to_stop)
        stop.wait(3.0)
    if inhibited:
        switch(strictness=SwitchControllerRequest.BEST_EFFORT, start_controllers=sorted(inhibited))
    rospy.signal_shutdown("unspawner stopped")
