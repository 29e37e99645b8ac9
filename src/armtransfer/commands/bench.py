"""armtransfer bench: learner steps per second (the world's first task, fine robot, no transfer)."""

from __future__ import annotations

import argparse
import gymnasium as gym
import os
import platform
import statistics
import time

import numpy as np

from armtransfer.commands.common import (add_world_argument, non_negative_int, options_of, positive_int,
                                         refuse_other_options, world_of)
from armtransfer.experiments import learner_trial
from armtransfer.experiments.stored_form import leave_out
from armtransfer.io import check_writable, write_json_atomic
from armtransfer.learning import plugin_calls, reference, sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learners import BUILTIN, get
from armtransfer.registration import MAX_EPISODE_STEPS
from armtransfer.tasks.catalog import world_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.layout import ROOMS, Layout

HELP = "Measure how many learning steps per second the learner runs on this machine."
EXAMPLE = "armtransfer bench --repeats 3"


STEPS = 2_000_000
LEARNER_STEPS = 20_000
"""``--steps``' default with ``--learner``: a learner of Python code runs thousands of steps a second."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--steps", type=positive_int, default=None,
                   help=f"learner steps per repeat, at least (default {STEPS:,}; {LEARNER_STEPS:,} with --learner)")
    p.add_argument("--repeats", type=positive_int, default=5, help="timed repeats (default 5)")
    p.add_argument("--seed", type=non_negative_int, default=0, help="random seed, >= 0 (default 0)")
    p.add_argument("--baseline-steps", type=positive_int, default=2_000,
                   help="steps per repeat of the plain-Python baseline, at least (default 2,000)")
    p.add_argument("--baseline-repeats", type=non_negative_int, default=3, help="baseline repeats (default 3; 0 skips it)")
    p.add_argument("--json", default=None, metavar="PATH", help="write the figures as JSON here")
    p.add_argument("--learner", default=None, metavar="NAME",
                   help="measure this learner instead of the built-in sarsa: a learner of an installed plugin "
                        "(docs/extending.md), its model made on the world's first task's environment (fine robot, no "
                        "transfer) and its learn(--steps) timed, the steps counted by the harness; no baseline")
    add_world_argument(p)


def measure(steps: int, seed: int, layout: Layout = ROOMS) -> tuple[int, float]:
    """Run trials of the world's first task (Table I task 1 on the rooms) back to back until
    ``steps`` steps; (steps done, seconds)."""
    robot = grid_robot("fine", layout)
    start, goal = world_task(layout).cells()
    s0 = robot.start_state(start)
    config = LearnerConfig(max_total_steps=steps)
    rng = np.random.default_rng(seed)
    done = 0
    t0 = time.perf_counter()
    while done < steps:
        cfg = LearnerConfig(max_total_steps=steps - done) if done else config
        res = sarsa.learn(robot, s0, goal, cfg, rng)
        done += int(np.abs(res.episode_steps).sum())
    return done, time.perf_counter() - t0


def measure_reference(steps: int, seed: int, layout: Layout = ROOMS) -> tuple[int, float]:
    """The baseline: the dense, line-by-line Algorithm 1 in plain Python (transfer.reference)."""
    robot = grid_robot("fine", layout)
    start, goal = world_task(layout).cells()
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    done = 0
    while done < steps:
        _, per_episode = reference.learn(robot, robot.start_state(start), goal, LearnerConfig(), rng, episodes=1)
        done += sum(per_episode)
    return done, time.perf_counter() - t0


def measure_learner(name: str, steps: int, seed: int, layout: Layout = ROOMS) -> tuple[int, float]:
    """``steps`` steps of learner ``name`` (``learning.learners``) on the world's first task, fine
    robot, no transfer, in the harness's environment (``learner_trial``): (steps it took, seconds)."""
    learner = get(name)
    robot = grid_robot("fine", layout)
    task = world_task(layout)
    start, goal = (list(layout.xy(c)) for c in task.cells())
    config = LearnerConfig()
    said = learner_trial.where(learner)
    env = learner_trial.Monitor(gym.wrappers.TimeLimit(learner_trial.case_env(robot, start, goal, 0.0, config),
                                                       max_episode_steps=MAX_EPISODE_STEPS), said)
    env.reset(seed=seed)
    model = plugin_calls.call(said, "make", learner.make, env, seed,
                                *learner_trial.handed(learner, "none", robot, None, None))
    t0 = time.perf_counter()
    plugin_calls.call(said, "learn", model.learn, steps)
    return env.total, time.perf_counter() - t0


