"""Every transfer method, defined once: the registry the API, the command, sweeps, reports,
the wrappers and the scripts read.

A method is a name, a one-line description, whether it is the paper's, how its shaping
arrays are built from a robot and the transferred trajectories (``None``: no shaping), its
automatic K, whether a too-large K can be farmed, whether it runs mapped macros, and the
baselines its gain is measured against. Adding a built-in method is one :class:`Method` entry
in :data:`METHODS` (and, for a new kind of reward term, a mode in ``armtransfer.learning.shaping``
that the kernel understands). A method from outside the package (``armtransfer.learning.plugins``:
an installed package's entry point, or :func:`register_method` in a notebook) joins
:data:`METHODS` on its first use, after the built-in ones.

Baselines. A method's gain is measured against a method that shares its learner and differs
only in what it is told: ``none`` for the reward terms on Algorithm 1 (``pseudo``, ``dense``,
...); ``plan`` for the methods on ``guided``'s learner (its model of its own moves and its
planner, with no trajectory at all); and ``goal-only`` (``guided`` told the goal and no route)
for what ``guided``'s route adds beyond knowing the goal. ``goal-dense`` (``dense`` told the goal
and no route) and ``goal-only`` are the goal-only baselines the benchmark sets beside every method
that reads the trajectory (``experiments.benchmark.GOAL_ONLY``); ``lazy`` is a control beside
``plan``: told nothing and exploring less. ``Method.baselines`` names them, the
no-transfer one first, and :func:`with_baselines` adds them to a list of methods to run.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import replace

import numpy as np

from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.learning import guide, plugins, potentials
from armtransfer.learning import shaping as modes
from armtransfer.learning.lazy_registry import Names, Registry
from armtransfer.learning.plugin_calls import PROBE_SECONDS, probe_seconds
from armtransfer.learning.method import DEFAULT_GAMMA, HALF_BOUND, Method
from armtransfer.learning.rewards import as_list, farming_bound, longest_n, union_index
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

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


LAZY_UNTRIED = -100.0
"""``lazy``'s planned Q of an untried move, in units of Q (``plan``'s is just above 0): the lowest
return there is at the default step reward and discount (-1 / (1 - 0.99)), so the planner never
leads to an untried move while it knows a way to the goal; only epsilon-greedy tries new moves.
A control, not a method: told nothing, it explores less, so the settled clock ranked it ahead of
``plan`` (2.3-3.8x on Table I tasks 1-4, fine robot) while the good-path clock must not
(0.11-0.85x there; ``learning.clock``). A milder penalty (-10 or -30) is no such control: it
reached a good path sooner than ``plan`` (1.2-2.5x, settling within 5% of the shortest), a
finding about ``plan``, not about the clock (docs/research-log.md)."""


def _lazy(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    g = planner_guide(robot)._replace(untried=np.full(robot.n_states, LAZY_UNTRIED))
    return replace(_plan(robot, trajs, k, beta), guide=g)


def _goal_dense(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    # dense's potential from a trajectory that is its goal alone: it falls with the straight-line distance to the goal
    goal = trajs[0].goal
    only = Trajectory((goal,), (0,), goal, source="goal-only")
    return _dense(robot, [only], k, beta)


GOAL_WINDOW = 1e6
"""``goal-only``'s window: past any trajectory, so its score is the straight-line distance to the goal."""
GOAL_FILL = 1.0
"""``goal-only``'s fill in cells per move (learning real-time search on the distance to the goal).
Chosen on the dev suite among five variants (docs/research-log.md, "goal-only as a fair learner";
``research/goal_only_variants.py``)."""


def goal_trajectory(traj: Trajectory) -> Trajectory:
    """All a trajectory says that does not depend on its route: its start and its goal."""
    return Trajectory((traj.start,), (0,), traj.goal, source="goal-only")


def goal_guide(robot: DiscreteRobot, traj: Trajectory) -> guide.Guide:
    """``guided``'s learner aiming at the goal as a fair learner told the goal would: its score is
    the straight-line distance from its label to the goal cell, never given up, and learning
    real-time search (Korf's LRTA*, the guide's fill) raises the score of a state each time it is
    left, so that a basin behind a wall fills and the robot walks round instead of bumping it. The
    planner after every episode is ``plan``'s. It knows no map and no route."""
    return guide.build(robot, [goal_trajectory(traj)], window=GOAL_WINDOW, give_up=0, fill=GOAL_FILL)


