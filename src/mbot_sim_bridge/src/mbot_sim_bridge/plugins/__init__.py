"""The ROS side of the emulated gazebo_ros plugins: one module and class per Gazebo ``.so``.

Each class is ``RosPlugin`` mixed into the plugin's core class (``core/``): it adds the publishers and
subscribers (owned by ``self.topics``) and nothing else, and calls only the core's hooks (``update``, ``idle``
and the values they leave). ``registry.REGISTRY`` maps the Gazebo file name to it. Updates run in the loop
thread that owns the engine; subscriber callbacks only store values under the core's lock. Messages are
built in ``messages.py``.
"""
import threading
from typing import Dict, List, Optional, Tuple

import rosgraph.names
import rospy
import rospy.impl.registration
import rospy.topics

from ..core.errors import ConfigError, PluginLeftOut
from ..core.plugin import WorldPluginContext
from ..loop_publishing import LoopPublisher
from ..subscriptions import TrackedSubscriber

# The md5sum of rospy.AnyMsg, which takes any type (roscpp matches it with every type too).
_ANY_TYPE = "*"


def loop_publisher(name: str, message_type) -> LoopPublisher:
    """A publisher written to synchronously by the loop thread (loop_publishing.py)."""
    return LoopPublisher(name, message_type)


def ros_time(sim_seconds: float) -> rospy.Time:
    """A stamp for sim time: plugins stamp with the simulation's time, never rospy.Time.now()."""
    return rospy.Time(*divmod(int(round(sim_seconds * 1e9)), 1000000000))


def resolve_in_namespace(namespace: Optional[str], name: str) -> str:
    """A plugin topic: absolute names stand, relative ones go under the plugin namespace."""
    if name.startswith("/"):
        return name
    return rospy.names.ns_join(namespace or "/", name)


def namespace_complaint(namespace: str) -> Optional[str]:
    """Why ``namespace`` cannot be a robot's namespace, or None: rosgraph's rules for a graph name, absolute or
    relative (empty: the default). A private name is refused too: roscpp would put the robot under the
    simulator's own namespace (/gazebo/...), where no launch file looks for it."""
    if namespace.startswith("~"):
        return ("is a private name, which would put the robot's topics under the simulator's own namespace; give "
                "an absolute ('/robot') or relative ('robot') namespace")
    if not rosgraph.names.is_legal_name(namespace):
        return ("is not a legal ROS name: a letter or '/' first, then only letters, digits, '_' and '/', and no "
                "'//'")
    return None


def plugin_owner(context, element) -> str:
    """How a clash names a plugin: 'plugin 'NAME' (FILE) of model 'M'' (or of world 'W')."""
    holder = "world" if isinstance(context, WorldPluginContext) else "model"
    return f"plugin '{element.get('name')}' ({element.get('filename')}) of {holder} '{context.model.name}'"


# Who holds each name the plugins advertise: (kind, resolved name) -> the PluginTopics, first first.
# Plugins are built in the loop's thread, the controllers they load in service threads: hence the lock.
_HOLDERS: Dict[Tuple[str, str], List["PluginTopics"]] = {}
_HOLDERS_LOCK = threading.Lock()


def _existing(kind: str, resolved: str):
    """The message (or service) class the node already has a ``kind`` of at ``resolved``, or None."""
    if kind == "service":
        service = rospy.impl.registration.get_service_manager().get_service(resolved)
        return None if service is None else service.service_class
    manager = rospy.topics.get_topic_manager()
    impl = (manager.get_publisher_impl if kind == "publisher" else manager.get_subscriber_impl)(resolved)
    return None if impl is None else impl.data_class


def _clash(kind: str, resolved: str, new_class, holder: str) -> Optional[str]:
    """What goes wrong when a plugin makes a ``kind`` of ``new_class`` at ``resolved``, or None when it can share
    it. A second service: rospy refuses it, roscpp logs an error and returns an empty server. A topic of another
    type: rospy would share the first's and send that type, roscpp refuses it; one of the same type is shared
    (two plugins publishing /tf), as both do."""
    existing = _existing(kind, resolved)
    if existing is None:
        return None
    if kind == "service":
        return f"it would advertise service '{resolved}', which {holder} already advertises"
    if _ANY_TYPE in (existing._md5sum, new_class._md5sum) or existing._md5sum == new_class._md5sum:
        return None
    verb, verbs = ("publish", "publishes") if kind == "publisher" else ("subscribe to", "subscribes to")
    return f"it would {verb} '{resolved}' as {new_class._type}, which {holder} already {verbs} as {existing._type}"


