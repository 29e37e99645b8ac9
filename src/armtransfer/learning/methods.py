"""Every transfer method, defined once: the registry the API, the command, sweeps, reports,
the wrappers and the scripts read.

A method is a name, a one-line description, whether it is the paper's, how its shaping
arrays are built from a robot and the transferred trajectories (``None``: no shaping), its
automatic K, whether a too-large K can be farmed, whether it runs mapped macros, and the
baselines its gain is measured against. Adding a method is one :class:`Method` entry in
:data:`METHODS` (and, for a new kind of reward term, a mode in ``armtransfer.learning.shaping``
that the kernel understands).

Baselines. A method's gain is measured against a method that shares its learner and differs
only in what it is told: ``none`` for the reward terms on Algorithm 1 (``pseudo``, ``dense``,
...); ``plan`` for the methods on ``guided``'s learner (its model of its own moves and its
planner, with no trajectory at all); and ``goal-only`` (``guided`` told the goal and no route)
for what ``guided``'s route adds beyond knowing the goal. ``Method.baselines`` names them, the
no-transfer one first, and :func:`with_baselines` adds them to a list of methods to run.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import guide, potentials
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning import shaping as modes
from armtransfer.learning.rewards import as_list, farming_bound, longest_n, union_index
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.worlds.layout import Layout
from armtransfer.tasks.robot import DiscreteRobot

HALF_BOUND = 0.5
"""K='auto' of a method without its own ``auto_k`` starts at this fraction of the farming
bound -step_reward/n (a farmable method's is then verified by value iteration, see
``armtransfer.learning.farming``)."""

DEFAULT_GAMMA = LearnerConfig().gamma
"""The discount :func:`build_shaping` bounds potentials for unless told the learner's."""

Builder = Callable[[DiscreteRobot, list[Trajectory], float, float], Shaping]
"""(robot, trajectories, K, beta) -> the shaping arrays."""


@dataclass(frozen=True)
class Method:
    name: str
    description: str
    """One line, for --help and reports."""
    paper: bool
    """The paper's own method (section III), not one added here."""
    build: Builder | None = None
    """The shaping arrays; None for a method without shaping (``none``)."""
    auto_k: float | None = None
    """K for ``K='auto'`` in units of -step_reward; None: half the farming bound -step_reward/n.
    Chosen on held-out start/goal pairs by research/select_defaults.py, never on Table I."""
    farmable: bool = False
    """A state bonus that a loop could collect forever: K is checked against farming."""
    macros: bool = False
    """Runs the action sequence mapping's macros (needs exactly one trajectory)."""
    chooses: bool = False
    """Changes how the learner chooses actions, not only its rewards (so no reward wrapper can
    give it to another learner)."""
    baselines: tuple[str, ...] = ()
    """The methods this one's gain is measured against: each shares its learner (the same
    updates, the same way of choosing actions) and is told less; the first is told nothing
    (no transfer). Empty for a method that is itself no transfer (``none``, ``plan``)."""
    is_baseline: bool = False
    """Exists to be compared against (run beside the methods naming it in ``baselines``), not a
    transfer method of its own: the controls (shuffled and random trajectories) and the paper's
    tables leave it out."""
    uses_trajectory: bool = True
    """Reads the transferred trajectories; False for a shaped method that transfers nothing
    (``plan``), which is then built without them."""

    @property
    def shaped(self) -> bool:
        return self.build is not None

    @property
    def baseline(self) -> str | None:
        """The no-transfer method that shares this one's learner (None: it is one itself)."""
        return self.baselines[0] if self.baselines else None

    def resolve_k(self, K: float | str | None, step_reward: float, trajs: Sequence[Trajectory]) -> float:
        """The K this method uses: ``K`` itself, or its automatic K for 'auto'/None."""
        if K is None or K == "auto":
            if step_reward >= 0:
                raise InvalidParameterError("K='auto' needs a negative step reward (it is scaled by -step_reward)")
            if self.auto_k is not None:
                return self.auto_k * -step_reward
            return HALF_BOUND * farming_bound(step_reward, trajs)
        try:
            k = float(K)
        except (TypeError, ValueError):
            raise InvalidParameterError(f"K must be a non-negative number or 'auto', got {K!r}") from None
        if not np.isfinite(k) or k < 0:
            raise InvalidParameterError(f"K must be a non-negative number or 'auto', got {K!r}")
        return k


