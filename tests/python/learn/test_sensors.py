"""Batched sensor reads from Python (ssx._ssx.VectorEnvironment.read): one kind of sensor of every
robot of every environment in one (E, R, width) array, into an array the caller keeps, equal to
what one environment reads; what a robot lacks is refused naming what to add."""
import numpy as np
import pytest

import ssx
import ssx.learn

EPUCKS = """<scene><environment timestep="0.002" seed="3"/><type name="e" file="artifacts/epuck_full.xml"/><ground/>
<swarm type="e" count="3" name="e{i}" spacing="0.1" xyz="0 0 0"/></scene>"""


def test_read_every_robots_sensor_into_one_array():
    sim = ssx._ssx.VectorEnvironment(EPUCKS, 2, base_dir=ssx.data_directory(), threads=2)
    sim.set_commands("wheels", np.tile([1.0, 2.0], (2, 3, 1)))
    sim.step(100)
    proximity = sim.read("proximity")
    assert proximity.shape == (2, 3, 8) and proximity.dtype == np.float64
    assert proximity.max() > 0 and np.all((proximity >= 0) & (proximity <= 1))
    out = np.empty((2, 3, 12))
    assert sim.read("range_and_bearing", out=out, slots=3) is out
    assert np.all(out[:, :, [0, 4]] == 1.0) and np.all(out[:, :, 8:] == 0.0)  # two neighbours heard, slot 3 empty
    odometry = sim.read("odometry")
    assert odometry.shape == (2, 3, 9) and np.all(odometry[:, :, 2] > 0)  # turned left: right wheel faster
    # the copies are the simulation one environment of the same scene and seed runs
    alone = ssx.load_scene_string(EPUCKS, base_dir=ssx.data_directory(), seed=3, threads=1)
    alone.set_commands("wheels", np.tile([1.0, 2.0], (3, 1)))
    alone.step(100)
    assert np.array_equal(sim.state_hashes()[0], alone.state_hash())
    with pytest.raises(ValueError, match='add <sensor plugin="pose"/>'):
        sim.read("pose")
    with pytest.raises(ValueError, match="no sensor kind 'sonar'"):
        sim.read("sonar")
    with pytest.raises(ValueError, match="shape"):
        sim.read("proximity", out=np.empty((2, 3, 7)))
    sim.close()


BOXES = """<scene><environment timestep="0.002"/><type name="box" file="artifacts/box.xml"/><ground/>
<artifact type="box" name="low" xyz="0 0 0.1"/><artifact type="box" name="high" xyz="0 0 0.3"/></scene>"""


def test_contacts_say_who_touched_whom_and_how_hard():
    env = ssx.load_scene_string(BOXES, base_dir=ssx.data_directory())
    with pytest.raises(ssx.Error, match="record_contacts|recordContacts"):
        env.contact_list()
    env.record_contacts()
    env.step(500)
    contacts = env.contact_list()
    assert [(c.artifact, c.other, c.static) for c in contacts] == [("low", "ground", True), ("low", "high", False)]
    (_, _, ground, _, up, _), (_, _, stacked, _, down, _) = contacts
    assert ground == pytest.approx(2 * 9.81 * 0.002, rel=0.05) and up[2] > 0.99
    assert stacked == pytest.approx(9.81 * 0.002, rel=0.05) and down[2] < -0.99

    sim = ssx._ssx.VectorEnvironment(EPUCKS, 2, base_dir=ssx.data_directory(), threads=2)
    sim.record_contacts()
    sim.step(10)
    impulses = sim.contact_impulses()
    assert impulses.shape == (2, 3, 2)
    assert np.all(impulses[:, :, 0] > 0) and np.all(impulses[:, :, 1] == 0)  # on the ground, apart
    assert {(c.other, c.static) for c in sim.contact_list(1)} == {("ground", True)}
    sim.close()


