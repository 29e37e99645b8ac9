"""One transfer experiment: a source trajectory, a target robot, methods x trials.

Every trial of every method gets its own generator from ``SeedSequence([seed, trial])``,
so the methods meet the same random streams trial by trial (paired comparison) and the
same seed gives the same result, bit for bit, however many threads run the trials.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np

from armtransfer.cpus import cpus as _cpus
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments.stats import learning_metrics as lm, metrics
from armtransfer.learning import controls, farming, methods, potentials, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.controls import CONTROLS
from armtransfer.learning.lazy_registry import Names
from armtransfer.learning.mapping import DEFAULT_MAX_SPAN, ActionMapping, MacroTable
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.learning.trial_result import TrialResult
from armtransfer.tasks.robot import DiscreteRobot

T = TypeVar("T")
SHAPING_METHODS = methods.SHAPED
METHODS = Names(methods.METHODS, lambda name, m: True)
"""Every method's name, from the registry ``armtransfer.learning.methods`` (a live view: a
plugin's method is among them once the registry has read it)."""


def trial_threads() -> int:
    """Threads the trials of one method run on: ``armtransfer.cpus.cpus()``
    (``$ARMTRANSFER_CPUS``, else the CPUs this process may use). The learner's kernel releases
    the GIL, and every trial has its own generator and arrays, so the results are the same,
    bit for bit, for any number."""
    return _cpus()


def map_trials(one: Callable[[int], T], trials: int, threads: int | None = None,
               on_trial: Callable[[], None] | None = None) -> list[T]:
    """``[one(0), ..., one(trials - 1)]``, computed on ``threads`` threads (None:
    :func:`trial_threads`). ``one(k)`` must depend on k alone (its own generator, its own
    arrays), so that the list is the same for any number of threads. ``on_trial`` is called
    once per finished trial, on this thread. The first error, in trial order, is raised, and
    no trial starts after an error or Ctrl-C (those running finish first)."""
    threads = min(trial_threads() if threads is None else int(threads), trials)
    if trials < 1 or threads < 1:
        raise InvalidParameterError(f"trials and threads must be positive integers, got {trials} and {threads}")
    if threads == 1:
        out = []
        for trial in range(trials):
            out.append(one(trial))
            if on_trial is not None:
                on_trial()
        return out
    with ThreadPoolExecutor(max_workers=threads, thread_name_prefix="trial") as pool:
        futures = [pool.submit(one, trial) for trial in range(trials)]
        try:
            for _ in as_completed(futures):
                if on_trial is not None:
                    on_trial()
            return [f.result() for f in futures]
        except BaseException:
            for f in futures:
                f.cancel()
            raise


def trial_rng(seed: int, trial: int, stream: int = 0) -> np.random.Generator:
    """The generator of one trial (``stream`` separates e.g. the source robot's learning)."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(stream), int(trial)]))


def source_trajectory(
    kind: str,
    source: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    config: LearnerConfig,
    seed: int,
) -> Trajectory:
    """``optimal`` (breadth-first shortest path) or ``learned`` (the source robot's
    converged greedy path after SARSA(lambda) without transfer)."""
    if kind == "optimal":
        return trajectories.shortest(source, start_cell, goal_cell)
    if kind == "learned":
        res = sarsa.learn(source, source.start_state(start_cell), goal_cell, config, trial_rng(seed, 0, stream=1))
        if not res.converged:
            raise InvalidParameterError(
                f"the source robot {source.name} did not converge on a path in "
                f"{config.max_episodes} episodes; use --trajectory optimal"
            )
        return trajectories.from_path(source, res.greedy_path)
    raise InvalidParameterError(f"unknown trajectory kind {kind!r}; valid: optimal, learned, or a JSON path")


@dataclass
class MethodResult:
    """Every trial of one method on one task; ``control`` names the control trajectory the
    method was given instead of the real one (None: the real trajectory)."""

    method: str
    trials: list[TrialResult] = field(default_factory=list)
    extra: dict = field(default_factory=dict)
    control: str | None = None
    evaluations: list[list] | None = None
    """An outside learner's greedy evaluations, per trial (``learner_trial.trial``); None for the
    built-in learner's."""
    learned_mapping: ActionMapping | None = None
    """Method ``mapping`` given a mapping (:func:`run_mapping`): that mapping updated from these
    trials' converged paths (not in the JSON); None otherwise."""

    @property
    def label(self) -> str:
        """How tables name it: ``dense``, or ``dense [shuffled]`` for a control."""
        return self.method if self.control is None else f"{self.method} [{self.control}]"

    def column(self, name: str) -> list:
        return [getattr(t, name) for t in self.trials]

    def __repr__(self) -> str:
        """One line: the method, its trials, how many reached the goal and converged, and the
        mean exploration steps of those that reached it (every trial's arrays stay out)."""
        reached = [x for x in self.column("exploration_steps") if x is not None]
        mean = f"{sum(reached) / len(reached):,.1f}" if reached else "n/a"
        return (f"<MethodResult {self.label}: {len(self.trials)} trials, reached {len(reached)}/{len(self.trials)}, "
                f"converged {sum(map(bool, self.column('converged')))}/{len(self.trials)}, mean exploration steps "
                f"of those reached {mean}>")


