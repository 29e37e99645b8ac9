"""A benchmark's results file made into its report again: the statistics recomputed from the
file's records by this build, checked byte for byte against the file's own, then report.md,
results.json and the figures written into a new directory.

So a report kept in docs/ can be checked by anyone with the repository: every number in it
comes back from the per-trial records beside it. The file may be gzip-compressed
(``results.json.gz``), which is how docs/ keeps the large ones.
"""

from __future__ import annotations

import json
import zlib
from pathlib import Path

from armtransfer.checks import MAX_COUNT
from armtransfer.commands.benchmark import results_bytes, write_report_files
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import suite_files, suites
from armtransfer.experiments.reports import benchmark_report
from armtransfer.experiments.stats import benchmark_stats
from armtransfer.io import parse_json_bytes, read_input, staged_directory

MAX_UNPACKED_BYTES = 1 << 30
"""The largest results file read once decompressed (1 GiB); a standard suite's is tens of MiB."""

FIELDS = (("suite", dict), ("seed", int), ("methods", list), ("not_in_registry", list), ("records", list),
          ("summary", dict))


def _unpack(path: Path, raw: bytes) -> bytes:
    if not path.name.endswith(".gz"):
        return raw
    try:
        out = zlib.decompressobj(wbits=31).decompress(raw, MAX_UNPACKED_BYTES)
    except (zlib.error, EOFError):
        raise InvalidParameterError(f"results file {str(path)!r} is not valid gzip") from None
    if len(out) >= MAX_UNPACKED_BYTES:
        raise InvalidParameterError(f"results file {str(path)!r} unpacks to over {MAX_UNPACKED_BYTES >> 20} MiB")
    return out


def read_results(path: Path) -> tuple[dict, bytes]:
    """(the results, their uncompressed bytes); anything else is a one-line error."""
    raw = _unpack(path, read_input(path, "results file", InvalidParameterError, limit=MAX_UNPACKED_BYTES))
    try:
        data = parse_json_bytes(raw)
    except ValueError as err:
        raise InvalidParameterError(f"results file {str(path)!r} {err}") from None
    if not isinstance(data, dict) or "records" not in data:
        raise InvalidParameterError(f"{str(path)!r} is not a benchmark's results file (no 'records')")
    for name, kind in FIELDS:
        if not isinstance(data.get(name), kind) or isinstance(data.get(name), bool):
            raise InvalidParameterError(f"results file {str(path)!r}: field {name!r} must be a {kind.__name__}")
    seed = data.get("seed")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_COUNT:
        raise InvalidParameterError(f"results file {str(path)!r}: field 'seed' is {str(seed)[:40]}, which no benchmark "
                                    f"takes (--seed is an integer 0..{MAX_COUNT})")
    return data, raw


def report_from_file(path: Path, out: str | None) -> int:
    """``armtransfer summarize FILE --out DIR``."""
    if out is None:
        raise InvalidParameterError("a results file needs --out DIR: an absent or empty directory for its report")
    data, raw = read_results(path)
    name, version = data["suite"].get("name"), data["suite"].get("version")
    builtin = suites.SUITES.get(name) if isinstance(name, str) else None
    try:  # a built-in suite as it ships, or any suite file's (its definition is in the results)
        suite = suite_files.from_dict(data["suite"], f"results file {str(path)!r}")
    except InvalidParameterError:
        suite = None
    if suite is None or json.loads(json.dumps(suite.to_dict())) != data["suite"] or (
            builtin is not None and not suites.is_builtin(suite)):
        have = f"version {builtin.version}" if builtin is not None else "no such suite"
        raise InvalidParameterError(f"{str(path)!r} holds suite {name!r} version {version}; this build has {have}, "
                                    "so it cannot recompute it (use the build that wrote it)")
    failures = data.get("failed")
    try:
        summary = benchmark_stats.summarize(data["records"])
        again = results_bytes(suite, data["seed"], data["methods"], data["not_in_registry"], data["records"], summary,
                              failures)
    except (KeyError, TypeError, ValueError, IndexError) as err:
        raise InvalidParameterError(f"results file {str(path)!r} has a malformed record ({type(err).__name__}: "
                                    f"{err})") from None
    if again != raw:
        raise InvalidParameterError(f"{str(path)!r}: the statistics this build recomputes from its "
                                    f"{len(data['records'])} records differ from the file's (another build wrote it)")
    with staged_directory(out) as tmp:
        write_report_files(tmp, suite, data["seed"], data["methods"], data["not_in_registry"], summary, again,
                           failures=failures, warnings=benchmark_report.record_warnings(data["records"]))
    print(f"recomputed the statistics of {len(data['records'])} records: the same bytes as {str(path)!r}; "
          f"wrote {str(Path(out) / 'report.md')!r}")
    return 0
