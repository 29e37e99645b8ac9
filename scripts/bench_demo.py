"""Wall time of the default demo (`python scripts/transfer_arms.py`), cold and warm.

Cold: empty arm-robot cache and empty numba cache (fresh directories), so compiling the arms
and the learner is included. Warm: the same command again with both caches filled.
Each is run ``--repeats`` times in fresh processes; medians are printed.

    python scripts/bench_demo.py --repeats 3
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
    args = p.parse_args()
    colds, warms = [], []
    for r in range(args.repeats):
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, ARMTRANSFER_CACHE=f"{tmp}/arms", NUMBA_CACHE_DIR=f"{tmp}/numba",
                       MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
            colds.append(run_demo(env, Path(tmp) / "cold"))
            warms.append(run_demo(env, Path(tmp) / "warm"))
        print(f"repeat {r + 1}: cold {colds[-1]:.1f} s, warm {warms[-1]:.1f} s", flush=True)
    print(f"median: cold {statistics.median(colds):.1f} s (target <= 120), "
          f"warm {statistics.median(warms):.1f} s (target <= 30)")


if __name__ == "__main__":
    script.exit_with(main)
