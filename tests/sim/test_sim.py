"""The PyBullet tabletop: skills, failures, determinism, rendering and export."""

from __future__ import annotations

import os
import pickle
import sys

import imageio.v2 as iio
import numpy as np
import pytest

from activeintent.sim.env import SimConfig, TabletopEnv
from activeintent.sim.render import render_frame, render_state
from activeintent.sim.video import export_video, frame_times
from activeintent.world import (
    BLOCK_SIZE,
    PutAt,
    PutIn,
    PutNextTo,
    PutOn,
    SceneError,
    WorldState,
    apply_plan,
    relations,
    table_position_name,
)
from activeintent.world.trajectory import Trajectory

SCENE = ["red block", "green block", "yellow block", "blue bowl", "purple bowl"]
PLAN = [
    PutIn(block="red block", bowl="blue bowl"),
    PutOn(block="green block", target="yellow block"),
    PutNextTo(block="green block", target="purple bowl"),
    PutAt(block="yellow block", position="bottom right corner"),
]
# A controlled layout: the moving block far from the target block in the middle.
CONTROLLED = WorldState(positions={
    "red block": (0.2, -0.7, 0.02),
    "green block": (0.0, -0.5, 0.02),
    "yellow block": (-0.2, -0.3, 0.02),
    "blue bowl": (-0.18, -0.68, 0.0),
})


@pytest.fixture(scope="module")
def env():
    with TabletopEnv(SimConfig()) as e:
        yield e


@pytest.fixture(scope="module")
def demo(env):
    """The 4-step plan on a seeded scene, executed once for the whole module."""
    env.reset(SCENE, seed=0)
    return env.execute(PLAN)


def run(env: TabletopEnv, state: WorldState, *plan) -> Trajectory:
    env.reset_to(state)
    return env.execute(list(plan))


def test_put_in_bowl(env):
    traj = run(env, CONTROLLED, PutIn(block="red block", bowl="blue bowl"))
    assert traj.steps[0].ok, traj.steps[0].reason
    assert relations(traj.final_state).in_bowl("red block") == "blue bowl"


def test_put_on_block(env):
    traj = run(env, CONTROLLED, PutOn(block="red block", target="green block"))
    assert traj.steps[0].ok, traj.steps[0].reason
    rel = relations(traj.final_state)
    assert rel.below("red block") == "green block"
    assert "red block" not in rel.on_table


def test_stack_of_three_stays_up(env):
    traj = run(
        env, CONTROLLED,
        PutOn(block="red block", target="green block"),
        PutOn(block="yellow block", target="red block"),
    )
    assert all(s.ok for s in traj.steps), [s.reason for s in traj.steps]
    rel = relations(traj.final_state)
    assert rel.below("yellow block") == "red block" and rel.below("red block") == "green block"
    assert traj.final_state.pos("yellow block")[2] == pytest.approx(2.5 * BLOCK_SIZE, abs=0.005)


@pytest.mark.parametrize("side,axis,sign", [("left", 0, -1), ("right", 0, 1), ("front", 1, -1), ("behind", 1, 1)])
def test_put_next_to_each_side(env, side, axis, sign):
    traj = run(env, CONTROLLED, PutNextTo(block="red block", target="green block", side=side))
    assert traj.steps[0].ok, traj.steps[0].reason
    final = traj.final_state
    assert relations(final).is_next_to("red block", "green block")
    delta = final.pos("red block") - final.pos("green block")
    assert sign * delta[axis] > BLOCK_SIZE  # on the asked side
    assert abs(delta[1 - axis]) < 0.01
    assert "red block" in relations(final).on_table


def test_put_at_named_position_and_point(env):
    traj = run(
        env, CONTROLLED,
        PutAt(block="red block", position="top right corner"),
        PutAt(block="yellow block", position=(0.05, -0.55)),
    )
    assert all(s.ok for s in traj.steps), [s.reason for s in traj.steps]
    final = traj.final_state
    assert relations(final).table_position["red block"] == "top right corner"
    assert np.allclose(final.pos("yellow block")[:2], (0.05, -0.55), atol=0.005)
    assert table_position_name(final.pos("yellow block")[:2]) == "middle"


