"""Calibrate the learner the paper leaves unstated on its no-transfer column only.

    python research/calibrate.py --out research/calibration     # the search (about 10 CPU-minutes)
    python research/calibrate.py --fast --out /tmp/cal            # a smoke run in seconds

The targets are the paper's Table II A (fine robot, no transfer) and Table V A (coarse robot,
no transfer) on the four Table I tasks: eight cells, which involve no transfer method, so
calibrating on them does not tune the transfer columns that are then predicted.

What can be calibrated from them. The no-transfer exploration steps are the steps of the first
episode (until the goal is first reached). Before the goal, the goal reward is never seen, and
with initial Q = q0 the learner's Q - q0 evolves exactly as a learner's from Q = 0 with step
reward r' = step - (1 - gamma) q0; multiplying r' by c > 0 multiplies every Q by c and leaves
every choice (ties included) the same. So the reward structure and the initial Q enter the
first episode only through the sign of r': negative (``cost``: untried actions look better,
systematic exploration), zero (``walk``: a positive goal with zero step cost and Q = 0, every
Q stays 0 until the goal, a uniform random walk whatever alpha, gamma, lambda, epsilon), or
positive (``pessimistic``: tried actions look better). The search covers the three classes,
each with the (step, goal, initial Q) that stands for it, and alpha, gamma, lambda and epsilon
on a grid. The episode caps censor the first episode only (it runs until the goal or the
total cap), so they are fixed at a cap no trial reaches (reported when one does).

The search, in two stages on disjoint trial seeds:
  1. every grid variant, ``--trials`` trials per cell (seeds 0..trials-1);
  2. the ``--top`` best of stage 1 again with ``--confirm`` trials per cell on fresh seeds
     (10_000 + k), so the choice is not the luck of stage 1's seeds.
  3. the ``--finalists`` first of stage 2's ranking once more with ``--validate`` trials per cell on
     fresh seeds (20_000 + k); the first of stage 3's ranking is the fit. (With 60 trials the
     count is still noisy: a first version took stage 2's first, 7 of 8 there, and it had 5 of 8
     at 200 trials.) ``armtransfer reproduce --preset paper-calibrated`` checks the fit again on
     seeds none of these stages used.
The error of a variant is the root mean square of log(ours / paper) over the eight cells, with
ours the mean over trials (the paper reports means of 10 trials), and how many cells are within
20% of the paper's (the criterion the preset must meet). Variants are ranked by that count, then
by the error (stage 1 ranks by the error alone: with 10 trials the count is too noisy to rank on).
No-transfer runs involve no source robot, so "source seeds" do not enter this stage.

Writes ``DIR/calibration.json`` (every variant with its eight means and errors, both stages)
and ``DIR/calibration.md`` (the fit, the top variants, and the best of each reward class).
"""

from __future__ import annotations

import itertools
import json
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.experiments import experiment, paper
from armtransfer.io import write_json_atomic, write_text_atomic
from armtransfer.learning import sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot

TASKS = (1, 2, 3, 4)
ROBOTS = ("fine", "coarse")
TARGETS = {("fine", t): paper.TABLE_II[t]["A"] for t in TASKS} | {("coarse", t): paper.TABLE_V[t]["A"] for t in TASKS}
WITHIN = 0.20
CAP = 2_000_000
"""The first episode's cap in the search (a trial that reaches it counts at it)."""

REWARDS = {
    # class: (step reward, goal reward, initial Q)
    "cost": (-1.0, 0.0, 0.0),        # ours: every untried action looks better
    "walk": (0.0, 1.0, 0.0),         # positive goal, zero step cost: a random walk until the goal
    "pessimistic": (0.0, 1.0, -1.0),  # tried actions look better (r' = (1 - gamma) > 0)
}
GRID = {
    "alpha": (0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0),
    "gamma": (0.9, 0.95, 0.99, 1.0),
    "lam": (0.0, 0.15, 0.3, 0.45, 0.6, 0.9),
    "epsilon": (0.0, 0.05, 0.1, 0.15, 0.2, 0.3),
}
"""Made finer where a first, wider grid (alpha 0.02-1, lambda 0-0.95, epsilon 0-0.5; 845 variants,
10 trials) put its best 15: alpha 0.02-1, lambda 0-0.9, epsilon 0-0.3; lambda 0.95 and epsilon
0.5 were never among them. Alpha 0.02 and epsilon 0.01 (one of those 15, which failed its
confirmation with 4 of 8 cells) were dropped to keep the search within the budget."""
PESSIMISTIC_GRID = {"alpha": (0.1, 0.5), "gamma": (0.99,), "lam": (0.9,), "epsilon": (0.05,)}
PESSIMISTIC_TRIALS = 5
"""Its trials run to the cap: 5 per cell say enough."""
"""Small: in a smoke run every pessimistic variant was 7 to 700 times the paper's, most trials at the cap."""
FAST_GRID = {"alpha": (0.1, 0.5), "gamma": (0.99,), "lam": (0.0, 0.9), "epsilon": (0.05, 0.3)}


