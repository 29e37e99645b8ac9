"""Sweep speed-up from 1 to 2 local workers on a sweep of 40 rooms runs (BENCHMARKS.md).

Each repeat runs the same 40-run sweep into a fresh directory with --workers 1 and with
--workers 2, in separate processes, and times them; the figure is the median of the
repeats' ratios (1 worker's time / 2 workers' time), so both sides share the machine's
state of the moment.

    python benchmarks/bench_sweep.py --repeats 3
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

SWEEP = """
[sweep]
name = "bench-40"
tasks = [1, 2, 3, 4]
pairs = [["coarse", "fine"]]
methods = ["none", "pseudo"]
seeds = [0, 1, 2, 3, 4]
trials = 10
"""  # 4 tasks x 2 methods x 5 seeds = 40 runs of 10 trials


def timed(sweep: Path, out: Path, workers: int) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "armtransfer.cli", "sweep", str(sweep), "--out", str(out),
                    "--workers", str(workers)], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        sweep = Path(tmp) / "bench.toml"
        sweep.write_text(SWEEP)
        timed(sweep, Path(tmp) / "warmup", 2)  # compile numba's cache once, outside the timing
        ratios, ones, twos = [], [], []
        for r in range(args.repeats):
            one = timed(sweep, Path(tmp) / f"w1-{r}", 1)
            two = timed(sweep, Path(tmp) / f"w2-{r}", 2)
            ones.append(one)
            twos.append(two)
            ratios.append(one / two)
            print(f"repeat {r + 1}: 1 worker {one:.1f} s, 2 workers {two:.1f} s, speed-up {one / two:.2f}x",
                  flush=True)
    print(f"median: 1 worker {statistics.median(ones):.1f} s, 2 workers {statistics.median(twos):.1f} s, "
          f"speed-up {statistics.median(ratios):.2f}x (target >= 1.7x); {os.cpu_count()} CPUs, "
          f"{platform.processor() or platform.machine()}")


if __name__ == "__main__":
    script.exit_with(main)
