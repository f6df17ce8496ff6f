"""The Python module: loading, stepping, state arrays, set-points, measurements, save and restore,
run and Ctrl-C, the GIL. Run by ctest (python_tests) with PYTHONPATH=<build>/python."""
import logging
import os
import signal
import threading
import time

import numpy as np
import pytest

import ssx

G = 9.80665

# nine mk_quads on a 3 x 3 grid, installed type by name, hovering 1 m above their start
HOVER = """<scene>
  <environment timestep="0.002" seed="7" duration="3"/>
  <type name="mk_quad"/>
  <ground/>
  <swarm type="mk_quad" count="9" name="q{i}" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm>
</scene>"""

# two formation quadrotors 1.5 m apart: each sees the other with its range sensor (2.5 m)
PAIR = """<scene>
  <environment timestep="0.002" seed="3"/>
  <type name="f" file="mk_quad_formation.xml"/>
  <artifact name="a" type="f" xyz="0 0 1"><driver formation_index="0" formation_size="2"/></artifact>
  <artifact name="b" type="f" xyz="1.5 0 1"><driver formation_index="1" formation_size="2"/></artifact>
</scene>"""


def hover(**kw):
    return ssx.load_scene_string(HOVER, label="hover.xml", **kw)


def artifacts_dir():
    return ssx.data_directory() / "artifacts"


def test_load_step_and_names():
    env = hover(threads=1)
    assert env.artifact_names() == ["ground"] + [f"q{i}" for i in range(9)]
    assert env.dynamic_names() == [f"q{i}" for i in range(9)]
    assert env.setpoint_names() == env.dynamic_names()
    assert env.step_count == 0 and env.time == 0.0
    assert env.timestep == pytest.approx(0.002)
    assert env.duration == pytest.approx(3.0)
    env.step()
    env.step(9)
    assert env.step_count == 10
    assert env.time_ns == 20_000_000
    assert env.time == pytest.approx(0.02)
    with pytest.raises(ValueError):
        env.step(-1)


def test_scene_errors_carry_file_and_line_and_start_nothing(tmp_path):
    scene = tmp_path / "broken.xml"
    log = tmp_path / "poses.csv"
    scene.write_text(f"""<scene>
  <type name="mk_quad"/>
  <extension name="log" plugin="csv_logger" file="{log}" rate_hz="10"/>
  <swarm type="mk_quad" count="2"><driver period="0"/></swarm>
  <physics partitions="0"/>
</scene>""")
    with pytest.raises(ssx.SceneError) as info:
        ssx.load_scene(scene)
    text = str(info.value)
    assert f"{scene}:4: error:" in text
    assert f"{scene}:5: error: <physics>: ode engine: parameter 'partitions'" in text
    assert "nothing was run" in text
    assert isinstance(info.value, ssx.Error)
    assert not log.exists()  # the logger's file was never opened
    with pytest.raises(ssx.SceneError, match=r"memory.xml:1: error: the root element"):
        ssx.load_scene_string("<robot/>", label="memory.xml")


def test_state_arrays_are_the_bodies_in_artifact_order():
    env = hover(threads=1)
    p0 = env.positions()
    assert p0.shape == (9, 3) and p0.dtype == np.float64
    # the 3 x 3 grid, 1.5 m apart, placed at z = 0.05
    np.testing.assert_allclose(p0[:, 2], 0.05)
    np.testing.assert_allclose(p0[1] - p0[0], [1.5, 0, 0], atol=1e-12)
    env.step(1000)  # 2 s: climbing to 1.05 m
    p, q, v, w = env.positions(), env.orientations(), env.linear_velocities(), env.angular_velocities()
    assert q.shape == (9, 4) and v.shape == (9, 3) and w.shape == (9, 3)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-9)
    assert np.all(p[:, 2] > 0.5)
    # the velocity is the derivative of the position: one more step moves each body by v * dt
    env.step(1)
    p1, v1 = env.positions(), env.linear_velocities()
    np.testing.assert_allclose((p1 - p) / env.timestep, (v + v1) / 2, atol=2e-3)
    # the pose sensor's reading (0.5 mm noise) agrees with the arrays
    m = env.pose("q4")
    np.testing.assert_allclose(m["position"], p1[4], atol=5e-3)
    assert m["stamp"] == pytest.approx(env.time)
    assert m["orientation"].shape == (4,)


