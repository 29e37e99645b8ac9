"""docs/continuous.md's claims re-measured on source seeds no one used to write them, whole cost first.

    python research/continuous_heldout.py --out runs/heldout                  # every pair and task below
    python research/continuous_heldout.py --fast --out /tmp/heldout           # a smoke run (seconds)
    python research/continuous_heldout.py --report DIR [DIR ...]              # one table from earlier runs

For each pair (source robot -> continuous target arm) and Table I task, source seeds
``--first-seed`` .. ``--first-seed + --seeds - 1`` (default 5000-5009: seeds no table in the
docs was measured on): source seed k hands over the source's learned trajectory and the target
runs one trial of ``none`` and one of ``pseudo`` with ``trial_rng(k, 0)``, exactly as
``benchmarks/bench_continuous.py`` does (its ``pairs``, the same ``runs.run_method`` and
``source_trajectory`` calls). Caps: the docs' for each pair (``CAPS``) unless ``--cap`` is given.

Reported per case, paired by source seed, in the order every claim states them:

  whole cost      steps until the greedy path settled (censored at the cap when it did not):
                  the factor none / pseudo, a geometric mean over seeds with the benchmark's
                  hierarchical bootstrap-t 95% interval (``benchmark_stats.compare``: a pair
                  censored in both is a tie, counted and left out; a pair censored in one is a
                  bound, counted), the worst seed's factor, converged k/n per method and the
                  Kaplan-Meier median of each
  first exposure  the same factor, interval and worst seed; failures per method
  transfer ratio  the share of the no-transfer cost of the first ``learning_metrics.HORIZON``
                  episodes that pseudo saves (``benchmark_stats``' cost metric; censored when
                  the cap came first)
  improvement     pseudo's paired improvement in mean first exposure (``metrics.paired_improvement``),
                  the figure docs/continuous.md gave, for comparison

Writes ``DIR/heldout.json`` after every case (the cases finished so far, each with its trials)
and ``DIR/heldout.md`` at the end.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from armtransfer import script
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments.stats import benchmark_stats, learning_metrics, metrics, survival
from armtransfer.io import check_output_dir, write_json_atomic, write_text_atomic
from armtransfer.learning.config import LearnerConfig
from armtransfer.tasks.catalog import TABLE_I

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    """``benchmarks/bench_continuous.py``: its pairs, arms and machine line (imported when a run
    starts, so the statistics below import without MuJoCo)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_continuous

    return bench_continuous

METHODS = ("none", "pseudo")
PAIRS = ("ur5e_like:cartesian->planar2", "planar2:joint->planar3")
"""The pairs of the docs' claims (``bench.PAIRS`` names)."""
CAPS = {"ur5e_like:cartesian->planar2": (1_000_000, 2000)}
"""(steps per trial, episodes) per pair as the docs measured it ("planar2 with room to converge");
any other pair: the docs' main table's ``DEFAULT_CAP``."""
DEFAULT_CAP = (150_000, 300)
EPISODE_CAP = 50_000
FIRST_SEED = 5000


def trial_record(trial) -> dict:
    """What the statistics need of one trial (None: censored at the cap)."""
    return {"first_exposure": trial.exploration_steps,
            "convergence": int(trial.total_steps) if trial.converged and trial.total_steps is not None else None,
            "converged": bool(trial.converged), "episodes": int(trial.episodes),
            "curve": [float(v) for v in learning_metrics.curve(trial.episode_steps, trial.greedy_steps)]}


def _records(trials: dict[int, dict], cap: int) -> list[dict]:
    """One method's trials (source seed -> trial record) as ``benchmark_stats`` records."""
    return [{"source_seed": s, "cap": cap, "first_exposure": [t["first_exposure"]],
             "convergence_steps": [t["convergence"]], "converged": [t["converged"]],
             "episodes": [t["episodes"]], "curves": [t["curve"]]} for s, t in sorted(trials.items())]


def _factor(c: dict) -> dict:
    return {k: c[k] for k in ("factor", "ci95", "p", "worst", "best", "ties", "bounds", "pairs", "seeds")} | (
        {k: c[k] for k in ("transfer_ratio", "transfer_ratio_ci95")} if "transfer_ratio" in c else {})