def method_shaping(
    method: str,
    target: DiscreteRobot,
    start_state: int,
    goal_cell: int,
    trajs: Trajectory | Sequence[Trajectory] | None,
    K: float | str | None,
    config: LearnerConfig,
    wind: float = 0.0,
    beta: float = potentials.DENSE_BETA,
) -> Shaping | None:
    """What ``method`` is paid with on this task from ``trajs`` (None for a method without
    shaping): its K checked (a farmable method's by value iteration over the shaped task;
    'auto' comes out verified), its arrays built, and its self-loops checked. Each raises one
    line before any learning; :func:`run_method` calls this once per run (once per trial when
    each trial has its own trajectories), or takes its answer made earlier."""
    m = methods.get(method)
    if not m.shaped:
        return None
    if trajs is None and m.uses_trajectory:
        raise InvalidParameterError(f"method {method!r} needs a trajectory")
    k = K
    if m.farmable:
        k = farming.check_k(method, target, start_state, goal_cell, [] if trajs is None else trajs, K, config, wind)
    sh = methods.build_shaping(method, target, trajs, k, config.step_reward, beta=beta, gamma=config.gamma)
    farming.check_self_loops(method, target, goal_cell, sh, config, wind)
    return sh


def shortest_steps(target: DiscreteRobot, start_state: int, goal_cell: int) -> int | None:
    """The target's shortest path from ``start_state`` to the goal, in its own steps (None: it
    cannot reach it): the harness's measure of a good path (``learning.clock``), read from the
    robot's table by the harness alone and handed to the stopping rule, never to the learner."""
    path = target.shortest_path(start_state, goal_cell)
    return None if path is None else len(path) - 1