def test_body_poses_include_the_moving_parts_of_a_static_rooted_arm(tmp_path):
    (tmp_path / "pendulum.xml").write_text("""<artifact>
  <physic name="base" static="true"><box size="0.1 0.1 0.1"/>
    <physic name="arm" joint="hinge" axis="0 1 0" rpy="0 1 0" mass="1"><sphere radius="0.05" xyz="0 0 -1"/></physic>
  </physic>
</artifact>""")
    env = ssx.load_scene_string("""<scene><environment timestep="0.01"/><type name="p" file="pendulum.xml"/>
      <artifact name="p" type="p" xyz="0 0 2"/><artifact name="ball" type="p" xyz="3 0 2"/></scene>""", base_dir=tmp_path)
    with pytest.raises(RuntimeError, match="from the first step on"):
        env.body_names()
    env.step(50)
    assert env.dynamic_names() == []  # no artifact's root moves
    assert env.body_names() == ["p/arm", "ball/arm"]
    poses = env.body_poses()
    assert poses.shape == (2, 7)
    assert np.allclose(poses[:, :3], [[0, 0, 2], [3, 0, 2]], atol=0.05)  # the arms' nodes: at their pivots
    # the arm turned from 1 rad about y towards the bottom: its quaternion's angle is below 1 rad
    assert 2 * np.arccos(abs(poses[0, 3])) < 0.9


def test_same_seed_same_bits_on_any_thread_count():
    a, b = hover(threads=1), hover(threads=2)
    a.step(300)
    b.step(300)
    assert a.state_hash() == b.state_hash()
    assert np.array_equal(a.positions(), b.positions())
    c = hover(threads=1, seed=8)
    c.step(300)
    assert c.seed == 8 and c.state_hash() != a.state_hash()


def test_seeds_have_one_range_everywhere():
    assert hover(seed=2**64 - 1).seed == 2**64 - 1
    for bad in (2**64, -1):
        with pytest.raises(TypeError):
            hover(seed=bad)


def test_either_physics_engine_flies_the_swarm():
    assert ssx.physics_engines() == ["ode", "bullet"]
    ode, bullet = hover(), hover(physics="bullet")
    ode.step(1500)
    bullet.step(1500)
    # both lift the nine quadrotors to 1 m above their start, to within a centimetre of each other
    assert np.allclose(ode.positions()[:, 2], 1.05, atol=0.05)
    assert np.allclose(ode.positions(), bullet.positions(), atol=0.01)
    assert ode.state_hash() != bullet.state_hash()
    with pytest.raises(ValueError, match="unknown physics engine 'physx'"):
        hover(physics="physx")


def test_setpoints_fly_the_swarm_there():
    env = hover(threads=2)
    start = env.positions()
    target = start + np.array([0.5, -0.5, 1.5])
    env.set_setpoints(target, velocities=np.zeros((9, 3)), yaws=np.full(9, 0.3))
    env.step(3000)  # 6 s
    np.testing.assert_allclose(env.positions(), target, atol=0.05)
    yaw = np.array([np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)) for w, x, y, z in env.orientations()])
    np.testing.assert_allclose(yaw, 0.3, atol=0.02)
    # every row is checked before any driver gets one
    with pytest.raises(ValueError, match=r"shape \(9, 3\).*got \(8, 3\)"):
        env.set_setpoints(target[:8])
    bad = target.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN or an infinity \\(row 3\\)"):
        env.set_setpoints(bad)
    with pytest.raises(ValueError, match=r"yaws must have shape \(9,\)"):
        env.set_setpoints(target, yaws=np.zeros(3))