def test_whole_workspace_is_reachable(env):
    """Corners of the 60 cm square and the edge right in front of the robot base."""
    points = [(-0.3, -0.8), (0.3, -0.8), (0.3, -0.2), (-0.3, -0.2), (0.0, -0.2), (0.0, -0.8)]
    traj = run(env, CONTROLLED, *[PutAt(block="red block", position=pt) for pt in points])
    assert all(s.ok for s in traj.steps), [s.reason for s in traj.steps]
    for step, pt in zip(traj.steps, points, strict=True):
        assert np.allclose(step.state_after.pos("red block")[:2], pt, atol=0.005)


def test_failed_steps_are_recorded_not_raised(env):
    plan = [
        PutOn(block="red block", target="green block"),
        PutAt(block="green block", position="middle"),  # under the red block
        PutIn(block="pink block", bowl="blue bowl"),  # not in the scene
        PutAt(block="yellow block", position=(0.6, -0.5)),  # out of reach
        PutIn(block="blue bowl", bowl="blue bowl"),  # bowls never move
        PutAt(block="yellow block", position="nonsense"),  # unknown position
    ]
    traj = run(env, CONTROLLED, *plan)
    ok = [s.ok for s in traj.steps]
    assert ok == [True, False, False, False, False, False]
    reasons = [s.reason for s in traj.steps[1:]]
    assert "under the red block" in reasons[0]
    assert "not in the scene" in reasons[1] and "green block" in reasons[1]  # lists the objects
    assert "out of reach" in reasons[2]
    assert "bowl" in reasons[3]
    assert "top left corner" in reasons[4]  # valid options are listed
    for step in traj.steps[1:]:
        assert step.end_tick > step.start_tick  # a short, visible pause
        for name in step.state_before.names:
            assert np.allclose(step.state_before.pos(name), step.state_after.pos(name), atol=1e-3)


def test_reveal_tick_is_when_the_block_is_up_and_leaving(demo):
    for step in demo.steps:
        assert step.start_tick < step.reveal_tick < step.end_tick
        i = demo.object_names.index(step.skill.block)
        lifted = demo.object_poses[step.reveal_tick, i, 2]
        assert lifted > step.state_before.pos(step.skill.block)[2] + 0.05
        assert demo.gripper_closed[step.reveal_tick]
        assert demo.step_index[step.reveal_tick] == step.index


def test_demo_plan_matches_the_symbolic_prediction(demo):
    assert all(s.ok for s in demo.steps), [s.reason for s in demo.steps]
    predicted, failures = apply_plan(demo.initial_state, PLAN)
    assert failures == [None] * len(PLAN)
    for name in demo.final_state.names:
        assert np.linalg.norm(demo.final_state.pos(name) - predicted[-1].pos(name)) < 0.01, name
    for step, state in zip(demo.steps, predicted, strict=True):
        for name in state.names:
            assert np.linalg.norm(step.state_after.pos(name) - state.pos(name)) < 0.01


def test_same_seed_same_trajectory(demo):
    with TabletopEnv() as other:  # two clients alive in one process
        start = other.reset(SCENE, seed=0)
        again = other.execute(PLAN)
    assert start == demo.initial_state
    assert np.array_equal(again.object_poses, demo.object_poses)
    assert np.array_equal(again.joint_positions, demo.joint_positions)
    assert [s.reveal_tick for s in again.steps] == [s.reveal_tick for s in demo.steps]


def test_reset_gives_layout_positions_and_different_seeds_differ(env):
    a = env.reset(SCENE, seed=1)
    b = env.reset(SCENE, seed=2)
    assert a.names == SCENE
    assert any(np.linalg.norm(a.pos(n) - b.pos(n)) > 0.01 for n in SCENE)
    with pytest.raises(SceneError, match="Valid objects"):
        env.reset(["red block", "teal block", "blue bowl"], seed=0)


def test_config_rejects_rates_that_do_not_divide():
    with pytest.raises(ValueError, match="must divide"):
        SimConfig(physics_hz=240, log_hz=50)