def run_method(
    method: str,
    target: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    traj: Trajectory | Sequence[Trajectory] | Callable[[int], Sequence[Trajectory]] | None,
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    K: float | str | None = "auto",
    macros=None,
    on_trial: Callable[[], None] | None = None,
    beta: float = potentials.DENSE_BETA,
    control: str | None = None,
    threads: int | None = None,
    shaping: Shaping | None = None,
    first_trial: int = 0,
) -> MethodResult:
    """``trials`` independent trials of one method on the target robot, on ``threads``
    threads (None: :func:`trial_threads`); the results do not depend on how many. ``traj``:
    the transferred trajectories, or a function giving each trial its own. ``shaping``: what
    :func:`method_shaping` made already for this method and ``traj`` (its K is then not
    checked again); None makes it here. The trials are numbered from ``first_trial`` (their
    generators too), so trial k run alone is trial k of a longer run, bit for bit."""
    if trials < 1:
        raise InvalidParameterError(f"trials must be a positive integer, got {trials}")
    if first_trial < 0:
        raise InvalidParameterError(f"first_trial must be an integer >= 0, got {first_trial}")
    start_state = target.start_state(start_cell)
    m = methods.get(method)
    if shaping is not None and (callable(traj) or not m.shaped):
        raise InvalidParameterError(f"a shaping made in advance goes with one shaped method's trajectories, "
                                    f"not with {method!r}" + (" and a trajectory per trial" if callable(traj) else ""))

    def shaping_for(trajs):
        return method_shaping(method, target, start_state, goal_cell, trajs, K, config, wind, beta)

    optimal = shortest_steps(target, start_state, goal_cell)

    out = MethodResult(method, control=control)
    if callable(traj):  # each trial its own trajectories (the controls: one draw per trial)
        shapings: list = [None] * trials

        def one(trial: int):
            shapings[trial] = sh = shaping_for(traj(first_trial + trial))
            return sarsa.learn(target, start_state, goal_cell, config, trial_rng(seed, first_trial + trial),
                               shaping=sh, wind=wind, macros=macros, optimal=optimal)

        out.trials = map_trials(one, trials, threads, on_trial)
        if m.shaped:
            out.extra["K"] = [sh.K for sh in shapings]
        return out
    if shaping is None:
        shaping = shaping_for(traj)
    made = shaping
    out.trials = map_trials(lambda trial: sarsa.learn(target, start_state, goal_cell, config,
                                                      trial_rng(seed, first_trial + trial),
                                                      shaping=made, wind=wind, macros=macros,
                                                      optimal=optimal),
                            trials, threads, on_trial)
    if made is not None:
        out.extra["K"] = made.K
        if made.notes:
            out.extra["warnings"] = list(made.notes)
    return out


def run_control(
    method: str,
    kind: str,
    source: DiscreteRobot,
    target: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    trajs: Sequence[Trajectory],
    trials: int,
    seed: int,
    config: LearnerConfig,
    keep_goal: bool = False,
    **kw,
) -> MethodResult:
    """``trials`` trials of a method given ``kind`` control trajectories in place of ``trajs``:
    each trial draws its own (:func:`control_trajectories` with ``trial``), so the mean is over
    the control's randomness too, not over one draw. ``keep_goal``: the ablation that keeps the
    task's goal (labelled ``kind, goal kept``). ``kw`` goes to :func:`run_method`."""
    if kind not in CONTROLS:
        raise InvalidParameterError(f"unknown control {kind!r}; valid: {', '.join(CONTROLS)}")
    return run_method(method, target, start_cell, goal_cell,
                      lambda trial: control_trajectories(kind, source, trajs, seed, keep_goal, trial),
                      trials, seed, config, control=controls.label(kind, keep_goal), **kw)


def run_mapping(
    target: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    traj: Trajectory,
    mapping: ActionMapping,
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    K: float | str | None = "auto",
    on_trial: Callable[[], None] | None = None,
    max_span: int = DEFAULT_MAX_SPAN,
    shaping: Shaping | None = None,
) -> tuple[MethodResult, ActionMapping]:
    """Method ``mapping``: pseudo rewards plus the macros ``mapping`` gives on ``traj``.

    Every trial uses ``mapping`` as given (the mappings of earlier tasks only), so trials
    stay independent and deterministic. Returns the result, with ``mapped_fraction`` per
    trial in ``extra``, and a new mapping (the result's ``learned_mapping`` too): ``mapping``
    plus what each converged trial's greedy path teaches, added in trial order. ``shaping``:
    see :func:`run_method`.
    """
    table = MacroTable(mapping, traj, target)
    res = run_method(
        "mapping", target, start_cell, goal_cell, traj, trials, seed, config,
        wind=wind, K=K, macros=table if len(table) else None, on_trial=on_trial, shaping=shaping,
    )
    learned = mapping.copy()
    learned.learned_on(start_cell, goal_cell)
    fractions = []
    for t in res.trials:
        fractions.append(table.mapped_fraction(target, t.greedy_path) if t.converged else None)
        if t.converged:
            learned.learn_from(target, t.greedy_path, traj, max_span)
    res.extra.update(
        mapped_fraction=fractions,
        macro_states=len(table),
        macro_steps_first_episode=[int(t.macro_steps[0]) if len(t.macro_steps) else 0 for t in res.trials],
        mapping_entries_used=len(mapping),
    )
    res.learned_mapping = learned
    return res, learned


