"""How `goal-only` should use the goal: its variants against `plan` on the dev suite.

    python research/goal_only_variants.py --seeds 4 --trials 2
    python research/goal_only_variants.py --seeds 2 --trials 1 --cases 0   # seconds

`goal-only` is `guided` told the goal and no route; `plan` is the same learner told nothing.
Knowing the goal should never hurt, so a fair `goal-only` is at least as fast as `plan`
everywhere. Each variant runs on the dev suite's cases (the only suite parameters may be
chosen on), source seeds as the benchmark draws them, with `plan` on the same random
streams. Prints per case and variant the geometric mean over trials of plan / variant of the
first exposure and of the steps to convergence (both censored at the cap: a pair capped in
both is a tie and left out), and the worst trial's first-exposure factor.
"""

from __future__ import annotations

import math
from dataclasses import replace

from armtransfer import script
from armtransfer.experiments import benchmark, experiment, suites
from armtransfer.learning import guide, methods
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory

VARIANTS = {
    "line": "the straight start -> goal line (through walls), guided's defaults (the old goal-only)",
    "goal": "the goal alone, scored by its straight-line distance, guided's defaults (gives up after 100 moves)",
    "goal-lrta": "the goal alone, never given up, learning real-time search (fill 1 cell per move)",
    "goal-lrta-0.25": "the goal alone, never given up, learning real-time search (fill 0.25 cell per move)",
    "line-lrta": "the straight line, never given up, learning real-time search (fill 1 cell per move)",
}


FAR = 1e6
"""A window past any trajectory: the score is the straight-line distance to the goal."""


def goal_trajectory(traj: Trajectory) -> Trajectory:
    return Trajectory((traj.start,), (0,), traj.goal, source="goal-only")


def builder(variant: str):
    def build(robot, trajs, k, beta):
        t = trajs[0]
        if variant == "line":
            g = guide.build(robot, [methods.straight_line(t, robot.layout)])
        elif variant == "goal":
            g = guide.build(robot, [goal_trajectory(t)], window=FAR)
        elif variant.startswith("goal-lrta"):
            fill = 0.25 if variant.endswith("0.25") else 1.0
            g = guide.build(robot, [goal_trajectory(t)], window=FAR, give_up=0, fill=fill)
        else:
            g = guide.build(robot, [methods.straight_line(t, robot.layout)], give_up=0, fill=1.0)
        base = methods._plan(robot, trajs, k, beta)
        return Shaping(base.mode, base.bonus, base.traj_index, base.phi, k, guide=g)
    return build


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--trials", type=int, default=2)
    p.add_argument("--cases", type=int, nargs="*", default=None)
    p.add_argument("--variants", nargs="*", default=list(VARIANTS))
    args = p.parse_args()
    dev = suites.get("dev").sections[0]
    robots = benchmark.Robots({})
    config = replace(benchmark.SOURCE_CONFIG, max_total_steps=dev.max_total_steps)
    for v in args.variants:
        methods.METHODS["goal-only:" + v] = replace(methods.METHODS["goal-only"], name="goal-only:" + v,
                                                    build=builder(v))
    for ci, case in enumerate(dev.cases):
        if args.cases is not None and ci not in args.cases:
            continue
        source, target = robots(case.source), robots(case.target)
        rows: dict[str, list[tuple[float | None, float | None]]] = {v: [] for v in args.variants}
        for j in range(args.seeds):
            rs = benchmark.run_seed(0, dev.name, ci, j)
            start, goal = benchmark.case_cells(case, source, target, 0, dev.name, ci, j)
            traj, why = benchmark._source_trajectory(source, start, goal, rs)
            if traj is None:
                print(f"  {case.label} seed {j}: {why}")
                continue
            plan = experiment.run_method("plan", target, start, goal, None, args.trials, rs, config, wind=case.wind)
            for v in args.variants:
                res = experiment.run_method("goal-only:" + v, target, start, goal, [traj], args.trials, rs, config,
                                            wind=case.wind)
                for a, b in zip(res.trials, plan.trials):
                    fe = None if a.exploration_steps is None and b.exploration_steps is None else math.log(
                        (b.exploration_steps or config.max_total_steps) / (a.exploration_steps or config.max_total_steps))
                    cv = None if not (a.converged or b.converged) else math.log(
                        (b.total_steps if b.converged else config.max_total_steps)
                        / (a.total_steps if a.converged else config.max_total_steps))
                    rows[v].append((fe, cv))
        print(f"{case.label} ({args.seeds} seeds x {args.trials} trials), plan / variant:")
        for v, pairs in rows.items():
            fe = [x for x, _ in pairs if x is not None]
            cv = [y for _, y in pairs if y is not None]
            gm = lambda xs: f"{math.exp(sum(xs) / len(xs)):.2f}x" if xs else "n/a"
            worst = f"{math.exp(min(fe)):.2f}x" if fe else "n/a"
            print(f"  {v:15s} first exposure {gm(fe)} (worst trial {worst}), convergence {gm(cv)}"
                  f" ({len(pairs) - len(fe)} ties in first exposure)")


if __name__ == "__main__":
    script.exit_with(main)
