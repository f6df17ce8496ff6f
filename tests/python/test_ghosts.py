"""Ghosts and operators from Python: a real robot's poses in (set_external_pose), what its virtual
sensors measure of the simulated world out (range), its status and the ages of the poses used; an
operator's commands in (operator_command), the force it should feel out (operator_force)."""
import numpy as np
import pytest

import ssx

# a real formation quadrotor (its range sensor, 2.5 m) beside a virtual pillar, and a simulated one
SCENE = """<scene>
  <environment timestep="0.001" seed="3"/>
  <physics gravity="0 0 0"/>
  <type name="f" file="mk_quad_formation.xml"/>
  <obstacle name="pillar" xyz="2 0 1"><cylinder radius="0.2" length="2"/></obstacle>
  <artifact name="real" type="f" xyz="0 0 1"><ghost timeout="0.1"/></artifact>
  <artifact name="sim" type="f" xyz="0 2 1"><driver formation_index="0" formation_size="1"/></artifact>
  <extension name="op" plugin="operator" robots="sim" deadman_s="0.2"/>
</scene>"""


def load():
    return ssx.load_scene_string(SCENE, base_dir=ssx.data_directory() / "artifacts", threads=1)


def test_a_ghost_is_where_its_poses_say_and_its_range_sensor_sees_the_virtual_pillar():
    env = load()
    assert env.ghost_status("real")["lost"]
    for k in range(21):  # 100 Hz for 0.2 s, moving along x at 1 m/s
        env.set_external_pose("real", [0.5 + 0.01 * k, 0, 1], [1, 0, 0, 0], stamp=0.01 * k)
    env.step(100)
    real = env.dynamic_names().index("real")
    # the interpolation at t = 0.1 s
    np.testing.assert_allclose(env.positions()[real], [0.6, 0, 1], atol=1e-9)
    np.testing.assert_allclose(env.linear_velocities()[real], [1, 0, 0], atol=1e-9)
    r = env.range("real")
    names = [env.artifact_names()[i] for i in r["artifact"]]
    assert "pillar" in names
    pillar = names.index("pillar")
    # (the sensor runs every 10th step: it measured where the ghost was at its stamp)
    assert r["distance"][pillar] == pytest.approx(2 - 0.2 - (0.5 + r["stamp"]), abs=1e-9)
    assert r["obstacle"][pillar]
    status = env.ghost_status("real")
    assert not status["lost"] and status["samples"] == 21
    ages = env.ghost_ages()
    assert ages["count"] == 100 and ages["max"] <= 0.01


def test_a_ghost_without_poses_is_lost_and_silent():
    env = load()
    env.set_external_pose("real", [0, 0, 1])  # stamped now (t = 0)
    env.step(100)
    assert not env.ghost_status("real")["lost"]
    env.step(20)  # 0.12 s since the only pose
    status = env.ghost_status("real")
    assert status["lost"] and status["age"] == pytest.approx(0.12)


def test_bad_poses_and_names_are_refused():
    env = load()
    with pytest.raises(ValueError, match="position"):
        env.set_external_pose("real", [0, 0])
    with pytest.raises(ValueError, match="not finite|NaN"):
        env.set_external_pose("real", [0, 0, float("nan")])
    with pytest.raises(ValueError, match="unit quaternion"):
        env.set_external_pose("real", [0, 0, 1], [2, 0, 0, 0])
    with pytest.raises(ssx.Error, match="'sim' is not a ghost"):
        env.set_external_pose("sim", [0, 0, 1])
    with pytest.raises(KeyError, match="nobody"):
        env.ghost_status("nobody")


def test_an_operator_steers_and_feels_the_real_robot_near_it():
    env = load()
    env.set_external_pose("real", [0, 1.2, 1], stamp=0)  # 0.8 m south of "sim", held there
    env.step(10)
    force = env.operator_force("op")
    # away from the real robot (0.8 m south): north, force_gain (1 - d / force_range)
    np.testing.assert_allclose(force, [0, 2 * (1 - 0.8 / 1.5), 0], atol=1e-3)  # (sim hovers within 1 mm)
    sim = env.dynamic_names().index("sim")
    y0 = env.positions()[sim][1]
    for _ in range(10):  # 0.3 m/s north for 1 s
        env.operator_command("op", [0, 0.3, 0])
        env.step(100)
    assert env.positions()[sim][1] - y0 > 0.15
    with pytest.raises(KeyError, match="nobody"):
        env.operator_force("nobody")
    with pytest.raises(ValueError, match="velocity"):
        env.operator_command("op", [0, 1])
