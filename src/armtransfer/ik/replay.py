"""Physics replay of an arm robot's path: position actuators track the joint waypoints.

A path of a discrete arm robot (``armtransfer.tasks.arms.arm_robot``) is a list of its states; every state has a
joint configuration (``robot.arm.qpos``). ``replay`` rebuilds the exact MuJoCo scene the
robot was compiled in (arm on the table with the rooms walls, from ``robot.arm``), puts the
arm at the first waypoint and then *simulates* the move: for each next waypoint the
position actuators' controls ramp linearly from the previous waypoint to it over
``segment_seconds`` and ``mj_step`` integrates the dynamics, then the controls hold the
goal configuration for ``settle_seconds``. Nothing is set kinematically after the first
waypoint, so what is recorded (tip position and qpos at every physics step) is what the
arm really did, lag, overshoot and contacts included.

Tracking controller (set on a copy of the model at replay time; the MJCF files keep their
own gains):

- Position-actuator gains are retuned per joint to a critically damped servo of natural
  frequency ``bandwidth_hz``: ``kp = I * w**2`` and ``kv = 2 * I * w`` with ``I`` the
  joint's diagonal of the mass matrix (armature included) at the first waypoint.
- Feed-forward forces through ``qfrc_applied``: gravity and Coriolis compensation
  (``qfrc_bias`` of the current state, split ``mj_step1``/``mj_step2`` so it is exact for
  the step) plus the ramp's velocity times (joint damping + kv), which removes the
  steady lag of a PD servo on a ramp. A real arm controller does the same; without it a
  UR5e-like arm sags by several cells under gravity.

Servos. A replay first drives the joints with the file's own servos (their gains retuned as
above, their force and control ranges kept). When those cannot track the path (too weak
against gravity or the ramp, a control range narrower than the path: the tip ends off the
goal cell or strays more than ``TRACKING_LIMIT`` cell from the planned tips) it is run
again with the scene's own servos: the same retuned position servos with no force or
control limit. ``Replay.settings["servos"]`` says which were used (``file`` or ``scene``),
and when it is ``scene``, ``file_servos`` says how the file's did.

Slowing down. Before the file's actuators are said to miss, a segment whose waypoint they
missed (the tip more than ``TRACKING_LIMIT`` cell from the planned tips during it or at its
end) while one of them was at its force limit is run again from its start at twice the time,
and again, up to ``MAX_SLOWDOWN`` times ``segment_seconds``. ``settings["slowdown"]`` is the
largest factor a segment needed and ``settings["slowed_segments"]`` how many were slowed.

Walls. Every physics step's collision is read: the deepest contact of a moving arm geom with
a wall or the table is ``Replay.max_penetration``, in the report as ``max_penetration_mm``. A
replay that goes deeper than ``PENETRATION_TOLERANCE`` did not reach the goal, whatever cell
its tip ended over (``ended_on_goal`` says where it ended).

Torque motors. A file may drive a joint with torque motors only (``motor`` actuators, no
position servo), as files written for torque control do. The scene keeps no such motor
(``armtransfer.ik.scene``: it gives the joint a servo of its own), so the replay with the
file's actuators drives that joint by computed torque instead, limited to what the file's
motors give: ``tau = qfrc_bias + kp * (q_ref - q) + kv * (v_ref - v) + (damping + kv) * v_ref``
with the same model-derived ``kp`` and ``kv`` (the joint's inertia from the mass matrix times
``w**2`` and ``2 w``; ``qfrc_bias`` is gravity and Coriolis of the current state), clipped
to the motors' torque range and applied as the joint's force; the joint's own servo does
nothing. ``settings["torque_motors"]`` names those joints and the steps their motors were at
their limit. When the motors cannot track the path, the scene's own servos take over as above.

The report (``Replay.report()``) gives the largest distance of the tip from the polyline
through the planned cells' centres, in cells, and whether the tip ends in the goal cell.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import mujoco
import numpy as np

from armtransfer.ik.labels import OFF_TABLE, cells_of_xy
from armtransfer.ik.scene import PREFIX, ArmScene, build_scene, torque_motors
from armtransfer.errors import ArmTransferError
from armtransfer.ik.description import ArmDescription

SEGMENT_SECONDS = 0.1
SETTLE_SECONDS = 0.3
BANDWIDTH_HZ = 8.0
TRACKING_LIMIT = 0.5
"""Largest distance (cells) of the tip from the planned tips that the file's servos may
leave before a replay uses the scene's own servos instead."""
PENETRATION_TOLERANCE = 5e-4
"""Deepest contact (m) of the arm with a wall or the table a replay may show and still be said
to reach the goal: a path that goes deeper went through a wall, whatever cell it ended over."""
MAX_SLOWDOWN = 8
"""How many times slower than ``segment_seconds`` a replay may run a segment whose waypoint its
file's actuators missed at their force limit (it doubles the segment's time until the
waypoint is met or this bound is reached)."""
SERVOS = ("auto", "file", "scene")
"""Which servos a replay drives the joints with: the file's, falling back to the scene's
(``auto``), or one of them."""


