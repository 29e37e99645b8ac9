"""armtransfer sweep: run a TOML grid of experiments into a store that resumes and loses nothing."""

from __future__ import annotations

import argparse
import os

from armtransfer.commands import common
from armtransfer.errors import PluginError
from armtransfer.experiments import learner_trial
from armtransfer.experiments.execute import robot_specs
from armtransfer.experiments.run import SweepRun
from armtransfer.tasks.catalog import custom_task
from armtransfer.parallel.executors import ExecutorError, check_reachable, check_address, import_ray, run_local, run_ray
from armtransfer.tasks.specs import resolve
from armtransfer.experiments import sweep as sweeps
from armtransfer.experiments.store import ResultStore
from armtransfer.learning import learners, methods, trajectory
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.learners import GROUP, RUN_TIME
from armtransfer.learning.methods import probe_on, refuse_run_time

HELP = "Run a grid of tasks, robots, methods and settings from a TOML file into a resumable result store."
EXAMPLE = "armtransfer sweep examples/sweeps/quick.toml --out runs/quick"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("sweep_file", metavar="SWEEP.toml", help="the sweep (see examples/sweeps/)")
    p.add_argument("--out", required=True, help="result store directory")
    p.add_argument("--max-runs", type=common.positive_int, default=sweeps.MAX_RUNS,
                   help=f"refuse a sweep with more runs than this (default {sweeps.MAX_RUNS:,})")
    add_executor_arguments(p)


def run(args: argparse.Namespace) -> int:
    check_executor_options(args)
    return run_sweep(sweeps.load(args.sweep_file, args.max_runs), args)


def add_executor_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--executor", choices=["local", "ray"], default="local",
                   help="local process pool (default) or Ray")
    p.add_argument("--workers", type=common.positive_int, default=None,
                   help="worker processes (default: all cores)")
    p.add_argument("--address", default=None, help="Ray cluster address (default: start a local instance)")
    p.add_argument("--retries", type=common.non_negative_int, default=2,
                   help="retries of a run whose worker died (default 2)")
    common.add_probe_timeout_argument(p)


def check_executor_options(args: argparse.Namespace) -> None:
    """The executor options that do not apply to the chosen executor are an error."""
    if args.address is not None and args.executor != "ray":
        raise ExecutorError("--address goes with --executor ray (the local executor has no address)")
    if args.address is not None:
        check_address(args.address)  # before anything uses it
    if args.address and args.workers is not None:
        raise ExecutorError("--workers does not apply to a Ray cluster (--address): its CPUs are the cluster's; "
                            "--workers sizes the local pool or a local Ray instance")


def run_sweep(sweep: sweeps.Sweep, args: argparse.Namespace) -> int:
    """Run every unfinished run of ``sweep`` into the store at ``args.out`` with the executor
    the arguments name; returns the exit code (1 when a run failed). The whole sweep is
    checked (every robot built, every task's cells checked for both robots) before anything
    is written. The caller has checked the executor options (:func:`check_executor_options`)."""
    if args.executor == "ray":
        import_ray()  # say how to install Ray before anything is written
        if args.address:
            check_reachable(args.address)
    robots = check_runs(list(sweep.runs), getattr(args, "probe_timeout", 60.0))
    store = ResultStore.open_for(args.out, sweep)
    try:
        return _run_into(store, sweep, robots, args)
    finally:
        store.unlock()


def check_runs(runs: list[SweepRun], probe_timeout: float = 60.0) -> dict:
    """Every robot the runs name, built once (arms come from the on-disk cache) to be shared
    with the workers; a robot that cannot be built, or a task cell it cannot start or end
    at, is a one-line error naming the run's robot and task."""
    if not runs:
        raise sweeps.SweepFileError("the sweep has no runs")
    refuse_run_time((run.method for run in runs), "a sweep's runs")
    outside = list(dict.fromkeys(run.learner for run in runs if run.learner != SARSA))
    refuse_run_time_learners(outside)
    arms = {name: arm for run in runs for name, arm in (run.arms or {}).items()}
    layout = sweeps.sweep_world(runs[0])  # one world a sweep
    robots = {spec: resolve(spec, arms=arms, layout=layout) for spec in robot_specs(runs)}
    seen = set()
    for run in runs:
        key = (run.source, run.target, run.start, run.goal)
        if key in seen:
            continue
        seen.add(key)
        start, goal = custom_task(run.start, run.goal, layout).cells()
        for spec in (run.source, run.target):
            robots[spec].start_state(start)
            robots[spec].start_state(goal, what="goal")
    _check_farming_bounds(runs, robots)
    probe_on((run.method for run in runs), [robots[s] for s in dict.fromkeys(run.target for run in runs)],
             probe_timeout)
    probe_learners(outside, runs, robots, probe_timeout)
    return robots


