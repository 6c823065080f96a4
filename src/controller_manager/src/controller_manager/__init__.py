"""Command-line clients of ros_control's controller manager services (spawner, unspawner, controller_manager)."""
