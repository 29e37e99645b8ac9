"""The README's arm table: for each default arm pair and each Table I task, exploration
steps with no transfer, the paper's pseudo reward and the dense potential, with 95% CIs.

    python research/arm_pairs.py --trials 20 --out runs/arm_pairs.md

The source arm learns the task (SARSA(lambda) without transfer) and transfers its converged
greedy path, as in `armtransfer arms`; controls are skipped here (the demo shows them).
"""

from __future__ import annotations

import time

from armtransfer import script
from armtransfer.tasks.specs import resolve
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.experiments import experiment
from armtransfer.learning.config import LearnerConfig
from armtransfer.io import write_text_atomic
from armtransfer.experiments.tables import fmt_ci, fmt_num, markdown_table

PAIRS = [
    ("planar2:joint", "ur5e_like:cartesian"),
    ("planar2:joint", "panda_like:cartesian"),
    ("ur5e_like:cartesian", "planar2:joint"),
]
DEFAULT_METHODS = ("none", "pseudo", "dense")


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--out", default=None, help="also write the markdown table here")
    p.add_argument("--methods", nargs="+", default=list(DEFAULT_METHODS),
                   help=f"methods, the first being the baseline (default: {' '.join(DEFAULT_METHODS)})")
    args = p.parse_args()
    METHODS = tuple(args.methods)
    config = LearnerConfig()
    rows = []
    t0 = time.perf_counter()
    for source_spec, target_spec in PAIRS:
        source, target = resolve(source_spec), resolve(target_spec)
        for number, task in TABLE_I.items():
            start, goal = task.cells()
            traj = experiment.source_trajectory("learned", source, start, goal, config, args.seed)
            summary, _ = experiment.run_transfer(source, target, start, goal, METHODS, [traj], args.trials,
                                                 args.seed, config, controls=False)
            optimal = len(target.shortest_path(target.start_state(start), goal)) - 1
            cells = [f"{fmt_num(summary[m]['mean'], 0)} {fmt_ci(summary[m]['ci95'], 0)}" for m in METHODS]
            imps = [f"{fmt_num(summary[m]['improvement_percent'], 0)}% {fmt_ci(summary[m]['improvement_ci95'], 0)}"
                    for m in METHODS[1:]]
            rows.append([f"{source_spec} -> {target_spec}", str(number), str(optimal), str(len(traj)), *cells, *imps])
            print(" | ".join(rows[-1]), flush=True)
    header = ["source -> target", "task", "target optimal", "source path", *[f"{m} [95% CI]" for m in METHODS],
              *[f"{m} improvement [95% CI]" for m in METHODS[1:]]]
    table = markdown_table(header, rows)
    print(table)
    print(f"({args.trials} trials per cell, seed {args.seed}, {time.perf_counter() - t0:.0f} s)")
    if args.out:
        write_text_atomic(args.out, table + "\n")


if __name__ == "__main__":
    script.exit_with(main)