def case_stats(none: dict[int, dict], pseudo: dict[int, dict], cap: int) -> dict:
    """The paired statistics of one case: ``none`` and ``pseudo`` map each source seed to its
    trial record (``trial_record``; the same seeds in both)."""
    if sorted(none) != sorted(pseudo):
        raise ValueError("none and pseudo must have trials of the same source seeds")
    base, meth = _records(none, cap), _records(pseudo, cap)
    against = benchmark_stats.paired(meth, base)  # factor = none / pseudo: above 1, pseudo is cheaper
    seeds = sorted(none)
    per_method = {}
    for name, trials in (("none", none), ("pseudo", pseudo)):
        conv = [trials[s]["convergence"] for s in seeds]
        first = [trials[s]["first_exposure"] for s in seeds]
        per_method[name] = {
            "n": len(seeds), "converged": sum(v is not None for v in conv),
            "convergence_km_median": survival.kaplan_meier(conv, cap)["median"],
            "failed": sum(v is None for v in first),
            "first_km_median": survival.kaplan_meier(first, cap)["median"]}
    imp = metrics.paired_improvement([none[s]["first_exposure"] for s in seeds],
                                     [pseudo[s]["first_exposure"] for s in seeds], cap, paired=True)
    return {"seeds": seeds, "methods": per_method,
            "convergence": _factor(against["convergence"]), "first_exposure": _factor(against["first_exposure"]),
            "cost": _factor(against["cost"]),
            "improvement": {k: imp[k] for k in ("percent", "ci95", "censored")}}


def verdict(f: dict) -> str:
    """"pseudo cheaper" / "pseudo dearer" when the factor's interval excludes 1, else "no reliable
    difference" (or "no pairs" when every pair was a tie)."""
    if f["factor"] is None:
        return "no pairs (all ties)"
    if f["ci95"] is None:
        return "no interval"
    lo, hi = f["ci95"]
    return "pseudo cheaper" if lo > 1 else "pseudo dearer" if hi < 1 else "no reliable difference"


def run_case(source_spec: str, arm, task: int, seeds: list[int], config: LearnerConfig, fast: bool) -> dict:
    from armtransfer.experiments import continuous as runs
    from armtransfer.experiments.experiment import source_trajectory
    from armtransfer.tasks.arms import robot as tabular_robot

    source = tabular_robot(source_spec)
    start, goal = TABLE_I[task].cells(arm.layout)
    arm.place(start)
    trials: dict[str, dict[int, dict]] = {m: {} for m in METHODS}
    t0 = time.perf_counter()
    for k in seeds:
        traj = source_trajectory("optimal" if fast else "learned", source, start, goal, LearnerConfig(), k)
        for m in METHODS:
            res = runs.run_method(m, arm, goal, [traj], 1, k, config, approx=runs.Approximation())
            trials[m][k] = trial_record(res.trials[0])
    return {"trials": {m: {str(k): v for k, v in t.items()} for m, t in trials.items()},
            "stats": case_stats(trials["none"], trials["pseudo"], config.max_total_steps),
            "seconds": time.perf_counter() - t0}


# ----------------------------------------------------------------------------- report


def _x(v) -> str:
    return "n/a" if v is None else f"{v:.2f}"


def _fx(f: dict) -> str:
    if f["factor"] is None:
        return f"all {f['ties']} pairs tied"
    ci = "" if f["ci95"] is None else f" [{f['ci95'][0]:.2f}, {f['ci95'][1]:.2f}]"
    extra = [f"{f['ties']} tied"] if f["ties"] else []
    extra += [f"{f['bounds']} bound{'s' if f['bounds'] > 1 else ''}"] if f["bounds"] else []
    return f"{f['factor']:.2f}{ci}" + (f" ({', '.join(extra)})" if extra else "")


def _pc(v: float) -> str:
    """A percentage's interval end: whole numbers, one decimal below 1 in size (so -0.2 is not "-0")."""
    return f"{v:.1f}" if abs(v) < 1 else f"{v:.0f}"


def _n(v) -> str:
    return "> cap" if v is None else f"{v:,.0f}"


def markdown(cases: list[dict]) -> str:
    lines = ["Factors are none / pseudo (above 1: pseudo took fewer steps), geometric means over source seeds "
             "paired by seed, with the hierarchical bootstrap-t 95% interval; worst: the smallest seed's factor. "
             "A pair censored in both trials is a tie (left out); a pair censored in one is a bound (kept, at the "
             "cap). Converged and failed: k of n per method, none / pseudo; KM: Kaplan-Meier medians, none / pseudo.",
             "",
             "| pair | task | cap | whole cost: convergence factor | worst | converged | KM median | "
             "first exposure factor | worst | failed | transfer ratio | improvement (docs' figure) | verdict (whole cost) |",
             "|---|---|---:|---|---:|---|---|---|---:|---|---|---|---|"]
    for c in cases:
        s = c["stats"]
        cv, fe, cost, mn, mp = s["convergence"], s["first_exposure"], s["cost"], s["methods"]["none"], s["methods"]["pseudo"]
        tr = ("censored" if cost["transfer_ratio"] is None else f"{100 * cost['transfer_ratio']:+.0f}%"
              + ("" if cost["transfer_ratio_ci95"] is None else
                 f" [{100 * cost['transfer_ratio_ci95'][0]:+.0f}, {100 * cost['transfer_ratio_ci95'][1]:+.0f}]"))
        imp = s["improvement"]
        ip = "n/a" if imp["percent"] is None else f"{imp['percent']:+.0f}%" + (
            "" if imp["ci95"] is None else f" [{_pc(imp['ci95'][0])}, {_pc(imp['ci95'][1])}]")
        lines.append(
            f"| {c['pair']} | {c['task']} | {c['cap']:,} | {_fx(cv)} | {_x(cv['worst'])} | "
            f"{mn['converged']}/{mn['n']} / {mp['converged']}/{mp['n']} | "
            f"{_n(mn['convergence_km_median'])} / {_n(mp['convergence_km_median'])} | {_fx(fe)} | {_x(fe['worst'])} | "
            f"{mn['failed']}/{mn['n']} / {mp['failed']}/{mp['n']} | {tr} | {ip} | {verdict(cv)} |")
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------- command