def online_mapping(
    source: DiscreteRobot,
    target: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    result: MethodResult,
    traj: Trajectory,
    mapping: ActionMapping | None = None,
    max_span: int = DEFAULT_MAX_SPAN,
) -> ActionMapping:
    """The action sequence mapping learned *during* a task: ``mapping`` (default: empty) plus
    what each trial's first exposure teaches, in trial order. A trial's first-episode path,
    its loops erased (``trial_result.TrialResult.first_path``), is set beside ``traj`` as a converged
    greedy path would be (``mapping.observe``: matched cells, the shorter target sequence wins),
    so the mapping exists as soon as the goal is first reached, before any trial converges,
    and the method ``mapping`` can use it on the next task at once."""
    learned = ActionMapping.for_robots(source, target) if mapping is None else mapping.copy()
    learned.learned_on(start_cell, goal_cell)
    for t in result.trials:
        if t.first_path:
            learned.learn_from(target, t.first_path, traj, max_span)
    return learned


def summarize(results: Sequence[MethodResult], baseline: str = "none", cap: int | None = None) -> dict:
    """The JSON ``results`` block: per method, per-trial lists, means, CIs, improvement.

    Exploration statistics count every trial (``metrics.exploration_stats``): one that never
    reached the goal counts at the step cap, ``cap`` (default: the steps its first episode
    ran before the cap stopped it, i.e. ``config.max_total_steps``), and the mean is then
    flagged as a lower bound. Improvements are paired (common random numbers,
    ``trial_rng``) when the baseline has as many trials, else independent.

    ``improvement_against`` holds, for every baseline that shares the method's learner
    (``Method.baselines``, the no-transfer one first) and is among ``results``, the same
    improvement measured against it: ``{name: {"percent", "ci95", "design", "censored",
    "cap_dominated"}}``."""

    def cap_of(r: MethodResult) -> int:
        if cap is not None:
            return int(cap)
        stopped = [abs(int(t.episode_steps[0])) for t in r.trials
                   if t.exploration_steps is None and len(t.episode_steps)]
        return max(stopped, default=0)

    by_name = {r.label: r for r in results}
    base = by_name.get(baseline)
    out: dict = {}
    for r in results:
        ex = r.column("exploration_steps")
        c = max(cap_of(r), cap_of(base) if base else 0)
        st = metrics.exploration_stats(ex, c)
        total = r.column("total_steps")
        greedy = r.column("greedy_steps")
        t_mean, t_ci = metrics.mean_ci(total)
        g_mean, g_ci = metrics.mean_ci(greedy)
        imp = None
        if r.label != baseline and base is not None:
            base_ex = base.column("exploration_steps")
            imp = metrics.paired_improvement(base_ex, ex, c, paired=len(base_ex) == len(ex))
        against = {}
        known = methods.METHODS.get(r.method)  # None: a result made outside the registry
        for name in known.baselines if known is not None else ():
            if name in by_name and name != r.label:
                b_ex = by_name[name].column("exploration_steps")
                bc = max(cap_of(r), cap_of(by_name[name]))
                d = metrics.paired_improvement(b_ex, ex, bc, paired=len(b_ex) == len(ex))
                against[name] = {key: d[key] for key in ("percent", "ci95", "design", "censored", "cap_dominated")}
        entry = {
            "exploration_steps": ex,
            "mean": st["mean"],
            "ci95": st["ci95"],
            "reached": st["reached"],
            "cap": c or None,
            "mean_is_lower_bound": st["mean_is_lower_bound"],
            "median": st["median"],
            "median_ci95": st["median_ci95"],
            "median_ci_coverage": st["median_ci_coverage"],
            "median_is_lower_bound": st["median_is_lower_bound"],
            "mean_cap_dominated": st["cap_dominated"],
            "improvement_censored": None if imp is None else imp["censored"],
            "improvement_cap_dominated": None if imp is None else imp["cap_dominated"],
            "improvement_percent": None if imp is None else imp["percent"],
            "improvement_ci95": None if imp is None else imp["ci95"],
            "improvement_design": None if imp is None else imp["design"],
            "improvement_against": against,
            "greedy_steps": greedy,
            "greedy_mean": g_mean,
            "greedy_ci95": g_ci,
            "total_steps": total,
            "total_mean": t_mean,
            "total_ci95": t_ci,
            "converged": r.column("converged"),
            **clock_columns(r),
            "episodes": r.column("episodes"),
            "episode_steps": [t.episode_steps.tolist() for t in r.trials],
            "greedy_path_states": [[int(s) for s, _ in t.greedy_path] for t in r.trials],
        }
        entry.update(r.extra)
        out[r.label] = entry
    return out


