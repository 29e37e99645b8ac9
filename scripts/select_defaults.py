"""Choose each shaping method's default K (and beta for ``dense``) on held-out tasks.

The defaults must not be tuned on the Table I tasks they are reported on, so this script
draws its own start/goal pairs in the rooms world (a fixed seed; every pair at least 20
fine steps apart, none of them a Table I task), transfers the coarse robot's shortest path
to the fine robot, and prints, for every candidate value, the geometric mean over the
pairs of exploration steps / optimal distance (first episode only, 20 trials per pair).

    python scripts/select_defaults.py            # about two minutes on 2 cores
"""

from __future__ import annotations

import argparse
import itertools

import numpy as np

from armtransfer.tasks.catalog import TABLE_I
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.tasks.layout import ROOMS
from armtransfer.learning import potentials, methods, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.experiment import trial_rng
from armtransfer.learning.shaping import Shaping

CANDIDATES = {
    "first-visit": [{"K": k} for k in (0.3, 1, 3, 10, 30)],
    "progress": [{"K": k} for k in (1, 3, 10, 30)],
    "potential": [{"K": k} for k in (0.3, 1, 3, 10)],
    "dense": [{"K": k, "beta": b} for k, b in itertools.product((1, 2, 3, 4, 6), (0.5, 1, 1.5, 2))],
}


def held_out_pairs(n: int, seed: int) -> list[tuple[int, int]]:
    rng = np.random.default_rng(seed)
    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    table = {(t.start, t.goal) for t in TABLE_I.values()}
    even = [c for c in np.flatnonzero(ROOMS.free) if all(v % 2 == 0 for v in ROOMS.xy(int(c)))]
    pairs: list[tuple[int, int]] = []
    while len(pairs) < n:
        s, g = (int(c) for c in rng.choice(even, 2, replace=False))
        if (ROOMS.xy(s), ROOMS.xy(g)) in table:
            continue
        path = fine.shortest_path(fine.start_state(s), g)
        if path is None or len(path) - 1 < 20 or coarse.shortest_path(coarse.start_state(s), g) is None:
            continue
        pairs.append((s, g))
    return pairs


def score(method: str, params: dict, pairs, trials: int) -> float:
    fine, coarse = grid_robot("fine"), grid_robot("coarse")
    config = LearnerConfig(max_episodes=1, max_total_steps=300_000)
    ratios = []
    for s, g in pairs:
        traj = trajectories.shortest(coarse, s, g)
        if method == "dense":
            phi = potentials.dense(fine, traj, params["K"], params["beta"])
            shaping = Shaping.potential(phi, params["K"])
        else:
            shaping = methods.build_shaping(method, fine, traj, params["K"], config.step_reward)
        optimal = len(fine.shortest_path(fine.start_state(s), g)) - 1
        for t in range(trials):
            res = sarsa.learn(fine, fine.start_state(s), g, config, trial_rng(12345, t), shaping=shaping)
            steps = res.exploration_steps or config.max_total_steps
            ratios.append(steps / optimal)
    return float(np.exp(np.mean(np.log(ratios))))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pairs", type=int, default=8)
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--seed", type=int, default=2026)
    p.add_argument("--method", nargs="*", default=None, help="only these methods")
    args = p.parse_args()
    pairs = held_out_pairs(args.pairs, args.seed)
    print("held-out pairs:", [(ROOMS.xy(s), ROOMS.xy(g)) for s, g in pairs])
    for method, cands in CANDIDATES.items():
        if args.method and method not in args.method:
            continue
        scores = [(score(method, c, pairs, args.trials), c) for c in cands]
        for sc, c in scores:
            print(f"{method:12s} {c}: {sc:.1f} x optimal")
        best = min(scores, key=lambda x: x[0])
        print(f"-> {method}: best {best[1]} ({best[0]:.1f} x optimal)", flush=True)


if __name__ == "__main__":
    main()