class ReplayError(ArmTransferError):
    """A path cannot be replayed (not an arm robot, empty path, unknown state)."""


@dataclass(frozen=True, eq=False)
class Replay:
    """What the arm did in a physics replay of a path (arrays per physics step)."""

    robot: str
    scene: ArmScene
    path_states: tuple[int, ...]
    goal_cell: int
    planned_xy: np.ndarray
    """[n_cells, 2] centres (m) of the planned cells: the path's labels, repeats removed."""
    planned_tip: np.ndarray
    """[n_waypoints, 3] the compiled tip position of each path state."""
    time: np.ndarray
    """[n_steps + 1] simulation time (s) of each sample; sample 0 is the start."""
    qpos: np.ndarray
    """[n_steps + 1, nq] joint configuration at each sample."""
    tip: np.ndarray
    """[n_steps + 1, 3] tip site position (m) at each sample."""
    waypoint_index: np.ndarray
    """[n_waypoints] the sample at which each waypoint's ramp ends."""
    penetration: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """[n_steps + 1] the deepest contact (m, 0 when none) of a moving arm geom with a wall or
    the table at each sample, as MuJoCo's collision found it during the step."""
    penetration_what: str = ""
    """The deepest contact's geoms ("link4 with wall wall_2"), "" when none."""
    settings: dict = field(default_factory=dict)

    @property
    def tip_xy(self) -> np.ndarray:
        return self.tip[:, :2]

    @property
    def cell(self) -> float:
        return self.scene.cell

    @property
    def duration(self) -> float:
        return float(self.time[-1])

    @property
    def tip_cells(self) -> np.ndarray:
        """The shared cell under the tip at each sample (-1 off the table)."""
        return cells_of_xy(self.tip_xy, self.cell, self.scene.layout)

    @property
    def final_cell(self) -> int:
        return int(self.tip_cells[-1])

    @property
    def ended_on_goal(self) -> bool:
        """The tip ends the replay over the goal cell."""
        return self.final_cell == self.goal_cell != OFF_TABLE

    @property
    def max_penetration(self) -> float:
        """The deepest the arm went into a wall or the table during the replay (m)."""
        return float(self.penetration.max()) if len(self.penetration) else 0.0

    @property
    def reached_goal(self) -> bool:
        """The tip ends the replay over the goal cell, and the arm never went deeper than
        ``PENETRATION_TOLERANCE`` into a wall or the table on the way."""
        return self.ended_on_goal and self.max_penetration <= PENETRATION_TOLERANCE

    @property
    def max_deviation_cells(self) -> float:
        """Largest distance (cells) of the tip from the polyline of the planned cells."""
        return float(polyline_distance(self.tip_xy, self.planned_xy).max() / self.cell)

    @property
    def max_tracking_error_cells(self) -> float:
        """Largest distance (cells) of the tip from the polyline of the planned tip positions
        (the compiled states' tips): the controller's error alone, without the offset of a
        state's tip from its cell's centre."""
        return float(polyline_distance(self.tip_xy, self.planned_tip[:, :2]).max() / self.cell)

    @property
    def final_error_cells(self) -> float:
        """Distance (cells) of the final tip from the last waypoint's compiled tip."""
        return float(np.linalg.norm(self.tip_xy[-1] - self.planned_tip[-1, :2]) / self.cell)

    @property
    def goal_offset_cells(self) -> float:
        """Largest distance (cells), along x or y, of the final tip from the goal cell's centre:
        at most half a cell when the tip ends over the goal cell."""
        centre = np.array(self.scene.layout.xy(self.goal_cell % self.scene.layout.n_cells), dtype=float) * self.cell
        return float(np.abs(self.tip_xy[-1] - centre).max() / self.cell)

    def shortfall(self) -> str:
        """One line saying why the tip does not end over the goal cell, or "" when it does."""
        if self.reached_goal:
            return ""
        if self.ended_on_goal:
            return (f"the arm went {self.max_penetration * 1000:.1f} mm into {self.penetrated_into()} on the way "
                    f"({self.penetration_what}; at most {PENETRATION_TOLERANCE * 1000:g} mm allowed)")
        servos = self.settings.get("servos", "file")
        limited = sorted(((n, k) for n, k in self.settings.get("at_limit_steps", {}).items() if k),
                         key=lambda item: -item[1])
        limit = (f"; actuator {limited[0][0]} was at its force limit {limited[0][1]} of {len(self.time) - 1} steps"
                 if limited else "")
        if self.settings.get("slowed_segments"):
            limit += (f", with {self.settings['slowed_segments']} segment(s) run up to {self.settings['slowdown']}x "
                      f"slower (at most {self.settings.get('max_slowdown', 1)}x)")
        return (f"the tip ends {self.goal_offset_cells:.2f} cell (along x or y) from the goal cell's centre "
                f"(half a cell is allowed) and {self.final_error_cells:.2f} cell from the last waypoint, driven by the "
                f"{'scene' if servos == 'scene' else 'file'}'s actuators{limit}")

    def penetrated_into(self) -> str:
        """"the table" or "a wall": what the deepest contact was with."""
        return "the table" if self.penetration_what.endswith("the table") else "a wall"

    def penetration_line(self) -> str:
        """One line on the deepest contact with a wall or the table: "no wall or table contact",
        "0.2 mm into a wall (at most 0.5 allowed)"."""
        if self.max_penetration <= 0.0:
            return "no wall or table contact"
        return (f"{self.max_penetration * 1000:.1f} mm into {self.penetrated_into()} "
                f"(at most {PENETRATION_TOLERANCE * 1000:g} allowed)")

    def frame_indices(self, fps: float) -> np.ndarray:
        """Sample index for each video frame at ``fps`` (frames at t = k / fps, last at the end)."""
        if not fps > 0:
            raise ReplayError(f"fps must be positive, got {fps}")
        n = int(np.floor(self.duration * fps + 1e-9)) + 1
        times = np.arange(n) / fps
        idx = np.searchsorted(self.time, times - 1e-9)
        idx = np.minimum(idx, len(self.time) - 1)
        if idx[-1] != len(self.time) - 1:  # always show the final pose
            idx = np.append(idx, len(self.time) - 1)
        return idx

    def frames_qpos(self, fps: float) -> np.ndarray:
        """[n_frames, nq] configurations to render at ``fps`` (real-time playback)."""
        return self.qpos[self.frame_indices(fps)]

    def report(self) -> dict:
        """JSON-able summary."""
        return {
            "robot": self.robot,
            "waypoints": len(self.path_states),
            "goal_cell": list(self.scene.layout.xy(self.goal_cell % self.scene.layout.n_cells)),
            "final_cell": (list(self.scene.layout.xy(self.final_cell))
                           if self.final_cell != OFF_TABLE else None),
            "reached_goal": self.reached_goal,
            "ended_on_goal": self.ended_on_goal,
            "max_penetration_mm": round(self.max_penetration * 1000, 4),
            "penetration_tolerance_mm": PENETRATION_TOLERANCE * 1000,
            **({"penetration_contact": self.penetration_what} if self.penetration_what else {}),
            "max_deviation_cells": round(self.max_deviation_cells, 4),
            "max_tracking_error_cells": round(self.max_tracking_error_cells, 4),
            "final_error_cells": round(self.final_error_cells, 4),
            "seconds_simulated": round(self.duration, 4),
            "physics_steps": len(self.time) - 1,
            **{k: v for k, v in self.settings.items() if k != "at_limit_steps"},
            **({} if self.reached_goal else {"shortfall": self.shortfall()}),
        }