def test_set_setpoints_for_chosen_robots_with_feed_forward():
    env = hover(threads=1)
    env.step(2500)  # 5 s: settled 1 m above the start
    start = env.positions()
    names = env.setpoint_names()
    # two robots, one by name and one by index; the others keep their own reference
    target = start[[4, 0]] + np.array([0.0, 0.0, 0.5])
    env.set_setpoints(target, accelerations=np.zeros((2, 3)), yaw_rates=np.zeros(2), robots=[names[4], 0])
    env.step(2500)
    np.testing.assert_allclose(env.positions()[[4, 0]], target, atol=0.05)
    np.testing.assert_allclose(env.positions()[1], start[1], atol=0.02)
    with pytest.raises(KeyError, match="no robot named 'nobody'"):
        env.set_setpoints(target, robots=["nobody", 1])
    with pytest.raises(IndexError, match="robot index 9 is outside 0..8"):
        env.set_setpoints(target, robots=[1, 9])
    with pytest.raises(ValueError, match="named twice"):
        env.set_setpoints(target, robots=[1, names[1]])
    with pytest.raises(ValueError, match=r"accelerations must have shape \(2, 3\)"):
        env.set_setpoints(target, accelerations=np.zeros((9, 3)), robots=[1, 2])


def yaw_of(q):
    w, x, y, z = q
    return np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def test_set_commands_at_every_level():
    env = hover(threads=2)
    env.step(2500)  # settled
    m, n = 0.82, 9  # the mk_quad's mass; nine of them
    start = env.positions()
    # velocity: the whole swarm moves at 0.5 m/s along y while turning at 0.2 rad/s
    env.set_commands("velocity", np.tile([0.0, 0.5, 0.0, 0.2], (n, 1)))
    env.step(1500)  # 3 s
    np.testing.assert_allclose(env.linear_velocities()[:, 1], 0.5, atol=0.05)
    np.testing.assert_allclose(env.angular_velocities()[:, 2], 0.2, atol=0.05)
    env.set_commands("velocity", np.zeros((n, 4)))
    env.step(1500)
    before = env.positions()
    env.set_commands("attitude", [[0.0, 0.0, 0.0, m * G]], robots=[3])
    env.set_commands("rates", [[0.0, 0.0, 0.0, m * G]], robots=[5])
    hover_speed = np.sqrt(m * G / 4e-5)
    env.set_commands("rotors", np.full((1, 4), hover_speed), robots=["q7"])
    env.step(500)  # 1 s
    after = env.positions()
    # open loop, the lower levels keep them upright and near where they were for a second (no
    # position loop corrects their drift); the others hold their place
    for row in (3, 5, 7):
        np.testing.assert_allclose(after[row], before[row], atol=0.3)
        w, x, y, z = env.orientations()[row]
        assert 1 - 2 * (x * x + y * y) > np.cos(0.1)  # tilted less than 0.1 rad
    for row in (0, 1, 2, 4, 6, 8):
        np.testing.assert_allclose(after[row], before[row], atol=0.02)
    # position with its yaw, back where they started
    rows = np.hstack([start, np.full((n, 1), 0.5)])
    env.set_commands("position", rows)
    env.step(5000)  # 10 s: 3 m back
    np.testing.assert_allclose(env.positions(), start, atol=0.05)
    np.testing.assert_allclose([yaw_of(q) for q in env.orientations()], 0.5, atol=0.03)


