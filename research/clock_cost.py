"""What the good-path clock costs: steps and seconds of trials that run on past a worse settled path.

    python research/clock_cost.py --trials 2 --seeds 2 --out runs/clock_cost.json

For each case (the standard suite's sections, a sample of their cases) and method, robot 1
learns the task (source seed j) and hands its path over; robot 2 runs ``--trials`` trials twice
from the same random streams: once stopping on any settled path (the settled clock's rule, as
before the good-path clock) and once stopping only on a good settled path (``learning.clock``),
alternating which goes first. Per trial it records the steps and seconds of both; the summary
is the ratio of the sums per section (steps: exact; seconds: measured in the same run, so load
on the machine is tolerable).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.experiments import experiment
from armtransfer.learning import methods, sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.specs import resolve

CASES = {"paper": [("coarse", "fine", 1), ("coarse", "fine", 3), ("fine", "coarse", 2), ("fine", "coarse", 4)],
         "embodiment": [("planar2:joint", "planar3:joint", 1), ("planar3:joint", "planar2:joint", 3),
                        ("planar3:joint", "planar4:joint", 2)],
         "wind": [("coarse", "fine", 2)]}
CAPS = {"paper": 2_000_000, "embodiment": 1_000_000, "wind": 2_000_000}
WIND = {"wind": 0.05}
METHODS = ("none", "pseudo", "dense", "goal-dense", "plan", "lazy", "guided", "goal-only", "corridor", "pseudo-plan")


def one(target, s0, goal, config, seed, trial, sh, wind, optimal):
    t0 = time.process_time()
    r = sarsa.learn(target, s0, goal, config, experiment.trial_rng(seed, trial), shaping=sh, wind=wind,
                    optimal=optimal)
    return int(np.abs(r.episode_steps).sum()), time.process_time() - t0, r.good_path_steps


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--trials", type=int, default=2)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    rows = []
    for section, cases in CASES.items():
        config = LearnerConfig(max_total_steps=CAPS[section])
        wind = WIND.get(section, 0.0)
        for src_name, tgt_name, task in cases:
            src, tgt = resolve(src_name), resolve(tgt_name)
            start, goal = table_task(task).cells()
            s0 = tgt.start_state(start)
            optimal = experiment.shortest_steps(tgt, s0, goal)
            for j in range(args.seeds):
                seed = 1000 + j
                try:
                    traj = experiment.source_trajectory("learned", src, start, goal, LearnerConfig(), seed)
                except Exception:  # noqa: BLE001 - robot 1 did not converge: the methods told nothing only
                    traj = None
                for name in METHODS:
                    m = methods.get(name)
                    if m.uses_trajectory and m.shaped and traj is None:
                        continue
                    sh = experiment.method_shaping(name, tgt, s0, goal, [traj] if traj else None, "auto", config, wind)
                    for k in range(args.trials):
                        order = (None, optimal) if (k + j) % 2 == 0 else (optimal, None)
                        got = {opt is None: one(tgt, s0, goal, config, seed, k, sh, wind, opt) for opt in order}
                        rows.append({"section": section, "case": f"{src_name}->{tgt_name} t{task}", "seed": seed,
                                     "method": name, "trial": k, "settled_steps": got[True][0],
                                     "settled_seconds": got[True][1], "good_steps": got[False][0],
                                     "good_seconds": got[False][1], "good_path_steps": got[False][2]})
                print(section, src_name, tgt_name, task, flush=True)
    summary = {}
    for section in CASES:
        mine = [r for r in rows if r["section"] == section]
        summary[section] = {
            "steps_ratio": sum(r["good_steps"] for r in mine) / max(1, sum(r["settled_steps"] for r in mine)),
            "seconds_ratio": sum(r["good_seconds"] for r in mine) / max(1e-9, sum(r["settled_seconds"] for r in mine)),
            "trials_run_on": sum(r["good_steps"] > r["settled_steps"] for r in mine), "trials": len(mine),
            "by_method": {m: sum(r["good_steps"] for r in mine if r["method"] == m)
                          / max(1, sum(r["settled_steps"] for r in mine if r["method"] == m)) for m in METHODS}}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"rows": rows, "summary": summary}, indent=1) + "\n")
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    script.exit_with(main)
