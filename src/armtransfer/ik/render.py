"""Offscreen video of physics replays: arms side by side over the rooms table.

Rendering is MuJoCo's offscreen OpenGL; ``MUJOCO_GL`` must name the backend before
``mujoco`` is first imported (this module sets ``egl`` unless the user chose one), which
works without a display and without a GPU through Mesa's EGL (llvmpipe). Every GL context
is made by :func:`offscreen_renderer`, which first checks that the backend works
(``armtransfer.ik.offscreen``): where none does, the caller gets an ``OffscreenError`` that
names the system packages to install, never a PyOpenGL traceback.

Each panel is one ``Replay`` (``armtransfer.ik.replay``) rendered with its own model and
``mujoco.Renderer`` from a fixed free camera that fits the whole scene: the table, its walls
and the arm wherever it is mounted; the tool tip's path is drawn on the table as a line.
Markers are drawn as MuJoCo user geoms added to the renderer's scene (they are not part
of the model, so they never collide): the transferred trajectory's cells as orange
tiles, the goal cell as a green disc. Each panel is captioned (``armtransfer.ik.font``, a
bitmap font drawn with numpy) with its lines, e.g. the arm and the method that moved it, and
the step of the path it is on; panels are concatenated left to right. A replay that ends
before the others holds its last frame, captioned "reached the goal" (or "ended off the
goal"), until the longest one ends, which gets the same caption on its last frame. Frames are
streamed to the encoder, one at a time: MP4
(H.264 through imageio's ffmpeg plugin, the binary from ``imageio-ffmpeg``) or GIF
(Pillow). The video is written to a temporary file beside the destination and renamed
over it only when complete, so a failed or interrupted render leaves nothing behind.

Shadows are off by default: on a CPU renderer MuJoCo's 4096² shadow map more than
halves the frame rate (see BENCHMARKS.md, "Rendering"); ``shadows=True`` turns them on.

Typical use (the ``armtransfer`` command does this)::

    from armtransfer.ik.render import rollout_video
    report = rollout_video([(src_robot, src_states), (tgt_robot, tgt_states)], "out.mp4",
                           trajectory_cells=traj.cells, goal_cell=traj.goal)
"""

from __future__ import annotations

import copy
import math
import numbers
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Iterator, Self, Sequence

import mujoco  # after armtransfer.ik named the backend
import numpy as np

from armtransfer.errors import ArmTransferError
from armtransfer.ik import font, offscreen
from armtransfer.ik.replay import Replay, replay
from armtransfer.ik.workspace import WALL_HEIGHT
from armtransfer.io import OutputError, check_writable

if TYPE_CHECKING:
    from imageio.core.format import Format
    from imageio.plugins.pillow import PillowPlugin

FORMATS = {".mp4": "mp4", ".gif": "gif"}
TRAJECTORY_RGBA = (1.0, 0.55, 0.1, 1.0)
GOAL_RGBA = (0.1, 0.75, 0.2, 1.0)
START_RGBA = (0.15, 0.35, 0.9, 1.0)
TIP_PATH_RGBA = (0.85, 0.1, 0.6, 1.0)
TIP_PATH_POINTS = 40

Marker = tuple[int, np.ndarray | float, np.ndarray | tuple[np.ndarray, np.ndarray], np.ndarray]
"""A decor geom: (geom type, size, pos, rgba); a line's size is its width and its pos its two ends."""
"""The tool tip's path is drawn as this many line segments."""
MAX_SIZE = 4096


WITHOUT = "draw nothing (learning and replays need no OpenGL)"
"""How a library user goes on where no backend works."""


class RenderError(ArmTransferError):
    """A video cannot be made as asked (unknown format, bad size or fps)."""


def gl_errors() -> tuple[type[BaseException], ...]:
    """The exceptions by which MuJoCo and PyOpenGL say that OpenGL failed."""
    errors: list[type[BaseException]] = [mujoco.FatalError]
    pyopengl = sys.modules.get("OpenGL.error")  # imported by the GL backend, if any
    if pyopengl is not None:
        errors.append(pyopengl.Error)
    return tuple(errors)