def test_set_commands_refuses_before_any_robot_gets_a_row():
    env = hover(threads=1)
    env.step(500)
    before = env.save_state()
    rows = np.tile([0.0, 0.0, 0.0, 8.0], (9, 1))
    bad = rows.copy()
    bad[6, 1] = np.nan
    with pytest.raises(ValueError, match=r"robot 'q6' \(row 6\): an attitude command holds a NaN"):
        env.set_commands("attitude", bad)
    bad = rows.copy()
    bad[2, 3] = -1
    with pytest.raises(ValueError, match="thrust must not be negative"):
        env.set_commands("attitude", bad)
    with pytest.raises(ValueError, match="unknown command level 'thrust'"):
        env.set_commands("thrust", rows)
    with pytest.raises(ValueError, match=r"has 4 \(one speed per rotor\) values, got 3"):
        env.set_commands("rotors", np.full((9, 3), 400.0))
    with pytest.raises(ValueError, match="4, 7, 10 or 11|got 5"):
        env.set_commands("position", np.zeros((9, 5)))
    with pytest.raises(ValueError, match=r"one row per robot commanded \(2\)"):
        env.set_commands("velocity", rows, robots=[0, 1])
    with pytest.raises(TypeError, match="list of names or indices"):
        env.set_commands("velocity", rows[:1], robots="q0")
    with pytest.raises(TypeError, match="list of names or indices"):
        env.set_commands("velocity", rows[:1], robots=[True])
    # nothing was applied: the run goes on as if no call was made
    env.step(200)
    expected = env.state_hash()
    env.restore_state(before)
    env.step(200)
    assert env.state_hash() == expected


def test_imu_reads_gravity_when_hovering():
    env = hover(threads=1)
    env.step(2500)  # 5 s: settled at 1.05 m
    m = env.imu("q0")
    assert m["stamp"] == pytest.approx(env.time)
    assert m["accelerometer"][2] == pytest.approx(G, abs=0.3)
    assert np.all(np.abs(m["gyroscope"]) < 0.1)
    np.testing.assert_array_equal(m["accelerometer_counts"], np.round(m["accelerometer"] / m["accelerometer_lsb"]))
    with pytest.raises(KeyError):
        env.imu("nobody")
    with pytest.raises(ValueError, match="has no range sensor"):
        env.range("q0")
    with pytest.raises(ValueError, match=r"sensor 0 of artifact 'q0' \(imu\) does not measure pose"):
        env.pose("q0", sensor=0)
    with pytest.raises(IndexError):
        env.imu("q0", sensor=7)


def test_range_sees_the_neighbour():
    env = ssx.load_scene_string(PAIR, base_dir=artifacts_dir(), threads=1)
    env.step(10)  # the range sensor runs every 10 steps
    r = env.range("a")
    assert list(r["artifact"]) == [env.artifact_names().index("b")]
    assert r["distance"][0] == pytest.approx(1.5, abs=0.02)
    assert r["relative"].shape == (1, 3)
    np.testing.assert_allclose(r["relative"][0], env.positions()[1] - env.positions()[0], atol=0.02)
    assert not r["obstacle"][0]