def _pseudo(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    eff, ids = union_index(robot, trajs)
    return Shaping(modes.MODE_PSEUDO, eff * k, ids, np.zeros(robot.n_states), k)


def _first_visit(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    eff, ids = union_index(robot, trajs)
    return Shaping(modes.MODE_FIRST_VISIT, eff * k, ids, np.zeros(robot.n_states), k)


def _progress(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    eff, ids = union_index(robot, trajs)
    return Shaping(modes.MODE_PROGRESS, eff * k, ids, np.zeros(robot.n_states), k)


def _potential(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    eff, ids = union_index(robot, trajs)
    return Shaping(modes.MODE_POTENTIAL, np.zeros(robot.n_states), ids, eff * k, k)


def _dense(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    if not (np.isfinite(beta) and beta >= 0):
        raise InvalidParameterError(f"beta must be a non-negative number, got {beta}")
    _, ids = union_index(robot, trajs)
    phi = np.max([potentials.dense(robot, t, k, beta) for t in trajs], axis=0)
    return Shaping(modes.MODE_POTENTIAL, np.zeros(robot.n_states), ids, phi, k)


def _guided(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    # no reward term: Algorithm 1's updates unchanged; the model chooses in the exploration phase
    _, ids = union_index(robot, trajs)
    n = robot.n_states
    return Shaping(modes.MODE_NONE, np.zeros(n), ids, np.zeros(n), k, guide=guide.build(robot, trajs))


CORRIDOR_RADIUS = 1.5
"""``corridor``: cells from the trajectory within which an untried move keeps its full optimism."""
CORRIDOR_FADE = 50.0
"""``corridor``: optimism lost per cell beyond CORRIDOR_RADIUS, in units of Q."""
CORRIDOR_ROUTE = 1.0
"""``corridor``: optimism lost per cell of trajectory left from the nearest trajectory cell, in
units of Q. The three were chosen on the dev suite by research/corridor_dev.py
(docs/research-log.md, "a transfer that pays for the whole of learning")."""


def _corridor(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    # guided, and after its first episode the planner's optimism for untried moves follows the route
    sh = _guided(robot, trajs, k, beta)
    return replace(sh, guide=guide.build(robot, trajs, radius=CORRIDOR_RADIUS, fade=CORRIDOR_FADE,
                                         route=CORRIDOR_ROUTE))


def planner_guide(robot: DiscreteRobot) -> guide.Guide:
    """``guided``'s learner told nothing: the same model of robot 2's own moves (a move tried
    here and blocked every time is never chosen, a move tried nowhere yet is tried first), the
    same planning after every episode, and no preference from any trajectory (weight 0). It never
    gives up on its placeholder trajectory (one point, give_up 0), so the
    trajectory cannot switch the model off either: no choice depends on it. The tip model and the
    fill only feed the trajectory's score, so they are off."""
    here = int(robot.label[0])
    null = Trajectory(cells=(here,), actions=(0,), goal=here, source="none")
    return guide.build(robot, [null], weight=0.0, give_up=0, tip=False, fill=0.0)


def _plan(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    return Shaping(modes.MODE_NONE, np.zeros(robot.n_states), np.full(robot.n_states, -1, np.int64),
                   np.zeros(robot.n_states), k, guide=planner_guide(robot))


def straight_line(traj: Trajectory, layout: Layout) -> Trajectory:
    """The cells of the straight line from ``traj``'s start to its goal, one cell apart (walls
    included: robot 2 knows no map), ending with the goal: all a trajectory says that does not
    depend on its route."""
    (x0, y0), (x1, y1) = layout.xy(traj.start), layout.xy(traj.goal)
    n = max(abs(x1 - x0), abs(y1 - y0), 1)
    cells: list[int] = []
    for i in range(n + 1):
        c = layout.cell(int(np.rint(x0 + (x1 - x0) * i / n)), int(np.rint(y0 + (y1 - y0) * i / n)))
        if not cells or cells[-1] != c:
            cells.append(c)
    if len(cells) > 1 and cells[-1] == traj.goal:
        cells.pop()  # the goal is s_tg, not one of the cells
    return Trajectory(tuple(cells), (0,) * len(cells), traj.goal, source="goal-only")


def _goal_only(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    return _guided(robot, [straight_line(trajs[0], robot.layout)], k, beta)


def _pseudo_plan(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    sh = _pseudo(robot, trajs, k, beta)
    return Shaping(sh.mode, sh.bonus, sh.traj_index, sh.phi, k, guide=planner_guide(robot))


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method("none", "Algorithm 1 without transfer", paper=True),
        Method("pseudo", "the paper's pseudo reward i*K on reaching the i-th trajectory cell",
               paper=True, build=_pseudo, farmable=True, baselines=("none",)),
        Method("mapping", "pseudo plus the action sequence mapping's macros (the paper's III.C)",
               paper=True, build=_pseudo, farmable=True, macros=True, baselines=("none",)),
        Method("first-visit", "the pseudo reward paid at most once per cell per episode",
               paper=False, build=_first_visit, auto_k=10.0, baselines=("none",)),
        Method("potential", "potential-based shaping with phi = i*K (Ng, Harada and Russell)",
               paper=False, build=_potential, auto_k=3.0, baselines=("none",)),
        Method("progress", "pays only for passing the highest trajectory index reached so far",
               paper=False, build=_progress, auto_k=30.0, baselines=("none",)),
        Method("dense", "potential from the progress along the trajectory and the distance to it",
               paper=False, build=_dense, auto_k=potentials.DENSE_K, baselines=("none",)),
        Method("guided", "robot 2 learns while it explores what its own actions do to its cell (an arm that moves its "
               "joints: where its tip is) and, until the goal is first reached, prefers those predicted to lead on along "
               "the trajectory; after every episode it plans over the moves it has tried",
               paper=False, build=_guided, auto_k=0.0, chooses=True, baselines=("plan", "goal-only")),
        Method("corridor", "guided, and after every episode it plans with the optimism of an untried move fading "
               "with its distance from the trajectory and with the trajectory left to the goal",
               paper=False, build=_corridor, auto_k=0.0, chooses=True, baselines=("plan",)),
        Method("plan", "guided's learner with no transfer: its model of its own moves and its planning after every "
               "episode, no trajectory", paper=False, build=_plan, auto_k=0.0, chooses=True, is_baseline=True,
               uses_trajectory=False),
        Method("goal-only", "guided told only the goal: the straight line from the start to the goal for its route",
               paper=False, build=_goal_only, auto_k=0.0, chooses=True, baselines=("plan",), is_baseline=True),
        Method("pseudo-plan", "the paper's pseudo reward on guided's learner told nothing (plan): the paper's reward "
               "and guided on equal footing", paper=False, build=_pseudo_plan, farmable=True, chooses=True,
               baselines=("plan",), is_baseline=True),
    )
}
"""Every method, ``none`` first. The order is the order of reports."""

SHAPED = tuple(name for name, m in METHODS.items() if m.shaped and not m.macros and not m.is_baseline)
"""The transfer methods without macros (the controls run these); the baselines are left out."""

REWARD_ONLY = tuple(name for name, m in METHODS.items() if m.shaped and not m.chooses)
"""The methods whose transfer is a reward term alone (what ``armtransfer.wrappers`` can add)."""
"""The methods that are a reward term only (controls run these)."""


def get(name: str) -> Method:
    """The method called ``name``; an unknown name is a one-line error listing the valid ones."""
    try:
        return METHODS[name]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"unknown method {name!r}; valid methods: {', '.join(METHODS)}") from None


def with_baselines(names: Sequence[str]) -> list[str]:
    """``names`` with every baseline they need (``Method.baselines``, and theirs) that is not
    among them, each put just before the first method that needs it: what a run of ``names``
    runs, so that every method can be compared with the baselines sharing its learner."""
    out: list[str] = []

    def add(name: str) -> None:
        if name not in out:
            for b in get(name).baselines:
                add(b)
            out.append(name)

    for name in names:
        add(get(name).name)
    return out


def build_shaping(
    method: str,
    robot: DiscreteRobot,
    trajs: Trajectory | Sequence[Trajectory] | None,
    K: float | str | None,
    step_reward: float,
    beta: float | None = None,
    gamma: float = DEFAULT_GAMMA,
) -> Shaping:
    """The shaping arrays of ``method`` for ``robot`` from one or several trajectories, for a
    learner with discount ``gamma``.

    A farmable method (``pseudo``, ``mapping``) refuses a K with step_reward + n*K >= 0, at
    which standing on the last trajectory cell pays at least as much as moving on. A
    potential-based method's potential is bounded for ``gamma`` (``potentials.bounded``), so
    that none of its self-loops pays."""
    m = get(method)
    build = m.build
    if build is None:
        raise InvalidParameterError(f"method {method!r} has no shaping")
    if m.uses_trajectory and trajs is None:
        raise InvalidParameterError(f"method {method!r} needs at least one trajectory")
    trajs = as_list(trajs) if trajs is not None and m.uses_trajectory else []
    k = m.resolve_k(K, step_reward, trajs)
    if m.farmable:
        n = longest_n(trajs)
        if step_reward + n * k >= 0:
            raise InvalidParameterError(
                f"K={k:g} can be farmed: step reward {step_reward:g} + largest pseudo reward "
                f"n*K = {n}*{k:g} >= 0; use K < {farming_bound(step_reward, trajs):.6g} "
                f"(-step_reward/n) or the method 'first-visit'"
            )
    sh = build(robot, trajs, k, potentials.DENSE_BETA if beta is None else float(beta))
    if sh.mode == modes.MODE_POTENTIAL:
        sh = replace(sh, phi=potentials.bounded(sh.phi, gamma, step_reward))
    return sh