def offscreen_renderer(model: mujoco.MjModel, height: int, width: int, max_geom: int,
                       without: str = WITHOUT) -> mujoco.Renderer:
    """A ``mujoco.Renderer`` for ``model``, once the backend is known to work here
    (``offscreen.require``); an ``OffscreenError`` ending with ``without`` when it does not."""
    offscreen.require(without)
    try:
        return mujoco.Renderer(model, height, width, max_geom=max_geom)
    except Exception as err:  # noqa: BLE001 - a GL context that fails here fails for the machine's reasons
        raise offscreen.broken(err, without) from None


@dataclass
class RolloutPanel:
    """One replay to draw, with its markers."""

    replay: Replay
    trajectory_cells: Sequence[int] = ()
    """The transferred trajectory's shared cells (orange tiles); none by default."""
    goal_cell: int | None = None
    """The goal cell (green disc); defaults to the replay's goal."""
    show_start: bool = True
    """A blue tile under the first planned cell."""
    show_tip_path: bool = True
    """A line on the table where the tool tip went during the replay."""
    label: Sequence[str] = ()
    """Caption lines in the top-left corner, e.g. the arm and the method that moved it."""
    show_step: bool = True
    """A caption line ``step k/n``: the moves of the path done so far; and, from the replay's
    end on, whether it ended on the goal (bottom-left). False draws no caption at all but
    ``label``."""


@dataclass
class RenderStats:
    path: str
    format: str
    frames: int
    width: int
    height: int
    """Size of the whole video frame (panels side by side)."""
    fps: float
    """Playback rate written into the file."""
    seconds: float
    """Wall-clock time of rendering plus encoding (not the replays)."""
    render_seconds: float
    encode_seconds: float
    panels: int = 1
    extra: dict = field(default_factory=dict)

    @property
    def fps_achieved(self) -> float:
        return self.frames / self.seconds if self.seconds > 0 else math.inf

    def report(self) -> dict:
        return {"video": self.path, "format": self.format, "frames": self.frames,
                "width": self.width, "height": self.height, "panels": self.panels,
                "fps": self.fps, "seconds": round(self.seconds, 4),
                "fps_achieved": round(self.fps_achieved, 2),
                "render_seconds": round(self.render_seconds, 4),
                "encode_seconds": round(self.encode_seconds, 4), **self.extra}


def video_format(path: str | os.PathLike, format: str | None = None) -> str:
    """'mp4' or 'gif', from ``format`` or else the path's suffix; RenderError otherwise."""
    if format is not None:
        fmt = str(format).lower().lstrip(".")
        if fmt not in FORMATS.values():
            raise RenderError(f"unknown video format {format!r}; valid formats: mp4, gif")
        return fmt
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        shown = suffix or "no suffix"
        raise RenderError(f"unknown video format for {str(path)!r} ({shown}); use a .mp4 or .gif path")
    return FORMATS[suffix]


ELEVATION = -70.0
"""Degrees below the horizon: nearly top-down, so cells keep their shape, tilted enough
that the arms' links stand out from the table."""


def _camera_axes(elevation: float, azimuth: float = 90.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right, up) unit vectors of a free camera at ``azimuth``/``elevation`` degrees."""
    el, az = math.radians(elevation), math.radians(azimuth)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def scene_points(replay_or_scene, samples: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """(points, radii) the view must show: the table's corners at its walls' height, and
    every arm geom (its centre and bounding radius) at up to ``samples`` configurations of
    the replay (at home for a bare scene)."""
    scene = getattr(replay_or_scene, "scene", replay_or_scene)
    model = scene.model
    half = scene.layout.width * scene.cell / 2
    corners = np.array([[sx * half, sy * half, z] for sx in (-1, 1) for sy in (-1, 1) for z in (0.0, WALL_HEIGHT)])
    qs = getattr(replay_or_scene, "qpos", None)
    qs = np.asarray(scene.home)[None] if qs is None else qs[np.unique(np.linspace(0, len(qs) - 1, samples).astype(int))]
    data = mujoco.MjData(model)
    table = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "table")
    arm = np.flatnonzero((model.geom_bodyid != table) & (model.geom_bodyid != 0))
    points, radii = [corners], [np.zeros(len(corners))]
    for q in qs:
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        points.append(data.geom_xpos[arm])
        radii.append(model.geom_rbound[arm])
    return np.vstack(points), np.concatenate(radii)


def _spans(replay_or_scene, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The view's (right, up, forward) extents [lo, hi] of everything it must show."""
    points, radii = scene_points(replay_or_scene)
    forward, right, up = _camera_axes(elevation)
    out = []
    for axis in (right, up, forward):
        c = points @ axis
        out.append(np.array([float(np.min(c - radii)), float(np.max(c + radii))]))
    return out[0], out[1], out[2]


