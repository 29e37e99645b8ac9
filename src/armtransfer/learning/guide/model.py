"""What the kernel is handed for method ``guided``: the ``Guide`` (fixed for a trial), the
``Model`` (what robot 2 learns during it, one record per mechanism), how both are built, and
the two calls the kernel makes after an episode starts and after every move."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.learning.guide import displacement, fill, planner, progress, tip
from armtransfer.learning.guide.displacement import Displacement
from armtransfer.learning.guide.fill import Fill
from armtransfer.learning.guide.planner import Planner
from armtransfer.learning.guide.progress import Progress
from armtransfer.learning.guide.tip import TipModel, tip_features, uses_tip
from armtransfer.learning.guide.params import (
    BLOCKED, EPISODES, FADE, FILL, FILL_COST, GIVE_UP, KNN, MEMORY, PLAN, PLAN_TOL, RADIUS, REACH, ROUTE, TIP, TIP_ANCHOR, TIP_NEAREST,
    TIP_ORDER, TIP_RIDGE, UNTRIED, WEIGHT, WINDOW, Params,
)
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot


class Guide(NamedTuple):
    """The arrays the guide reads, fixed for a trial (``build``)."""

    feat: np.ndarray
    """float64 [S, D]: robot 2's own configuration of each of its states."""
    lxy: np.ndarray
    """float64 [S, 2]: the xy of the label robot 2 perceives at each state."""
    tx: np.ndarray
    """float64 [T]: the trajectory cells' x (its goal last), trajectories one after another."""
    ty: np.ndarray
    """float64 [T]: their y."""
    trem: np.ndarray
    """float64 [T]: trajectory length (cells) from this cell to its end."""
    tstart: np.ndarray
    """int64 [n_traj + 1]: where each trajectory starts in tx, ty, trem."""
    params: Params
    tq: np.ndarray
    """float64 [S, C]: the moving joints of each state (the tip model's input; [0, 1] without it)."""
    fj: np.ndarray
    """int64 [F, TIP_ORDER]: the joints (columns of tq) each tip feature multiplies, -1 past its last."""
    fk: np.ndarray
    """int64 [F, TIP_ORDER]: 0 for the cosine of that joint, 1 for its sine."""
    untried: np.ndarray
    """float64 [S]: the planned Q of a pair never tried at each state (``planner.plan``): UNTRIED
    everywhere, or less away from the trajectories (``corridor_prior``)."""


class Model(NamedTuple):
    """What robot 2 learns during a trial, one record per mechanism (``new_model``)."""

    displacement: Displacement
    progress: Progress
    planner: Planner
    tip: TipModel
    fill: Fill


def build(robot: DiscreteRobot, trajs: list[Trajectory], window: float = WINDOW, reach: float = REACH,
          knn: int = KNN, memory: int = MEMORY, weight: float = WEIGHT, episodes: int = EPISODES,
          blocked: bool = BLOCKED, give_up: int = GIVE_UP, plan: bool = PLAN, tip: bool | None = TIP,
          tip_ridge: float = TIP_RIDGE, tip_nearest: int = TIP_NEAREST, tip_anchor: bool = TIP_ANCHOR,
          fill: float | None = FILL, radius: float = RADIUS, fade: float = FADE,
          route: float = ROUTE) -> Guide:
    """The guide for ``robot`` following ``trajs`` (one or several). ``tip`` None: the tip
    model for robots whose actions move a joint (``uses_tip``). ``fade`` > 0: the optimism
    of an untried pair fades by ``fade`` per cell its state's label lies beyond ``radius`` cells
    from the trajectories' cells, and by ``route`` per cell of trajectory left from the nearest
    cell (``corridor_prior``)."""
    for name, v in (("window", window), ("reach", reach), ("weight", weight)):
        if not (np.isfinite(v) and v >= 0):
            raise InvalidParameterError(f"{name} must be a non-negative number, got {v}")
    if not (np.isfinite(give_up) and give_up >= 0):
        raise InvalidParameterError(f"give_up must be a non-negative number of moves, got {give_up}")
    if int(knn) < 1 or int(memory) < 1 or int(episodes) < 1:
        raise InvalidParameterError(f"knn, memory and episodes must be positive integers, got {knn}, {memory}, {episodes}")
    if not (np.isfinite(tip_ridge) and tip_ridge > 0):
        raise InvalidParameterError(f"tip_ridge must be a positive number, got {tip_ridge}")
    if int(tip_nearest) < 1:
        raise InvalidParameterError(f"tip_nearest must be a positive integer, got {tip_nearest}")
    if not (np.isfinite(fade) and fade >= 0 and np.isfinite(route) and route >= 0) or not (radius >= 0):
        raise InvalidParameterError(f"fade, route and radius must be non-negative numbers, got {fade}, {route}, {radius}")
    if fill is not None and not (np.isfinite(fill) and fill >= 0):
        raise InvalidParameterError(f"fill must be a non-negative number of cells, got {fill}")
    layout = robot.layout
    lxy = layout.xy_of(robot.label % layout.n_cells).astype(np.float64).reshape(-1, 2)  # voxels: their cells
    if robot.arm is not None:
        feat = np.asarray(robot.arm.qpos, dtype=np.float64).reshape(robot.n_states, -1)
    else:
        feat = lxy.copy()
    xs, ys, rem, starts = [], [], [], [0]
    for t in trajs:
        cells = [*t.cells, t.goal]  # s_t0 .. s_tn and the goal s_tg
        c = np.array([layout.xy(int(cell) % layout.n_cells) for cell in cells], dtype=np.float64).reshape(-1, 2)
        seg = np.sqrt(((c[1:] - c[:-1]) ** 2).sum(axis=1))
        r = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]]) if len(seg) else np.zeros(1)
        xs.append(c[:, 0])
        ys.append(c[:, 1])
        rem.append(r)
        starts.append(starts[-1] + len(c))
    use_tip = uses_tip(robot) if tip is None else bool(tip)
    if use_tip:  # the joints that move (a held finger is constant over the states)
        tq = feat[:, np.ptp(feat, axis=0) > 0] if len(feat) else feat
        fj, fk = tip_features(tq.shape[1])
    else:
        tq, fj, fk = np.zeros((0, 1)), np.zeros((0, TIP_ORDER), np.int64), np.zeros((0, TIP_ORDER), np.int64)
    params = Params(window=float(window), reach=float(reach), knn=int(knn), memory=int(memory), weight=float(weight),
                    episodes=int(episodes), blocked=bool(blocked), give_up=int(give_up), plan=bool(plan),
                    plan_tol=PLAN_TOL, tip=use_tip, tip_ridge=float(tip_ridge), tip_nearest=int(tip_nearest),
                    tip_anchor=bool(tip_anchor),
                    fill=(FILL_COST if use_tip else 0.0) if fill is None else float(fill))
    tx, ty, trem = np.concatenate(xs), np.concatenate(ys), np.concatenate(rem)
    return Guide(feat=np.ascontiguousarray(feat), lxy=np.ascontiguousarray(lxy),
                 tx=tx, ty=ty, trem=trem,
                 tstart=np.array(starts, np.int64), params=params,
                 tq=np.ascontiguousarray(tq, dtype=np.float64), fj=fj, fk=fk,
                 untried=corridor_prior(lxy, tx, ty, trem, radius, fade, route))


