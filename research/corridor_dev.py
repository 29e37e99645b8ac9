"""Choosing the corridor prior on the dev suite: steps until the greedy path settled, per method
variant, against ``plan`` (guided's learner told nothing) on the same trial streams.

    python research/corridor_dev.py --seeds 2 --trials 3 --out runs/corridor_dev
    python research/corridor_dev.py --seeds 1 --trials 1 --cases 0 --out /tmp/cd   # a smoke run

Runs the dev suite's cases (``suites.DEV``; never a held-out one) with the benchmark's own seeds,
tasks and robot 1 (``benchmark.run_seed``, ``case_cells``, robot 1's converged greedy path),
``--seeds`` source seeds of each and ``--trials`` trials per method. A variant is a registered
method name, or ``corridor:R:F[:C]`` / ``corridor-plan:R:F[:C]``: ``guided`` / ``plan``'s first episode
with the planner's untried optimism fading by F per cell beyond R cells of the trajectory and by C per
cell of trajectory left (``guide.corridor_prior``). The factor of a (case, seed) pair is plan's median steps to
convergence over the variant's (unconverged trials count at the cap); reported as the geometric
mean over pairs with a 95% percentile bootstrap interval over the pairs, and the worst pair.

Writes ``DIR/corridor_dev.json`` and prints a table.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.experiments import benchmark, experiment, suites
from armtransfer.learning import guide, methods, sarsa
from armtransfer.learning.shaping import MODE_NONE, Shaping
from armtransfer.learning.trajectory import Trajectory


def shaping_of(variant: str, robot, traj: Trajectory, config):
    """The shaping of a registered method or of a corridor variant (see the module's doc)."""
    if ":" not in variant:
        m = methods.get(variant)
        if not m.shaped:
            return None
        return methods.build_shaping(variant, robot, [traj] if m.uses_trajectory else None, "auto",
                                     config.step_reward, gamma=config.gamma)
    kind, r, f, *c = variant.split(":")
    route = float(c[0]) if c else 0.0
    n = robot.n_states
    if kind == "corridor":
        g = guide.build(robot, [traj], radius=float(r), fade=float(f), route=route)
    elif kind == "corridor-plan":  # plan's first episode (weight 0, nothing from the trajectory), then the prior
        base = methods.planner_guide(robot)
        full = guide.build(robot, [traj], radius=float(r), fade=float(f), route=route)
        g = base._replace(untried=full.untried)
    else:
        raise SystemExit(f"unknown variant kind {kind!r}")
    return Shaping(MODE_NONE, np.zeros(n), np.full(n, -1, np.int64), np.zeros(n), 0.0, guide=g)


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--out", required=True)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--first-seed", type=int, default=0, help="the first source seed (a check on seeds not chosen on)")
    p.add_argument("--trials", type=int, default=3)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--cases", default="0,1,2", help="indices into the dev section's cases")
    p.add_argument("--variants", default="plan,guided,corridor:1.5:5,corridor:1.5:50")
    a = p.parse_args(argv)
    section = suites.DEV
    config = replace(benchmark.SOURCE_CONFIG, max_total_steps=section.max_total_steps)
    cap = section.max_total_steps
    variants = a.variants.split(",")
    robots = benchmark.Robots({})
    rows = []
    for ci in map(int, a.cases.split(",")):
        case = section.cases[ci]
        source, target = robots(case.source), robots(case.target)
        for j in range(a.first_seed, a.first_seed + a.seeds):
            rs = benchmark.run_seed(a.seed, section.name, ci, j)
            start, goal = benchmark.case_cells(case, source, target, a.seed, section.name, ci, j)
            traj = experiment.source_trajectory("learned", source, start, goal, benchmark.SOURCE_CONFIG, rs)
            s0 = target.start_state(start)
            row: dict = {"case": case.label, "source_seed": j, "optimal": len(target.shortest_path(s0, goal)) - 1,
                         "methods": {}}
            for v in variants:
                sh = shaping_of(v, target, traj, config)
                ts = [sarsa.learn(target, s0, goal, config, experiment.trial_rng(rs, t), shaping=sh)
                      for t in range(a.trials)]
                row["methods"][v] = {"convergence": [t.total_steps if t.converged else cap for t in ts],
                                     "converged": [bool(t.converged) for t in ts],
                                     "first": [t.exploration_steps for t in ts],
                                     "greedy": [t.greedy_steps for t in ts]}
            rows.append(row)
            print(row["case"], j, {v: int(np.median(m["convergence"])) for v, m in row["methods"].items()}, flush=True)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "corridor_dev.json").write_text(json.dumps(rows, indent=1) + "\n")
    print("| variant | geo. mean factor vs plan [95% bootstrap over pairs] | worst pair | converged | "
          "median greedy / optimal |")
    boot = np.random.default_rng(0)
    for v in variants:
        f = [np.median(r["methods"]["plan"]["convergence"]) / np.median(r["methods"][v]["convergence"]) for r in rows]
        logs = np.log(f)
        means = logs[boot.integers(0, len(logs), (2000, len(logs)))].mean(axis=1)
        lo, hi = np.exp(np.percentile(means, [2.5, 97.5]))
        conv = sum(sum(r["methods"][v]["converged"]) for r in rows)
        n = sum(len(r["methods"][v]["converged"]) for r in rows)
        g = [x / r["optimal"] for r in rows for x in r["methods"][v]["greedy"] if x is not None]
        print(f"| {v} | {np.exp(logs.mean()):.2f}x [{lo:.2f}, {hi:.2f}] | {min(f):.2f}x | {conv}/{n} | "
              f"{np.median(g) if g else float('nan'):.2f} |")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