def table_camera(replay_or_scene, width: int = 320, height: int = 240, *,
                 elevation: float = ELEVATION) -> mujoco.MjvCamera:
    """A fixed free camera from the front (-y side), ``elevation`` degrees down, looking at the
    middle of everything the replay shows: the table and the arm wherever it is mounted (see
    ``view_extent`` for the orthographic scale that fits it)."""
    u, v, depth = _spans(replay_or_scene, elevation)
    forward, right, up = _camera_axes(elevation)
    centre = right * u.mean() + up * v.mean() + forward * depth.mean()
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = centre
    cam.distance = float(depth[1] - depth[0]) + 2.0  # in front of everything; orthographic, so no zoom
    cam.azimuth = 90.0
    cam.elevation = elevation
    return cam


def view_extent(replay_or_scene, width: int, height: int, elevation: float = ELEVATION) -> float:
    """Vertical extent (m) of the orthographic view that shows the table, its walls and the
    arm's geoms with a small margin at aspect ``width / height``."""
    u, v, _ = _spans(replay_or_scene, elevation)
    return 1.08 * max(float(v[1] - v[0]), float(u[1] - u[0]) * height / width)


def offscreen_model(replay_or_scene, width: int, height: int, samples: int = 4) -> mujoco.MjModel:
    """A copy of the scene's model set up for an orthographic offscreen view of the table."""
    scene = getattr(replay_or_scene, "scene", replay_or_scene)
    model = copy.copy(scene.model)
    model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
    model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
    model.vis.quality.offsamples = int(samples)
    model.vis.global_.orthographic = 1
    model.vis.global_.fovy = view_extent(replay_or_scene, width, height)
    return model


def render_with_markers(renderer: mujoco.Renderer, model: mujoco.MjModel, data: mujoco.MjData,
                        camera: mujoco.MjvCamera, qpos: np.ndarray, markers: Sequence[Marker],
                        shadows: bool = False) -> np.ndarray:
    """[height, width, 3] uint8 image of the arm at ``qpos`` with decor ``markers``
    (geom type, size, pos, rgba; a size of length 2 draws a line between two points)."""
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    renderer.update_scene(data, camera)
    scn = renderer.scene
    scn.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = shadows
    for gtype, size, pos, rgba in markers:
        if scn.ngeom >= scn.maxgeom:
            break
        g = scn.geoms[scn.ngeom]
        if gtype == int(mujoco.mjtGeom.mjGEOM_LINE):
            mujoco.mjv_initGeom(g, gtype, np.zeros(3), np.zeros(3), np.eye(3).reshape(-1), rgba)
            mujoco.mjv_connector(g, gtype, float(size), pos[0], pos[1])
        else:
            mujoco.mjv_initGeom(g, gtype, size, pos, np.eye(3).reshape(-1), rgba)
        g.category = mujoco.mjtCatBit.mjCAT_DECOR
        scn.ngeom += 1
    return renderer.render()


