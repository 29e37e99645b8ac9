"""Coverage of the hierarchical bootstrap-t interval (``experiments.stats.hierarchical``), simulated.

    python research/interval_coverage.py --datasets 600          # the table in docs/research-log.md

Data sets of log factors with true mean 0: either one case of N source seeds (seeds are the
units) or N cases of 5 seeds (cases are the units), two trials per seed; a unit's effect and a
trial's noise (half its scale) are drawn from a normal, a heavy-tailed (Student t, 3 degrees of
freedom) or a skewed distribution (gamma of shape 2, skewness 1.4; log-normal of sigma 0.5,
skewness 1.75), each centred. In the standard benchmark's records the seed-level mean log
factors have skewness -0.9 to 0.8 and the trial-level ones excess kurtosis up to 1.5 (10th-90th
percentiles; docs/benchmark.md), inside this range.
Prints the share of data sets whose 95% interval holds 0, per design, size and distribution.
"""

from __future__ import annotations

import numpy as np

from armtransfer import script
from armtransfer.experiments.stats import hierarchical

DISTRIBUTIONS = ("normal", "t3", "gamma2", "lognormal05")
SIZES = (6, 8, 10, 24)


def draw(kind: str, rng: np.random.Generator, shape) -> np.ndarray:
    """Centred draws of ``kind``."""
    if kind == "normal":
        return rng.normal(0.0, 1.0, shape)
    if kind == "t3":
        return rng.standard_t(3, shape) / np.sqrt(3.0)
    if kind == "gamma2":
        return rng.gamma(2.0, 1.0, shape) - 2.0
    if kind == "lognormal05":
        return rng.lognormal(0.0, 0.5, shape) - np.exp(0.125)
    raise ValueError(kind)


def data_set(kind: str, units: int, rng: np.random.Generator, cases: bool) -> list:
    """cases -> seeds -> trials, true mean 0."""
    if cases:
        return [(draw(kind, rng, 1)[0] + 0.5 * draw(kind, rng, (5, 2))).tolist() for _ in range(units)]
    return [(draw(kind, rng, (units, 1)) + 0.5 * draw(kind, rng, (units, 2))).tolist()]


def coverage(kind: str, units: int, cases: bool, datasets: int, seed: int, resamples: int = 999) -> float:
    rng = np.random.default_rng(seed)
    hits = 0
    for i in range(datasets):
        lo, hi = hierarchical.bootstrap_t(data_set(kind, units, rng, cases), resamples=resamples, seed=i)["ci95"]
        hits += lo <= 0.0 <= hi
    return hits / datasets


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--datasets", type=int, default=600)
    p.add_argument("--seed", type=int, default=7)
    args = p.parse_args(argv)
    print("| design | units | " + " | ".join(DISTRIBUTIONS) + " |")
    print("|---|---|" + "---|" * len(DISTRIBUTIONS))
    for cases in (False, True):
        for n in SIZES:
            row = [f"{100 * coverage(k, n, cases, args.datasets, args.seed):.1f}%" for k in DISTRIBUTIONS]
            print(f"| {'cases' if cases else 'seeds of one case'} | {n} | " + " | ".join(row) + " |", flush=True)
    return 0


if __name__ == "__main__":
    script.exit_with(main)
