"""Scene files from Python: a top-level <appell robot="..."> around a robot
description left as published (docs/scene-format.md §3). The same drop as
tests/test_io_scene_file.cpp: the quadruped's four point feet touch together,
the plastic impact stops it dead, and it rests at the legs' height."""

import pytest

import appell
from conftest import SOURCE_DIR, tight_simulation

PUBLISHED = SOURCE_DIR / "tests" / "data" / "published"
DROP = PUBLISHED / "scenes" / "quadruped_drop.xml"
ROS1 = str(PUBLISHED / "ros1" / "src")


def test_a_scene_file_loads_its_description_and_the_robot_lands_on_its_feet():
    scene = appell.load_scene(DROP, package_paths=[ROS1], use_ros_package_path=False)
    assert scene.source == str(DROP)
    assert scene.robot_source.endswith("quadruped_description/urdf/quadruped.urdf")
    assert scene.nv == 18
    assert len(scene.warnings) == 1 and "body 'FL_HIP'" in scene.warnings[0]
    sim = tight_simulation(scene)
    sim.advance_to(1.0)
    assert sim.q[2] == pytest.approx(0.42, abs=1e-8)
    assert max(abs(x) for x in sim.v) < 1e-8
    assert sim.kinetic_energy < 1e-12


def test_a_description_not_found_is_named_at_the_scene_files_line():
    with pytest.raises(appell.SceneError,
                       match=r"quadruped_drop.xml:8: <appell>: robot "
                             r"'package://quadruped_description/urdf/quadruped.urdf': "
                             r"package 'quadruped_description' not found"):
        appell.load_scene(DROP, use_ros_package_path=False)