class OwnsRenderer:
    """An object holding one ``mujoco.Renderer`` as ``self.renderer``: ``close()`` frees it, and
    ``with`` closes it on the way out."""

    renderer: mujoco.Renderer

    def close(self) -> None:
        self.renderer.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class PanelRenderer(OwnsRenderer):
    """Renders one replay's configurations with its markers (close it, or use ``with``)."""

    def __init__(self, panel: RolloutPanel, width: int = 320, height: int = 240, *,
                 shadows: bool = False, samples: int = 4,
                 camera: mujoco.MjvCamera | None = None, without: str = WITHOUT) -> None:
        self.panel = panel
        rp = panel.replay
        self.model = offscreen_model(rp, width, height, samples)
        self.data = mujoco.MjData(self.model)
        self.camera = camera or table_camera(rp, width, height)
        self.shadows = shadows
        self._markers = _markers(panel)
        self.renderer = offscreen_renderer(self.model, height, width, self.model.ngeom + len(self._markers) + 100,
                                           without)

    def render(self, qpos: np.ndarray) -> np.ndarray:
        """[height, width, 3] uint8 image of the arm at ``qpos``."""
        return render_with_markers(self.renderer, self.model, self.data, self.camera, qpos, self._markers,
                                   self.shadows)


def _markers(panel: RolloutPanel) -> list[Marker]:
    rp = panel.replay
    cell, layout = rp.cell, rp.scene.layout
    thin = cell * 0.05

    def centre(c: int, z: float) -> np.ndarray:
        x, y = layout.xy(int(c) % layout.n_cells)  # a voxel: the cell under it
        return np.array([x * cell, y * cell, z])

    box = int(mujoco.mjtGeom.mjGEOM_BOX)
    out: list[Marker] = []
    if panel.show_start and len(rp.planned_xy):
        x, y = rp.planned_xy[0]
        out.append((box, np.array([0.45 * cell, 0.45 * cell, thin]), np.array([x, y, thin]),
                    np.array(START_RGBA)))
    for c in dict.fromkeys(int(c) for c in panel.trajectory_cells):
        out.append((box, np.array([0.35 * cell, 0.35 * cell, thin]), centre(c, 2 * thin),
                    np.array(TRAJECTORY_RGBA)))
    goal = rp.goal_cell if panel.goal_cell is None else panel.goal_cell
    out.append((int(mujoco.mjtGeom.mjGEOM_CYLINDER), np.array([1.2 * cell, thin, 0.0]),
                centre(goal, thin), np.array(GOAL_RGBA)))
    if panel.show_tip_path:  # where the tool tip went, as a line on the table (lines are cheap to draw)
        line = int(mujoco.mjtGeom.mjGEOM_LINE)
        points = rp.tip[np.unique(np.linspace(0, len(rp.tip) - 1, TIP_PATH_POINTS + 1).astype(int))]
        for a, b in zip(points[:-1], points[1:]):
            out.append((line, 2.0, (np.array([a[0], a[1], 3 * thin]), np.array([b[0], b[1], 3 * thin])),
                        np.array(TIP_PATH_RGBA)))
    return out


REACHED_RGB = (120, 255, 120)
MISSED_RGB = (255, 150, 90)


def caption_scale(width: int) -> int:
    """The font's scale for a panel ``width`` pixels wide: 2 from 300 px on, else 1."""
    return 2 if width >= 300 else 1


def panel_steps(rp: Replay, indices: np.ndarray) -> np.ndarray:
    """Moves of the path done at each of the replay's samples ``indices`` (0 at the start,
    ``len(path) - 1`` once the last waypoint's ramp has ended)."""
    return np.searchsorted(rp.waypoint_index[1:], indices, side="right")


def caption(image: np.ndarray, panel: RolloutPanel, step: int, ended: bool) -> np.ndarray:
    """``image`` (a frame of ``panel``, changed in place and returned) with its caption: the
    panel's label lines and ``step k/n`` top left; once ``ended``, whether the replay ended on
    the goal, and the deepest it went into a wall or the table, bottom left."""
    rp = panel.replay
    scale = caption_scale(image.shape[1])
    lines = list(panel.label)
    if panel.show_step:
        lines.append(f"step {step}/{len(rp.path_states) - 1}")
    font.draw_lines(image, lines, scale=scale)
    if panel.show_step and ended:
        reached = rp.reached_goal
        said = ("reached the goal" if reached
                else f"ended on the goal through {rp.penetrated_into()}" if rp.ended_on_goal else "ended off the goal")
        font.draw_lines(image, [said, rp.penetration_line()], corner="bottom-left",
                        scale=scale, color=REACHED_RGB if reached else MISSED_RGB)
    return image