@dataclass(frozen=True)
class Variant:
    reward: str
    alpha: float
    gamma: float
    lam: float
    epsilon: float

    def config(self) -> LearnerConfig:
        step, goal, _ = REWARDS[self.reward]
        return LearnerConfig(alpha=self.alpha, gamma=self.gamma, lam=self.lam, epsilon=self.epsilon,
                             step_reward=step, goal_reward=goal, max_episodes=1, max_total_steps=CAP)

    def key(self) -> dict:
        step, goal, q0 = REWARDS[self.reward]
        return {"reward": self.reward, "step_reward": step, "goal_reward": goal, "initial_q": q0,
                "alpha": self.alpha, "gamma": self.gamma, "lam": self.lam, "epsilon": self.epsilon}


def variants(fast: bool) -> list[Variant]:
    out = []
    grid = FAST_GRID if fast else GRID
    for a, g, lam, e in itertools.product(*grid.values()):
        out.append(Variant("cost", a, g, lam, e))
    out.append(Variant("walk", 0.1, 0.99, 0.9, 0.1))  # every setting gives the same random walk
    pgrid = FAST_GRID if fast else PESSIMISTIC_GRID
    for a, g, lam, e in itertools.product(*pgrid.values()):
        out.append(Variant("pessimistic", a, g, lam, e))
    return out


def measure(v: Variant, seeds: range, robots: dict) -> dict:
    """Mean first-episode steps per cell over ``seeds`` (a censored trial counts at the cap)."""
    if v.reward == "pessimistic":
        seeds = range(seeds.start, seeds.start + min(len(seeds), PESSIMISTIC_TRIALS))
    cfg = v.config()
    q0 = REWARDS[v.reward][2]
    cells: dict[str, dict] = {}
    for (name, t), target in TARGETS.items():
        robot, start, goal = robots[name, t]
        q = None if q0 == 0.0 else np.full((robot.n_states, robot.n_actions), q0)
        steps = []
        censored = 0
        for k in seeds:
            res = sarsa.learn(robot, start, goal, cfg, np.random.default_rng(k), q_init=q)
            if res.exploration_steps is None:
                censored += 1
                steps.append(CAP)
            else:
                steps.append(res.exploration_steps)
        mean = float(np.mean(steps))
        cells[f"{name} {t}"] = {"mean": mean, "median": float(np.median(steps)), "censored": censored,
                                "paper": target, "ratio": mean / target}
    logs = [math.log(c["ratio"]) for c in cells.values()]
    return {**v.key(), "trials": len(seeds), "seeds": [seeds.start, seeds.stop],
            "rms_log_error": math.sqrt(float(np.mean(np.square(logs)))),
            "within_20": sum(abs(c["ratio"] - 1.0) <= WITHIN for c in cells.values()), "cells": cells}


def _row(r: dict) -> str:
    ratios = " | ".join(f"{c['mean']:,.0f} ({100 * (c['ratio'] - 1):+.0f}%)" for c in r["cells"].values())
    return (f"| {r['reward']} | {r['alpha']:g} | {r['gamma']:g} | {r['lam']:g} | {r['epsilon']:g} | "
            f"{r['rms_log_error']:.3f} | {r['within_20']}/8 | {ratios} |")


def markdown(stage1: list[dict], stage2: list[dict], stage3: list[dict], seconds: float, command: str,
             checked: int) -> str:
    cells = list(stage1[0]["cells"])
    head = ("| reward | alpha | gamma | lambda | epsilon | RMS log error | within 20% | "
            + " | ".join(cells) + " |\n|" + "---|" * (7 + len(cells)))
    best = stage3[0]
    paper_row = "| paper | | | | | | | " + " | ".join(f"{TARGETS[tuple((c.split()[0], int(c.split()[1])))]:,.1f}"
                                                        for c in cells) + " |"
    lines = [
        "# Calibration of the learner on the paper's no-transfer column",
        "",
        f"Command: `{command}`; {len(stage1)} variants in stage 1 ({stage1[0]['trials']} trials per cell), "
        f"the best {len(stage2)} of those that converge ({checked} checked in stage 1's order) again in stage 2 "
        f"({stage2[0]['trials']} trials per cell, fresh seeds), "
        f"its first {len(stage3)} in stage 3 ({stage3[0]['trials']} trials per cell, fresh seeds); "
        f"{seconds / 60:.1f} CPU-minutes.",
        "",
        f"**Fit** (first of stage 3 by cells within 20%, then RMS log error, "
        f"{best['trials']} trials per cell on fresh seeds): reward class `{best['reward']}` (step {best['step_reward']:g}, "
        f"goal {best['goal_reward']:g}, initial Q {best['initial_q']:g}), alpha {best['alpha']:g}, "
        f"gamma {best['gamma']:g}, lambda {best['lam']:g}, epsilon {best['epsilon']:g}: RMS log error "
        f"{best['rms_log_error']:.3f}, {best['within_20']} of 8 cells within 20% of the paper's.",
        "",
        "## Stage 3 (the first of stage 2 again, on fresh seeds), ranked by cells within 20%, then error",
        "",
        head, paper_row, *(_row(r) for r in stage3),
        "",
        "## Stage 2 (confirmation on fresh seeds), ranked by cells within 20%, then error",
        "",
        head, paper_row, *(_row(r) for r in stage2),
        "",
        "## Stage 1: the best 15, and the best of each reward class",
        "",
        head, paper_row, *(_row(r) for r in stage1[:15]),
    ]
    for cls in REWARDS:
        rs = [r for r in stage1 if r["reward"] == cls]
        if rs:
            lines.append(_row(rs[0]))
    lines += ["", "Every variant of both stages is in `calibration.json`.", ""]
    return "\n".join(lines)


