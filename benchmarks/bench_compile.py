"""Cold and warm compile times of every arm robot (median of N runs each).

    MUJOCO_GL=egl python benchmarks/bench_compile.py [--runs 3] [ROBOT ...]

Cold: a fresh empty cache directory, so the robot is compiled from its MJCF. Warm: the
same call again, loading the cached entry. Each run is a fresh Python process, so the
times include importing mujoco/dm_control/mink where the call needs them (not the
interpreter start-up itself).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from armtransfer import script

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

CHILD = r"""
import json, sys, time
t0 = time.perf_counter()
from armtransfer.tasks.arms import robot
r = robot(sys.argv[1])
print(json.dumps({"seconds": time.perf_counter() - t0, "states": r.n_states,
                  "reach": r.arm.reach, "cache": r.arm.cache}))
"""


def _run(spec: str, cache: str) -> dict:
    env = dict(os.environ, ARMTRANSFER_CACHE=cache, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    out = subprocess.run([sys.executable, "-c", CHILD, spec], env=env, check=True, cwd=ROOT,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    from armtransfer.tasks.arms import robot_specs

    parser = script.parser(__doc__)
    parser.add_argument("robots", nargs="*", default=robot_specs())
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print("| robot | states | reach | cold s (median) | warm s (median) |")
    print("|---|---:|---:|---:|---:|")
    for spec in args.robots:
        cold, warm = [], []
        for _ in range(args.runs):
            with tempfile.TemporaryDirectory() as cache:
                c = _run(spec, cache)
                w = _run(spec, cache)
            assert c["cache"] == "miss" and w["cache"] == "hit", (c, w)
            cold.append(c["seconds"])
            warm.append(w["seconds"])
        print(f"| {spec} | {c['states']} | {c['reach']:.1%} | {statistics.median(cold):.2f} "
              f"| {statistics.median(warm):.2f} |", flush=True)


if __name__ == "__main__":
    script.exit_with(main)
