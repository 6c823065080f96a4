"""``libgazebo_ros_template.so`` without ROS (gazebo_plugins noetic-devel ``gazebo_ros_template.cpp``): the
starting point of a new plugin, as gazebo_plugins ships its template, and like it a plugin that does nothing.

A new plugin starts as a copy of this module, in the sub-package of core/ it belongs to, and of its ROS side
(``plugins/gazebo_ros_template.py``); the package README's "Adding a plugin" names every file it needs, and
``test/unit/test_plugin_table.py`` fails while one is missing.
"""
from .clock import EveryStopTimer
from .plugin import Plugin


class Template(Plugin):
    """Core of libgazebo_ros_template.so (GazeboRosTemplate)."""
    # Gazebo's class name, for messages: "GazeboRosTemplate(ns = <model>): ...".
    GAZEBO_CLASS = "GazeboRosTemplate"
    # The tags the plugin reads (core/params.py: Gazebo's name, type, default, valid range, meaning); the README's
    # tag table is generated from them. Upstream's template reads none. A plugin with a <robotNamespace> tag also
    # names how an empty one resolves (NAMESPACE_RULE, core/names.py).
    PARAMS = ()
    # Empty for a model plugin; a sensor plugin names the <sensor type="..."> it goes inside.
    SENSOR_TYPES = ()

    def __init__(self, context, element, sensor=None):
        super().__init__(context, element, sensor)
        # Every tag checked: a bad value refuses the spawn naming the tag, an unknown one is said once.
        self.params = self.read_params()
        # When ``update`` runs. A plugin with a rate uses UpdateTimer(rate, start=context.simulation.sim_time);
        # this one has nothing to do, so it never makes the loop stop for itself.
        self.timer = EveryStopTimer()

    def update(self, now: float):
        """Upstream's UpdateChild, empty. A plugin reads the physics here through ``self.context.robot`` and
        leaves its outputs in its state (``self.latest``) for the ROS side; its noise comes from
        ``self.context.random_stream(name)``, its joints are declared in ``driven_joints``."""
