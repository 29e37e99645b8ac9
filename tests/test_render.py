"""Physics replays and offscreen rendering (EGL on the CPU; conftest sets MUJOCO_GL)."""

import os
import stat

import numpy as np
import pytest

pytest.importorskip("mujoco")

from armtransfer.ik.render import (  # noqa: E402
    PanelRenderer, RenderError, RolloutPanel, render_rollouts, rollout_video)
from armtransfer.ik.replay import ReplayError, polyline_distance, replay  # noqa: E402
from armtransfer.errors import ArmTransferError  # noqa: E402
from armtransfer.worlds.layout import ROOMS  # noqa: E402

START, GOAL = (0, 0), (4, 5)  # a few cells apart in room 1, a short replay


@pytest.fixture(scope="module")
def robots(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv("ARMTRANSFER_CACHE", str(tmp_path_factory.mktemp("cache")))
    from armtransfer.tasks.arms import robot

    out = {spec: robot(spec) for spec in ("planar2:cartesian", "ur5e_like:cartesian")}
    mp.undo()
    return out


def _path(r, start=START, goal=GOAL):
    g = ROOMS.free_cell(*goal)
    path = r.shortest_path(r.start_state(ROOMS.free_cell(*start)), g)
    assert path is not None
    return [s for s, _ in path], g


@pytest.fixture(scope="module")
def replays(robots):
    out = {}
    for spec, r in robots.items():
        states, g = _path(r)
        out[spec] = replay(r, states, segment_seconds=0.06, settle_seconds=0.1)
    return out


@pytest.mark.parametrize("spec", ["planar2:cartesian", "ur5e_like:cartesian"])
def test_replay_reaches_goal_close_to_plan(replays, spec):
    rp = replays[spec]
    assert rp.reached_goal
    assert rp.max_deviation_cells < 0.75
    assert rp.tip_cells[0] == ROOMS.free_cell(*START)
    rep = rp.report()
    assert rep["reached_goal"] is True and rep["goal_cell"] == list(GOAL)
    assert rep["physics_steps"] == len(rp.time) - 1 > 0


def test_replay_is_physics_not_slideshow(robots):
    # Deterministic; the joints lag the ramping controls (a slideshow would sit exactly on
    # the waypoints), and softer servos without feed-forward lag more.
    r = robots["planar2:cartesian"]
    states, _ = _path(r)
    a = replay(r, states, segment_seconds=0.06, settle_seconds=0.0)
    b = replay(r, states, segment_seconds=0.06, settle_seconds=0.0)
    np.testing.assert_array_equal(a.qpos, b.qpos)
    way = r.arm.qpos[states]
    lag = np.abs(a.qpos[a.waypoint_index[1:]] - way[1:]).max()
    assert 1e-6 < lag < 0.05
    stiff = replay(r, states, segment_seconds=0.06, settle_seconds=0.0, feedforward=False)
    soft = replay(r, states, segment_seconds=0.06, settle_seconds=0.0, feedforward=False,
                  bandwidth_hz=1.0)
    assert soft.final_error_cells > stiff.final_error_cells > 0


def test_replay_bad_input(robots):
    r = robots["planar2:cartesian"]
    with pytest.raises(ReplayError):
        replay(r, [])
    with pytest.raises(ReplayError, match="not a state"):
        replay(r, [r.n_states + 5])
    from armtransfer.tasks.grid_robots import grid_robot

    with pytest.raises(ReplayError, match="not an arm robot"):
        replay(grid_robot("fine"), [0, 1])


def test_polyline_distance():
    d = polyline_distance(np.array([[0.5, 1.0], [3.0, 0.0], [-1.0, 0.0]]),
                          np.array([[0.0, 0.0], [2.0, 0.0]]))
    np.testing.assert_allclose(d, [1.0, 1.0, 1.0])


@pytest.mark.rendering
def test_frame_shape_not_blank_and_arm_moves(replays):
    rp = replays["ur5e_like:cartesian"]
    q = rp.frames_qpos(30)
    with PanelRenderer(RolloutPanel(rp), width=160, height=120) as pr:
        first = pr.render(q[0]).copy()
        last = pr.render(q[-1]).copy()
    assert first.shape == (120, 160, 3) and first.dtype == np.uint8
    assert first.std() > 10  # not a blank (single-colour) image
    moved = np.any(first != last, axis=-1)
    assert moved.mean() > 0.005  # the arm's pixels moved between start and end


@pytest.mark.rendering
@pytest.mark.parametrize("suffix", [".mp4", ".gif"])
def test_video_decodes_with_expected_frames(replays, tmp_path, suffix):
    import imageio.v3 as iio

    panels = [RolloutPanel(replays["planar2:cartesian"], trajectory_cells=[1300, 1301]),
              RolloutPanel(replays["ur5e_like:cartesian"])]
    fps = 20
    expected = max(len(p.replay.frame_indices(fps)) for p in panels)
    out = tmp_path / f"roll{suffix}"
    stats = render_rollouts(panels, out, width=96, height=64, fps=fps)
    assert stats.frames == expected and stats.width == 192 and stats.height == 64
    frames = iio.imread(out, index=None)
    assert frames.shape[0] == expected
    assert frames.shape[1:3] == (64, 192)
    assert frames[0].std() > 10
    assert [p.name for p in tmp_path.iterdir()] == [out.name]  # no temp file left


@pytest.mark.rendering
def test_rollout_video_report(robots, tmp_path):
    r = robots["planar2:cartesian"]
    states, g = _path(r)
    traj = [int(r.label[s]) for s in states]
    rep = rollout_video([(r, states)], tmp_path / "one.gif", trajectory_cells=traj, goal_cell=g,
                        width=64, height=48, fps=10,
                        replay_options={"segment_seconds": 0.05, "settle_seconds": 0.0})
    import json

    json.dumps(rep)
    assert rep["frames"] > 1 and rep["replays"][0]["reached_goal"] is True
    assert rep["replays"][0]["max_deviation_cells"] < 0.75


@pytest.mark.rendering
def test_rollout_video_renders_from_a_scene_it_is_given(robots, tmp_path, monkeypatch):
    from armtransfer.ik import replay as replay_module
    from armtransfer.ik.replay import check_replayable

    r = robots["planar2:cartesian"]
    states, g = _path(r)
    options = dict(goal_cell=g, width=64, height=48, fps=10,
                   replay_options={"segment_seconds": 0.05, "settle_seconds": 0.0})
    built = rollout_video([(r, states)], tmp_path / "built.gif", **options)
    scene = check_replayable(r)

    def no_rebuild(robot):
        raise AssertionError("the scene was rebuilt")

    monkeypatch.setattr(replay_module, "robot_scene", no_rebuild)
    given = rollout_video([(r, states)], tmp_path / "given.gif", scenes=[scene], **options)
    assert given["replays"] == built["replays"]
    assert (tmp_path / "given.gif").read_bytes() == (tmp_path / "built.gif").read_bytes()
    with pytest.raises(RenderError, match="1 scenes for 2 rollouts"):
        rollout_video([(r, states), (r, states)], tmp_path / "two.gif", scenes=[scene], **options)


def test_unknown_format_is_one_line_error(replays, tmp_path):
    with pytest.raises(RenderError) as err:
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "x.avi")
    assert isinstance(err.value, ArmTransferError) and "\n" not in str(err.value)
    with pytest.raises(RenderError):
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "x.mp4",
                        format="webm")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_unwritable_output_is_one_line_error_and_leaves_nothing(replays, tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        with pytest.raises(ArmTransferError) as err:
            render_rollouts([RolloutPanel(replays["planar2:cartesian"])], locked / "v.mp4",
                            width=32, height=32)
        assert "\n" not in str(err.value) and "v.mp4" in str(err.value)
        assert list(locked.iterdir()) == []
    finally:
        locked.chmod(stat.S_IRWXU)


def test_output_under_a_file_is_one_line_error(replays, tmp_path):
    # Unwritable even for root: the destination's folder is a regular file.
    (tmp_path / "file").write_text("x")
    with pytest.raises(ArmTransferError) as err:
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "file" / "v.gif")
    assert "\n" not in str(err.value)
    assert [p.name for p in tmp_path.iterdir()] == ["file"]