def run_learner(args: argparse.Namespace, layout: Layout) -> int:
    """``bench --learner NAME``: an outside learner's steps per second."""
    name = get(args.learner).name  # a typo lists the valid names
    if name in BUILTIN:
        args.learner = None
        return run(args)
    refuse_other_options(args, {a.dest for a in options_of(args)} - {"baseline_steps", "baseline_repeats"},
                         f"bench --learner {name} (no baseline)")
    args.steps = args.steps or LEARNER_STEPS
    if args.json:
        check_writable(args.json)
    measure_learner(name, 1_000, args.seed, layout)  # imports and first calls outside the timing
    rates = []
    for r in range(args.repeats):
        done, secs = measure_learner(name, args.steps, args.seed + r, layout)
        rates.append(done / secs)
        print(f"repeat {r + 1}: {done:,} steps in {secs:.3f} s = {done / secs:,.0f} steps/s")
    med = statistics.median(rates)
    print(f"learner {name}: median {med:,.0f} steps/s over {args.repeats} repeats (steps counted by the harness)")
    if args.json:
        write_json_atomic(args.json, {
            "benchmark": f"learner {name} steps per second, the world's first task, fine robot, no transfer",
            "learner": name, **({} if layout is ROOMS else {"world": layout.name}),
            "steps_per_repeat": args.steps, "steps_per_second": rates, "median_steps_per_second": med,
            "machine": {"cpus": os.cpu_count(), "processor": platform.processor() or platform.machine(),
                        "python": platform.python_version()}})
    return 0


def run(args: argparse.Namespace) -> int:
    if getattr(args, "learner", None) is not None:
        return run_learner(args, world_of(args))
    args.steps = args.steps or STEPS
    if args.baseline_repeats == 0:
        refuse_other_options(args, {a.dest for a in options_of(args)} - {"baseline_steps"},
                             "bench with --baseline-repeats 0 (no baseline)")
    layout = world_of(args)
    if args.json:
        check_writable(args.json)
    measure(10_000, args.seed, layout)  # compile (or load the cached kernel) outside the timing
    rates = []
    for r in range(args.repeats):
        done, secs = measure(args.steps, args.seed + r, layout)
        rates.append(done / secs)
        print(f"repeat {r + 1}: {done:,} steps in {secs:.3f} s = {done / secs:,.0f} steps/s")
    med = statistics.median(rates)
    print(f"median: {med:,.0f} steps/s over {args.repeats} repeats (target >= 2,000,000)")
    base = []
    for r in range(args.baseline_repeats):
        done, secs = measure_reference(args.baseline_steps, args.seed + r, layout)
        base.append(done / secs)
    base_med = statistics.median(base) if base else None
    if base_med:
        print(f"baseline (dense Algorithm 1 in plain Python): median {base_med:,.0f} steps/s "
              f"over {len(base)} repeats; compiled / baseline = {med / base_med:,.0f}x")
    if args.json:
        write_json_atomic(args.json, leave_out({
            "benchmark": "learner steps per second, task 1, fine robot, no transfer",
            "world": None if layout is ROOMS else layout.name,  # the paper's rooms: left out
            "steps_per_repeat": args.steps,
            "steps_per_second": rates,
            "median_steps_per_second": med,
            "baseline": "dense Algorithm 1 in plain Python (transfer.reference)",
            "baseline_steps_per_second": base,
            "baseline_median_steps_per_second": base_med,
            "speedup_vs_baseline": None if not base_med else med / base_med,
            "machine": {"cpus": os.cpu_count(), "processor": platform.processor() or platform.machine(),
                        "python": platform.python_version()},
        }, {"world": None}))
    return 0