CLOCK = ("good_path_steps", "shortest_path_steps", "settled_ratio", "final_ratio", "optimal", "good_len",
         "steps_run")
"""The good-path clock's per-trial lists (``trial_result.TrialResult``, ``learning.clock``): steps until the
greedy path was good (at most ``good_len`` = ceil(quality x optimal) steps) and stayed so, the same
at quality 1.0, the first settled path's and the final path's length over the shortest, and the
steps each trial ran (where a trial that never got there is censored)."""


def clock_columns(r: MethodResult) -> dict:
    """A method's :data:`CLOCK` lists (None where a learner does not measure one)."""
    return {name: [getattr(t, name, None) for t in r.trials] for name in CLOCK}


BULKY = ("episode_steps", "greedy_path_states")
"""Per-trial lists in a summary entry that a report's JSON can do without."""


def compact(entry: dict) -> dict:
    """Drop an entry's per-episode and per-path lists (and per-trial transfer metrics), keeping
    every per-trial number the tables use; ``rooms --json`` and ``arms`` keep everything."""
    for key in BULKY:
        entry.pop(key, None)
    for m in entry.get("transfer_metrics", {}).values():
        if isinstance(m, dict):
            m.pop("per_trial", None)
    return entry


def control_trajectories(
    kind: str, source: DiscreteRobot, trajs: Sequence[Trajectory], seed: int, keep_goal: bool = False,
    trial: int | None = None,
) -> list[Trajectory]:
    """``shuffled`` or ``random`` stand-ins for the real trajectories, seeded by ``seed`` (and
    ``trial``: one draw per trial, see :func:`run_control`); with ``keep_goal`` they keep the
    task's goal (an ablation, see :mod:`controls`) and are otherwise the same cells and actions."""
    key = [int(seed), 2, CONTROLS.index(kind)] + ([] if trial is None else [int(trial)])
    rng = np.random.default_rng(np.random.SeedSequence(key))
    if kind == "shuffled":
        return [controls.shuffled(t, rng, keep_goal) for t in trajs]
    return [controls.random_walk(source, t, rng, keep_goal) for t in trajs]


def add_transfer_metrics(summary: dict, optimal: int, baseline: str = "none") -> None:
    """Add Taylor and Stone's metrics (``transfer.learning_metrics``) to every method."""
    base = summary.get(baseline)
    if base is None:
        return
    ref_first, ref_area = lm.baseline_reference(list(zip(base["episode_steps"], base["greedy_steps"])))
    for entry in summary.values():
        per_trial = [
            lm.trial_metrics(ep, g, optimal, ref_first, ref_area)
            for ep, g in zip(entry["episode_steps"], entry["greedy_steps"])
        ]
        block: dict[str, object] = {}
        for name in ("jumpstart", "time_to_threshold", "area", "transfer_ratio", "asymptotic"):
            values = [m[name] for m in per_trial]
            mean, ci = metrics.mean_ci(values)
            block[name] = {"per_trial": values, "mean": mean, "ci95": ci}
        block["threshold"] = f"episode <= {lm.THRESHOLD:g} x optimal ({optimal})"
        block["horizon_episodes"] = lm.HORIZON
        entry["transfer_metrics"] = block


