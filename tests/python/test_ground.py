"""Ground robots from Python: e-pucks take 'wheels' and 'velocity' commands through set_commands,
one row per robot, and drive at the speeds their wheels give."""
import math

import numpy as np
import pytest

import ssx

SCENE = """<scene>
  <environment timestep="0.002" seed="1"/>
  <type name="epuck" file="epuck.xml"/>
  <ground/>
  <artifact name="a" type="epuck" xyz="0 0 0"/>
  <artifact name="b" type="epuck" xyz="0 1 0"/>
</scene>"""

R, L = 0.0205, 0.053


def test_e_pucks_take_wheel_and_velocity_commands_from_python():
    env = ssx.load_scene_string(SCENE, base_dir=ssx.data_directory() / "artifacts", threads=1)
    env.step(10)
    env.set_commands("wheels", np.array([[4.0, 4.0], [-3.0, 3.0]]), robots=["a", "b"])
    env.step(500)
    names = env.dynamic_names()
    a, b = names.index("a"), names.index("b")
    np.testing.assert_allclose(env.linear_velocities()[a], [4.0 * R, 0, 0], atol=1e-3)
    assert env.angular_velocities()[b][2] == pytest.approx(2 * 3.0 * R / L, rel=0.01)
    # a velocity command: the component along the heading, and the yaw rate
    env.set_commands("velocity", np.array([[0.05, 0, 0, 0.5]]), robots=["a"])
    env.step(250)
    v = env.linear_velocities()[a]
    assert math.hypot(v[0], v[1]) == pytest.approx(0.05, rel=0.01)
    assert env.angular_velocities()[a][2] == pytest.approx(0.5, rel=0.01)
    with pytest.raises(ValueError, match="2 \\(left, right wheel speed\\)"):
        env.set_commands("wheels", np.array([[1.0, 2.0, 3.0]]), robots=["a"])
    # the run's summary counts them as on their wheels, not as landed quadrotors
    s = env.flight_summary()
    assert (s["robots"], s["on_wheels"], s["landed"], s["airborne"]) == (2, 2, 0, 0)
    assert s["text"].startswith("robots 2: airborne 0, landed 0, on wheels 2, crashed 0")


def test_foraging_metrics_reach_python():
    # the foraging extension's count, read from Python as the drivers' metrics are
    env = ssx.load_scene(ssx.data_directory() / "ground" / "foraging.xml", threads=1)
    env.step(50)
    m = env.metrics()
    assert set(m["foraging"]) == {"items_delivered", "items_per_minute"}
    assert m["foraging"]["items_delivered"] == 0  # nobody reaches an item and the nest in a second


CARRY = """<scene>
  <environment timestep="0.002" seed="1"/>
  <type name="epuck" file="epuck.xml"/>
  <type name="item" file="item.xml"/>
  <type name="burger" file="turtlebot3_burger.xml"/>
  <ground/>
  <artifact name="a" type="epuck" xyz="0 0 0"/>
  <artifact name="puck" type="item" xyz="0.06 0 0"/>
  <artifact name="burger" type="burger" xyz="0 1 0"/>
</scene>"""


def test_python_attaches_releases_and_drives_joints():
    env = ssx.load_scene_string(CARRY, base_dir=ssx.data_directory() / "artifacts", threads=1)
    names = env.dynamic_names()
    a, puck = names.index("a"), names.index("puck")
    env.attach("a", "puck")  # (starts the world, as set_commands does)
    assert env.attachments("a") == 1 and env.attachments("puck") == 1
    offset = env.positions()[puck] - env.positions()[a]
    # a turn on the spot: the held puck goes round with the robot, at its place in the robot's frame
    env.set_commands("wheels", np.array([[-3.0, 3.0]]), robots=["a"])
    env.step(500)
    yaw = 2 * math.atan2(env.orientations()[a][3], env.orientations()[a][0])
    assert abs(yaw) > 1.0
    c, s = math.cos(yaw), math.sin(yaw)
    expected = env.positions()[a][:2] + np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1]])
    np.testing.assert_allclose(env.positions()[puck][:2], expected, atol=0.005)
    # let go, back off: the puck stays where it was left
    env.release("a")
    assert env.attachments("puck") == 0
    env.set_commands("wheels", np.array([[-4.0, -4.0]]), robots=["a"])
    left = env.positions()[puck].copy()
    env.step(500)
    np.testing.assert_allclose(env.positions()[puck][:2], left[:2], atol=0.005)
    assert np.linalg.norm(env.positions()[a][:2] - left[:2]) > 0.1
    # the joints of a node tree: the Burger's wheel hinges, driven by its diff_drive
    env.set_commands("wheels", np.array([[2.0, 2.0]]), robots=["burger"])
    env.step(500)
    assert env.joint_velocity("burger/left_wheel") == pytest.approx(2.0, rel=0.02)
    assert env.joint_position("burger/left_wheel") > 1.0
    with pytest.raises(KeyError, match="no physic node named 'wheel'"):
        env.joint_position("burger/wheel")
    with pytest.raises(KeyError, match="no artifact named 'b'"):
        env.attach("b", "puck")
    with pytest.raises(ssx.Error):
        env.attach("burger/left_wheel", "burger/left_wheel")  # one body
