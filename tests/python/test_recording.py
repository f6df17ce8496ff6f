"""Recordings from Python: Environment.record and run(record=), read back with ssx.Recording into numpy,
and a saved state from it continuing the recorded scene to the recorded poses bit for bit."""
import numpy as np
import pytest

import ssx


def test_a_recording_read_back_into_numpy_and_continued_from_its_state(tmp_path):
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml")
    env.record(tmp_path / "hover.mcap", rate_hz=50, state_every_s=1)
    assert env.recording
    env.step(1500)  # 3 s
    summary = env.stop_recording()
    assert not env.recording
    assert (summary["samples"], summary["dropped"], summary["states"], summary["bodies"]) == (150, 0, 3, 3)

    r = ssx.Recording(tmp_path / "hover.mcap")
    assert len(r) == 150 and r.names == ["mk", "hb", "cf"] and r.complete
    assert np.allclose(r.times, 0.02 * np.arange(1, 151))
    p, q = r.positions(), r.orientations()
    assert p.shape == (150, 3, 3) and p.dtype == np.float32 and q.shape == (150, 3, 4)
    assert np.allclose(np.linalg.norm(q, axis=2), 1, atol=1e-6)
    assert np.array_equal(p[-1], env.positions().astype(np.float32))  # the last sample is the world now
    assert p[-1, :, 2].min() > 0.8  # they took off
    t, p_at, _ = r.at(1.011)
    assert t == pytest.approx(1.0) and np.array_equal(p_at, p[49])
    assert r.state_times == pytest.approx([0.02, 1.02, 2.02])
    # three bodies: Foxglove's channels by default, a transform message per sample and the shapes once
    assert r.channels() == {"/ssx/poses": 150, "/tf": 150, "/scene": 1} and r.scene == "quad_hover.xml"
    t_tf, tf = r.channel("/tf")[-1]
    assert t_tf == pytest.approx(3.0) and [f["child_frame_id"] for f in tf["transforms"]] == r.names
    assert [f["translation"]["z"] for f in tf["transforms"]] == pytest.approx(p[-1, :, 2], abs=1e-6)
    assert isinstance(r.channel("/ssx/poses")[0][1], bytes)
    with pytest.raises(RuntimeError, match="no channel '/imu'"):
        r.channel("/imu")

    # the recorded scene from its state at 1.5 s (re-simulated from the one saved at 1.02 s): the
    # recorded poses again, bit for bit
    at, state = r.snapshot(1.5)
    assert at == pytest.approx(1.5)
    again = ssx.load_scene_string(r.scene_xml, threads=1)
    again.restore_state(state)
    assert again.time == pytest.approx(1.5)
    for k in range(75, 150):
        again.step(10)
        assert np.array_equal(again.positions().astype(np.float32), p[k]), f"sample {k}"
    assert r.snapshot(1.02)[0] == pytest.approx(1.02) and r.snapshot(0)[0] == pytest.approx(0.02)
    with pytest.raises(ValueError, match="the recording ends at 3"):
        r.snapshot(3.5)


def test_run_records_and_refuses_what_it_must_not_write(tmp_path):
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml")
    out = env.run(1, realtime=False, record=tmp_path / "run.mcap")
    assert out["recording"]["samples"] == 25 and not env.recording
    assert len(ssx.Recording(tmp_path / "run.mcap")) == 25
    with pytest.raises(ValueError, match="which this run reads"):
        env.record(ssx.data_directory() / "scenes" / "quad_hover.xml")
    with pytest.raises(ValueError, match="not recording"):
        env.stop_recording()
    env.record(tmp_path / "two.mcap")
    with pytest.raises(ValueError, match="already recording"):
        env.record(tmp_path / "three.mcap")
    env.close()  # finishes the recording
    assert ssx.Recording(tmp_path / "two.mcap").complete
    (tmp_path / "not.mcap").write_text("<scene/>")
    with pytest.raises(RuntimeError, match=r"not.mcap: byte 0: not an MCAP file"):
        ssx.Recording(tmp_path / "not.mcap")


def test_optional_channels_from_python(tmp_path):
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml")
    env.record(tmp_path / "all.mcap", foxglove=False, timing=True, sensors=True, commands=True)
    env.step(50)
    env.set_commands("attitude", [[0.0, 0.0, 0.0, 9.0]], robots=["hb"])
    env.step(50)
    env.stop_recording()
    r = ssx.Recording(tmp_path / "all.mcap")
    assert set(r.channels()) == {"/ssx/poses", "/ssx/timing", "/ssx/sensors", "/ssx/commands"}
    first, last = r.channel("/ssx/commands")[0][1], r.channel("/ssx/commands")[-1][1]
    assert first["hb"]["level"] == "position" and len(first["hb"]["values"]) == 11
    assert last["hb"]["level"] == "attitude" and last["mk"]["level"] == "position"
    timing = r.channel("/ssx/timing")
    assert [m["step"] for _, m in timing] == list(range(100))
    assert all(m["total_ms"] >= m["physics_ms"] >= 0 for _, m in timing)
    t, sensors = r.channel("/ssx/sensors")[-1]
    assert t == pytest.approx(0.2) and set(sensors) == {"mk", "hb", "cf"}
    kinds = sorted(m["kind"] for m in sensors["mk"].values())
    assert "imu" in kinds and "pose" in kinds


def test_snapshot_between_saved_states_never_writes_over_the_scenes_absolute_outputs(tmp_path):
    log = tmp_path / "poses.csv"
    box = ssx.data_directory() / "artifacts" / "box.xml"
    env = ssx.load_scene_string(f"""<scene><environment timestep="0.01"/><type name="b" file="{box}"/>
      <artifact name="b" type="b" xyz="0 0 1"/>
      <extension name="log" plugin="csv_logger" file="{log}"/></scene>""")
    env.record(tmp_path / "run.mcap", state_every_s=1.0)
    env.step(150)
    env.close()
    written = log.read_bytes()
    r = ssx.Recording(tmp_path / "run.mcap")
    saved = r.state_times[1]
    assert r.snapshot(saved)[0] == pytest.approx(saved)  # a saved state: nothing re-simulated
    with pytest.raises(ValueError, match="poses.csv: it would be written over"):
        r.snapshot(1.2)
    assert log.read_bytes() == written


def test_a_run_switched_between_engines_records_its_switches_and_snapshots_make_them_again(tmp_path):
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml")
    assert env.physics_engine == "ode"
    env.record(tmp_path / "switched.mcap", rate_hz=50, state_every_s=1)
    env.step(600)  # 1.2 s on ODE
    env.switch_physics("bullet")
    assert env.physics_engine == "bullet"
    env.step(600)  # 1.2 s on Bullet
    env.switch_physics("ode")
    env.step(300)
    env.stop_recording()
    assert env.physics_switches == [(pytest.approx(1.2), "ode", "bullet"), (pytest.approx(2.4), "bullet", "ode")]
    with pytest.raises(ssx.ConfigError, match="unknown physics engine 'physx'"):
        env.switch_physics("physx")
    r = ssx.Recording(tmp_path / "switched.mcap")
    assert r.physics_switches == env.physics_switches
    # between two saved states across a switch (1.02 s on ODE, the switch at 1.2 s): re-simulated
    # with the switch made again, the poses are the recorded ones bit for bit
    t, state = r.snapshot(1.8)
    again = ssx.load_scene_string(r.scene_xml)
    again.restore_state(state)
    assert again.physics_engine == "bullet"
    _, p, _ = r.at(1.8)
    assert np.array_equal(again.positions().astype(np.float32), p)
