"""Cold compile time of arm robots, this tree against another (an export of an earlier commit),
alternated rounds in one run, each compile a fresh process with an empty arm cache.

    git archive 033f586 src | tar -x -C /tmp/base
    python benchmarks/bench_compile_against.py --base /tmp/base/src --robots planar3:joint,ur5e_like:cartesian

Prints one Markdown row per robot: states (base / this), CPU seconds of the child's import and
compile (``time.process_time``, medians), the median of the per-round CPU ratios (this / base,
their range) and the wall seconds (medians). CPU time is the figure to read on a loaded machine.
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

CHILD = ("import json, time\nfrom armtransfer.tasks import arms\nt0, w0 = time.process_time(), time.time()\n"
         "robot = arms.robot({spec!r})\n"
         "print(json.dumps([time.process_time() - t0, time.time() - w0, int(robot.n_states)]))")


def compile_once(src: str, spec: str) -> tuple[float, float, int]:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, PYTHONPATH=src, ARMTRANSFER_CACHE=cache)
        out = subprocess.run([sys.executable, "-c", CHILD.format(spec=spec)], env=env, capture_output=True,
                             text=True, check=True)
    cpu, wall, states = json.loads(out.stdout.strip().splitlines()[-1])
    return cpu, wall, states


def main() -> None:
    p = script.parser(__doc__)
    p.add_argument("--base", required=True, help="the src folder of the tree to compare against")
    p.add_argument("--robots", default="planar3:joint,planar4:joint,ur5e_like:cartesian,panda_like:cartesian")
    p.add_argument("--rounds", type=int, default=3)
    a = p.parse_args()
    if not (Path(a.base) / "armtransfer").is_dir():
        p.error(f"--base {a.base!r} holds no armtransfer package (give the src folder of an exported tree)")
    if a.rounds < 1:
        p.error("--rounds must be >= 1")
    trees = [("base", a.base), ("this", str(Path(__file__).resolve().parents[1] / "src"))]
    specs = a.robots.split(",")
    res: dict[tuple[str, str], list[tuple[float, float, int]]] = {}
    for rnd in range(a.rounds):
        for spec in specs:
            for name, src in (trees if rnd % 2 == 0 else trees[::-1]):  # alternate who goes first
                res.setdefault((spec, name), []).append(compile_once(src, spec))
    print("| robot | states base / this | CPU s base / this | CPU ratio (range) | wall s base / this |")
    print("|---|---:|---:|---:|---:|")
    for spec in specs:
        b, t = res[(spec, "base")], res[(spec, "this")]
        ratios = [y[0] / x[0] for x, y in zip(b, t)]
        print(f"| {spec} | {b[0][2]:,} / {t[0][2]:,} | {statistics.median(x[0] for x in b):.2f} / "
              f"{statistics.median(x[0] for x in t):.2f} | {statistics.median(ratios):.2f} "
              f"({min(ratios):.2f}-{max(ratios):.2f}) | {statistics.median(x[1] for x in b):.2f} / "
              f"{statistics.median(x[1] for x in t):.2f} |")


if __name__ == "__main__":
    script.exit_with(main)
