"""A robot from URDF end to end from Python: the KUKA iiwa bolted to the world
(examples/scenes/iiwa_arm.xml, its URDF and OBJ meshes in examples/robots/kuka_iiwa) is commanded by
joint position and velocity, read back (joint positions and velocities, link poses), recorded with
its meshes, and rebuilt from the recording with its meshes drawn."""
import pathlib

import numpy as np
import pytest

import ssx

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENE = ROOT / "examples" / "scenes" / "iiwa_arm.xml"
LINKS = [f"arm/lbr_iiwa_link_{i}" for i in range(1, 8)]
POSE = [0.4, 0.5, -0.3, -1.0, 0.2, 0.6, -0.5]  # rad, within every joint's limits


def orange_pixels(png):
    image = pytest.importorskip("matplotlib.image").imread(str(png))[..., :3]
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(np.count_nonzero((r > 0.7) & (g > 0.25) & (g < 0.65) & (b < 0.3)))


def test_an_arm_from_urdf_is_commanded_read_recorded_and_rebuilt_with_its_meshes(tmp_path):
    env = ssx.load_scene(str(SCENE), threads=1)
    env.record(tmp_path / "arm.mcap", rate_hz=50, state_every_s=1.0, foxglove=True)
    for link, q in zip(LINKS, POSE):
        env.set_joint_position(link, q)
    env.step(5000)  # (joint 2, carrying the arm out of its tilt, swings past its target before it settles)
    # its seven moving links are the bodies (the base is the world's); each joint holds its pose
    assert env.body_names() == LINKS
    np.testing.assert_allclose([env.joint_position(link) for link in LINKS], POSE, atol=0.02)
    assert max(abs(env.joint_velocity(link)) for link in LINKS) < 0.05
    # joint 1 turned at 0.3 rad/s for 1 s: the flange swings about joint 1's axis (the base's z axis,
    # the base set up pitched by 0.3 rad), at its distance from it, and no other joint moves
    flange = env.body_poses()[6, :3].copy()
    env.set_joint_velocity(LINKS[0], 0.3)
    env.step(1000)
    assert env.joint_velocity(LINKS[0]) == pytest.approx(0.3, abs=0.01)
    assert env.joint_position(LINKS[0]) == pytest.approx(POSE[0] + 0.3, abs=0.02)
    np.testing.assert_allclose([env.joint_position(link) for link in LINKS[1:]], POSE[1:], atol=0.02)
    moved = env.body_poses()[6, :3]
    axis = np.array([np.sin(0.3), 0.0, np.cos(0.3)])
    before, after = (p - np.dot(p, axis) * axis for p in (flange, moved))
    turned = np.arctan2(np.dot(axis, np.cross(before, after)), np.dot(before, after))
    assert turned == pytest.approx(0.3, abs=0.02)
    assert np.linalg.norm(after) == pytest.approx(np.linalg.norm(before), abs=0.005)
    assert np.dot(moved, axis) == pytest.approx(np.dot(flange, axis), abs=0.005)
    env.stop_recording()
    # the recording: the links' poses as the run had them, and their meshes as Foxglove triangle lists
    recording = ssx.Recording(tmp_path / "arm.mcap")
    assert recording.names == LINKS
    assert recording.times[-1] == pytest.approx(env.time)
    np.testing.assert_allclose(recording.positions()[-1], env.body_poses()[:, :3], atol=1e-5)
    scene = recording.channel("/scene")[0][1]
    triangles = {e["id"]: len(e["triangles"]) for e in scene["entities"]}
    assert all(triangles.get(link, 0) > 0 for link in LINKS), triangles
    # rebuilt from the recording (the scene it holds names the URDF) at its saved state: the arm
    # drawn with its meshes (KUKA's orange links), where it was
    t, state = recording.snapshot(recording.state_times[-1])
    assert t > 5.0
    rebuilt = ssx.load_scene_string(recording.scene_xml, base_dir=tmp_path, threads=1)
    rebuilt.restore_state(state)
    assert rebuilt.time == pytest.approx(t)
    _, positions, _ = recording.at(t)
    np.testing.assert_allclose(rebuilt.body_poses()[:, :3], positions, atol=1e-5)
    rebuilt.attach_renderer(snapshot=tmp_path / "rebuilt.png", engine="osmesa", width=640, height=480)
    rebuilt.step(1)
    rebuilt.detach_renderer()
    assert orange_pixels(tmp_path / "rebuilt.png") > 150
