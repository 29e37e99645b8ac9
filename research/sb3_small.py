"""stable-baselines3's DQN and PPO on the small rooms worlds, with and without a reward term:
first exposure, convergence and wall time per trial, under the benchmark's protocol.

    python research/sb3_small.py --world rooms11 --task 3 --seeds 100-104 --trials 1 --budget 60000

For each source seed the coarse robot learns the task with SARSA(lambda) (the benchmark's
source run) and its converged greedy path is handed over; the fine robot then learns with
each learner and method on ``armtransfer/Rooms-v0``'s environment (the registered time limit,
``TransferReward`` for pseudo/dense), in chunks of budget/200 steps with a greedy episode
after each; converged = 3 greedy episodes in a row within 1.25 x the shortest path (the
harness's rule, ``armtransfer.experiments.learner_trial``). Variants of the settings are
chosen with ``--set learner.key=value`` (repeatable) on the dev cases only; docs/research-log.md
keeps what was tried. Prints one line per trial and a summary per (learner, method).
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium as gym
import numpy as np

from armtransfer.experiments import experiment
from armtransfer.learning import sb3
from armtransfer.learning.config import LearnerConfig
from armtransfer.registration import MAX_EPISODE_STEPS
from armtransfer.tasks.catalog import world_task
from armtransfer.tasks.envs import RobotRoomsEnv
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.worlds.resolve import world as resolve_world
from armtransfer.wrappers import TransferReward

CHUNKS, EVALS, TOLERANCE, EVAL_CAP = 200, 3, 0.25, 4
MAKERS = {"dqn": sb3.make_dqn, "ppo": sb3.make_ppo}


class Count(gym.Wrapper):
    def __init__(self, env):
        super().__init__(env)
        self.total = 0
        self.first = None

    def step(self, action):
        out = self.env.step(action)
        self.total += 1
        if out[2] and self.first is None:
            self.first = self.total
        return out


def greedy(model, env, cap):
    obs, _ = env.reset()
    for k in range(1, cap + 1):
        a, _ = model.predict(obs, deterministic=True)
        obs, _, term, _, _ = env.step(int(a))
        if term:
            return k
    return None


def trial(learner, method, target, task, traj, seed, budget, config):
    env = gym.wrappers.TimeLimit(RobotRoomsEnv(target, task, step_reward=config.step_reward,
                                               goal_reward=config.goal_reward), max_episode_steps=MAX_EPISODE_STEPS)
    if method != "none":
        env = TransferReward(env, traj, method=method, K="auto", gamma=config.gamma)
    env = Count(env)
    env.reset(seed=seed + 1)
    ev = RobotRoomsEnv(target, task)
    optimal = len(target.shortest_path(ev.start_state, ev.goal_cell)) - 1
    t0 = time.perf_counter()
    model = MAKERS[learner](env, seed)
    chunk, evals, conv = max(budget // CHUNKS, 1), [], None
    while env.total < budget:
        model.learn(min(chunk, budget - env.total))
        evals.append((env.total, greedy(model, ev, EVAL_CAP * optimal)))
        last = evals[-EVALS:]
        if len(last) == EVALS and all(s is not None and s <= (1 + TOLERANCE) * optimal for _, s in last):
            conv = last[0][0]
            break
    return {"learner": learner, "method": method, "seed": seed, "first": env.first, "converged": conv,
            "steps": env.total, "seconds": round(time.perf_counter() - t0, 2), "optimal": optimal}


def seeds(text):
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def apply_sets(sets):
    for s in sets:
        key, _, value = s.partition("=")
        learner, _, name = key.partition(".")
        v = json.loads(value)
        if learner == "dqn" and name in ("exploration_steps", "final_eps"):
            setattr(sb3, {"exploration_steps": "DQN_EXPLORATION_STEPS", "final_eps": "DQN_FINAL_EPS"}[name], v)
        elif learner in ("dqn", "ppo"):
            getattr(sb3, f"{learner.upper()}_KWARGS")[name] = v
        else:
            sys.exit(f"unknown setting {key!r}")


def main(argv=None):
    from armtransfer import script

    p = script.parser(__doc__)
    p.add_argument("--world", default="rooms11")
    p.add_argument("--task", default="3")
    p.add_argument("--seeds", default="100-104")
    p.add_argument("--trials", type=int, default=1)
    p.add_argument("--budget", type=int, default=60_000)
    p.add_argument("--learners", default="dqn,ppo")
    p.add_argument("--methods", default="none,pseudo,dense")
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--json", help="write every trial here")
    a = p.parse_args(argv)
    apply_sets(a.set)
    layout = resolve_world(a.world)
    task = world_task(layout, a.task)
    source, target = grid_robot("coarse", layout), grid_robot("fine", layout)
    start, goal = task.cells()
    config = LearnerConfig()
    rows = []
    for s in seeds(a.seeds):
        traj = experiment.source_trajectory("learned", source, start, goal, config, s)
        for learner in a.learners.split(","):
            for method in a.methods.split(","):
                for t in range(a.trials):
                    r = trial(learner, method, target, task, traj, 1000 * s + t, a.budget, config)
                    rows.append(r)
                    print(json.dumps(r), flush=True)
    print(f"# {a.world} task {a.task}, seeds {a.seeds} x {a.trials}, budget {a.budget}, sets {a.set}")
    for learner in a.learners.split(","):
        for method in a.methods.split(","):
            rs = [r for r in rows if r["learner"] == learner and r["method"] == method]
            conv = [r["converged"] for r in rs if r["converged"] is not None]
            first = [r["first"] if r["first"] is not None else a.budget for r in rs]
            print(f"{learner:4} {method:7} converged {len(conv)}/{len(rs)}  median conv "
                  f"{statistics.median(conv) if conv else None}  median first {statistics.median(first)}  "
                  f"mean s/trial {np.mean([r['seconds'] for r in rs]):.1f}  steps/s "
                  f"{sum(r['steps'] for r in rs) / sum(r['seconds'] for r in rs):.0f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    from armtransfer import script

    script.exit_with(main)
