"""Every call of ssx.Environment and ssx.Recording, made in any order (before the first step, after
close(), with names that are not there), works or raises a Python exception: never a signal. Each
call runs in one child process, so that a crash names the call that made it."""
import subprocess
import sys
import textwrap

import pytest

import ssx

# quadrotors with IMU, a ghost, a Burger on hinged wheels, an operator steering one quadrotor
SCENE = """<scene>
  <environment timestep="0.002" seed="3"/>
  <type name="q" file="mk_quad.xml"/>
  <type name="f" file="mk_quad_formation.xml"/>
  <type name="burger" file="turtlebot3_burger.xml"/>
  <ground/>
  <swarm type="q" count="2" name="q{i}" spacing="1" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm>
  <artifact name="ghost" type="f" xyz="3 0 1"><ghost timeout="0.1"/></artifact>
  <artifact name="burger" type="burger" xyz="0 3 0"/>
  <extension name="op" plugin="operator" robots="q0"/>
</scene>"""

# (name, call): each made on a freshly loaded environment before any step, then again after close()
CALLS = [
    ("step", "env.step(1)"),
    ("time", "env.time; env.time_ns; env.timestep; env.step_count; env.duration; env.seed; env.threads"),
    ("names", "env.artifact_names(); env.dynamic_names(); env.setpoint_names()"),
    ("state_hash", "env.state_hash()"),
    ("bodies", "env.body_names(); env.body_poses()"),
    ("arrays", "env.positions(); env.orientations(); env.linear_velocities(); env.angular_velocities()"),
    ("set_setpoints", "env.set_setpoints([[0, 0, 1], [1, 0, 1]])"),
    ("set_commands", "env.set_commands('velocity', [[0, 0, 0, 0]], robots=['q0'])"),
    ("imu", "env.imu('q0')"),
    ("pose", "env.pose('q0')"),
    ("range", "env.range('ghost')"),
    ("flight_summary", "env.flight_summary()"),
    ("metrics", "env.metrics()"),
    ("set_external_pose", "env.set_external_pose('ghost', [3, 0, 1])"),
    ("ghost_status", "env.ghost_status('ghost')"),
    ("ghost_ages", "env.ghost_ages()"),
    ("operator_command", "env.operator_command('op', [0.1, 0, 0])"),
    ("operator_force", "env.operator_force('op')"),
    ("attach", "env.attach('q0', 'q1')"),
    ("release", "env.release('q0')"),
    ("detach", "env.detach('burger/left_wheel')"),
    ("attachments", "env.attachments('q0')"),
    ("joint_position", "env.joint_position('burger/left_wheel')"),
    ("joint_velocity", "env.joint_velocity('burger/left_wheel')"),
    ("set_joint_velocity", "env.set_joint_velocity('burger/left_wheel', 1.0)"),
    ("set_joint_position", "env.set_joint_position('burger/left_wheel', 1.0)"),
    ("contacts", "env.contacts()"),
    ("save_state", "env.save_state()"),
    ("restore_state", "env.restore_state(env.save_state())"),
    ("restore_garbage", "env.restore_state(b'not a state')"),
    ("run", "env.run(seconds=0.01, realtime=False)"),
    ("record", "env.record(RECORDING); env.step(5); env.stop_recording()"),
    ("stop_recording", "env.stop_recording()"),
    ("recording", "env.recording"),
    ("view_bad_rate", "env.view(port=0, rate_hz=-1)"),
    ("view_stop_view", "env.view(port=0); env.step(2); env.stop_view(); env.view(port=0); env.stop_view()"),
    ("stop_view", "env.stop_view()"),
    ("attach_renderer", "env.attach_renderer(snapshot=RECORDING + '.png'); env.step(3); env.detach_renderer()"),
    ("detach_renderer", "env.detach_renderer(); env.frame_count"),
    ("close", "env.close(); env.close()"),
]

CHILD = textwrap.dedent("""
    import sys, traceback
    import ssx
    scene, base, recording, order, code = sys.argv[1:6]
    RECORDING = recording
    env = ssx.load_scene_string(scene, base_dir=base, threads=1)
    if order == "after_close":
        env.close()
    try:
        exec(code)
        print("worked")
    except (TypeError, AttributeError, NameError) as e:  # the test's own mistake, not an answer
        print("wrong call", type(e).__name__, e)
    except Exception as e:  # an exception is an answer; a signal is not
        print("raised", type(e).__name__, e)
""")


@pytest.mark.parametrize("order", ["before_step", "after_close"])
@pytest.mark.parametrize("name,code", CALLS, ids=[c[0] for c in CALLS])
def test_a_call_in_any_order_works_or_raises(tmp_path, order, name, code):
    base = str(ssx.data_directory() / "artifacts")
    p = subprocess.run([sys.executable, "-c", CHILD, SCENE, base, str(tmp_path / "r.mcap"), order, code],
                       capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert p.returncode == 0, f"{name} ({order}) ended with status {p.returncode}: {p.stderr[-2000:]}"
    assert p.stdout.startswith(("worked", "raised")), p.stdout + p.stderr


def test_an_operator_command_before_the_first_step_says_why():
    env = ssx.load_scene_string(SCENE, base_dir=ssx.data_directory() / "artifacts", threads=1)
    with pytest.raises(Exception, match="has not started"):
        env.operator_command("op", [0.1, 0, 0])
    env.step(1)
    env.operator_command("op", [0.1, 0, 0])  # from the first step on it works


def test_view_refused_leaves_the_environment_as_it_was():
    env = ssx.load_scene_string(SCENE, base_dir=ssx.data_directory() / "artifacts", threads=1)
    for bad in (dict(rate_hz=-1), dict(bind="127.0.0.1+"), dict(port=70000)):
        with pytest.raises(Exception):
            env.view(port=bad.get("port", 0), **{k: v for k, v in bad.items() if k != "port"})
    url = env.view(port=0)  # another view works
    assert url.startswith("http://127.0.0.1:")
    env.step(5)  # and so do steps
    assert env.step_count == 5
    env.close()
