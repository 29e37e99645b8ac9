"""Wall time of the default demo (`python scripts/transfer_arms.py`), cold and warm.

Cold: empty arm-robot cache and empty numba cache (fresh directories), so compiling the arms
and the learner is included. Warm: the same command again with both caches filled.
Each is run ``--repeats`` times in fresh processes; medians are printed.

    python benchmarks/bench_demo.py --repeats 3
    python benchmarks/bench_demo.py --repeats 3 --threads 1,2   # trials on 1 thread, then on 2, in turn
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from armtransfer import script

ROOT = Path(__file__).resolve().parents[1]


def run_demo(env: dict, out: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, str(ROOT / "scripts" / "transfer_arms.py"), "--out", str(out)],
                   check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--threads", default="",
                   help="comma-separated trial thread counts to compare, taking turns in each repeat "
                        "(ARMTRANSFER_CPUS; default: unset, all CPUs); the first is the baseline")
    args = p.parse_args()
    try:
        settings = [int(t) for t in args.threads.split(",")] if args.threads else [None]
    except ValueError:
        p.error(f"--threads takes comma-separated positive integers, got {args.threads!r}")
    if args.repeats < 1 or any(t is not None and t < 1 for t in settings):
        p.error("--repeats and --threads must be positive")
    colds = {t: [] for t in settings}
    warms = {t: [] for t in settings}
    for r in range(args.repeats):
        for t in settings:
            with tempfile.TemporaryDirectory() as tmp:
                env = dict(os.environ, ARMTRANSFER_CACHE=f"{tmp}/arms", NUMBA_CACHE_DIR=f"{tmp}/numba",
                           MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
                if t is not None:
                    env["ARMTRANSFER_CPUS"] = str(t)
                colds[t].append(run_demo(env, Path(tmp) / "cold"))
                warms[t].append(run_demo(env, Path(tmp) / "warm"))
            name = "" if t is None else f" ({t} trial threads)"
            print(f"repeat {r + 1}{name}: cold {colds[t][-1]:.1f} s, warm {warms[t][-1]:.1f} s", flush=True)
    base = settings[0]
    for t in settings:
        name = "" if t is None else f" ({t} trial threads)"
        cold, warm = statistics.median(colds[t]), statistics.median(warms[t])
        ratio = "" if t == base else (f"; {statistics.median(colds[base]) / cold:.2f}x cold and "
                                      f"{statistics.median(warms[base]) / warm:.2f}x warm against {base} threads")
        print(f"median{name}: cold {cold:.1f} s (target <= 120), warm {warm:.1f} s (target <= 30){ratio}")


if __name__ == "__main__":
    script.exit_with(main)
