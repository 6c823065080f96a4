"""The small robots of the plugin tests, one or two per plugin family, shared with the bad-input tests
(test_new_plugin_inputs.py): URDF texts, plugin blocks and the mobile_test_robots xacros."""
import os

MOBILE_TEST_ROBOTS = os.path.join(os.path.dirname(__file__), "..", "..", "..", "mobile_test_robots")

# A base with a bumper plate on a fixed joint: lumped into base_link, its collision keeps sdformat's lump name.
BUMPER_ROBOT = """<robot name="bumper_bot">
  <link name="base_link">
    <inertial><mass value="8"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <link name="bumper_link">
    <collision><geometry><box size="0.02 0.3 0.1"/></geometry></collision>
  </link>
  <joint name="bumper_joint" type="fixed"><parent link="base_link"/><child link="bumper_link"/>
    <origin xyz="0.21 0 0.1"/></joint>
  <gazebo reference="bumper_link">
    <sensor type="contact" name="bumper">
      <update_rate>50</update_rate>
      <contact><collision>{collision}</collision></contact>
      <plugin name="bumper_controller" filename="libgazebo_ros_bumper.so">
        <bumperTopicName>bumper</bumperTopicName><frameName>world</frameName>
      </plugin>
    </sensor>
  </gazebo>
</robot>"""

BUMPER_LUMPED_COLLISION = "base_link_fixed_joint_lump__bumper_link_collision"

HECTOR_ROBOT = """<robot name="box">
  <link name="base_link">
    <inertial><mass value="10"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.4 0.4 0.2"/></geometry></collision>
  </link>
  <link name="imu_link"/>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  <gazebo>
    <plugin name="imu_controller" filename="libhector_gazebo_ros_imu.so">
      <updateRate>100</updateRate><bodyName>base_link</bodyName><frameId>imu_link</frameId>
      <topicName>imu/data</topicName>{imu}
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="magnetometer" filename="libhector_gazebo_ros_magnetic.so">
      <updateRate>50</updateRate><bodyName>base_link</bodyName><topicName>magnetic</topicName>
      <magnitude>0.5</magnitude><declination>10</declination><inclination>60</inclination>
      <referenceHeading>{heading}</referenceHeading>
    </plugin>
  </gazebo>
  <gazebo>
    <plugin name="gps_controller" filename="libhector_gazebo_ros_gps.so">
      <updateRate>40</updateRate><bodyName>base_link</bodyName><frameId>base_link</frameId>
      <referenceLatitude>49.9</referenceLatitude><referenceLongitude>8.9</referenceLongitude>
      <referenceHeading>{heading}</referenceHeading><referenceAltitude>100</referenceAltitude>{gps}
    </plugin>
  </gazebo>
</robot>"""

MIMIC_GRIPPER = """<robot name="gripper">
  <link name="palm">
    <inertial><mass value="100"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.3 0.1"/></geometry></collision>
  </link>
  <link name="left_finger">
    <inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.08"/></geometry></collision>
  </link>
  <link name="right_finger">
    <inertial><mass value="0.1"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.08"/></geometry></collision>
  </link>
  <joint name="left_finger_joint" type="prismatic"><parent link="palm"/><child link="left_finger"/>
    <origin xyz="0 0.05 0.15"/><axis xyz="0 1 0"/><limit lower="-0.04" upper="0.04" effort="20" velocity="0.2"/>
  </joint>
  <joint name="right_finger_joint" type="prismatic"><parent link="palm"/><child link="right_finger"/>
    <origin xyz="0 -0.05 0.15"/><axis xyz="0 1 0"/><limit lower="-0.04" upper="0.04" effort="20" velocity="0.2"/>
    {mimic}
  </joint>
  {plugin}
</robot>"""

MIMIC_PLUGIN_BLOCK = """<gazebo>
  <plugin name="right_finger_mimic" filename="libroboticsgroup_upatras_gazebo_mimic_joint_plugin.so">
    <joint>left_finger_joint</joint><mimicJoint>right_finger_joint</mimicJoint><multiplier>-1</multiplier>
    <offset>0.002</offset>{extra}</plugin></gazebo>"""

STEREO_XACRO = os.path.join(os.path.dirname(__file__), "..", "..", "..", "mobile_test_robots", "urdf",
                    "stereo_head.urdf.xacro")

HOLONOMIC_XACRO = os.path.join(os.path.dirname(__file__), "..", "..", "..", "mobile_test_robots", "urdf",
                    "holonomic_base.urdf.xacro")

SONAR_SENSOR = """<sensor type="ray" name="{name}">
  <pose>0 0 0 0 0 0</pose><update_rate>20</update_rate>
  <ray><scan>
    <horizontal><samples>5</samples><resolution>1</resolution><min_angle>-0.13</min_angle><max_angle>0.13</max_angle>
    </horizontal>
    <vertical><samples>5</samples><resolution>1</resolution><min_angle>-0.05</min_angle><max_angle>0.05</max_angle>
    </vertical></scan>
    <range><min>0.02</min><max>4.0</max><resolution>0.01</resolution></range></ray>
  {plugin}
</sensor>"""

RANGE_PLUGIN = """<plugin name="range" filename="libgazebo_ros_range.so">
  <topicName>sonar_front</topicName><frameName>sonar_link</frameName><radiation>{radiation}</radiation>
  <fov>0.26</fov><gaussianNoise>{noise}</gaussianNoise></plugin>"""

HECTOR_SONAR_PLUGIN = """<plugin name="sonar" filename="libhector_gazebo_ros_sonar.so">
  <topicName>sonar_rear</topicName><frameId>sonar_link</frameId><gaussianNoise>{noise}</gaussianNoise></plugin>"""

SONAR_ROBOT = """<robot name="sonar_bot">
  <link name="base_link">
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.3 0.3 0.2"/></geometry></collision>
  </link>
  <link name="sonar_link"/>
  <joint name="sonar_joint" type="fixed"><parent link="base_link"/><child link="sonar_link"/>
    <origin xyz="0.15 0 0.3"/></joint>
  <gazebo reference="sonar_link">{sensors}</gazebo>
</robot>"""

SKID_XACRO = os.path.join(os.path.dirname(__file__), "..", "..", "..", "mobile_test_robots", "urdf",
                    "skid_steer_base.urdf.xacro")

TRICYCLE_XACRO = os.path.join(os.path.dirname(__file__), "..", "..", "..", "mobile_test_robots", "urdf",
                        "tricycle.urdf.xacro")

VELODYNE_STAND = """<robot name="stand" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{macro}"/>
  <link name="base_link">
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.25"/><geometry><box size="0.3 0.3 0.5"/></geometry></collision>
  </link>
  <xacro:VLP-16 parent="base_link" name="velodyne" topic="velodyne_points" hz="10" samples="440" noise="{noise}"
                organize_cloud="{organize}">
    <origin xyz="0 0 0.5" rpy="0 0 0"/>
  </xacro:VLP-16>
</robot>"""