def test_save_and_restore_continue_bitwise():
    env = hover(threads=2)
    env.step(200)
    saved = env.save_state()
    assert isinstance(saved, bytes) and len(saved) > 0
    env.step(300)
    expected, expected_p = env.state_hash(), env.positions()
    env.restore_state(saved)
    assert env.step_count == 200
    env.step(300)
    assert env.state_hash() == expected
    assert np.array_equal(env.positions(), expected_p)
    # in another environment loaded from the same scene, on another thread count
    other = hover(threads=1)
    other.restore_state(saved)
    other.step(300)
    assert other.state_hash() == expected
    # a damaged state is refused and changes nothing
    before = env.state_hash()
    damaged = bytearray(saved)
    damaged[len(damaged) // 2] ^= 0xFF
    with pytest.raises(ssx.StateError):
        env.restore_state(bytes(damaged))
    with pytest.raises(ssx.StateError):
        ssx.load_scene_string(PAIR, base_dir=artifacts_dir()).restore_state(saved)
    assert env.state_hash() == before


def test_run_returns_the_timing_summary():
    env = hover(threads=1)
    s = env.run(0.5, realtime=False)
    assert s["steps"] == 250 and env.step_count == 250
    assert s["simulated_s"] == pytest.approx(0.5)
    assert 0 < s["median_ms"] <= s["p99_ms"] <= s["max_ms"]
    # late steps, told apart (none unpaced); paced, the kinds never add up to more than the late
    assert (s["overruns"], s["overruns_long"], s["overruns_began_late"]) == (0, 0, 0)
    paced = env.run(0.05, realtime=True)
    assert paced["overruns_long"] + paced["overruns_began_late"] <= paced["overruns"]
    s = env.run(realtime=False)  # the scene's duration, 3 s
    assert env.step_count == 250 + 25 + 1500
    with pytest.raises(ValueError, match="needs seconds"):
        ssx.load_scene_string(PAIR, base_dir=artifacts_dir()).run()


def test_a_real_time_priority_is_checked_before_a_step():
    env = hover(threads=2)
    for bad in (0, 100, -3):
        with pytest.raises(ValueError, match="priority must be from 1 to 99"):
            env.run(0.05, realtime=True, realtime_priority=bad)
    assert env.step_count == 0
    if _fifo_permitted():
        s = env.run(0.05, realtime=True, realtime_priority=5)
        assert s["steps"] == 25
        assert os.sched_getscheduler(0) == os.SCHED_OTHER  # put back after the run
    else:
        with pytest.raises(ValueError, match="not permitted"):
            env.run(0.05, realtime=True, realtime_priority=5)
        assert env.step_count == 0


def _fifo_permitted():
    # as the library checks it: on a thread of its own, which ends
    result = []

    def probe():
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(5))
            result.append(True)
        except PermissionError:
            result.append(False)

    t = threading.Thread(target=probe)
    t.start()
    t.join()
    return result[0]


def test_ctrl_c_stops_a_run_between_steps():
    env = hover(threads=1)
    # a real SIGINT, sent from another thread while the main thread is inside run()
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    began = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        env.run(60.0, realtime=True)
    timer.join()
    assert time.monotonic() - began < 10
    stopped = env.step_count
    assert 0 < stopped < 30000
    env.step(5)  # still usable
    assert env.step_count == stopped + 5


def test_ctrl_c_stops_step_n_between_steps_and_the_steps_are_the_same():
    env = hover(threads=1)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    began = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        env.step(10**12)
    timer.join()
    assert time.monotonic() - began < 10
    stopped = env.step_count
    assert stopped > 0
    env.step(5)  # still usable
    assert env.step_count == stopped + 5
    # stepping n at once gives the bits of stepping one at a time
    a, b = hover(threads=1), hover(threads=1)
    a.step(600)
    for _ in range(600):
        b.step(1)
    assert a.state_hash() == b.state_hash()


def refusals_while_stepping(env, reads, steps=20000):
    """Calls each of `reads` over and over while another thread steps `env`; how often each was
    refused with RuntimeError (any other outcome of a read fails the test)."""
    done = threading.Event()

    def long_step():
        env.step(steps)
        done.set()

    t = threading.Thread(target=long_step)
    t.start()
    refused = {name: 0 for name in reads}
    while not done.is_set():
        for name, read in reads.items():
            try:
                read()
            except RuntimeError as e:
                assert "in use by another thread" in str(e)
                refused[name] += 1
    t.join()
    return refused


def test_stepping_releases_the_gil():
    env = hover(threads=1)
    # while the other thread is inside step(), this thread runs Python (so the GIL is free) and the
    # environment refuses a second user instead of racing it
    refused = refusals_while_stepping(env, {"positions": lambda: env.positions()})
    assert refused["positions"] > 0
    assert env.step_count == 20000


def test_reads_while_another_thread_steps_are_refused_not_torn():
    env = hover(threads=1)
    refused = refusals_while_stepping(env, {"state_hash": lambda: env.state_hash(), "time": lambda: env.time,
                                            "step_count": lambda: env.step_count,
                                            "artifact_names": lambda: env.artifact_names(),
                                            "threads": lambda: env.threads, "pose": lambda: env.pose("q0"),
                                            "save_state": lambda: env.save_state()})
    assert all(n > 0 for n in refused.values()), refused


