"""armtransfer summarize: per-group tables (mean, 95% CI, improvement) and plots of a sweep; a
benchmark store's report, written again from its runs; or a benchmark's results file
(``results.json``, or ``results.json.gz`` as docs/ keeps it), its statistics recomputed from its
records, checked against the file's, and its report written into ``--out``."""

from __future__ import annotations

import argparse
from pathlib import Path

from armtransfer.commands.benchmark import summarize as benchmark_report
from armtransfer.commands.benchmark_file import report_from_file
from armtransfer.commands.matrix import write_summary
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments.matrix import is_matrix
from armtransfer.experiments.reports.summary import plot, summarize, summary_markdown
from armtransfer.experiments.store import ResultStore, is_benchmark
from armtransfer.io import write_json_atomic, write_text_atomic

HELP = ("Turn a result store into tables and a plot: summary.md, summary.json and summary.png (a benchmark's "
        "store: its report again; a benchmark's results.json[.gz]: its statistics recomputed from its records).")
EXAMPLE = "armtransfer summarize runs/quick"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dir", metavar="DIR", help="a directory written by `armtransfer sweep`, `matrix` or `benchmark`, "
                                              "or a benchmark's results.json or results.json.gz")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="with a results file: an absent or empty directory for the report made again from it")


def run(args: argparse.Namespace) -> int:
    if Path(args.dir).is_file():
        return report_from_file(Path(args.dir), args.out)
    if not Path(args.dir).exists():
        raise InvalidParameterError(f"{args.dir!r} does not exist (expected a result store or a results file)")
    if args.out is not None:
        raise InvalidParameterError("--out is for a results file; a store's summary is written into the store")
    store = ResultStore.open_existing(args.dir)
    with store.reading():  # a store a sweep or benchmark is writing is refused in one line
        return _summarize(store, args)


def _summarize(store: ResultStore, args: argparse.Namespace) -> int:
    if is_benchmark(store.meta["spec"]):
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
    if is_matrix(store.meta["spec"]):
        print(write_summary(store, out))
    if failures:
        print(f"{len(failures)} runs failed; see {out / 'failed'}")
    return 0