def test_the_drawn_hand_carries_the_simulated_block(demo):
    """The arm is solved by IK only when drawn, from the commanded grasp points the physics
    moved the held block along: while a block is held, the drawn hand stays on it."""
    t = demo.n_ticks
    assert callable(demo.__dict__["joint_positions"]) or demo.__dict__["joint_positions"].shape[0] == t
    moved = [demo.object_names.index(s.skill.block) for s in demo.steps if s.ok]
    gaps = []
    for step, body in zip([s for s in demo.steps if s.ok], moved, strict=True):
        ticks = [k for k in range(step.start_tick, step.end_tick + 1) if demo.gripper_closed[k]]
        assert len(ticks) > 30
        offsets = demo.object_poses[ticks, body, :3] - demo.ee_pose[ticks, :3]
        gaps.append((np.abs(np.diff(offsets, axis=0)).max(),
                     np.linalg.norm(offsets - np.median(offsets, axis=0), axis=1).max()))
    # the block hangs under the hand it is drawn in (it swings by 1.5 cm as it is lifted: a
    # hand drawn one tick late is off by up to 8 mm per tick)
    assert max(g[0] for g in gaps) < 0.005 and max(g[1] for g in gaps) < 0.02
    again = pickle.loads(pickle.dumps(demo))  # a trajectory crossing processes draws the same arm
    assert np.array_equal(again.joint_positions, demo.joint_positions)


def test_trajectory_log_shapes(demo):
    n, k = demo.n_ticks, len(demo.object_names)
    assert demo.object_poses.shape == (n, k, 7)
    assert demo.joint_positions.shape == (n, 9)
    assert demo.ee_pose.shape == (n, 7) and demo.gripper_closed.shape == (n,)
    assert demo.dt == pytest.approx(1 / 60)
    assert demo.step_at(demo.time_of(demo.steps[2].reveal_tick)) == 2


def test_frames_have_shape_and_change_with_motion(demo):
    step = demo.steps[0]
    before = render_frame(demo, demo.time_of(step.start_tick))
    after = render_frame(demo, demo.time_of(step.end_tick))
    assert before.shape == (240, 240, 3) and before.dtype == np.uint8
    assert np.abs(before.astype(int) - after.astype(int)).mean() > 0.5
    small = demo.frame(1.0, size=(96, 64))
    assert small.shape == (64, 96, 3)
    assert np.array_equal(render_frame(demo, 1.0), render_frame(demo, 1.0))  # deterministic
    # Colours are visible: the red block is in the initial frame.
    red = (before[:, :, 0] > 200) & (before[:, :, 1] < 110) & (before[:, :, 2] < 110)
    assert red.sum() > 10


def test_a_frame_is_what_one_z_buffer_over_the_table_and_the_scene_draws(demo):
    """The table is drawn apart and composited by depth; the result is the single-pass picture."""
    import pybullet as p

    from activeintent.sim import render
    from activeintent.sim.assets import create_table

    size = (200, 150)
    drawn = render.renderer_for(demo.object_names)
    whole = render.SceneRenderer(demo.object_names)
    try:
        create_table(whole.client, collide=False)  # the table in the scene's own client: one pass
        for t in (0.0, demo.duration / 3, demo.duration):
            k = demo.tick_at(t)
            whole.draw(demo.object_poses[k], demo.joint_positions[k], size)  # poses the bodies
            one_pass, _ = render._camera_image(whole.client, size, whole.view)
            assert np.array_equal(drawn.draw(demo.object_poses[k], demo.joint_positions[k], size), one_pass)
    finally:
        whole.close()
    assert p.isConnected(drawn.client)


def test_frames_drawn_in_worker_processes_are_the_same(demo):
    from activeintent.sim.render import render_frames, warm_render_pool

    times = frame_times(demo, 2)
    assert warm_render_pool(2)  # pytest's main module can be imported: the processes start
    here = list(render_frames(demo, times, (96, 72), workers=1))
    there = list(render_frames(demo, times, (96, 72), workers=2))
    assert len(here) == len(there) == len(times) > 8  # more than one chunk
    assert all(np.array_equal(a, b) for a, b in zip(here, there, strict=True))