def test_output_is_a_directory(replays, tmp_path):
    (tmp_path / "d.mp4").mkdir()
    with pytest.raises(ArmTransferError, match="directory"):
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "d.mp4")


@pytest.mark.rendering
def test_failed_render_leaves_no_temp_file(replays, tmp_path, monkeypatch):
    import armtransfer.ik.render as render

    def boom(self, qpos):
        raise RuntimeError("render failed")

    monkeypatch.setattr(render.PanelRenderer, "render", boom)
    with pytest.raises(RuntimeError):
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "v.mp4",
                        width=32, height=32)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("kwargs", [{"fps": 0}, {"fps": float("nan")}, {"width": 8},
                                    {"height": 10.5}])
def test_bad_size_or_fps_is_render_error(replays, tmp_path, kwargs):
    with pytest.raises(RenderError):
        render_rollouts([RolloutPanel(replays["planar2:cartesian"])], tmp_path / "v.mp4", **kwargs)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.rendering
def test_panels_are_captioned_and_the_shorter_holds_its_end_with_reached(robots, replays, tmp_path):
    """Each panel names its arm and method and counts its steps; the shorter replay's frames
    after its end are its last frame, captioned "reached the goal", repeated exactly."""
    import imageio.v3 as iio

    from armtransfer.ik import font
    from armtransfer.ik.render import caption, panel_steps, rollout_frames

    r = robots["planar2:cartesian"]
    states, _ = _path(r, goal=(2, 0))
    short = replay(r, states, segment_seconds=0.06, settle_seconds=0.1)
    long = replays["ur5e_like:cartesian"]
    fps, width, height = 20, 160, 120
    panels = [RolloutPanel(short, label=["planar2:cartesian", "source"]),
              RolloutPanel(long, label=["ur5e_like:cartesian", "target: pseudo"])]
    ends = [len(p.replay.frame_indices(fps)) for p in panels]
    assert ends[0] < ends[1] - 3  # the first panel ends frames before the second
    renderers = [PanelRenderer(p, width, height) for p in panels]
    try:
        frames = list(rollout_frames(panels, renderers, fps))
        plain = [np.array(rd.render(p.replay.qpos[p.replay.frame_indices(fps)[0]]))
                 for p, rd in zip(panels, renderers)]
        short_end = np.array(renderers[0].render(short.qpos[-1]))
    finally:
        for rd in renderers:
            rd.close()
    assert len(frames) == ends[1] and frames[0].shape == (height, 2 * width, 3)

    # the caption is drawn over the first frame, top left, and nowhere else
    box_h, box_w = font.text_size(["planar2:cartesian", "source", "step 0/9"])
    first = frames[0][:, :width]
    changed = np.any(first != plain[0], axis=-1)
    assert changed[:box_h, :box_w].mean() > 0.5
    assert not changed[box_h:].any() and not changed[:, box_w:].any()
    assert np.array_equal(first, caption(plain[0].copy(), panels[0], 0, ended=False))

    # the step counter follows the path: 0 at the start, every move once its ramp has ended
    steps = panel_steps(short, short.frame_indices(fps))
    assert steps[0] == 0 and steps[-1] == len(states) - 1 and np.all(np.diff(steps) >= 0)

    # after its end the shorter panel is its last pose, captioned as reached, frame after frame
    assert short.reached_goal
    held = caption(short_end.copy(), panels[0], len(states) - 1, ended=True)
    for k in range(ends[0] - 1, len(frames)):
        assert np.array_equal(frames[k][:, :width], held), k
    running = caption(short_end.copy(), panels[0], len(states) - 1, ended=False)
    reached_box = np.any(held != running, axis=-1)
    assert reached_box[height // 2:].sum() > 100 and not reached_box[:height // 2].any()
    # while the second panel keeps moving
    assert not np.array_equal(frames[ends[0]][:, width:], frames[-1][:, width:])

    # the written video shows the captions too (H.264 is lossy: compared on average)
    out = tmp_path / "captioned.mp4"
    stats = render_rollouts(panels, out, width=width, height=height, fps=fps)
    video = iio.imread(out, index=None).astype(int)
    assert stats.frames == len(frames) == len(video)
    box = (slice(0, box_h), slice(0, box_w))
    assert np.abs(video[0][box] - frames[0][box]).mean() < 12 < np.abs(video[0][box] - plain[0][box]).mean()
