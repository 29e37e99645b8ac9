"""An outside learner through the harness against the built-in kernel, on the same case, in one
process, alternating, so that the machine's drift cancels out.

    python benchmarks/bench_learners.py                 # 7 rounds of 100,000 steps per contender
    python benchmarks/bench_learners.py --rounds 9 --steps 200000
    python benchmarks/bench_learners.py --fast          # a smoke run

The case: world ``rooms11``, task 1, the fine robot, method ``none`` (what ``armtransfer rooms
--world rooms11 --learner NAME --method none`` runs). Each round runs, in turn, trials back to
back until ``--steps`` environment steps, seed = the round:

- ``sarsa``: the compiled SARSA(lambda) kernel (``sarsa.learn``), default settings;
- ``tabular-q, bare``: the example plugin's learner (``examples/plugin``, one-step Q-learning
  in numpy) learning on the case's environment under its time limit, no harness: the learner's
  own cost;
- ``tabular-q, harness``: the same learner through the harness (``learner_trial.trial``), each
  trial a budget of ``--trial-budget`` steps: the monitor, the chunks, a greedy evaluation after
  each chunk and the convergence test included, as ``rooms``, ``arms``, sweeps, the matrix and
  the benchmark run it. Steps are training steps (the greedy evaluations' are not counted:
  they are the harness's overhead).

Reported: each contender's median steps/s over the rounds, the medians of the per-round ratios
of ``sarsa`` to each, and of the bare learner to the harnessed one (the harness's overhead),
with the machine, the load (``uptime``) before and after, the date and the command.
"""

from __future__ import annotations

import argparse
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np

from armtransfer import script
from armtransfer.experiments import learner_trial
from armtransfer.experiments.work import Work
from armtransfer.learning import sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.registration import MAX_EPISODE_STEPS
from armtransfer.tasks.catalog import world_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.resolve import world

ROOT = Path(__file__).resolve().parents[1]
WORLD, TASK, ROBOT = "rooms11", "1", "fine"


def example_learner():
    """The example plugin's ``tabular-q`` (installed, or from ``examples/plugin/src``)."""
    from armtransfer.learning.learners import LEARNERS

    if "tabular-q" in LEARNERS:
        return LEARNERS["tabular-q"]
    sys.path.insert(0, str(ROOT / "examples" / "plugin" / "src"))
    from armtransfer_example_plugin.learner import TABULAR_Q

    return TABULAR_Q


def case():
    layout = world(WORLD)
    robot = grid_robot(ROBOT, layout=layout)
    task = world_task(layout, TASK)
    return robot, list(task.start), list(task.goal)


def kernel(robot, start: list[int], goal: list[int], steps: int, seed: int) -> int:
    s0, g = robot.start_state(robot.layout.cell(*start)), robot.layout.cell(*goal)
    rng = np.random.default_rng(seed)
    done = 0
    while done < steps:
        res = sarsa.learn(robot, s0, g, LearnerConfig(max_total_steps=steps - done), rng)
        done += int(np.abs(res.episode_steps).sum())
    return done


def bare(robot, start: list[int], goal: list[int], steps: int, seed: int) -> int:
    learner = example_learner()
    env = gym.wrappers.TimeLimit(learner_trial.case_env(robot, start, goal, 0.0, LearnerConfig()),
                                 max_episode_steps=MAX_EPISODE_STEPS)
    env.reset(seed=seed)
    learner.make(env, seed).learn(steps)
    return steps


def harness(robot, start: list[int], goal: list[int], steps: int, seed: int, budget: int) -> int:
    learner = example_learner()
    work = Work("none", robot.name, (start[0], start[1]), (goal[0], goal[1]), 1, seed,
                LearnerConfig(max_total_steps=budget))
    done, trial = 0, 0
    while done < steps:
        _, stream = learner_trial.trial(learner, work, trial, robot, None)
        done += sum(abs(s) for s in stream)
        trial += 1
    return done


def uptime() -> str:
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    except OSError:
        return "(uptime not available)"


def machine() -> str:
    import os

    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor()) if Path("/proc/cpuinfo").exists() else ""
    import numba

    return (f"{os.cpu_count()} CPUs ({cpu}), Python {platform.python_version()}, numpy {np.__version__}, "
            f"numba {numba.__version__}, gymnasium {gym.__version__}")


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--rounds", type=int, default=7, help="rounds, each contender once a round (default 7, >= 5)")
    p.add_argument("--steps", type=int, default=100_000, help="environment steps per contender a round (default "
                                                             "100,000)")
    p.add_argument("--trial-budget", type=int, default=20_000,
                   help="max_total_steps of one harness trial (default 20,000: chunks of 100 steps)")
    p.add_argument("--fast", action="store_true", help="a smoke run: 5 rounds of 5,000 steps")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    from armtransfer.errors import InvalidParameterError

    rounds, steps = (5, 5_000) if args.fast else (args.rounds, args.steps)
    if rounds < 5 or steps < 1_000 or args.trial_budget < 200:
        raise InvalidParameterError("--rounds is at least 5, --steps at least 1,000, --trial-budget at least 200")
    robot, start, goal = case()
    kernel(robot, start, goal, 1_000, 0)  # compile (or load) the kernel outside the timing
    contenders: dict[str, Callable[[int], int]] = {
        "sarsa": lambda seed: kernel(robot, start, goal, steps, seed),
        "tabular-q, bare": lambda seed: bare(robot, start, goal, steps, seed),
        "tabular-q, harness": lambda seed: harness(robot, start, goal, steps, seed, args.trial_budget),
    }
    before = uptime()
    rates: dict[str, list[float]] = {name: [] for name in contenders}
    for r in range(rounds):
        for name, fn in contenders.items():
            t0 = time.perf_counter()
            done = fn(r)
            rates[name].append(done / (time.perf_counter() - t0))
    after = uptime()
    print(f"command: python {' '.join(sys.argv)}")
    print(f"date: {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; machine: {machine()}")
    print(f"load before: {before}\nload after:  {after}")
    print(f"{rounds} rounds of {steps:,} steps per contender (world {WORLD}, task {TASK}, {ROBOT}, none; harness "
          f"trials of {args.trial_budget:,} steps at most)")
    for name, xs in rates.items():
        print(f"  {name}: median {statistics.median(xs):,.0f} steps/s (min {min(xs):,.0f}, max {max(xs):,.0f})")
    for name in ("tabular-q, bare", "tabular-q, harness"):
        ratios = [k / o for k, o in zip(rates["sarsa"], rates[name])]
        print(f"  sarsa / {name}: median {statistics.median(ratios):,.1f}x")
    overhead = [b / h for b, h in zip(rates["tabular-q, bare"], rates["tabular-q, harness"])]
    print(f"  tabular-q bare / harness: median {statistics.median(overhead):.2f}x (the harness's overhead)")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
