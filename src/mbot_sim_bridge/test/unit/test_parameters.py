"""core/parameters.py: the parameter source the simulation is handed (searchParam semantics), and
gazebo_ros_control reading a robot_description whose collision meshes are package:// URIs."""
import os

from mbot_sim_bridge.core.parameters import Parameters, absolute_name
from mbot_sim_bridge.core.plugin_table import CORE_PLUGINS
from mbot_sim_bridge.core.description.robot_model import parse_robot
from mbot_sim_bridge.core.description.sdf_world import parse_world
from mbot_sim_bridge.core.simulation import Simulation
from mbot_sim_bridge.package_uris import resolve_package_uris

HERE = os.path.dirname(os.path.abspath(__file__))
WORLDS = os.path.join(HERE, "..", "..", "..", "..", "worlds")
MESHES = os.path.abspath(os.path.join(HERE, "..", "worlds", "meshes"))


def test_search_goes_up_from_the_namespace_and_absolute_keys_stand():
    parameters = Parameters({"robot_description": "root", "a": {"b": {"robot_description": "deep"}, "x": 1}})
    assert parameters.search("/a/b/c", "robot_description") == "/a/b/robot_description"
    assert parameters.search("/a", "robot_description") == "/robot_description"
    assert parameters.search("/a/b", "/robot_description") == "/robot_description"
    assert parameters.search("/a/b", "missing") is None
    assert parameters.get("/a/b") == {"robot_description": "deep"} and parameters.get("/a/x/y", 5) == 5
    assert parameters.has("/a/x") and not parameters.has("/a/y")
    assert absolute_name("/a", "b/c") == "/a/b/c" and absolute_name("/a", "/b") == "/b"


def test_package_uris_resolve_to_the_package_folder():
    resolved = resolve_package_uris("<mesh filename='package://mbot_description/urdf/x.stl'/>")
    assert "package://" not in resolved and resolved.endswith("mbot_description/urdf/x.stl'/>")


def test_package_uris_in_comments_are_left_alone():
    text = "<!-- meshes are package:// URIs --><mesh filename='package://mbot_description/m.stl'/>"
    assert resolve_package_uris(text).startswith("<!-- meshes are package:// URIs --><mesh filename='/")


ARM = """<robot name="meshy">
  <link name="base"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><mesh filename="package://meshes_pkg/block.stl"/></geometry></collision></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial><collision><geometry><mesh filename="package://meshes_pkg/block.stl" scale="0.2 0.2 0.2"/>
    </geometry></collision></link>
  <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 1"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
  <transmission name="swing_tr"><type>transmission_interface/SimpleTransmission</type>
    <joint name="swing"><hardwareInterface>hardware_interface/PositionJointInterface</hardwareInterface></joint>
    <actuator name="swing_motor"/></transmission>
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so"/></gazebo>
</robot>"""


def test_gazebo_ros_control_reads_package_meshes_from_robot_description_as_spawning_does():
    def package_uris(text):
        return text.replace("package://meshes_pkg/", MESHES + "/")

    sim = Simulation(parse_world(os.path.join(WORLDS, "empty.world")), CORE_PLUGINS,
                     parameters=Parameters({"robot_description": ARM}), package_uris=package_uris)
    try:
        spawned = sim.spawn_robot(parse_robot(package_uris(ARM), "model 'meshy'"), "meshy")
        plugin = next(plugin for plugin in spawned.plugins if type(plugin).__name__ == "GazeboRosControlPlugin")
        assert list(plugin.hw.joints) == ["swing"]
        limits = plugin.hw.joints["swing"].limits
        assert (limits.min_position, limits.max_position, limits.max_effort) == (-1, 1, 10)
    finally:
        sim.close()