def test_two_videos_drawn_at_once_get_their_first_frames_before_either_is_drawn(demo, monkeypatch):
    """A round's videos are drawn at the same time (the web app shows them as they grow): each
    video asks the render processes for its first chunk alone, then for at most ``workers``
    chunks at a time, so the second video's first frames never queue behind the whole first."""
    import activeintent.sim.render as render

    assert render.warm_render_pool(2)
    pool = render._render_pool(2)
    asked: list[str] = []
    submit = pool.submit

    def recorded(fn, names, poses, *args):
        asked.append(recorded.video)
        return submit(fn, names, poses, *args)

    times = frame_times(demo, 10)
    chunks = -(-len(times) // render.CHUNK_FRAMES)
    assert chunks >= 5
    monkeypatch.setattr(pool, "submit", recorded)
    recorded.video = "A"
    a = render.render_frames(demo, times, (32, 24), workers=2)
    next(a)  # A's first frame: its first chunk, then two more asked for
    recorded.video = "B"
    b = render.render_frames(demo, times, (32, 24), workers=2)
    next(b)
    assert asked == ["A", "A", "A", "B", "B", "B"]  # not all of A's chunks before B's first
    recorded.video = "A"
    rest = list(a)
    assert len(rest) == len(times) - 1 and asked.count("A") == chunks
    b.close()


def test_frames_drawn_in_this_process_by_two_threads_are_each_their_own(demo):
    """Two sessions drawing the same scene in this process (no render processes) share one
    PyBullet client: each frame must still show its own pose, never the other thread's."""
    from concurrent.futures import ThreadPoolExecutor

    from activeintent.sim.render import render_frames

    times = frame_times(demo, 30)
    ahead, behind = times, times[::-1]  # the same scene, different poses at every moment
    alone = [list(render_frames(demo, t, (48, 36), workers=1)) for t in (ahead, behind)]
    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)  # threads take turns between any two PyBullet calls
    try:
        with ThreadPoolExecutor(2) as pool:
            together = list(pool.map(lambda t: list(render_frames(demo, t, (48, 36), workers=1)), (ahead, behind)))
    finally:
        sys.setswitchinterval(switch)
    for one, other in zip(alone, together, strict=True):
        assert all(np.array_equal(a, b) for a, b in zip(one, other, strict=True))


def test_render_state(demo):
    img = render_state(demo.initial_state, size=(120, 120))
    assert img.shape == (120, 120, 3) and img.std() > 5


@pytest.mark.parametrize("suffix", [".gif", ".webm", ".mp4"])
def test_exports_are_readable(demo, tmp_path, suffix):
    fps = 4
    path = export_video(demo, tmp_path / f"demo{suffix}", fps=fps, size=(96, 96))
    reader = iio.get_reader(path) if suffix == ".gif" else iio.get_reader(path, format="FFMPEG")
    frames = [np.asarray(f) for f in reader]
    reader.close()
    expected = len(frame_times(demo, fps))
    if suffix == ".gif":  # the GIF writer merges identical consecutive frames, adding up their durations
        from PIL import Image, ImageSequence

        with Image.open(path) as gif:
            total_ms = sum(f.info["duration"] for f in ImageSequence.Iterator(gif))
        assert len(frames) <= expected and total_ms == pytest.approx(expected * 1000 / fps, abs=expected)
    else:
        assert len(frames) == expected
    assert frames[0].shape[:2] == (96, 96)


def test_export_rejects_unknown_format(demo, tmp_path):
    with pytest.raises(ValueError, match=r"\.gif"):
        export_video(demo, tmp_path / "demo.avi")


def test_save_load_roundtrip(demo, tmp_path):
    loaded = Trajectory.load(demo.save(tmp_path / "tau.npz"))
    assert np.array_equal(loaded.object_poses, demo.object_poses)
    assert np.array_equal(loaded.joint_positions, demo.joint_positions)
    assert loaded.steps[1].skill == demo.steps[1].skill
    assert loaded.final_state == demo.final_state and loaded.scene == demo.scene
    assert np.array_equal(render_frame(loaded, 2.0), render_frame(demo, 2.0))


