"""Running a benchmark suite: every case, every source seed, every method beside its baseline.

For each case and source seed, robot 1 (the source) learns the task without transfer and
its converged greedy path is the trajectory handed over, so the source's own learning is a
random effect of the benchmark, not one fixed path. Then every method of
``suites.METHODS`` that this build's registry has, and the baseline each names, run
``trials`` trials on robot 2 from the same random streams (common random numbers), so a
method and its baseline are paired trial by trial and seed by seed.

A source that does not converge, or a method that refuses the case, is recorded (counted
as a failure in the statistics), never dropped. Every random draw comes from
``SeedSequence([seed, section, case, source seed, ...])``, so the same seed gives the same
records, bit for bit, whatever else the suite holds; wall times are kept apart from them.
"""

from __future__ import annotations

import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from armtransfer.errors import ArmTransferError, InvalidTaskError
from armtransfer.experiments import experiment, suites
from armtransfer.experiments.stats import learning_metrics
from armtransfer.learning import methods
from armtransfer.learning import presets
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.robot import DiscreteRobot

MIN_DISTANCE = 10
"""A drawn task's goal lies at least this many cells (shortest path of the finer robot) from
its start, so no drawn task is trivial."""

DRAWS = 1000
"""Draws of a random task at most before the case is declared impossible."""

SOURCE_CONFIG = LearnerConfig()
"""Robot 1 learns with the learner's defaults (its own step cap), whatever a section caps
robot 2's trials at."""


def baselines_of(name: str) -> tuple[str, ...]:
    """The methods ``name``'s gain is measured against, each sharing its learner and told less:
    the registry's ``Method.baselines`` (the no-transfer one first; empty for a method that is
    itself no transfer), or, from a registry without that field, ``none`` for every method but
    ``none``."""
    m = methods.get(name)
    if hasattr(m, "baselines"):
        return tuple(b for b in m.baselines if b in methods.METHODS and b != name)
    return () if name == "none" else ("none",)


def registered_baseline(name: str) -> bool:
    """Whether the registry itself names ``name``'s baselines (rather than the ``none`` default)."""
    return hasattr(methods.get(name), "baselines")


def baseline_of(name: str) -> str | None:
    """The no-transfer method sharing ``name``'s learner (None: ``name`` is one itself)."""
    named = baselines_of(name)
    return named[0] if named else None


def methods_to_run(wanted: tuple[str, ...] = suites.METHODS) -> tuple[list[str], list[str]]:
    """(the methods to run, in registry order: those of ``wanted`` this build has and every
    baseline they name; those of ``wanted`` this build does not have)."""
    chosen: set[str] = set()

    def add(name: str) -> None:
        if name not in chosen:
            chosen.add(name)
            for b in baselines_of(name):
                add(b)

    for m in wanted:
        if m in methods.METHODS:
            add(m)
    return [m for m in methods.METHODS if m in chosen], [m for m in wanted if m not in methods.METHODS]


def section_key(name: str) -> int:
    return zlib.crc32(name.encode())


def run_seed(seed: int, section: str, case: int, source_seed: int) -> int:
    """The seed of one (case, source seed): robot 1's learning and every trial of robot 2."""
    ss = np.random.SeedSequence([int(seed), section_key(section), int(case), int(source_seed)])
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def draw_task(source: DiscreteRobot, target: DiscreteRobot, rng: np.random.Generator) -> tuple[int, int]:
    """(start cell, goal cell) drawn uniformly over the cells both robots can be placed on and
    reach from the start, anywhere in the world, at least :data:`MIN_DISTANCE` apart."""
    common = np.intersect1d(np.unique(source.label), np.unique(target.label))
    common = common[common >= 0]
    for _ in range(DRAWS):
        start = int(rng.choice(common))
        reach = [np.unique(r.label[r.reachable_from(r.start_state(start))]) for r in (source, target)]
        goals = np.intersect1d(np.intersect1d(reach[0], reach[1]), common)
        goals = goals[goals != start]
        if len(goals) == 0:
            continue
        goal = int(rng.choice(goals))
        lengths = [r.shortest_path(r.start_state(start), goal) for r in (source, target)]
        steps = [len(p) - 1 for p in lengths if p is not None]
        if len(steps) == 2 and max(steps) >= MIN_DISTANCE:
            return start, goal
    raise InvalidTaskError(f"no task of {MIN_DISTANCE}+ steps that both {source.name} and {target.name} "
                           f"can do in {DRAWS} draws")


@dataclass
class Robots:
    """Robots by spec, each resolved (and, for an arm, compiled or loaded) once per run."""

    resolved: dict

    def __call__(self, spec: str) -> DiscreteRobot:
        if spec not in self.resolved:
            from armtransfer.tasks.specs import resolve

            self.resolved[spec] = resolve(spec)
        return self.resolved[spec]


def case_cells(case: suites.Case, source: DiscreteRobot, target: DiscreteRobot, seed: int, section: str,
               index: int, source_seed: int) -> tuple[int, int]:
    if case.task is not None:
        return table_task(case.task).cells()
    rng = np.random.default_rng(np.random.SeedSequence(
        [int(seed), section_key(section), int(index), int(source_seed), 1]))
    return draw_task(source, target, rng)