def rollout_frames(panels: Sequence[RolloutPanel], renderers: Sequence[PanelRenderer],
                   fps: float) -> Iterator[np.ndarray]:
    """The video's frames, one per 1 / ``fps`` s of simulation: the panels side by side, each
    captioned; a replay that has ended repeats its last captioned frame (drawn once)."""
    indices = [p.replay.frame_indices(fps) for p in panels]
    steps = [panel_steps(p.replay, idx) for p, idx in zip(panels, indices)]
    held: dict[int, np.ndarray] = {}
    for k in range(max(len(idx) for idx in indices)):
        images = []
        for i, (p, r, idx) in enumerate(zip(panels, renderers, indices)):
            if i not in held:
                j = min(k, len(idx) - 1)
                image = caption(np.array(r.render(p.replay.qpos[idx[j]])), p, int(steps[i][j]), j == len(idx) - 1)
                if j == len(idx) - 1:
                    held[i] = image
            else:
                image = held[i]
            images.append(image)
        yield images[0] if len(images) == 1 else np.concatenate(images, axis=1)


def _pad_even(frame: np.ndarray) -> np.ndarray:
    """H.264 in yuv420p needs even sizes: repeat the last row/column when odd."""
    h, w = frame.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return frame
    return np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


class _Writer:
    def __init__(self, tmp: str, fmt: str, fps: float, quality: int | None) -> None:
        import imageio  # start-up: only when a video is written

        self.fmt = fmt
        self._mp4: Format.Writer | None = None  # one of the two is set
        self._gif: PillowPlugin | None = None
        if fmt == "mp4":
            self._mp4 = imageio.v2.get_writer(
                tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                pixelformat="yuv420p", macro_block_size=1, quality=quality or 7,
                ffmpeg_log_level="error", output_params=["-preset", "veryfast"])
        else:
            import imageio.v3 as iio  # start-up: only when a GIF is written

            self._gif = iio.imopen(tmp, "w", plugin="pillow", extension=".gif")
            self._duration = 1000.0 / fps

    def append(self, frame: np.ndarray) -> None:
        if self._mp4 is not None:
            self._mp4.append_data(_pad_even(frame))
        elif self._gif is not None:
            self._gif.write(frame, duration=self._duration, loop=0)

    def close(self) -> None:
        if self._mp4 is not None:
            self._mp4.close()
        elif self._gif is not None:
            self._gif.close()