def _config(pair: str, args) -> LearnerConfig:
    if args.fast:
        return LearnerConfig(max_episodes=5, max_total_steps=20_000, max_episode_steps=5_000, patience=2)
    cap, episodes = CAPS.get(pair, DEFAULT_CAP)
    return LearnerConfig(max_episodes=args.episodes or episodes, max_total_steps=args.cap or cap,
                         max_episode_steps=EPISODE_CAP, patience=LearnerConfig().patience)


def _run(args) -> int:
    if args.report:
        cases = []
        for d in args.report:
            path = Path(d) / "heldout.json"
            if not path.is_file():
                raise InvalidParameterError(f"--report {d!r} holds no heldout.json")
            cases += json.loads(path.read_text())["cases"]
        order = {p: i for i, p in enumerate(PAIRS)}
        cases.sort(key=lambda c: (order.get(c["pair"], len(order)), c["pair"], c["cap"], c["task"]))
        print(markdown(cases), end="")
        return 0
    if args.out is None:
        raise InvalidParameterError("--out is required unless --report is given")
    bench = _bench()
    bad = [t for t in args.tasks if t not in TABLE_I] + [p for p in args.pairs if p not in bench.PAIRS]
    if bad:
        raise InvalidParameterError(f"unknown task or pair {bad[0]!r}; valid tasks: {', '.join(map(str, TABLE_I))}; "
                                    f"valid pairs: {', '.join(bench.PAIRS)}")
    if args.seeds < 2 or args.first_seed < 0:
        raise InvalidParameterError("--seeds must be at least 2 (an interval over seeds) and --first-seed at least 0")
    if (args.cap is not None and args.cap < 1) or (args.episodes is not None and args.episodes < 1):
        raise InvalidParameterError("--cap and --episodes must be positive")
    check_output_dir(args.out)
    chosen, tasks = list(dict.fromkeys(args.pairs)), list(dict.fromkeys(args.tasks))
    if args.fast:
        chosen, tasks = chosen[:1], tasks[:1]
    seeds = list(range(args.first_seed, args.first_seed + args.seeds))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    from armtransfer.experiments.continuous import Approximation

    result: dict = {"command": " ".join(["python", "research/continuous_heldout.py", *sys.argv[1:]]),
                    "machine": bench.machine(), "started": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
                    "seeds": seeds, "approximation": Approximation().to_json(), "cases": []}
    with tempfile.TemporaryDirectory() as tmp:
        for pair in chosen:
            config = _config(pair, args)
            [(source_spec, target_name, arm)] = bench.pairs(Path(tmp), args.fast, [pair])
            for task in tasks:
                case = run_case(source_spec, arm, task, seeds, config, args.fast)
                case.update(pair=pair, target=target_name, task=task, cap=config.max_total_steps,
                            config=config.to_dict(), load=list(os.getloadavg()),
                            ended=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
                result["cases"].append(case)
                write_json_atomic(out / "heldout.json", result)
                print(f"  {pair}, task {task}: {case['seconds']:.0f} s", file=sys.stderr, flush=True)
    text = markdown(result["cases"])
    write_text_atomic(out / "heldout.md", f"Command: `{result['command']}`; {result['machine']}; "
                                          f"{result['started']}.\n\n" + text)
    print(text, end="")
    return 0


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("--out", help="an absent or empty directory for heldout.json and heldout.md")
    p.add_argument("--report", nargs="+", metavar="DIR", help="print one table from earlier runs' directories")
    p.add_argument("--fast", action="store_true",
                   help="a smoke run: the first pair and task, tiny caps, the source's shortest path handed over")
    p.add_argument("--pairs", nargs="+", default=list(PAIRS), help=f"pairs (default: {', '.join(PAIRS)})")
    p.add_argument("--tasks", type=int, nargs="+", default=list(TABLE_I), help="Table I tasks (default: all)")
    p.add_argument("--first-seed", type=int, default=FIRST_SEED)
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--cap", type=int, default=None, help="steps per trial (default: the docs' cap of the pair)")
    p.add_argument("--episodes", type=int, default=None, help="episodes per trial (default: the docs' of the pair)")
    args = p.parse_args(argv)
    if args.fast:
        args.seeds = min(args.seeds, 2)
    return script.run(_run, args)


if __name__ == "__main__":
    script.exit_with(main)