def _goal_only(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    n = robot.n_states
    return Shaping(modes.MODE_NONE, np.zeros(n), np.full(n, -1, np.int64), np.zeros(n), k,
                   guide=goal_guide(robot, trajs[0]))


def _pseudo_plan(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
    sh = _pseudo(robot, trajs, k, beta)
    return Shaping(sh.mode, sh.bonus, sh.traj_index, sh.phi, k, guide=planner_guide(robot))


_BUILTIN: dict[str, Method] = {
    m.name: m
    for m in (
        Method("none", "Algorithm 1 without transfer", paper=True),
        Method("pseudo", "the paper's pseudo reward i*K on reaching the i-th trajectory cell",
               paper=True, build=_pseudo, farmable=True, baselines=("none",)),
        Method("mapping", "pseudo plus the action sequence mapping's macros (the paper's III.C)",
               paper=True, build=_pseudo, farmable=True, macros=True, baselines=("none",)),
        Method("first-visit", "the pseudo reward paid the first time each trajectory cell is reached in a trial",
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
        Method("goal-only", "guided's learner told only the goal: it heads for the goal by straight-line distance, "
               "with learning real-time search round the walls it meets, and plans after every episode",
               paper=False, build=_goal_only, auto_k=0.0, chooses=True, baselines=("plan",), is_baseline=True),
        Method("pseudo-plan", "the paper's pseudo reward on guided's learner told nothing (plan): the paper's reward "
               "and guided on equal footing", paper=False, build=_pseudo_plan, farmable=True, chooses=True,
               baselines=("plan",), is_baseline=True),
        Method("goal-dense", "dense told only the goal: a potential falling with the straight-line distance to the "
               "goal, on Algorithm 1; what the reward-term methods' route adds beyond the goal", paper=False,
               build=_goal_dense, auto_k=potentials.DENSE_K, baselines=("none",), is_baseline=True),
        Method("lazy", "a control: plan with every untried move valued lower (LAZY_UNTRIED), so it explores less and "
               "is told nothing; the benchmark's clock must not rank it ahead of plan", paper=False, build=_lazy,
               auto_k=0.0, chooses=True, is_baseline=True, uses_trajectory=False, baselines=("plan",)),
    )
}
"""The built-in methods, ``none`` first."""

METHODS: Registry[Method] = Registry(_BUILTIN, plugins.load_entry_points)
"""Every method, ``none`` first: the built-in ones, then those of installed plugins (read on the
first use) and those registered in this process. The order is the order of reports."""

BUILTIN = tuple(_BUILTIN)
"""The built-in methods' names (what the paper's reproduction and its reports run)."""

BUILTIN_SHAPED = tuple(name for name, m in _BUILTIN.items() if m.shaped and not m.macros and not m.is_baseline)
"""The built-in transfer methods without macros: what ``reproduce`` compares beyond the paper,
whatever plugins are installed."""

SHAPED = Names(METHODS, lambda name, m: m.shaped and not m.macros and not m.is_baseline,
               "The transfer methods without macros (the controls run these); the baselines are left out.")

REWARD_ONLY = Names(METHODS, lambda name, m: m.shaped and not m.chooses,
                    "The methods whose transfer is a reward term alone (what ``armtransfer.wrappers`` can add).")


def register_method(method: Method, replace: bool = False, probe_timeout: float = PROBE_SECONDS) -> Method:
    """Make ``method`` (``armtransfer.potential_method(...)`` or ``armtransfer.bonus_method(...)``)
    a method of this process, everywhere a built-in one is (``plugins.register``): a notebook's
    way. Worker processes (a sweep's pool, Ray) do not see it: an installed package's entry point
    is seen by every process (:func:`refuse_run_time`)."""
    return plugins.register(METHODS, method, replace=replace, seconds=probe_seconds(probe_timeout))


def refuse_run_time(names: Iterable[str], where: str) -> None:
    """A method registered in this process only (:func:`register_method`) cannot run in other
    processes, which import the package afresh: a one-line error, before anything is written."""
    for name in dict.fromkeys(names):
        m = get(name)
        if m.origin == plugins.RUN_TIME:
            raise PluginError(
                f"method {name!r} was registered in this process (register_method) and {where} run in other "
                f"processes, which cannot see it; install it as a package declaring it under the entry-point "
                f"group {plugins.GROUP} (docs/extending.md), or run it with armtransfer.transfer(...)")


def probe_on(names: Iterable[str], robots: Iterable[DiscreteRobot], seconds: float = PROBE_SECONDS) -> None:
    """Build every plugin method among ``names`` once on each of ``robots`` (``plugins.probe``),
    each under a time limit of ``seconds``: a fault that shows only on one robot, or a potential
    that does not return, is a one-line error before a run that writes starts."""
    robots = list(robots)
    for name in dict.fromkeys(names):
        m = get(name)
        if m.origin != "armtransfer":
            for robot in robots:
                plugins.probe(m, f"{m.origin}, on robot {robot.name}", robot, seconds)


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
    if m.farmable and m.bonus_per_k is not None:  # a plugin's state bonus: its own largest bonus
        k = _check_bonus_k(m, robot, trajs, K, step_reward)
    else:
        k = m.resolve_k(K, step_reward, trajs)
    if m.farmable and m.bonus_per_k is None:
        n = longest_n(trajs)
        if step_reward + n * k >= 0:
            raise InvalidParameterError(
                f"K={k:g} can be farmed: step reward {step_reward:g} + largest pseudo reward "
                f"n*K = {n}*{k:g} >= 0; use K < {farming_bound(step_reward, trajs):.6g} "
                f"(-step_reward/n) or the method 'first-visit'"
            )
    sh = build(robot, trajs, k, potentials.DENSE_BETA if beta is None else float(beta))
    _check_scaled(m.name, k, sh)
    if sh.mode == modes.MODE_POTENTIAL:
        said: tuple[str, ...] = ()
        if m.origin != "armtransfer" and trajs:  # a potential of one's own says what happened to it
            goal = np.isin(robot.label % robot.layout.n_cells, [t.goal % robot.layout.n_cells for t in trajs])
            said = tuple(potentials.notes(m.name, sh.phi, goal, gamma, step_reward))
        sh = replace(sh, phi=potentials.bounded(sh.phi, gamma, step_reward), notes=said)
    return sh


def _check_scaled(name: str, k: float, sh: Shaping) -> None:
    """Every value of the shaping, after the multiplication by K, finite and at most
    ``plugins.MAX_VALUE`` in magnitude: a K too large for the method is one line, not a run
    filled with inf that reports nothing converged."""
    for values in (sh.bonus, sh.phi):
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(values) | (np.abs(values) > plugins.MAX_VALUE)
        if bad.any():
            raise InvalidParameterError(f"method {name!r} with K={k:g} gives the shaping value {values[bad][0]:g} at "
                                        f"{int(bad.sum())} states; every value must be finite and at most "
                                        f"{plugins.MAX_VALUE:g} in magnitude: use a smaller K")


def bonus_bound(m: Method, robot: DiscreteRobot, trajs: Sequence[Trajectory], step_reward: float) -> float:
    """The K at and above which standing on the state of ``m``'s largest bonus pays at least as much
    as moving on: -step_reward / (the largest bonus per K) (inf: no bonus anywhere)."""
    assert m.bonus_per_k is not None
    top = float(np.max(m.bonus_per_k(robot, list(trajs)), initial=0.0))
    return -step_reward / top if top > 0 else float("inf")


def _check_bonus_k(m: Method, robot: DiscreteRobot, trajs: list[Trajectory], K: float | str | None,
                   step_reward: float) -> float:
    """A plugin's state-bonus K: 'auto' is half the bound :func:`bonus_bound` (``farming.check_k``
    verifies it by value iteration on the task), a given K is refused at or above the bound."""
    if (K is None or K == "auto") and m.auto_k is None:
        if step_reward >= 0:
            raise InvalidParameterError("K='auto' needs a negative step reward (it is scaled by -step_reward)")
        bound = bonus_bound(m, robot, trajs, step_reward)
        return HALF_BOUND * bound if np.isfinite(bound) else 0.0
    k = m.resolve_k(K, step_reward, trajs)
    bound = bonus_bound(m, robot, trajs, step_reward)
    if k >= bound:
        raise InvalidParameterError(
            f"K={k:g} can be farmed: step reward {step_reward:g} + method {m.name!r}'s largest bonus "
            f"{-step_reward / bound:g}*K >= 0; use K < {bound:.6g}")
    return k
