"""armtransfer benchmark: run a fixed, versioned suite and write one report.

The report directory holds report.md, results.json (one record per case, source seed and
method, then the statistics; the same seed gives the same bytes), timings.json (wall
times, apart so results.json stays deterministic) and the figures. It is written into a
hidden temporary directory beside ``--out`` and renamed into place only when complete.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import time
from pathlib import Path

from armtransfer.commands import common
from armtransfer.experiments import benchmark, suites
from armtransfer.experiments.reports import benchmark_report
from armtransfer.experiments.stats import benchmark_stats
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic

HELP = "Compare every method with the baselines that share its learner on a fixed suite, over many source seeds."
EXAMPLE = "armtransfer benchmark --suite fast --out runs/bench-fast"


def add_arguments(p: argparse.ArgumentParser) -> None:
    listing = "; ".join(f"{s.name}{' (held out)' if s.held_out else ''}: {s.description}" for s in suites.SUITES.values())
    p.add_argument("--suite", required=True, metavar="NAME", help=f"the suite to run. {listing}")
    p.add_argument("--out", default=None,
                   help="output directory, absent or empty; written whole or not at all "
                        "(default runs/benchmark-<suite>-<timestamp>)")
    p.add_argument("--seed", type=common.non_negative_int, default=0, help="random seed, >= 0 (default 0)")
    common.add_preset_argument(p)


def results_bytes(suite: suites.Suite, seed: int, ran: list[str], missing: list[str], records: list[dict],
                  summary: dict) -> bytes:
    """results.json's bytes: the same for the same suite, seed and build."""
    data = {"suite": suite.to_dict(), "seed": seed, "methods": ran, "not_in_registry": missing,
            "baselines": {m: list(benchmark.baselines_of(m)) for m in ran}, "records": records, "summary": summary}
    return (json.dumps(data, indent=1, sort_keys=False) + "\n").encode()


def run(args: argparse.Namespace) -> int:
    suite = suites.get(args.suite)
    out = Path(args.out) if args.out else Path("runs") / _dt.datetime.now().strftime(
        f"benchmark-{suite.name}-%Y%m%d-%H%M%S")
    check_output_dir(out)  # before the long run, not after
    ran, missing = benchmark.methods_to_run()
    t0 = time.perf_counter()
    with common.progress_bar(benchmark.plan_size(suite), f"benchmark {suite.name}") as bar:
        records, timings = benchmark.run_suite(suite, args.seed, tick=bar.update, preset=args.preset)
    summary = benchmark_stats.summarize(records)
    with staged_directory(out) as tmp:  # out appears only complete
        (tmp / "results.json").write_bytes(results_bytes(suite, args.seed, ran, missing, records, summary))
        write_json_atomic(tmp / "timings.json", timings)
        benchmark_report.write_figures(summary, suite, tmp)
        write_text_atomic(tmp / "report.md", benchmark_report.report_markdown(suite, args.seed, summary, ran, missing))
    print(f"wrote {out / 'report.md'} ({time.perf_counter() - t0:.0f} s)")
    for section in suite.sections:
        for name, against in summary[section.name]["pooled"].items():
            for ab in against.values():
                print(benchmark_report.sentence(name, ab, section.name))
    return 0