def plan_size(suite: suites.Suite) -> int:
    """Trials the suite runs (for a progress bar)."""
    run, _ = methods_to_run()
    return sum(len(s.cases) * s.source_seeds * s.trials * len(run) for s in suite.sections)


def run_suite(suite: suites.Suite, seed: int = 0, tick: Callable[[], None] | None = None,
              threads: int | None = None, preset: str = "default") -> tuple[list[dict], dict]:
    """Every run of ``suite``: (records, one per (section, case, source seed, method), and the
    wall times of the run, kept apart so that the records depend on ``seed`` alone). Robot 2
    learns with the settings of ``preset`` (``learning.presets``)."""
    learner = presets.config(preset)
    run, _ = methods_to_run()
    robots = Robots({})
    records: list[dict] = []
    timings: dict = {"runs": []}
    t_all = time.perf_counter()
    for section in suite.sections:
        config = replace(learner, max_total_steps=section.max_total_steps)
        for ci, case in enumerate(section.cases):
            source, target = robots(case.source), robots(case.target)
            for j in range(section.source_seeds):
                rs = run_seed(seed, section.name, ci, j)
                start, goal = case_cells(case, source, target, seed, section.name, ci, j)
                t0 = time.perf_counter()
                traj, why = _source_trajectory(source, start, goal, rs)
                per_method: dict[str, float] = {}
                timing = {"section": section.name, "case": ci, "source_seed": j,
                          "source_seconds": time.perf_counter() - t0, "methods": per_method}
                path = target.shortest_path(target.start_state(start), goal)
                if path is None:
                    raise InvalidTaskError(f"{case.label}: {target.name} cannot reach the goal")
                base = {"section": section.name, "case": ci, "label": case.label, "source": case.source,
                        "target": case.target, "task": case.task, "start": list(target.layout.xy(start)),
                        "goal": list(target.layout.xy(goal)), "wind": case.wind, "source_seed": j, "seed": rs,
                        "source_steps": None if traj is None else len(traj),
                        "source_failure": why, "optimal": len(path) - 1, "cap": section.max_total_steps,
                        "budget": suites.BUDGET_FACTOR * (len(path) - 1)}
                for name in run:
                    t1 = time.perf_counter()
                    records.append(_run_one(name, base, target, start, goal, traj, section.trials, rs, config,
                                            case.wind, tick, threads))
                    per_method[name] = time.perf_counter() - t1
                timings["runs"].append(timing)
    timings["total_seconds"] = time.perf_counter() - t_all
    return records, timings


def _source_trajectory(source: DiscreteRobot, start: int, goal: int, seed: int) -> tuple[Trajectory | None, str | None]:
    """Robot 1's converged greedy path, or None and why not (it did not converge)."""
    try:
        return experiment.source_trajectory("learned", source, start, goal, SOURCE_CONFIG, seed), None
    except ArmTransferError:
        return None, (f"robot 1 ({source.name}) did not converge on a path within "
                      f"{SOURCE_CONFIG.max_episodes:,} episodes and {SOURCE_CONFIG.max_total_steps:,} steps")


def _run_one(name: str, base: dict, target: DiscreteRobot, start: int, goal: int, traj: Trajectory | None,
             trials: int, seed: int, config: LearnerConfig, wind: float, tick, threads) -> dict:
    """One record: ``trials`` trials of method ``name`` (none when it could not run: then
    ``error`` says why and every trial counts as a failure)."""
    m = methods.get(name)
    rec = dict(base, method=name, baselines=list(baselines_of(name)), error=None)
    res = None
    needs = m.shaped and getattr(m, "uses_trajectory", True)
    if needs and traj is None:
        rec["error"] = f"no trajectory: {base['source_failure']}"
    else:
        try:
            given = [traj] if needs and traj is not None else None
            res = experiment.run_method(name, target, start, goal, given, trials, seed, config, wind=wind,
                                        on_trial=tick, threads=threads)
        except ArmTransferError as err:
            rec["error"] = str(err)
    if res is None:
        if tick is not None:
            for _ in range(trials):
                tick()
        rec.update(first_exposure=[None] * trials, converged=[False] * trials, convergence_steps=[None] * trials,
                   greedy_steps=[None] * trials, episodes=[0] * trials, area=[None] * trials, curves=[])
        return rec
    ts = res.trials
    curves = [learning_metrics.curve(t.episode_steps, t.greedy_steps) for t in ts]
    rec.update(
        first_exposure=[t.exploration_steps for t in ts],
        converged=[bool(t.converged) for t in ts],
        convergence_steps=[t.total_steps if t.converged else None for t in ts],
        greedy_steps=[t.greedy_steps for t in ts],
        episodes=[int(t.episodes) for t in ts],
        area=[float(c.sum()) for c in curves],
        curves=[[float(v) for v in c] for c in curves],
    )
    return rec
