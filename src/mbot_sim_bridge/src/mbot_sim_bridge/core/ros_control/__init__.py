"""ros_control in the simulator, without ROS, along upstream's package lines (ros_control 0.20, ros_controllers and
gazebo_ros_control of Noetic). The ROS layer (``plugins/gazebo_ros_control.py``, ``plugins/ros_controllers.py``)
adds services and topics.

- ``gazebo_ros_control``: the ``libgazebo_ros_control.so`` plugin over all of them;
- ``hardware_interface``: the interface names; ``transmissions``: the ``<transmission>`` parser;
  ``joint_limits``: limits from the URDF and the parameters; ``angles`` and ``control_toolbox`` (Pid);
- ``robot_hw_sim``: the robot hardware simulation (DefaultRobotHWSim); ``controller_manager``;
- the controllers, a module per package: ``controller_interface`` (the base), ``joint_state_controller``,
  ``diff_drive_controller``, ``forward_command_controller`` (position_/velocity_/effort_controllers' forward
  ones), ``pid_controllers`` (their PID ones), ``joint_trajectory_controller``, ``gripper_action_controller``.
  Adding a controller is a module and a line in ``controller_table.CORE_CONTROLLERS``.
"""