class PluginTopics:
    """The publishers, services and subscribers one plugin owns: made the loop's way, asked whether anyone
    listens (the loop publishes synchronously, so a topic nobody takes is work skipped), and closed together.

    Every name a plugin advertises comes through here, so here it is checked: one that is not a legal ROS name
    refuses the plugin (ConfigError), one another plugin (or the simulator itself) already holds in a way that
    cannot be shared leaves this plugin out (PluginLeftOut), its handles closed, naming both."""

    def __init__(self, owner: str):
        self.owner = owner
        self._owned = []
        self._claims: List[Tuple[str, str]] = []

    def publisher(self, name: str, message_type) -> LoopPublisher:
        return self._make("publisher", name, message_type, lambda: loop_publisher(name, message_type))

    def subscriber(self, name: str, message_type, callback, **options) -> TrackedSubscriber:
        return self._make("subscriber", name, message_type,
                          lambda: TrackedSubscriber(name, message_type, callback, **options))

    def service(self, name: str, service_type, handler) -> rospy.Service:
        return self._make("service", name, service_type, lambda: rospy.Service(name, service_type, handler))

    def _make(self, kind: str, name: str, new_class, make):
        self._claim(kind, name, new_class)
        try:
            return self.own(make())
        except BaseException:  # rospy's own refusal: the plugin is not built, so it holds nothing
            self.close()
            raise

    def own(self, handle):
        """Close ``handle`` (a rospy Service, Subscriber or TrackedSubscriber) with the others; returns it."""
        self._owned.append(handle)
        return handle

    def _claim(self, kind: str, name: str, new_class):
        resolved = rospy.resolve_name(name)  # which makes "a//b" "/a/b": roscpp refuses it, and rospy warns
        if not (rosgraph.names.is_legal_name(name) and rosgraph.names.is_legal_name(resolved)):
            self.close()
            raise ConfigError(f"{self.owner}: {kind} name '{name}' is not a legal ROS name (a letter, '/' or '~' "
                              "first, then only letters, digits, '_' and '/', and no '//')")
        key = (kind, resolved)
        with _HOLDERS_LOCK:
            holders = _HOLDERS.get(key)
            clash = _clash(kind, resolved, new_class, holders[0].owner if holders else "the simulator itself")
            if clash is None:
                _HOLDERS.setdefault(key, []).append(self)
                self._claims.append(key)
                return
        self.close()
        raise PluginLeftOut(f"{self.owner} is left out: {clash}")

    def _release(self):
        for key in self._claims:
            holders = [holder for holder in _HOLDERS.get(key, []) if holder is not self]
            if holders:
                _HOLDERS[key] = holders
            else:
                _HOLDERS.pop(key, None)
        self._claims.clear()

    @staticmethod
    def listened(*publishers: Optional[LoopPublisher]) -> bool:
        return any(publisher is not None and publisher.get_num_connections() > 0 for publisher in publishers)

    def close(self):
        for handle in self._owned:
            handle.shutdown() if isinstance(handle, rospy.Service) else handle.unregister()
        self._owned.clear()
        with _HOLDERS_LOCK:
            self._release()


class RosPlugin:
    """Mixed in before a core plugin class: ``self.topics``, closed with the plugin."""

    def __init__(self, context, element, sensor=None):
        self.topics = PluginTopics(plugin_owner(context, element))
        super().__init__(context, element, sensor)

    def robot_namespace(self) -> str:
        """The core's namespace, refused with one line naming it when it cannot be a ROS namespace."""
        namespace = super().robot_namespace()
        complaint = namespace_complaint(namespace)
        if complaint:
            tag = self.namespace_tag()
            source = (f"<robotNamespace> '{tag}'" if tag else
                      f"its namespace '{namespace}' (the model's name, as <robotNamespace> is not set)")
            raise ConfigError(f"{self.context.where(self.element)}: {self.label}: {source} {complaint}")
        return namespace

    def nobody_listens(self, now: float, *publishers: Optional[LoopPublisher]) -> bool:
        """Whether none of ``publishers`` has a subscriber; the core then idles (``idle(now)``) and the update
        stops there, as gazebo_ros's sensors work only while someone listens."""
        if self.topics.listened(*publishers):
            return False
        self.idle(now)
        return True

    def close(self):
        self.topics.close()
        super().close()