def test_a_stopped_round_video_ends_at_the_stop_with_a_marker(tmp_path):
    import imageio.v2 as iio

    from activeintent.runner import RunSpec, build_episode

    build_episode(RunSpec.from_options(method="bayes-stop", intention="stack", env="pybullet", llm="none", user="exact",
                             video="all", budget=1, test_scenes=1, seed=2), tmp_path).run()
    from activeintent.records import read_rounds

    (r,) = read_rounds(tmp_path / "rounds.jsonl")
    frames = iio.mimread(tmp_path / "round1_y.gif")
    red = [bool((f[:3, :, 0] > 200).all() and (f[:3, :, 1] < 60).all()) for f in frames]
    stop = r["answer"]["stop_time"]
    assert stop is not None  # seed 2: the exact user stops the first query
    # the clip ends where the person stopped: the frames before it plain, the stop frame in red
    # (held for a second; a GIF writer may merge the identical held frames into one)
    before = sum(1 for k in range(1000) if k / 10 < stop)
    assert not any(red[:before]) and all(red[before:]) and len(frames) >= before + 1
    assert len(frames) <= before + 10


def test_render_processes_leave_when_their_parent_is_killed(tmp_path):
    import os
    import subprocess
    import sys
    import time

    script = tmp_path / "warm.py"
    script.write_text("from activeintent.sim.render import warm_render_pool\n"
                      "if __name__ == '__main__':\n"
                      "    import time\n    print(warm_render_pool(2), flush=True)\n    time.sleep(120)\n")
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        assert parent.stdout.readline().strip() == "True"
        kids = subprocess.run(["pgrep", "-P", str(parent.pid)], capture_output=True, text=True).stdout.split()
        workers = [k for k in kids if "spawn_main" in open(f"/proc/{k}/cmdline").read()]
        assert len(workers) == 2
    finally:
        parent.kill()
        parent.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(os.path.exists(f"/proc/{k}") for k in workers):
        time.sleep(0.2)
    # a zombie (reaped by init soon) has an empty command line
    assert not [k for k in workers if os.path.exists(f"/proc/{k}") and open(f"/proc/{k}/cmdline").read()]


def test_a_pool_that_cannot_start_is_tried_once(demo, tmp_path):
    """Render processes that cannot start (here: an interpreter that exits at once) are tried
    once; later videos are drawn in this process without paying for another failed start."""
    import pickle
    import subprocess
    import sys

    (tmp_path / "demo.pkl").write_bytes(pickle.dumps(demo))
    script = tmp_path / "broken.py"
    script.write_text(
        "import multiprocessing, pickle\nimport activeintent.sim.render as r\n"
        "from activeintent.sim.video import frame_times\n"
        "from multiprocessing import resource_tracker\n"
        "if __name__ == '__main__':\n"
        # the tracker must start on the real interpreter: one that exits at once makes the
        # first lock's registration race a closed pipe (BrokenPipeError under load)
        "    resource_tracker.ensure_running()\n"
        "    multiprocessing.set_executable('/bin/false')\n"
        "    tries = []\n    start = r._render_pool\n    r._render_pool = lambda w: tries.append(w) or start(w)\n"
        "    first = r.warm_render_pool(2)\n"
        f"    demo = pickle.loads(open({str(tmp_path / 'demo.pkl')!r}, 'rb').read())\n"
        "    frames = list(r.render_frames(demo, frame_times(demo, 4), (64, 48), workers=2))\n"
        "    print(first, r.warm_render_pool(2), len(frames) == len(frame_times(demo, 4)), len(tries))\n")
    got = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert got.stdout.split() == ["False", "False", "True", "1"], got.stdout + got.stderr[-2000:]


def test_light_panda_is_written_once_for_every_process():
    """The light Panda's file name comes from its text, not from a per-process salted hash()
    (else every benchmark process leaves one more copy in the cache)."""
    import subprocess

    code = "from activeintent.sim.assets import light_panda_urdf; print(light_panda_urdf())"
    paths = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                            env={**os.environ, "PYTHONHASHSEED": seed}).stdout.strip() for seed in ("1", "2")}
    assert len(paths) == 1