def polyline_distance(points: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """Distance of each point [n, 2] from the polyline through ``vertices`` [m, 2]."""
    p = np.asarray(points, dtype=float)[:, None, :2]
    v = np.asarray(vertices, dtype=float)[:, :2]
    if len(v) == 1:
        return np.linalg.norm(p[:, 0] - v[0], axis=-1)
    a, b = v[:-1][None], v[1:][None]
    ab = b - a
    denom = np.maximum(np.sum(ab * ab, axis=-1), 1e-18)
    t = np.clip(np.sum((p - a) * ab, axis=-1) / denom, 0.0, 1.0)
    closest = a + t[..., None] * ab
    return np.linalg.norm(p - closest, axis=-1).min(axis=1)


def arm_of(robot) -> ArmDescription:
    """The arm description of a discrete robot; a grid robot cannot be replayed."""
    arm = getattr(robot, "arm", None)
    if not isinstance(arm, ArmDescription):
        raise ReplayError(f"robot {robot.name} is not an arm robot; only ARM:ACTIONS robots can be "
                          "replayed in MuJoCo")
    return arm


def robot_scene(robot) -> ArmScene:
    """The MuJoCo scene ``robot`` (a discrete arm robot) was compiled in, rebuilt from its arm."""
    arm = arm_of(robot)
    return build_scene(Path(arm.xml_path), arm.tool, arm.mount, arm.yaw, arm.cell_size, layout=arm.layout)


def check_replayable(robot) -> ArmScene:
    """Before any learning: the robot's scene rebuilds, every joint has a position servo, and
    the rebuilt scene puts the tip where the compiled states say. Returns the scene."""
    arm = arm_of(robot)
    scene = robot_scene(robot)
    model = scene.model
    driven = set(model.actuator_trnid[model.actuator_trntype == mujoco.mjtTrn.mjTRN_JOINT, 0].tolist())
    if driven != set(range(model.njnt)):
        raise ReplayError(f"robot {robot.name}: not every joint of its scene has a servo to replay a path with")
    tip_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    data = mujoco.MjData(model)
    if arm.tip is not None and np.linalg.norm(_fk(model, data, arm.qpos[0], tip_id) - arm.tip[0]) > 1e-5:
        raise ReplayError(f"the rebuilt scene of {robot.name} does not match its compiled tips; recompile the robot")
    return scene


def _dedupe(cells: Sequence[int]) -> list[int]:
    out: list[int] = []
    for c in cells:
        if not out or out[-1] != c:
            out.append(int(c))
    return out


def replay(robot, path_states: Sequence[int], *, goal_cell: int | None = None,
           segment_seconds: float = SEGMENT_SECONDS, settle_seconds: float = SETTLE_SECONDS,
           bandwidth_hz: float = BANDWIDTH_HZ, feedforward: bool = True,
           scene: ArmScene | None = None, servos: str = "auto", max_slowdown: int = MAX_SLOWDOWN) -> Replay:
    """Simulate the arm of ``robot`` following ``path_states`` with its position actuators.

    ``path_states``: the robot's states in order (e.g. ``[s for s, _ in
    robot.shortest_path(start, goal)]``). ``goal_cell`` defaults to the last state's label.
    Each segment between waypoints lasts ``segment_seconds``; the goal is then held for
    ``settle_seconds``. ``scene`` may be passed to skip rebuilding it (it must be the
    robot's own scene). ``servos``: one of ``SERVOS`` (see the module docstring). ``max_slowdown``:
    how many times ``segment_seconds`` a segment the file's actuators miss at their force limit
    may be stretched to (1: never).
    Deterministic: no randomness anywhere.
    """
    if servos not in SERVOS:
        raise ReplayError(f"unknown servos {servos!r}; valid: {', '.join(SERVOS)}")
    if isinstance(max_slowdown, bool) or not isinstance(max_slowdown, int) or max_slowdown < 1:
        raise ReplayError(f"max_slowdown must be a whole number of at least 1, got {max_slowdown!r}")

    def simulate(own_servos: bool, scene: ArmScene | None) -> Replay:
        return _simulate(robot, path_states, goal_cell=goal_cell, segment_seconds=segment_seconds,
                         settle_seconds=settle_seconds, bandwidth_hz=bandwidth_hz, feedforward=feedforward,
                         scene=scene, own_servos=own_servos, max_slowdown=max_slowdown)

    if servos == "scene":
        return simulate(True, scene)
    first = simulate(False, scene)
    if servos == "file" or (first.reached_goal and first.max_tracking_error_cells <= TRACKING_LIMIT):
        return first
    second = simulate(True, first.scene)
    second.settings["file_servos"] = {"reached_goal": first.reached_goal,
                                      "max_tracking_error_cells": round(first.max_tracking_error_cells, 4)}
    if not first.reached_goal:
        second.settings["file_servos"]["shortfall"] = first.shortfall()
    if "torque_motors" in first.settings:
        second.settings["file_servos"]["torque_motors"] = first.settings["torque_motors"]
    return second


def _simulate(robot, path_states: Sequence[int], *, goal_cell: int | None, segment_seconds: float,
              settle_seconds: float, bandwidth_hz: float, feedforward: bool, scene: ArmScene | None,
              own_servos: bool, max_slowdown: int = MAX_SLOWDOWN) -> Replay:
    """One replay, with the file's servos or (``own_servos``) the scene's."""
    states = [int(s) for s in path_states]
    if not states:
        raise ReplayError("a replay needs at least one path state")
    arm = arm_of(robot)
    qtable = arm.qpos
    scene = scene or robot_scene(robot)
    if any(not 0 <= s < len(qtable) for s in states):
        bad = next(s for s in states if not 0 <= s < len(qtable))
        raise ReplayError(f"state {bad} is not a state of {robot.name} (0..{len(qtable) - 1})")
    if not (segment_seconds > 0 and settle_seconds >= 0 and bandwidth_hz > 0):
        raise ReplayError("segment_seconds and bandwidth_hz must be positive, settle_seconds >= 0")
    goal = int(robot.label[states[-1]]) if goal_cell is None else int(goal_cell)

    model = copy.copy(scene.model)  # the gains are retuned on this copy only
    if own_servos:  # position servos with no force or control limit
        model.actuator_forcelimited[:] = 0
        model.actuator_ctrllimited[:] = 0
        model.actuator_gaintype[:] = mujoco.mjtGain.mjGAIN_FIXED
        model.actuator_biastype[:] = mujoco.mjtBias.mjBIAS_AFFINE
    data = mujoco.MjData(model)
    tip_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, scene.tip)
    way = np.asarray(qtable[states], dtype=float)
    planned_tip = _planned_tips(robot, arm, model, data, way, states, tip_id)

    run = _Drive(model, data, scene, tip_id, feedforward,
                 _tune_gains(model, data, bandwidth_hz), [] if own_servos else _motors_in(model, arm))
    dt = float(model.opt.timestep)
    seg_steps = max(1, int(round(segment_seconds / dt)))
    settle_steps = int(round(settle_seconds / dt))
    slow_ok = not own_servos and max_slowdown > 1
    factors, waypoint_index = run.follow(way, planned_tip, seg_steps, slow_ok, max_slowdown)
    zero = np.zeros(model.nq)
    for _ in range(settle_steps):
        run.step(way[-1], zero)
    qpos, tip, depths = run.recorded()

    layout = scene.layout
    planned_cells = _dedupe(robot.label[states].tolist())
    planned_xy = np.array([np.array(layout.xy(c % layout.n_cells), dtype=float) * scene.cell for c in planned_cells])
    settings: dict[str, Any] = {"segment_seconds": seg_steps * dt, "settle_seconds": settle_steps * dt,
                                "bandwidth_hz": bandwidth_hz, "feedforward": feedforward, "timestep": dt,
                                "servos": "scene" if own_servos else "file",
                                "slowdown": max(factors, default=1),
                                "slowed_segments": sum(f > 1 for f in factors)}
    if slow_ok:
        settings["max_slowdown"] = max_slowdown
    settings.update(run.limit_settings())
    return Replay(robot=robot.name, scene=scene, path_states=tuple(states), goal_cell=goal,
                  planned_xy=planned_xy, planned_tip=planned_tip, time=np.arange(len(qpos)) * dt,
                  qpos=qpos, tip=tip, waypoint_index=waypoint_index, penetration=depths,
                  penetration_what=_contact_name(model, scene, *run.deepest[1]) if run.deepest[0] > 0 else "",
                  settings=settings)