def refuse_run_time_learners(names: list[str]) -> None:
    """A learner registered in this process only (``register_learner``) cannot run in the
    sweep's worker processes, which import the package afresh: one line, before anything is
    written."""
    for name in names:
        if learners.get(name).origin == RUN_TIME:
            raise PluginError(f"learner {name!r} was registered in this process (register_learner) and a sweep's "
                              "runs run in other processes, which cannot see it; install it as a package declaring "
                              f"it under the entry-point group {GROUP} (docs/extending.md), or run it with "
                              "armtransfer.transfer(..., learner=...)")


def probe_learners(names: list[str], runs: list[SweepRun], robots: dict, seconds: float = 60.0) -> None:
    """Every outside learner made, learning a few steps and predicting on each target robot's
    first task (``learner_trial.probe``): a learner's fault is one line now, before the store
    is opened."""
    for name in names:
        seen: set[str] = set()
        for run in runs:
            if run.learner == name and run.target not in seen:
                seen.add(run.target)
                learner_trial.probe(learners.get(name), robots[run.target], list(run.start), list(run.goal), seconds)


def _check_farming_bounds(runs: list[SweepRun], robots: dict) -> None:
    """A numeric K of a farmable method that is farmable whatever trajectory the source hands
    over: any trajectory is at least as long as the source's shortest path, n, and K >= the
    bound -step_reward/n already pays more than a step. (The exact check, by value iteration on
    the trajectory actually handed over, runs with each run.)"""
    shortest: dict[tuple, int] = {}
    for run in runs:
        if run.K is None or run.K == "auto" or not methods.get(run.method).farmable:
            continue
        key = (run.source, run.start, run.goal)
        if key not in shortest:
            start, goal = custom_task(run.start, run.goal, robots[run.source].layout).cells()
            shortest[key] = trajectory.shortest(robots[run.source], start, goal).n
        n = max(shortest[key], 1)
        step = run.learner_config().step_reward
        if step + n * float(run.K) >= 0:
            raise sweeps.SweepFileError(
                f"K={run.K:g} can be farmed for {run.method} on {run.source} -> {run.target} "
                f"(task {run.task or list(run.start)}): any trajectory has n >= {n}, so K must stay below "
                f"{-step / n:.6g}")


def _run_into(store: ResultStore, sweep: sweeps.Sweep, robots: dict, args: argparse.Namespace) -> int:
    todo = [r for r in sweep.runs if not store.is_done(r.key())]
    print(f"sweep {sweep.name!r}: {len(sweep.runs)} runs, {len(sweep.runs) - len(todo)} already done, "
          f"{len(todo)} to run ({args.executor})")
    if not todo:
        return 0
    failed: list[str] = []
    with common.progress_bar(len(todo), "sweep") as bar:
        def on_done(run, result, secs):
            store.write_run(run, result, secs)
            bar.update()

        def on_failed(run, error, attempts):
            store.write_failure(run, error, attempts)
            failed.append(f"{run.key()}: {error}")
            bar.update()

        workers = args.workers or os.cpu_count() or 1
        if args.executor == "ray":
            run_ray(todo, robots, args.workers, args.address, on_done, on_failed, retries=args.retries)
        else:
            run_local(todo, robots, workers, on_done, on_failed, retries=args.retries)
    done = len(store.records())
    print(f"{done}/{len(sweep.runs)} runs in {args.out}; {len(failed)} failed")
    for line in failed[:10]:
        print(f"  failed {line}")
    return 1 if failed else 0