def render_rollouts(panels: Sequence[RolloutPanel] | RolloutPanel, path: str | os.PathLike, *,
                    width: int = 320, height: int = 240, fps: float = 30.0,
                    format: str | None = None, shadows: bool = False, samples: int = 4,
                    quality: int | None = None, without: str = WITHOUT) -> RenderStats:
    """Render the panels side by side into a video at ``path`` and return its stats.

    ``width`` x ``height`` is the size of one panel; the video is ``len(panels) * width``
    wide. Playback is real time: frame k shows simulation time k / ``fps``. The format
    comes from ``format`` or the suffix (.mp4, .gif). Bad format, size, fps or an
    unwritable path raise an ``ArmTransferError`` subclass before anything is rendered;
    the file appears only complete (temporary file, then ``os.replace``). Where OpenGL cannot
    draw here, an ``OffscreenError`` names what to install and ends with ``without``.
    """
    if isinstance(panels, RolloutPanel):
        panels = [panels]
    panels = list(panels)
    fmt = video_format(path, format)
    if not panels:
        raise RenderError("nothing to render: no panels")
    for name, v in (("width", width), ("height", height)):
        if not (isinstance(v, numbers.Integral) and 16 <= v <= MAX_SIZE):
            raise RenderError(f"{name} must be an integer in 16..{MAX_SIZE}, got {v!r}")
    if not (isinstance(fps, numbers.Real) and math.isfinite(fps) and 0 < fps <= 240):
        raise RenderError(f"fps must be in (0, 240], got {fps!r}")
    dest = Path(path)
    check_writable(dest)
    try:
        dest.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{dest.name}.", suffix=f".tmp.{fmt}", dir=dest.parent)
        os.close(fd)
    except OSError as err:
        raise OutputError(f"cannot write {str(dest)!r}: {err.strerror}") from None

    start = time.perf_counter()
    render_s = encode_s = 0.0
    n_frames = 0
    renderers: list[PanelRenderer] = []
    writer = None
    try:
        for p in panels:
            renderers.append(PanelRenderer(p, width, height, shadows=shadows, samples=samples, without=without))
        writer = _Writer(tmp, fmt, fps, quality)
        frames = rollout_frames(panels, renderers, fps)
        while True:
            t0 = time.perf_counter()
            frame = next(frames, None)
            if frame is None:
                break
            t1 = time.perf_counter()
            writer.append(frame)
            n_frames += 1
            render_s += t1 - t0
            encode_s += time.perf_counter() - t1
        t1 = time.perf_counter()
        w, writer = writer, None
        w.close()
        encode_s += time.perf_counter() - t1
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, dest)
    except gl_errors() as err:  # the context was made, then OpenGL failed drawing
        raise offscreen.broken(err, without) from None
    except OSError as err:
        raise OutputError(f"cannot write {str(dest)!r}: {err.strerror or err}") from None
    finally:
        if writer is not None:
            try:
                writer.close()
            except Exception:  # noqa: BLE001 - already failing; the temp file goes anyway
                pass
        for r in renderers:
            r.close()
        Path(tmp).unlink(missing_ok=True)
    seconds = time.perf_counter() - start
    return RenderStats(path=str(dest), format=fmt, frames=n_frames, width=width * len(panels),
                       height=height, fps=float(fps), seconds=seconds, render_seconds=render_s,
                       encode_seconds=encode_s, panels=len(panels))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def rollout_video(rollouts: Sequence[tuple[object, Sequence[int]]],
                  path: str | os.PathLike, *, trajectory_cells: Sequence[int] = (),
                  goal_cell: int | None = None, width: int = 320, height: int = 240,
                  fps: float = 30.0, format: str | None = None, shadows: bool = False,
                  replay_options: dict | None = None, scenes: Sequence | None = None,
                  labels: Sequence[Sequence[str]] | None = None, without: str = WITHOUT) -> dict:
    """Replay each (robot, path states) in MuJoCo and render them side by side to ``path``.

    ``trajectory_cells`` (the transferred trajectory) and ``goal_cell`` are marked in every
    panel. ``scenes``, one per rollout (None: rebuilt), are the robots' own scenes, e.g. those
    ``check_replayable`` returned. ``labels``, one list of caption lines per rollout, name
    each panel (default: the robot's name). Returns a JSON-able report: the video's stats and, per
    panel, the replay's ``max_deviation_cells``, ``reached_goal`` and friends
    (``Replay.report()``). A machine where OpenGL cannot draw is found out before the
    replays: an ``OffscreenError`` names what to install and ends with ``without``.
    """
    video_format(path, format)  # fail on bad input, or a machine that cannot render, before the replays
    check_writable(path)
    offscreen.require(without)
    scenes = list(scenes) if scenes is not None else [None] * len(rollouts)
    if len(scenes) != len(rollouts):
        raise RenderError(f"{len(scenes)} scenes for {len(rollouts)} rollouts")
    if labels is not None and len(labels) != len(rollouts):
        raise RenderError(f"{len(labels)} labels for {len(rollouts)} rollouts")
    replays = [replay(robot, states, goal_cell=goal_cell, scene=scene, **(replay_options or {}))
               for (robot, states), scene in zip(rollouts, scenes)]
    labels = [[rp.robot] for rp in replays] if labels is None else labels
    panels = [RolloutPanel(rp, trajectory_cells, goal_cell, label=list(lines)) for rp, lines in zip(replays, labels)]
    stats = render_rollouts(panels, path, width=width, height=height, fps=fps, format=format,
                            shadows=shadows, without=without)
    return {**stats.report(), "replays": [rp.report() for rp in replays]}


__all__ = ["PanelRenderer", "RenderError", "RenderStats", "RolloutPanel", "caption", "render_rollouts",
           "rollout_frames", "rollout_video", "table_camera", "video_format"]