def corridor_prior(lxy: np.ndarray, tx: np.ndarray, ty: np.ndarray, trem: np.ndarray, radius: float, fade: float,
                   route: float = 0.0) -> np.ndarray:
    """float64 [S]: the planned Q of an untried pair at each state, UNTRIED minus ``fade`` per
    cell its label ``lxy`` lies beyond ``radius`` cells from the nearest trajectory cell (tx, ty,
    the goals s_tg included), minus ``route`` per cell of trajectory left from that cell (trem).
    The planner then leads to untried pairs along the route before those away from it, and to
    one ``d`` cells off it only when that could save more than about fade * (d - radius) steps.
    Reads the trajectories' cells and robot 2's labels only: no map, nothing about the task
    beyond the trajectories. ``fade`` and ``route`` 0: UNTRIED everywhere (``plan``, ``guided``)."""
    out = np.full(len(lxy), UNTRIED)
    if (fade > 0.0 or route > 0.0) and len(lxy) and len(tx):
        d = np.full(len(lxy), np.inf)
        left = np.zeros(len(lxy))
        for j in range(len(tx)):  # one trajectory cell at a time: an arm has up to 1e6 states
            dj = np.sqrt((lxy[:, 0] - tx[j]) ** 2 + (lxy[:, 1] - ty[j]) ** 2)
            closer = dj < d
            d[closer] = dj[closer]
            left[closer] = trem[j]
        if fade > 0.0:
            out -= fade * np.maximum(d - radius, 0.0)
        if route > 0.0:
            out -= route * left
    return out


def new_model(g: Guide, n_states: int, n_actions: int) -> Model:
    """What robot 2 knows before its first move, sized for guide ``g``."""
    n_features = g.fj.shape[0]
    return Model(displacement=displacement.new(n_states, n_actions, g.params.memory),
                 progress=progress.new(len(g.tstart) - 1),
                 planner=planner.new(n_states, n_actions),
                 tip=tip.new(n_states, n_actions, n_features, g.tq.shape[1] if n_features else 0, g.params.tip_ridge),
                 fill=fill.new(n_states, n_actions, g.params.fill > 0.0))


def inactive(n_actions: int) -> tuple[Guide, Model]:
    """(guide, model) for a trial without a guide on the kernel compiled with one: no
    trajectories, empty arrays of the right types."""
    params = Params(window=0.0, reach=0.0, knn=1, memory=1, weight=0.0, episodes=0, blocked=False, give_up=0,
                    plan=False, plan_tol=0.0, tip=False, tip_ridge=1.0, tip_nearest=1, tip_anchor=False, fill=0.0)
    g = Guide(np.zeros((0, 1)), np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(1, np.int64),
              params, np.zeros((0, 1)), np.zeros((0, TIP_ORDER), np.int64), np.zeros((0, TIP_ORDER), np.int64),
              np.zeros(0))
    return g, new_model(g, 0, n_actions)


@numba.njit(cache=True)
def start_episode(g, m, s, guided):
    """At an episode's start at s: progress at each trajectory's first cell, then what s
    reaches; in the exploration phase (``guided``) the tip model learns from s."""
    progress.reset(g, m.progress)
    if guided and g.params.tip:
        tip.learn(g, m.tip, s)
    progress.update(g, m.progress, s)


@numba.njit(cache=True)
def observe(g, m, s, a, s2, guided):
    """Robot 2 records the move s --a--> s2 (s2: the state whose label it perceives after it)
    in each mechanism (the tip model only in the exploration phase, ``guided``), then its
    progress along the trajectories."""
    if g.params.fill > 0.0:
        fill.observe(m.fill, s, a, s2)
    if guided and g.params.tip:
        tip.observe(g, m.tip, s, a, s2)
    displacement.record(g, m.displacement, s, a, s2)
    if g.params.plan:
        planner.observe(m.planner, s * m.displacement.tries.shape[1] + a, s, s2)
    progress.update(g, m.progress, s2)
