"""Benchmark speed-up from 1 to 2 local workers (BENCHMARKS.md).

Each repeat runs `armtransfer benchmark --suite SUITE` into a fresh store with --workers 1 and
with --workers 2, in separate processes, and times them (the pool's start-up, the store's
writes and the report included); the figure is the median of the repeats' ratios (1 worker's
time / 2 workers' time), so both sides share the machine's state of the moment. The load
average is printed before each timing: on a shared machine it says what the figure is worth.

    python benchmarks/bench_benchmark.py --suite paper --repeats 3
"""

from __future__ import annotations

import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from armtransfer import script
from armtransfer.commands.common import positive_int
from armtransfer.experiments import suites


def timed(suite: str, out: Path, workers: int) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "armtransfer.cli", "benchmark", "--suite", suite, "--out", str(out),
                    "--workers", str(workers)], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def load() -> str:
    return " ".join(f"{x:.1f}" for x in os.getloadavg())


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--suite", default="paper", choices=list(suites.SUITES), help="the suite (default paper)")
    p.add_argument("--repeats", type=positive_int, default=3, help="repeats of each (default 3)")
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        timed("fast", Path(tmp) / "warmup", 2)  # compile numba's cache once, outside the timing
        ratios, ones, twos = [], [], []
        for r in range(args.repeats):
            load_one = load()
            one = timed(args.suite, Path(tmp) / f"w1-{r}", 1)
            load_two = load()
            two = timed(args.suite, Path(tmp) / f"w2-{r}", 2)
            ones.append(one)
            twos.append(two)
            ratios.append(one / two)
            print(f"repeat {r + 1}: 1 worker {one:.1f} s (load {load_one}), 2 workers {two:.1f} s (load {load_two}), "
                  f"speed-up {one / two:.2f}x", flush=True)
    print(f"median: 1 worker {statistics.median(ones):.1f} s, 2 workers {statistics.median(twos):.1f} s, "
          f"speed-up {statistics.median(ratios):.2f}x (target >= 1.8x); load now {load()}; {os.cpu_count()} CPUs, "
          f"{platform.processor() or platform.machine()}")


if __name__ == "__main__":
    script.exit_with(main)