def test_what_is_fixed_from_loading_on_reads_while_stepping_and_repr_never_raises():
    env = hover(threads=1)
    names, setpoints = env.dynamic_names(), env.setpoint_names()
    seen = []
    refused = refusals_while_stepping(env, {"fixed": lambda: seen.append(
        (env.dynamic_names() == names, env.setpoint_names() == setpoints, env.timestep, env.seed)),
        "repr": lambda: seen.append(repr(env))})
    assert refused == {"fixed": 0, "repr": 0}
    assert all(s[0] and s[1] for s in seen if isinstance(s, tuple))
    assert any("stepping in another thread" in s for s in seen if isinstance(s, str))
    assert "t = 40.000000 s" in repr(env)


def test_close_finishes_the_run(tmp_path):
    log = tmp_path / "log.csv"
    scene = HOVER.replace("<ground/>", f'<ground/><extension name="log" plugin="csv_logger" file="{log}" rate_hz="10"/>')
    with ssx.load_scene_string(scene) as env:
        env.step(500)  # 1 s at 10 Hz
    rows = log.read_text().splitlines()
    assert len(rows) == 1 + 9 * 10


def test_the_library_speaks_through_pythons_logging(caplog):
    caplog.set_level(logging.INFO, logger="ssx")
    # a warning of loading, and one written while stepping (the GIL released, taken again to log)
    env = ssx.load_scene_string('<scene><environment timestep="0.002" colour="red"/>'
                                '<render engine="null"><camera name="c"/></render>'
                                '<type name="b" file="box.xml"/><artifact name="b" type="b"/></scene>',
                                ssx.data_directory() / "artifacts")
    env.step(5)
    messages = [(r.name, r.levelname, r.getMessage()) for r in caplog.records]
    assert ("ssx", "WARNING", "<string>:1: warning: unknown attribute 'colour' of <environment> (ignored)") in messages
    assert any(n == "ssx" and "draws no pixels: camera 'c' gets no frames" in m for n, _, m in messages)


def test_flight_summary_metrics_and_contacts_say_what_happened_to_the_robots():
    env = ssx.load_scene(ssx.data_directory() / "scenes" / "quad_hover.xml")
    assert env.contacts() == 0  # not started
    env.step(2500)  # 5 s: they took off and hover 1 m up
    s = env.flight_summary()
    assert (s["robots"], s["airborne"], s["landed"], s["crashed"], s["collisions"]) == (3, 3, 0, 0, 0)
    assert s["first_collision_s"] is None
    assert abs(s["closest_approach_m"] - 1.5) < 0.05 and s["closest_pair"] in ("mk and hb", "hb and cf")
    assert 0.9 < s["mean_distance_flown_m"] < 1.5
    assert s["text"].startswith("robots 3: airborne 3, landed 0, crashed 0; collisions 0")
    assert env.contacts() == 0  # none touches anything in the air
    box = ssx.load_scene_string('<scene><ground/><type name="b" file="box.xml"/><artifact name="b" type="b" xyz="0 0 0.5"/>'
                                '</scene>', ssx.data_directory() / "artifacts")
    box.step(2000)  # fallen and resting on the ground
    assert box.contacts() > 0
    assert s["impacts"] == 0 and s["hardest_impact_robot"] == ""
    fallen = box.flight_summary()  # it hit the ground at about 3 m/s: an impact, and down after one
    assert (fallen["crashed"], fallen["impacts"], fallen["hardest_impact_robot"]) == (1, 1, "b")
    assert fallen["hardest_impact_mps"] > 1.5
    # a formation publishes its error per member; hovering quadrotors publish nothing
    assert env.metrics() == {}
    formation = ssx.load_scene(ssx.data_directory() / "scenes" / "formation_sphere.xml", threads=1)
    formation.step(500)
    m = formation.metrics()
    assert len(m) == 70 and all(set(v) == {"formation_error"} for v in m.values())