CONVERGE_SEEDS = 3
"""Source seeds of the convergence check: those ``armtransfer reproduce`` hands over from (0, 1, 2)."""


def converges(v: Variant) -> bool:
    """Does the learner learn every task, as robot 1 must before it hands over its path: a whole
    trial converges (the greedy path unchanged for ``patience`` episodes within the episode cap) on
    the eight cells, for the first :data:`CONVERGE_SEEDS` source seeds (the generators
    ``experiment.source_trajectory`` draws from)? Stops at the first trial that does not."""
    cfg = replace(v.config(), max_episodes=LearnerConfig().max_episodes, max_total_steps=CONVERGE_CAP)
    for seed in range(CONVERGE_SEEDS):
        for name in ROBOTS:
            robot = grid_robot(name)
            for t in TASKS:
                s, g = TABLE_I[t].cells()
                res = sarsa.learn(robot, robot.start_state(s), g, cfg, experiment.trial_rng(seed, 0, stream=1))
                if not res.converged:
                    return False
    return True


CONVERGE_CAP = 5_000_000


def main() -> int:
    p = script.parser(__doc__)
    p.add_argument("--out", required=True)
    p.add_argument("--trials", type=int, default=10)
    p.add_argument("--confirm", type=int, default=60)
    p.add_argument("--validate", type=int, default=200)
    p.add_argument("--top", type=int, default=30)
    p.add_argument("--finalists", type=int, default=6)
    p.add_argument("--max-checked", type=int, default=300,
                   help="stage-1 variants checked for convergence at most, in stage 1's order")
    p.add_argument("--stage1", default=None, help="take stage 1 from this calibration.json (same grid and seeds)")
    p.add_argument("--fast", action="store_true")
    a = p.parse_args()
    robots = {}
    for name in ROBOTS:
        r = grid_robot(name)
        for t in TASKS:
            s, g = TABLE_I[t].cells()
            robots[name, t] = (r, r.start_state(s), g)
    t0 = time.process_time()
    vs = variants(a.fast)
    if a.stage1:  # the same grid and seeds as a run before: its stage 1 again, not recomputed
        stage1 = json.loads(Path(a.stage1).read_text())["stage1"]
    else:
        stage1 = []
        for i, v in enumerate(vs):
            stage1.append(measure(v, range(a.trials), robots))
            if i % 50 == 0:
                print(f"{i}/{len(vs)} {time.process_time() - t0:.0f}s", flush=True)
    stage1.sort(key=lambda r: r["rms_log_error"])
    top, checked = [], []
    for r in stage1[: a.max_checked]:  # in stage 1's order, the first --top that learn the task
        v = Variant(r["reward"], r["alpha"], r["gamma"], r["lam"], r["epsilon"])
        ok = converges(v)
        checked.append({**v.key(), "converges": ok})
        if ok:
            top.append(v)
            if len(top) == a.top:
                break
    print(f"convergence: {len(top)} of {len(checked)} checked converge", flush=True)
    stage2 = sorted((measure(v, range(10_000, 10_000 + a.confirm), robots) for v in top),
                    key=lambda r: (-r["within_20"], r["rms_log_error"]))
    stage3 = sorted((measure(Variant(r["reward"], r["alpha"], r["gamma"], r["lam"], r["epsilon"]),
                             range(20_000, 20_000 + a.validate), robots) for r in stage2[: a.finalists]),
                    key=lambda r: (-r["within_20"], r["rms_log_error"]))
    seconds = time.process_time() - t0
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    command = ("python research/calibrate.py" + (" --fast" if a.fast else "") + f" --out {a.out}"
               + (f" --stage1 {a.stage1}" if a.stage1 else ""))
    write_json_atomic(out / "calibration.json", {"command": command, "cap": CAP, "grid": GRID,
                                                 "pessimistic_grid": PESSIMISTIC_GRID, "rewards": REWARDS,
                                                 "cpu_seconds": round(seconds, 1), "fit": stage3[0],
                                                 "convergence_checked": checked,
                                                 "stage3": stage3, "stage2": stage2, "stage1": stage1})
    text = markdown(stage1, stage2, stage3, seconds, command, len(checked))
    write_text_atomic(out / "calibration.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    script.exit_with(lambda: script.run(main))
