"""The statistics of a benchmark run, from its records alone.

Four step counts are measured per trial, each a time until an event, restricted to the
trial's step cap and *censored* there when the event did not happen (survival data, never
padded with a made-up value):

  good path          steps until the greedy path was good, at most ceil(quality x shortest)
                     steps, and stayed so to the end of the trial (``learning.clock``): every
                     claim's headline. A trial whose path was not good at its end (it settled
                     on a worse path and ran on to its episode or step cap) counts at the cap.
  convergence        steps until the greedy path first settled (unchanged for ``patience``
                     episodes, however long): the settled clock, which a learner that explores
                     less can buy with a worse path
  first exposure     steps until the goal was first reached
  cost of HORIZON    steps of the first ``learning_metrics.HORIZON`` episodes (a converged trial
  episodes           goes on at its greedy length); a trial the cap stopped before that is
                     censored at the cap

Per case and method: Kaplan-Meier medians of each (intervals by a cluster bootstrap over
source seeds), failure and success rates, and the share of the variance of log first
exposure that lies between source seeds (the seed effect, from the one-way analysis of
variance of trials within seeds).

Against a baseline (the method sharing its learner), paired trial by trial (common random
numbers): the log factor log(baseline / method) of the restricted times. A pair where both
trials were censored is a *tie*: it is counted and left out of the factor, whose value it
does not inform; a pair with one censored trial gives a bound and is counted too. The
factor is the geometric mean over cases, then source seeds, then trials, with the
hierarchical bootstrap-t interval of ``hierarchical``, its p-value, and the factors
detectable at 80% power. The transfer ratio (Taylor and Stone) is the share of the
baseline's cost of HORIZON episodes that the method saves, 1 - 1 / (its factor).

Every verdict of the run (each method, baseline, metric and section) is Holm-adjusted
across the whole run (``multiplicity.holm``): ``p_holm`` decides "faster" or "slower".
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Callable, Iterator

import numpy as np

from armtransfer.experiments.stats import hierarchical, learning_metrics, multiplicity, survival

METRICS = ("good_path", "convergence", "first_exposure", "cost")
"""The paired metrics in the order every claim states them: the good-path clock first."""

DESCRIBED = ("shortest_path",)
"""Paired metrics reported beside the claims without a verdict (outside Holm's correction): the
good-path clock at quality 1.0, the shortest path itself."""

CLOCKS = {"good_path": "good_path_steps", "shortest_path": "shortest_path_steps"}
"""The good-path clocks and the record field each reads."""


def measured(rec: dict, metric: str) -> bool:
    """Whether ``rec``'s trials measured ``metric``: a good-path clock is missing from records
    written before it and from a continuous target's (``clock_note`` says why)."""
    return metric not in CLOCKS or (CLOCKS[metric] in rec and not rec.get("clock_note"))


def _restricted(rec: dict, metric: str) -> list[float | None]:
    """One record's trials' times for ``metric`` (None: censored at the cap)."""
    cap = rec["cap"]
    if metric in CLOCKS:
        return [None if v is None else min(float(v), cap) for v in rec[CLOCKS[metric]]]
    if metric == "first_exposure":
        return [None if v is None else min(float(v), cap) for v in rec["first_exposure"]]
    if metric == "convergence":
        return [None if v is None else min(float(v), cap) for v in rec["convergence_steps"]]
    out: list[float | None] = []
    curves = rec.get("curves") or []
    for i, conv in enumerate(rec["converged"]):
        if i >= len(curves):
            out.append(None)
            continue
        done = conv or rec["episodes"][i] >= learning_metrics.HORIZON
        total = float(np.sum(curves[i]))
        out.append(min(total, cap) if done and total < cap else None)
    return out


def seed_share(seeds: list[list[float | None]], cap: float) -> float | None:
    """The share of the variance of log restricted first exposure between source seeds (one-way
    ANOVA: (MSB - MSW) / n0 over the total, at least 0); None without two seeds of two trials."""
    groups = [np.log([cap if v is None else max(v, 1.0) for v in s]) for s in seeds if len(s) >= 2]
    if len(groups) < 2:
        return None
    k = len(groups)
    n = np.array([len(g) for g in groups], dtype=np.float64)
    big_n = n.sum()
    grand = np.concatenate(groups).mean()
    msb = float(sum(len(g) * (g.mean() - grand) ** 2 for g in groups) / (k - 1))
    msw = float(sum(((g - g.mean()) ** 2).sum() for g in groups) / (big_n - k))
    n0 = (big_n - (n ** 2).sum() / big_n) / (k - 1)
    between = max(0.0, (msb - msw) / n0)
    total = between + msw
    return float(between / total) if total > 0 else 0.0


def _km_block(seeds: list[list[float | None]], cap: float) -> dict:
    flat = [v for s in seeds for v in s]
    km = survival.kaplan_meier(flat, cap)
    return {"km_median": km["median"], "km_median_ci95": survival.cluster_median_ci(seeds),
            "km_median_beyond_cap": km["median_beyond_cap"], "events": km["events"], "n": km["n"], "km": km}


def cell_stats(recs: list[dict]) -> dict:
    """The statistics of one case and method (``recs``: its records, one per source seed)."""
    cap = recs[0]["cap"]
    fe_seeds = [_restricted(r, "first_exposure") for r in recs]
    fe = [v for s in fe_seeds for v in s]
    n = len(fe)
    fe_block = _km_block(fe_seeds, cap)
    km = fe_block.pop("km")
    conv = _km_block([_restricted(r, "convergence") for r in recs], cap)
    conv.pop("km")
    clocked = [r for r in recs if measured(r, "good_path")]
    good = _km_block([_restricted(r, "good_path") for r in clocked], cap) if clocked else None
    if good is not None:
        good.pop("km")
    cost = _km_block([_restricted(r, "cost") for r in recs], cap)
    cost.pop("km")
    within = [v is not None and v <= r["budget"] for r in recs for v in r["first_exposure"]]
    curves = [c for r in recs for c in r["curves"]]
    return {
        "trials": n,
        "source_seeds": len(recs),
        "errors": sorted({r["error"] for r in recs if r["error"]}),
        "failure_rate": sum(v is None for v in fe) / n if n else None,
        "success_rate": sum(within) / n if n else None,
        "seed_share": seed_share(fe_seeds, cap),
        "first_exposure": fe_block,
        "survival": {k: km[k] for k in ("times", "survival", "low", "high")},
        "good_path": good,
        "settled_quality": settled_quality(recs),
        "convergence": dict(conv, converged=conv["events"]),
        "cost": cost,
        "curve_mean": [float(v) for v in np.mean(curves, axis=0)] if curves else [],
    }


def settled_quality(recs: list[dict]) -> dict:
    """How good the settled paths were: the median and worst (largest) ``settled_ratio`` (the first
    settled greedy path over the shortest) over the trials that settled, how many did, and how
    many trials' paths were good at the end (``good_path_steps`` not None)."""
    ratios = [v for r in recs for v in r.get("settled_ratio") or [] if v is not None]
    clocked = [r for r in recs if measured(r, "good_path")]
    trials = sum(len(r["first_exposure"]) for r in clocked)
    return {"median": float(np.median(ratios)) if ratios else None, "worst": max(ratios) if ratios else None,
            "settled": len(ratios), "good_at_end": sum(v is not None for r in clocked for v in r["good_path_steps"]),
            "trials": trials}


def _pairs(method: list[dict], base: list[dict], metric: str) -> tuple[list[list[float]], int, int]:
    """Per source seed, the trial-paired log factors log(baseline / method) of ``metric`` (ties
    left out), the number of ties (both censored) and of bounds (one censored). A pair whose
    either record did not measure ``metric`` (:func:`measured`) is left out."""
    by_seed = {b["source_seed"]: b for b in base}
    seeds, ties, bounds = [], 0, 0
    for m in method:
        b = by_seed.get(m["source_seed"])
        if b is None or not (measured(m, metric) and measured(b, metric)):
            continue
        logs = []
        cap = m["cap"]
        for mv, bv in zip(_restricted(m, metric), _restricted(b, metric)):
            if mv is None and bv is None:
                ties += 1
                continue
            bounds += (mv is None) or (bv is None)
            logs.append(math.log(max(cap if bv is None else bv, 1.0) / max(cap if mv is None else mv, 1.0)))
        seeds.append(logs)
    return seeds, ties, bounds


def compare(cases: list[tuple[list[dict], list[dict]]], metric: str, refine: bool = True) -> dict:
    """(method records, baseline records) per case: the paired factor of ``metric`` over cases,
    source seeds and trials, with its hierarchical bootstrap-t interval, p-value, detectable
    factors, worst and best seed (geometric mean of its trials), ties and bounds. ``refine``: a
    small p from more resamples (``hierarchical.FINE_RESAMPLES``), for a verdict Holm corrects."""
    nested, ties, bounds = [], 0, 0
    for method, base in cases:
        seeds, t, b = _pairs(method, base, metric)
        nested.append(seeds)
        ties += t
        bounds += b
    out = hierarchical.as_factor(hierarchical.bootstrap_t(nested, refine=refine))
    seed_factors = [math.exp(float(np.mean(s))) for c in nested for s in c if s]
    out.update(metric=metric, ties=ties, bounds=bounds, pairs=sum(len(s) for c in nested for s in c) + ties,
               worst=min(seed_factors) if seed_factors else None, best=max(seed_factors) if seed_factors else None)
    if metric == "cost":
        f, ci = out["factor"], out["ci95"]
        out["transfer_ratio"] = None if f is None else 1.0 - 1.0 / f
        out["transfer_ratio_ci95"] = None if ci is None else [1.0 - 1.0 / ci[0], 1.0 - 1.0 / ci[1]]
    return out


def paired(method: list[dict], base: list[dict]) -> dict:
    """The method against one baseline on one case, every metric (``METRICS``, ``DESCRIBED``)."""
    return {k: compare([(method, base)], k, refine=False) for k in (*METRICS, *DESCRIBED)}


def _pooled(cases: list[tuple[list[dict], list[dict]]], base: str, refine: bool = True) -> dict:
    """Every metric over ``cases``, the described ones without a verdict, and the settled quality
    of the method's and the baseline's trials beside them."""
    out = dict({k: compare(cases, k, refine) for k in METRICS}, baseline=base)
    for k in DESCRIBED:
        out[k] = dict(compare(cases, k, refine=False), p_holm=None, verdicts=0)
    out["settled"] = {"method": settled_quality([r for m, _ in cases for r in m]),
                      "baseline": settled_quality([r for _, b in cases for r in b])}
    return out


def summarize(records: list[dict]) -> dict:
    """``{section: {"cases": [{label, methods: {name: stats}}], "pooled": {name: {baseline: {metric:
    factor}}}}}``.

    A method's stats hold ``against``: per baseline it names (the no-transfer one first), the
    paired comparison on one case. ``pooled`` is the comparison over every case of the section
    (cases, then seeds, then trials). Every pooled comparison's p-value is Holm-adjusted across
    the run (``p_holm``). A section where robot 1 did not converge on some (case, source seed)
    pairs also has ``with_trajectory``: the same comparisons over the other pairs alone, a
    stratum described beside the claims (:func:`with_trajectory`)."""
    by_cell: dict = defaultdict(list)
    for r in records:
        by_cell[(r["section"], r["case"], r["method"])].append(r)
    for recs in by_cell.values():
        recs.sort(key=lambda r: r["source_seed"])
    out: dict = {}
    for r in records:
        sec = out.setdefault(r["section"], {"cases": {}, "pooled": {}})
        sec["cases"].setdefault(r["case"], {"label": r["label"], "optimal_per_seed": [], "methods": {}})
    for (section, case, method), recs in by_cell.items():
        entry = cell_stats(recs)
        entry["baselines"] = recs[0]["baselines"]
        entry["against"] = {b: paired(recs, by_cell[(section, case, b)])
                            for b in entry["baselines"] if (section, case, b) in by_cell}
        out[section]["cases"][case]["methods"][method] = entry
        out[section]["cases"][case]["optimal_per_seed"] = [r["optimal"] for r in recs]
        out[section]["cases"][case]["source_failures"] = sum(r["source_failure"] is not None for r in recs)
    verdicts: list[dict] = []
    for section, sec in out.items():
        names = list(dict.fromkeys(r["method"] for r in records if r["section"] == section))
        for name in names:
            pooled: dict = {}
            for base, cases in _pairings(section, name, by_cell):
                pooled[base] = _pooled(cases, base)
                verdicts += [pooled[base][k] for k in METRICS]
            if pooled:
                sec["pooled"][name] = pooled
        sec["cases"] = [sec["cases"][k] for k in sorted(sec["cases"])]
        for case in sec["cases"]:
            case["methods"] = {n: case["methods"][n] for n in names if n in case["methods"]}
    for section, sec in out.items():
        if any(case["source_failures"] for case in sec["cases"]):
            sec["with_trajectory"] = with_trajectory(section, by_cell)
    tested = [v for v in verdicts if v["p"] is not None]
    for v, adj in zip(tested, multiplicity.holm([v["p"] for v in tested])):
        v["p_holm"] = adj
        v["verdicts"] = len(tested)
    for v in verdicts:
        v.setdefault("p_holm", None)
        v.setdefault("verdicts", len(tested))
    return out


def _pairings(section: str, name: str, by_cell: dict,
              keep: Callable[[list[dict]], list[dict]] | None = None) -> Iterator[tuple[str, list]]:
    """(baseline, [(method's records, baseline's records) per case]) for every baseline that
    ``name``'s records name in ``section``, over the cases both ran; ``keep`` filters a case's
    records (a case left empty on either side is left out)."""
    case_ids = sorted({c for (s, c, _) in by_cell if s == section})
    bases = dict.fromkeys(b for (s, _, m), recs in by_cell.items() if s == section and m == name
                          for b in recs[0]["baselines"])
    for base in bases:
        cases = [(by_cell[(section, c, name)], by_cell[(section, c, base)]) for c in case_ids
                 if (section, c, name) in by_cell and (section, c, base) in by_cell]
        if keep is not None:
            cases = [(a, b) for a, b in ((keep(m), keep(bl)) for m, bl in cases) if a and b]
        if cases:
            yield base, cases


def with_trajectory(section: str, by_cell: dict) -> dict:
    """The stratum of a section's (case, source seed) pairs on which robot 1 converged and
    handed a trajectory over: ``{"pairs", "of", "pooled": {name: {baseline: {metric: factor}}}}``
    (and ``told_nothing`` when the records ran their baselines there).
    On the other pairs every method that needs a trajectory learned as its baseline told nothing
    (records written before that rule: counted as failed); the claims keep them, and this says
    what the methods did where there was something to transfer. It is a
    description: its comparisons carry no verdict and do not enter Holm's correction."""
    def kept(recs: list[dict]) -> list[dict]:
        return [r for r in recs if r["source_failure"] is None]

    names = list(dict.fromkeys(m for (s, _, m) in by_cell if s == section))
    pooled: dict = {}
    for name in names:
        for base, cases in _pairings(section, name, by_cell, kept):
            block = _pooled(cases, base, refine=False)
            for k in METRICS:
                block[k] = dict(block[k], p_holm=None, verdicts=0)
            pooled.setdefault(name, {})[base] = block
    pairs = {(c, r["source_seed"]): r["source_failure"] is None for (s, c, _), recs in by_cell.items()
             if s == section for r in recs}
    told = any(r.get("told_nothing") for (s, _, _), recs in by_cell.items() if s == section for r in recs)
    return {"pairs": sum(pairs.values()), "of": len(pairs), "pooled": pooled, **({"told_nothing": True} if told else {})}
