"""armtransfer bench: learner steps per second (the world's first task, fine robot, no transfer)."""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import numpy as np

from armtransfer.commands.common import (add_world_argument, non_negative_int, options_of, positive_int,
                                         refuse_other_options, world_of)
from armtransfer.tasks.catalog import world_task
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.learning import sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.io import check_writable, write_json_atomic

HELP = "Measure how many learning steps per second the learner runs on this machine."
EXAMPLE = "armtransfer bench --repeats 3"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--steps", type=positive_int, default=2_000_000,
                   help="learner steps per repeat, at least (default 2,000,000)")
    p.add_argument("--repeats", type=positive_int, default=5, help="timed repeats (default 5)")
    p.add_argument("--seed", type=non_negative_int, default=0, help="random seed, >= 0 (default 0)")
    p.add_argument("--baseline-steps", type=positive_int, default=2_000,
                   help="steps per repeat of the plain-Python baseline, at least (default 2,000)")
    p.add_argument("--baseline-repeats", type=non_negative_int, default=3, help="baseline repeats (default 3; 0 skips it)")
    p.add_argument("--json", default=None, metavar="PATH", help="write the figures as JSON here")
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
    from armtransfer.learning import reference

    robot = grid_robot("fine", layout)
    start, goal = world_task(layout).cells()
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    done = 0
    while done < steps:
        _, per_episode = reference.learn(robot, robot.start_state(start), goal, LearnerConfig(), rng, episodes=1)
        done += sum(per_episode)
    return done, time.perf_counter() - t0


def run(args: argparse.Namespace) -> int:
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
        world = {} if layout is ROOMS else {"world": layout.name}  # the rooms' JSON is as it was
        write_json_atomic(args.json, {
            "benchmark": "learner steps per second, task 1, fine robot, no transfer",
            **world,
            "steps_per_repeat": args.steps,
            "steps_per_second": rates,
            "median_steps_per_second": med,
            "baseline": "dense Algorithm 1 in plain Python (transfer.reference)",
            "baseline_steps_per_second": base,
            "baseline_median_steps_per_second": base_med,
            "speedup_vs_baseline": None if not base_med else med / base_med,
            "machine": {"cpus": os.cpu_count(), "processor": platform.processor() or platform.machine(),
                        "python": platform.python_version()},
        })
    return 0