def _planned_tips(robot, arm: ArmDescription, model: mujoco.MjModel, data: mujoco.MjData, way: np.ndarray,
                  states: list[int], tip_id: int) -> np.ndarray:
    """Put the arm at the first waypoint; the compiled tips of the path (checked against the
    rebuilt scene), or the scene's own where the description has none."""
    planned_tip = np.asarray(arm.tip[states], dtype=float) if arm.tip is not None else None
    data.qpos[:] = way[0]
    data.ctrl[:] = _ctrl_of(model, way[0])
    mujoco.mj_forward(model, data)
    if planned_tip is not None and np.linalg.norm(data.site_xpos[tip_id] - planned_tip[0]) > 1e-5:
        raise ReplayError(f"the rebuilt scene of {robot.name} does not match its compiled tips; "
                          "recompile the robot")
    if planned_tip is None:
        planned_tip = np.array([_fk(model, data, q, tip_id) for q in way])
        data.qpos[:] = way[0]
        mujoco.mj_forward(model, data)
    return planned_tip


class _Drive:
    """The arm driven through one replay: its servos (and torque motors) step by step, with
    what each step recorded (qpos, tip, deepest contact) and the steps each actuator spent at
    its force limit."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, scene: ArmScene, tip_id: int,
                 feedforward: bool, kv: np.ndarray, motors: list) -> None:
        self.model, self.data, self.scene, self.tip_id, self.feedforward = model, data, scene, tip_id, feedforward
        joint_of = model.actuator_trnid[:, 0]
        self.dof_of = model.jnt_dofadr[joint_of]
        self.qadr_of = model.jnt_qposadr[joint_of]
        self.damping = model.dof_damping[self.dof_of] + kv
        self.motors = motors
        tq = np.array([a for a, _ in motors], dtype=np.int64)  # the actuators (scene servos) they replace
        self.tq = tq
        self.tq_kp, self.tq_kv = model.actuator_gainprm[tq, 0].copy(), kv[tq]
        self.tq_lo = np.array([m.lower for _, m in motors])
        self.tq_hi = np.array([m.upper for _, m in motors])
        self.tq_dof, self.tq_qadr = self.dof_of[tq], self.qadr_of[tq]
        model.actuator_gainprm[tq, 0] = 0.0  # the joint's own servo does nothing: the motors drive it
        model.actuator_biasprm[tq, :3] = 0.0
        self.limited = model.actuator_forcelimited.astype(bool) & ~np.isin(np.arange(model.nu), tq)
        self.f_lo, self.f_hi = model.actuator_forcerange[self.limited].T
        self.at_limit = np.zeros(model.nu, dtype=np.int64)
        self.qpos_l: list[np.ndarray] = [data.qpos.copy()]
        self.tip_l: list[np.ndarray] = [data.site_xpos[tip_id].copy()]
        self.depth_l: list[float] = [0.0]
        self.env, self.moving = scene.env_geoms, scene.arm_geoms
        self.deepest: list = [0.0, (-1, -1)]  # depth (m), geoms

    def step(self, ctrl_q: np.ndarray, vel_q: np.ndarray) -> None:
        model, data, tq = self.model, self.data, self.tq
        data.ctrl[:] = ctrl_q[self.qadr_of]
        mujoco.mj_step1(model, data)
        if self.feedforward:
            data.qfrc_applied[:] = data.qfrc_bias
            data.qfrc_applied[self.dof_of] += self.damping * vel_q[self.qadr_of]
        if len(tq):  # computed torque, within the motors' range
            base = data.qfrc_applied[self.tq_dof] if self.feedforward else 0.0
            tau = (base + self.tq_kp * (ctrl_q[self.tq_qadr] - data.qpos[self.tq_qadr])
                   - self.tq_kv * data.qvel[self.tq_dof])
            clipped = np.clip(tau, self.tq_lo, self.tq_hi)
            self.at_limit[tq] += clipped != tau
            data.qfrc_applied[self.tq_dof] = clipped
        mujoco.mj_step2(model, data)
        limited = self.limited
        if limited.any():
            force = data.actuator_force[limited]
            f_lo, f_hi = self.f_lo, self.f_hi
            self.at_limit[limited] += (force <= f_lo + 1e-9 * np.abs(f_lo)) | (force >= f_hi - 1e-9 * np.abs(f_hi))
        depth = 0.0
        n = data.ncon
        if n:  # the contacts of this step's collision, at its start
            env, moving, deepest = self.env, self.moving, self.deepest
            g1, g2 = data.contact.geom1[:n], data.contact.geom2[:n]
            hit = (env[g1] & moving[g2]) | (env[g2] & moving[g1])
            if hit.any():
                i = int(np.argmin(np.where(hit, data.contact.dist[:n], np.inf)))
                depth = max(0.0, -float(data.contact.dist[i]))
                if depth > deepest[0]:
                    deepest[0], deepest[1] = depth, (int(g1[i]), int(g2[i]))
        self.qpos_l.append(data.qpos.copy())
        self.tip_l.append(data.site_xpos[self.tip_id].copy())
        self.depth_l.append(depth)

    def follow(self, way: np.ndarray, planned_tip: np.ndarray, seg_steps: int, slow_ok: bool,
               max_slowdown: int) -> tuple[list[int], np.ndarray]:
        """Ramp through the waypoints, a segment slowed down (``slow_ok``) where the file's
        actuators missed it at their force limit; each segment's factor and the step at which
        each waypoint was reached."""
        model, data, tip_id = self.model, self.data, self.tip_id
        qpos_l, tip_l, depth_l, at_limit, deepest = self.qpos_l, self.tip_l, self.depth_l, self.at_limit, self.deepest
        dt = float(model.opt.timestep)
        waypoint_index = np.zeros(len(way), dtype=np.int64)
        probe = mujoco.MjData(model)
        saved = mujoco.MjData(model)
        miss = TRACKING_LIMIT * self.scene.cell
        factors = []
        for i in range(1, len(way)):
            q0, q1 = way[i - 1], way[i]
            factor = 1
            while True:
                if slow_ok:
                    mujoco.mj_copyData(saved, model, data)
                    mark, limits, before = len(qpos_l), at_limit.copy(), list(deepest)
                steps = seg_steps * factor
                vel = (q1 - q0) / (steps * dt)
                for j in range(1, steps + 1):
                    self.step(q0 + (q1 - q0) * (j / steps), vel)
                if slow_ok and 2 * factor <= max_slowdown and np.any(at_limit > limits):
                    seg = _tips_of(model, np.array(qpos_l[mark:]), tip_id, probe)
                    off = polyline_distance(seg, planned_tip[i - 1:i + 1]).max()
                    if off > miss or np.linalg.norm(seg[-1] - planned_tip[i]) > miss:  # missed, saturated: slower
                        mujoco.mj_copyData(data, model, saved)
                        del qpos_l[mark:], tip_l[mark:], depth_l[mark:]
                        at_limit[:] = limits
                        deepest[:] = before
                        factor *= 2
                        continue
                break
            factors.append(factor)
            waypoint_index[i] = len(qpos_l) - 1
        return factors, waypoint_index

    def recorded(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """qpos, tip and deepest contact of every step, the tips recomputed from qpos."""
        model, data, tip_id = self.model, self.data, self.tip_id
        k = len(self.qpos_l) - 1
        qpos, tip, depths = np.array(self.qpos_l), np.array(self.tip_l), np.array(self.depth_l)
        # site_xpos after mj_step2 is from the step's start; refresh the last sample exactly.
        mujoco.mj_kinematics(model, data)
        tip[k] = data.site_xpos[tip_id]
        # Likewise every recorded tip lags its qpos by one step: recompute them from qpos.
        if k > 1:
            tip[1:k] = _tips_of(model, qpos[1:k], tip_id)
        return qpos, tip, depths

    def limit_settings(self) -> dict[str, Any]:
        """The torque motors and the steps each actuator spent at its force limit."""
        model, at_limit, motors = self.model, self.at_limit, self.motors
        settings: dict[str, Any] = {}
        if motors:
            settings["torque_motors"] = {m.joint: {"actuators": list(m.actuators), "torque_range": [m.lower, m.upper],
                                                   "steps_at_limit": int(at_limit[a])} for a, m in motors}
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a) or f"#{a}" for a in range(model.nu)]
        for a, m in motors:  # a joint the motors drive is named by them, not by the servo that stood in
            names[a] = "+".join(m.actuators)
        settings["at_limit_steps"] = {names[a].removeprefix(PREFIX): int(at_limit[a]) for a in range(model.nu)}
        return settings


def _motors_in(model: mujoco.MjModel, arm: ArmDescription) -> list:
    """(scene actuator, file's torque motors) for each chain joint the scene gave a servo of
    its own because the file drives it with torque motors only."""
    own = {}
    for a in range(model.nu):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, a) or ""
        if name.startswith(PREFIX + "servo_"):
            own[name[len(PREFIX + "servo_"):]] = a
    if not own:
        return []
    return [(own[m.joint], m) for m in torque_motors(Path(arm.xml_path), [j for j in arm.chain if j in own])
            if m.joint in own]


def _ctrl_of(model: mujoco.MjModel, q: np.ndarray) -> np.ndarray:
    return np.asarray(q)[model.jnt_qposadr[model.actuator_trnid[:, 0]]]


def _fk(model, data, q, tip_id) -> np.ndarray:
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    return data.site_xpos[tip_id].copy()


def _contact_name(model: mujoco.MjModel, scene: ArmScene, g1: int, g2: int) -> str:
    """"link4 with wall wall_2", "hand with the table": a contact between an arm geom and the scenery."""
    if scene.env_geoms[g1]:
        g1, g2 = g2, g1
    body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[g1]))
    arm = (body or "the arm").removeprefix(PREFIX)
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g2) or ""
    return f"{arm} with {'wall ' + name if name.startswith('wall_') else 'the table'}"


def _tips_of(model, qs: np.ndarray, tip_id: int, d: mujoco.MjData | None = None) -> np.ndarray:
    d = d if d is not None else mujoco.MjData(model)
    out = np.empty((len(qs), 3))
    for i, q in enumerate(qs):
        out[i] = _fk(model, d, q, tip_id)
    return out


def _tune_gains(model: mujoco.MjModel, data: mujoco.MjData, bandwidth_hz: float) -> np.ndarray:
    """Critically damped position servos per joint; returns each actuator's kv."""
    if not np.all(model.actuator_trntype == mujoco.mjtTrn.mjTRN_JOINT):
        raise ReplayError("every actuator must drive a joint to replay a path")
    w = 2 * np.pi * bandwidth_hz
    mujoco.mj_forward(model, data)
    dense = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, dense)
    dofs = model.jnt_dofadr[model.actuator_trnid[:, 0]]
    inertia = np.diag(dense)[dofs]
    kp, kv = inertia * w * w, 2 * inertia * w
    model.actuator_gainprm[:, 0] = kp
    model.actuator_biasprm[:, 0] = 0.0
    model.actuator_biasprm[:, 1] = -kp
    model.actuator_biasprm[:, 2] = -kv
    return kv


__all__ = ["SERVOS", "Replay", "ReplayError", "check_replayable", "polyline_distance", "replay", "robot_scene"]