def test_camera_images_of_every_robot_in_one_uint8_array(tmp_path):
    # e-pucks with a camera looking along +x, a red wall ahead: e1 is nearer it than e0 (which sees e1 too)
    epuck = (ssx.data_directory() / "artifacts" / "epuck.xml").read_text()
    camera = '<sensor plugin="camera" xyz="0.04 0 0.03" width="32" height="24" fov_deg="60" period="5"/>'
    (tmp_path / "eye.xml").write_text(epuck.replace("</artifact>", camera + "</artifact>"))
    xml = """<scene><environment timestep="0.002" seed="3"/><render engine="osmesa"/><type name="e" file="eye.xml"/>
    <ground/><swarm type="e" count="2" name="e{i}" spacing="0.3" xyz="0 0 0"/>
    <obstacle name="wall" xyz="0.6 0 0.1" color="1 0 0"><box size="0.05 2 0.2"/></obstacle></scene>"""
    sim = ssx._ssx.VectorEnvironment(xml, 3, base_dir=tmp_path, threads=2)
    with pytest.raises(ValueError, match="camera has not drawn yet: step"):
        sim.images()
    sim.step(5)  # one image each
    images = sim.images()
    assert images.shape == (3, 2, 24, 32, 3) and images.dtype == np.uint8
    red = (images[..., 0] > 150) & (images[..., 1] < 80) & (images[..., 2] < 80)
    share = red.mean(axis=(2, 3))  # (3, 2): how much of each picture the wall fills
    assert np.all(share[:, 1] > share[:, 0] + 0.03) and np.all(share[:, 0] > 0.02)
    assert np.array_equal(images[0], images[2])  # the copies are one scene
    out = np.zeros_like(images)
    assert sim.images(out=out) is out and np.array_equal(out, images)
    with pytest.raises(ValueError, match=r"shape \(3, 2, 24, 32, 3\)"):
        sim.images(out=np.zeros((3, 2, 24, 32), dtype=np.uint8))
    with pytest.raises(TypeError, match="uint8"):
        sim.images(out=np.zeros((3, 2, 24, 32, 3)))
    sim.close()
    # one environment reads the same pictures, (robots, height, width, 3)
    alone = ssx.load_scene_string(xml, base_dir=tmp_path, seed=3, threads=1)
    alone.step(5)
    assert np.array_equal(alone.images(), images[0])
    plain = ssx._ssx.VectorEnvironment(EPUCKS, 1, base_dir=ssx.data_directory(), threads=1)
    with pytest.raises(ValueError, match='add <sensor plugin="camera"/>'):
        plain.images()
    plain.close()


def test_one_environment_reads_every_robots_sensor_in_one_array():
    env = ssx.load_scene_string(EPUCKS, base_dir=ssx.data_directory(), seed=3, threads=1)
    env.set_commands("wheels", np.tile([1.0, 2.0], (3, 1)))
    env.step(100)
    sim = ssx._ssx.VectorEnvironment(EPUCKS, 2, base_dir=ssx.data_directory(), seed=3, threads=2)
    sim.set_commands("wheels", np.tile([1.0, 2.0], (2, 3, 1)))
    sim.step(100)
    for kind, slots in (("proximity", 0), ("ground", 0), ("odometry", 0), ("range_and_bearing", 3)):
        one = env.read(kind, slots=slots)
        assert one.shape == sim.read(kind, slots=slots).shape[1:]
        assert np.array_equal(one, sim.read(kind, slots=slots)[1])
    out = np.empty((3, 8))
    assert env.read("proximity", out=out) is out
    with pytest.raises(ValueError, match=r"shape \(3, 8\)"):
        env.read("proximity", out=np.empty((3, 7)))
    with pytest.raises(ValueError, match='add <sensor plugin="imu"/>') as refused:
        env.read("imu")
    assert str(refused.value).startswith("ssx: robot 'e0' has no imu")  # (no "<code>: error:" before it)
    with pytest.raises(ValueError, match='add <sensor plugin="camera"/>'):
        env.images()
    # the IMU as a kind: what imu() reads
    goto = ssx._ssx.VectorEnvironment(ssx.learn.GoTo().scene(), 2, base_dir=ssx.data_directory(), threads=1)
    goto.step(3)
    assert np.array_equal(goto.read("imu"), goto.imu())
    goto.close()
    sim.close()
