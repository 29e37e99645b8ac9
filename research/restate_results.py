"""A kept benchmark results file restated with this build's statistics, its records unchanged.

    python research/restate_results.py docs/benchmark-standard/results.json.gz --out /tmp/standard

``armtransfer summarize FILE`` refuses a file whose statistics another build computed; when the
statistics change (not the trials), this recomputes them from the file's records and writes
report.md, results.json (gzip-compressed when the input was) and the figures into ``--out``, so
the copy kept in docs/ can be replaced. Records written before a measure existed (the
good-path clock) show it as not measured; only a new run of the suite measures it.
"""

from __future__ import annotations

import gzip
from pathlib import Path

from armtransfer import script
from armtransfer.commands.benchmark import results_bytes, write_report_files
from armtransfer.commands.benchmark_file import read_results
from armtransfer.experiments import suites
from armtransfer.experiments.stats import benchmark_stats


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("results", type=Path)
    p.add_argument("--out", type=Path, required=True)
    args = p.parse_args(argv)
    data, _ = read_results(args.results)
    suite = suites.get(data["suite"]["name"])
    summary = benchmark_stats.summarize(data["records"])
    again = results_bytes(suite, data["seed"], data["methods"], data["not_in_registry"], data["records"], summary)
    args.out.mkdir(parents=True, exist_ok=True)
    write_report_files(args.out, suite, data["seed"], data["methods"], data["not_in_registry"], summary, again)
    if args.results.name.endswith(".gz"):
        (args.out / "results.json.gz").write_bytes(gzip.compress(again, mtime=0))
        (args.out / "results.json").unlink()
    print(f"restated {len(data['records'])} records into {str(args.out)!r}")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
