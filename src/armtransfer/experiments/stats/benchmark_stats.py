"""The statistics of a benchmark run, from its records alone.

Per case and method, over every source seed and trial:

  first exposure     steps until the goal is first reached: Kaplan-Meier median and 95%
                     interval (censored at the trial's cap), the median over source seeds of
                     each seed's median (with a percentile bootstrap interval over seeds),
                     and the worst source seed's median
  failure rate       the share of trials that never reached the goal within the cap (a
                     method that could not run counts every trial as failed)
  success rate       the share of trials that reached it within the budget
                     (``suites.BUDGET_FACTOR`` x the target's shortest path)
  convergence        steps until the greedy path settled: Kaplan-Meier median (censored at
                     the cap: a trial that never settled)
  area               the area under the learning curve (``learning_metrics.curve``: steps of
                     the first ``HORIZON`` episodes), mean over trials

and against the method's baseline (the method sharing its learner), paired per source seed:
the factor baseline / method of the seeds' median first exposures (geometric mean over seeds
with a bootstrap interval on the log scale, the worst seed's factor) and Taylor and Stone's
transfer ratio, the share of the baseline's learning-curve area the method saves.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

from armtransfer.experiments.stats import survival
from armtransfer.experiments.stats.metrics import median_is_lower_bound


def _seed_median(values: list, cap: float) -> tuple[float, bool]:
    """(median with None counted at ``cap``, whether censoring reaches it: a lower bound)."""
    x = np.array([cap if v is None else v for v in values], dtype=np.float64)
    return float(np.median(x)), median_is_lower_bound(sum(v is None for v in values), len(values))


def cell_stats(recs: list[dict]) -> dict:
    """The statistics of one case and method (``recs``: its records, one per source seed)."""
    cap = recs[0]["cap"]
    fe = [v for r in recs for v in r["first_exposure"]]
    n = len(fe)
    km = survival.kaplan_meier(fe, cap)
    seeds = [_seed_median(r["first_exposure"], cap) for r in recs]
    medians = [m for m, _ in seeds]
    conv = [v for r in recs for v in r["convergence_steps"]]
    conv_km = survival.kaplan_meier(conv, cap)
    within = [v is not None and v <= r["budget"] for r in recs for v in r["first_exposure"]]
    areas = [a for r in recs for a in r["area"] if a is not None]
    curves = [c for r in recs for c in r["curves"]]
    return {
        "trials": n,
        "source_seeds": len(recs),
        "errors": sorted({r["error"] for r in recs if r["error"]}),
        "failure_rate": sum(v is None for v in fe) / n if n else None,
        "success_rate": sum(within) / n if n else None,
        "first_exposure": {
            "km_median": km["median"], "km_median_ci95": km["median_ci95"],
            "km_median_beyond_cap": km["median_beyond_cap"],
            "seed_medians": medians,
            "median_over_seeds": float(np.median(medians)) if medians else None,
            "median_over_seeds_ci95": survival.bootstrap_ci(medians, np.median),
            "worst_seed": max(medians) if medians else None,
            "worst_seed_is_lower_bound": any(lb and m == max(medians) for m, lb in seeds),
            "seeds_at_cap": sum(lb for _, lb in seeds),
        },
        "survival": {k: km[k] for k in ("times", "survival", "low", "high")},
        "convergence": {"km_median": conv_km["median"], "km_median_ci95": conv_km["median_ci95"],
                        "km_median_beyond_cap": conv_km["median_beyond_cap"],
                        "converged": sum(v is not None for v in conv)},
        "area": {"mean": float(np.mean(areas)) if areas else None,
                 "ci95": survival.bootstrap_ci([np.mean(r["area"]) for r in recs if None not in r["area"]])},
        "curve_mean": [float(v) for v in np.mean(curves, axis=0)] if curves else [],
    }


def _factors(method: list[dict], base: list[dict], key: str) -> dict:
    """baseline / method of the per-seed medians of ``key`` (censored at the cap), paired by
    source seed: the summary of :func:`survival.ratio_summary`, the log factors, and how many
    seeds had a median that censoring reached (their factor is a bound)."""
    cap = method[0]["cap"]
    by_seed = {b["source_seed"]: b for b in base}
    logs, bounds = [], 0
    for m in method:
        mm, mlb = _seed_median(m[key], cap)
        bm, blb = _seed_median(by_seed[m["source_seed"]][key], cap)
        logs.append(math.log(bm / mm))
        bounds += bool(mlb or blb)
    return dict(survival.ratio_summary(logs), log_factors=logs, seeds_with_censored_median=bounds)


def paired(method: list[dict], base: list[dict]) -> dict:
    """The method against one baseline, paired by source seed: the first-exposure factor (the
    top level), the convergence factor, and the transfer ratio of the learning-curve areas."""
    by_seed = {b["source_seed"]: b for b in base}
    ratios = [1.0 - float(np.mean(m["area"])) / float(np.mean(by_seed[m["source_seed"]]["area"]))
              for m in method if None not in m["area"] and None not in by_seed[m["source_seed"]]["area"]]
    out = _factors(method, base, "first_exposure")
    out["convergence"] = _factors(method, base, "convergence_steps")
    out["transfer_ratio"] = float(np.mean(ratios)) if ratios else None
    out["transfer_ratio_ci95"] = survival.bootstrap_ci(ratios)
    return out


def _pool(entries: list[dict], base: str) -> dict:
    logs = [x for e in entries for x in e["log_factors"]]
    cens = sum(e["seeds_with_censored_median"] for e in entries)
    return dict(survival.ratio_summary(logs), baseline=base, seeds_with_censored_median=cens)


def summarize(records: list[dict]) -> dict:
    """``{section: {"cases": [{label, methods: {name: stats}}], "pooled": {name: {baseline: factor}}}}``.

    A method's stats hold ``against``: per baseline it names (the no-transfer one first), the
    paired comparison. ``pooled`` is that factor over every (case, source seed) of the section,
    each pair one unit of the bootstrap."""
    by_cell: dict = defaultdict(list)
    for r in records:
        by_cell[(r["section"], r["case"], r["method"])].append(r)
    out: dict = {}
    for r in records:
        sec = out.setdefault(r["section"], {"cases": {}, "pooled": {}})
        sec["cases"].setdefault(r["case"], {"label": r["label"], "optimal_per_seed": [], "methods": {}})
    for (section, case, method), recs in by_cell.items():
        recs.sort(key=lambda r: r["source_seed"])
        entry = cell_stats(recs)
        entry["baselines"] = recs[0]["baselines"]
        entry["against"] = {b: paired(recs, sorted(by_cell[(section, case, b)], key=lambda r: r["source_seed"]))
                            for b in entry["baselines"] if (section, case, b) in by_cell}
        out[section]["cases"][case]["methods"][method] = entry
        out[section]["cases"][case]["optimal_per_seed"] = [r["optimal"] for r in recs]
    for section, sec in out.items():
        order = [r["method"] for r in records if r["section"] == section]
        names = list(dict.fromkeys(order))
        for name in names:
            pairs: dict[str, list[dict]] = {}
            for case in sec["cases"].values():
                for base, ab in case["methods"].get(name, {}).get("against", {}).items():
                    pairs.setdefault(base, []).append(ab)
            if pairs:
                sec["pooled"][name] = {base: dict(_pool(abs_, base),
                                                  convergence=_pool([a["convergence"] for a in abs_], base))
                                       for base, abs_ in pairs.items()}
        sec["cases"] = [sec["cases"][k] for k in sorted(sec["cases"])]
        for case in sec["cases"]:
            case["methods"] = {n: case["methods"][n] for n in names if n in case["methods"]}
    return out
