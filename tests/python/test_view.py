"""Looking at a run from Python while it goes on: the live view and the scene cameras' frames are
attached between steps and taken off again without a restart, and change nothing in the run."""
import urllib.request

import pytest

import ssx

SCENE = """<scene>
  <environment timestep="0.002" seed="4"/>
  <type name="q" file="mk_quad.xml"/>
  <ground/>
  <swarm type="q" count="4" spacing="1.5" xyz="0 0 0.05"><driver offset="0 0 1"/></swarm>
</scene>"""


def load():
    return ssx.load_scene_string(SCENE, base_dir=ssx.data_directory() / "artifacts", threads=1)


def test_a_view_attached_after_steps_serves_the_run_and_comes_off_again():
    env, ref = load(), load()
    env.step(100)
    ref.step(100)
    url = env.view(port=0)  # attached to the run as it is
    assert urllib.request.urlopen(url, timeout=10).status == 200
    with pytest.raises(ValueError, match="attached already"):
        env.view(port=0)
    env.step(100)
    ref.step(100)
    state = env.save_state()
    env.stop_view()
    with pytest.raises(Exception):
        urllib.request.urlopen(url, timeout=2)  # nothing listens any more
    with pytest.raises(ValueError, match="no view is attached"):
        env.stop_view()
    url = env.view(port=0)  # another one, later
    assert urllib.request.urlopen(url, timeout=10).status == 200
    env.step(50)
    ref.step(50)
    # the view is no part of the run: the same bits, and the states restore into each other
    assert env.state_hash() == ref.state_hash()
    assert state == load_and_save(200)
    env.close()
    ref.close()


def load_and_save(steps):
    env = load()
    env.step(steps)
    state = env.save_state()
    env.close()
    return state


def test_frames_attached_and_detached_between_steps_are_written_and_change_nothing(tmp_path):
    env, ref = load(), load()
    env.step(250)
    ref.step(250)
    assert env.frame_count == 0
    env.attach_renderer(snapshot=tmp_path / "middle.png", frames=tmp_path / "frames", rate_hz=50, width=64, height=48)
    env.step(100)  # every 10 steps: 10 frames
    ref.step(100)
    env.detach_renderer()
    assert env.frame_count == 10
    assert len(list((tmp_path / "frames").glob("*.png"))) == 10
    assert (tmp_path / "middle.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"  # written when it came off
    env.step(100)
    ref.step(100)
    assert env.frame_count == 10
    assert env.state_hash() == ref.state_hash()
    # two outputs onto one file are refused, nothing attached
    with pytest.raises(ValueError, match="middle.png"):
        env.attach_renderer(snapshot=tmp_path / "middle.png", video=tmp_path / "middle.png")
    env.step(10)
    assert env.frame_count == 10
    env.close()
    ref.close()
