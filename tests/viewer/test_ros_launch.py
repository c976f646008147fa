"""ROS launch files are valid Python / XML and point at the URDF beside them."""

import ast
import xml.etree.ElementTree as ET

from react3d_core.export.ros_launch import write_ros_launch


def test_launch_files(tmp_path):
    urdf = tmp_path / "scene.urdf"
    urdf.write_text("<robot name='x'/>")
    py, xml = write_ros_launch(urdf)
    tree = ast.parse(py.read_text())
    assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description" for n in tree.body)
    assert '"scene.urdf"' in py.read_text()
    root = ET.parse(xml).getroot()
    assert root.find("param").get("textfile").endswith("/scene.urdf")
    assert {n.get("pkg") for n in root.findall("node")} == {"joint_state_publisher_gui", "robot_state_publisher", "rviz"}
