"""Time one source seed of a benchmark suite's cases and extrapolate to the whole suite.

    MUJOCO_GL=egl python benchmarks/bench_suite.py --suite standard [--case embodiment:0 ...]

Runs every case (or those named SECTION:INDEX, or whole SECTIONs) with one source seed and
every method the suite runs, and prints per case the wall and CPU seconds (CPU: this
process's, all its threads) and the whole suite's CPU seconds extrapolated: each measured
case times its section's source seeds. On a busy machine the wall time says little; the CPU
time bounds what a quiet machine needs (2 cores running the trials in pairs need about half
of it to all of it).
"""

from __future__ import annotations

import json
import time
from dataclasses import replace

from armtransfer import script
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import benchmark, suites


def main() -> int:
    return script.run(_main)


def _main() -> int:
    p = script.parser(__doc__)
    p.add_argument("--suite", default="standard", help="the suite (default standard)")
    p.add_argument("--case", nargs="*", default=[], metavar="SECTION[:INDEX]",
                   help="only these cases or sections (default: every case)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = p.parse_args()
    suite = suites.get(args.suite)
    known = {s.name for s in suite.sections} | {f"{s.name}:{i}" for s in suite.sections for i in range(len(s.cases))}
    bad = [c for c in args.case if c not in known]
    if bad:
        raise InvalidParameterError(f"unknown case {bad[0]!r}; valid: {', '.join(sorted(known))}")
    total = 0.0
    measured = 0
    for section in suite.sections:
        for index, case in enumerate(section.cases):
            key = f"{section.name}:{index}"
            if args.case and key not in args.case and section.name not in args.case:
                continue
            piece = suites.Suite("piece", suite.version, suite.held_out, "",
                                 (replace(section, cases=(case,), source_seeds=1),))
            t0, c0 = time.perf_counter(), time.process_time()
            records, timings = benchmark.run_suite(piece, args.seed)
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            total += cpu * section.source_seeds
            measured += 1
            print(json.dumps({"case": key, "label": case.label, "wall_s": round(wall, 1), "cpu_s": round(cpu, 1),
                              "source_wall_s": round(timings["runs"][0]["source_seconds"], 1),
                              "method_wall_s": {k: round(v, 1) for k, v in timings["runs"][0]["methods"].items()}}),
                  flush=True)
    cases = sum(len(s.cases) for s in suite.sections)
    print(f"{measured} of {cases} cases measured; their CPU seconds x source seeds: {total:,.0f} s")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