def check_trajectories(method_names: Sequence[str], trajs: Sequence[Trajectory]) -> None:
    """Refuse, in one line, trajectories the methods cannot be given: none for a method paid
    for a trajectory, or other than one for ``mapping``."""
    chosen = [methods.get(m) for m in method_names]
    if any(m.shaped and m.uses_trajectory for m in chosen) and not trajs:
        raise InvalidParameterError("the transfer methods need a trajectory")
    if any(m.macros for m in chosen) and len(trajs) != 1:
        raise InvalidParameterError("method 'mapping' takes exactly one trajectory")


def run_all(
    source: DiscreteRobot,
    target: DiscreteRobot,
    start_cell: int,
    goal_cell: int,
    method_names: Sequence[str],
    trajs: Sequence[Trajectory],
    trials: int,
    seed: int,
    config: LearnerConfig,
    wind: float = 0.0,
    K: float | str | None | dict = "auto",
    beta: float = potentials.DENSE_BETA,
    mapping: ActionMapping | None = None,
    max_span: int = DEFAULT_MAX_SPAN,
    controls: bool = True,
    tick: Callable[[], None] | None = None,
    shapings: dict[str, Shaping] | None = None,
) -> tuple[list[MethodResult], ActionMapping | None]:
    """Every method on one task, then (``controls``) every reward-only method again with each
    control trajectory. ``K`` is one K for every method or a dict of K per method;
    ``shapings`` holds the shaping :func:`method_shaping` made already for a method and
    ``trajs`` (its K is not checked again). Returns the results in that order and, for
    ``mapping``, the mapping updated from this task's converged trials."""
    chosen = [methods.get(m) for m in method_names]
    check_trajectories(method_names, trajs)
    results: list[MethodResult] = []
    learned = None

    def k_of(name: str):
        return K.get(name, "auto") if isinstance(K, dict) else K

    for m in chosen:
        kw = dict(wind=wind, K=k_of(m.name), on_trial=tick, shaping=(shapings or {}).get(m.name))
        if m.macros:
            if mapping is None:
                mapping = ActionMapping.for_robots(source, target)
            res, learned = run_mapping(target, start_cell, goal_cell, trajs[0], mapping, trials, seed,
                                       config, max_span=max_span, **kw)
            results.append(res)
        else:
            results.append(run_method(m.name, target, start_cell, goal_cell, trajs if m.shaped else None,
                                      trials, seed, config, beta=beta, **kw))
    if controls:
        for kind in CONTROLS:
            for m in chosen:
                if m.name in SHAPING_METHODS:  # the same K as the real trajectory's
                    results.append(run_control(m.name, kind, source, target, start_cell, goal_cell, trajs, trials,
                                               seed, config, beta=beta, wind=wind, K=k_of(m.name), on_trial=tick))
    return results, learned


def summary_of(results: Sequence[MethodResult], target: DiscreteRobot, start_cell: int, goal_cell: int) -> dict:
    """The ``summarize`` block of ``results`` (keyed by label), with the transfer metrics."""
    labels = [r.label for r in results]
    summary = summarize(results, baseline="none" if "none" in labels else "")
    path = target.shortest_path(target.start_state(start_cell), goal_cell)
    if path is not None:
        add_transfer_metrics(summary, len(path) - 1)
    return summary


def run_transfer(
    source: DiscreteRobot, target: DiscreteRobot, start_cell: int, goal_cell: int, *args, **kwargs
) -> tuple[dict, ActionMapping | None]:
    """:func:`run_all`, summarised by label (``dense``, ``dense [shuffled]``, ...), for reports
    that tabulate every run side by side. Returns the summary and the updated mapping."""
    results, learned = run_all(source, target, start_cell, goal_cell, *args, **kwargs)
    return summary_of(results, target, start_cell, goal_cell), learned


def count_trials(method_names: Sequence[str], trials: int, controls: bool) -> int:
    """How many trials ``run_transfer`` runs (for progress bars)."""
    shaped = sum(m in SHAPING_METHODS for m in method_names)
    return trials * (len(method_names) + (len(CONTROLS) * shaped if controls else 0))
