"""armtransfer summarize: per-group tables (mean, 95% CI, improvement) and plots of a sweep; a
benchmark store's report, written again from its runs."""

from __future__ import annotations

import argparse
from pathlib import Path

from armtransfer.io import write_json_atomic, write_text_atomic
from armtransfer.experiments.store import ResultStore, is_benchmark
from armtransfer.experiments.reports.summary import plot, summarize, summary_markdown

HELP = ("Turn a result store into tables and a plot: summary.md, summary.json and summary.png (a benchmark's "
        "store: its report again).")
EXAMPLE = "armtransfer summarize runs/quick"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", metavar="DIR", help="a directory written by `armtransfer sweep`, `matrix` or `benchmark`")


def run(args: argparse.Namespace) -> int:
    store = ResultStore.open_existing(args.dir)
    if is_benchmark(store.meta["spec"]):
        from armtransfer.commands.benchmark import summarize as benchmark_report

        return benchmark_report(store)
    records = store.records()
    rows = summarize(records)
    failures = store.failures()
    text = summary_markdown(rows) if rows else "(no finished runs yet)"
    out = Path(args.dir)
    write_json_atomic(out / "summary.json", {"sweep": store.meta["name"], "runs": len(records),
                                            "failed": len(failures), "rows": rows})
    if rows:
        plot(rows, out / "summary.png")
    write_text_atomic(out / "summary.md", f"# Sweep {store.meta['name']!r}\n\n{len(records)} finished runs, "
                      f"{len(failures)} failed.\n\n{text}\n")
    print(text)
    from armtransfer.experiments.matrix import is_matrix

    if is_matrix(store.meta["spec"]):
        from armtransfer.commands.matrix import write_summary

        print(write_summary(store, out))
    if failures:
        print(f"{len(failures)} runs failed; see {out / 'failed'}")
    return 0
