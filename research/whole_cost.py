"""Where the steps after the first episode go: the whole cost of learning, per method.

    python research/whole_cost.py --out runs/whole_cost                 # the issue's two cases
    python research/whole_cost.py --trials 2 --methods plan --out /tmp/w  # a smoke run

For each case (robot 1 -> robot 2, Table I task), robot 1 learns the task (seed ``--seed``) and
hands over its converged greedy path; robot 2 runs ``--trials`` trials of each method. Per trial
it records the steps of the first episode, the steps after it until the greedy path settled, the
episodes that took, how often the greedy path changed, and where robot 2 went: every (state,
action) pair tried, binned by the distance (cells) of the state's label from the nearest cell of
the trajectory (its goal included), split into pairs tried in the first episode and pairs first
tried after it. For the methods on ``guided``'s learner (its planner counts every move) the moves
themselves are binned the same way. The first episode alone is re-run with the same generator
(``max_episodes=1``), which replays it exactly.

Writes ``DIR/whole_cost.json`` and prints a table.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.experiments import experiment
from armtransfer.learning import methods, sarsa
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.guide import new_model
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.specs import resolve

CASES = (("coarse", "fine", 2), ("fine", "coarse", 3))
METHODS = ("none", "progress", "first-visit", "plan", "guided")
BINS = (0.0, 1.5, 3.5, 6.5, np.inf)
"""Distance bins (cells) from the trajectory: on it (within one diagonal), near, off, far."""
BIN_NAMES = ("<=1.5", "1.5-3.5", "3.5-6.5", ">6.5")


def distances(robot, traj) -> np.ndarray:
    """float [S]: each state's label distance (cells) from the nearest trajectory cell."""
    lxy = robot.layout.xy_of(robot.label).astype(np.float64).reshape(-1, 2)
    cells = np.array([robot.layout.xy(int(c)) for c in (*traj.cells, traj.goal)], np.float64)
    return np.sqrt(((lxy[:, None, :] - cells[None, :, :]) ** 2).sum(-1)).min(axis=1)


def binned(weights_per_state: np.ndarray, dist: np.ndarray) -> list[float]:
    idx = np.digitize(dist, BINS[1:-1], right=True)
    return [float(weights_per_state[idx == b].sum()) for b in range(len(BIN_NAMES))]


def one_trial(robot, start_state, goal, sh, config, seed, trial, dist) -> dict:
    guide = getattr(sh, "guide", None)
    model = new_model(guide, robot.n_states, robot.n_actions) if guide is not None else None
    full = sarsa.learn(robot, start_state, goal, config, experiment.trial_rng(seed, trial), shaping=sh,
                       keep_q=True, guide_model=model)
    model1 = new_model(guide, robot.n_states, robot.n_actions) if guide is not None else None
    first = sarsa.learn(robot, start_state, goal, replace(config, max_episodes=1), experiment.trial_rng(seed, trial),
                        shaping=sh, keep_q=True, guide_model=model1)
    assert first.episode_steps[0] == full.episode_steps[0]
    if guide is not None:  # the planner's own record of what was tried
        tried_all = (model.planner.n_succ > 0).reshape(robot.n_states, -1)
        tried_1 = (model1.planner.n_succ > 0).reshape(robot.n_states, -1)
    else:
        tried_all, tried_1 = full.Q != 0, first.Q != 0
    new_pairs = (tried_all & ~tried_1).sum(axis=1)
    steps = np.abs(full.episode_steps)
    gl = full.greedy_lengths
    changes = int(sum(1 for i in range(1, len(gl)) if gl[i] != gl[i - 1]))
    settled_ep = full.episodes - config.patience if full.converged else None
    out = {
        "trial": trial, "converged": bool(full.converged), "first": int(steps[0]),
        "after_first": int(steps[1: (settled_ep + 1) if settled_ep is not None else None].sum()),
        "episodes_to_settle": settled_ep, "episodes": int(full.episodes), "greedy_length_changes": changes,
        "greedy_steps": full.greedy_steps, "pairs_tried_first": binned(tried_1.sum(axis=1), dist),
        "pairs_new_after_first": binned(new_pairs, dist),
        "first_greedy_reaching": int(np.flatnonzero(gl >= 0)[0]) if (gl >= 0).any() else None,
    }
    if guide is not None:
        visits_all = model.planner.count.sum(axis=1).reshape(robot.n_states, -1).sum(axis=1)
        visits_1 = model1.planner.count.sum(axis=1).reshape(robot.n_states, -1).sum(axis=1)
        out["moves_first"] = binned(visits_1.astype(float), dist)
        out["moves_after_first"] = binned((visits_all - visits_1).astype(float), dist)
    return out


def run_case(source_spec, target_spec, task, names, trials, seed, config) -> dict:
    source, target = resolve(source_spec), resolve(target_spec)
    start, goal = table_task(task).cells()
    traj = experiment.source_trajectory("learned", source, start, goal, LearnerConfig(), seed)
    dist = distances(target, traj)
    start_state = target.start_state(start)
    optimal = len(target.shortest_path(start_state, goal)) - 1
    res: dict = {"case": f"{source_spec} -> {target_spec}, task {task}", "optimal": optimal,
                 "trajectory_cells": len(traj.cells), "methods": {}}
    for name in names:
        sh = methods.build_shaping(name, target, [traj], "auto", config.step_reward, gamma=config.gamma) \
            if methods.get(name).shaped else None
        res["methods"][name] = [one_trial(target, start_state, goal, sh, config, seed, t, dist) for t in range(trials)]
    return res


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--out", required=True)
    p.add_argument("--trials", type=int, default=5)
    p.add_argument("--seed", type=int, default=8123)
    p.add_argument("--cap", type=int, default=2_000_000, help="steps per trial at most")
    p.add_argument("--methods", default=",".join(METHODS))
    a = p.parse_args(argv)
    names = [methods.get(n).name for n in a.methods.split(",")]
    config = LearnerConfig(max_total_steps=a.cap)
    results = [run_case(s, t, k, names, a.trials, a.seed, config) for s, t, k in CASES]
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "whole_cost.json").write_text(json.dumps(results, indent=1) + "\n")
    for r in results:
        print(f"## {r['case']} (optimal {r['optimal']}, trajectory {r['trajectory_cells']} cells)")
        print("| method | first | after first | episodes to settle | greedy changes | converged | new pairs after "
              "ep 1 by distance " + "/".join(BIN_NAMES) + " | moves after ep 1 by distance |")
        for name, ts in r["methods"].items():
            med = lambda k: np.median([t[k] if t[k] is not None else np.nan for t in ts])  # noqa: E731
            pairs = np.mean([t["pairs_new_after_first"] for t in ts], axis=0)
            moves = np.mean([t["moves_after_first"] for t in ts], axis=0) if "moves_after_first" in ts[0] else None
            mv = "/".join(f"{v:,.0f}" for v in moves) if moves is not None else "-"
            print(f"| {name} | {med('first'):,.0f} | {med('after_first'):,.0f} | {med('episodes_to_settle'):.0f} | "
                  f"{med('greedy_length_changes'):.0f} | {sum(t['converged'] for t in ts)}/{len(ts)} | "
                  + "/".join(f"{v:,.0f}" for v in pairs) + f" | {mv} |")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
