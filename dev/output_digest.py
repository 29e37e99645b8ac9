"""Run a fixed set of the project's commands and print a SHA-256 of every file they write.

A restructure that moves code but changes no result must leave this listing unchanged:
run it before and after into the same OUTDIR (results name their own paths) and compare
with ``diff``. Wall-clock files (``timings.json``, a store's ``timings/``) are listed by name
only, since those hold times.

    python dev/output_digest.py /tmp/digest examples/sweeps/quick.toml > digest.txt
"""

from __future__ import annotations

import hashlib
import shutil
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = [
    ["armtransfer", "rooms", "--task", "2", "--trials", "3", "--method", "none", "pseudo", "dense",
     "guided", "mapping", "--json", "{out}/rooms.json", "--mapping", "{out}/rooms-map.json"],
    ["armtransfer", "rooms", "--task", "1", "--trials", "2", "--wind", "0.01", "--source", "fine",
     "--target", "coarse", "--json", "{out}/rooms-wind.json"],
    ["armtransfer", "arms", "--fast", "--no-video", "--out", "{out}/arms"],
    ["armtransfer", "arms", "--fast", "--source", "planar3:joint", "--target", "planar2:joint",
     "--task", "3", "--method", "none", "guided", "--out", "{out}/arms-joint"],
    ["armtransfer", "arms", "generate", "--family", "planar", "--dof", "3", "--seed", "1",
     "--out", "{out}/generated"],
    ["armtransfer", "reproduce", "--trials", "2", "--max-total-steps", "2000000",
     "--out", "{out}/reproduce"],
    ["armtransfer", "sweep", "{root}/SWEEP", "--out", "{out}/sweep", "--workers", "2"],
    ["armtransfer", "summarize", "{out}/sweep"],
    ["armtransfer", "matrix", "--robots", "coarse,fine", "--tasks", "1", "--trials", "2",
     "--out", "{out}/matrix", "--workers", "2"],
]


def main(out: Path, sweep: str) -> None:
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
    for cmd in COMMANDS:
        argv = [a.replace("{out}", str(out)).replace("{root}/SWEEP", sweep) for a in cmd]
        done = subprocess.run(argv, env=env, capture_output=True, text=True)
        print(f"# exit {done.returncode}: {' '.join(cmd)}")
    for path in sorted(p for p in out.rglob("*") if p.is_file()):
        rel = path.relative_to(out)
        if "timings" in rel.name or "timings" in rel.parts:
            print(f"{'(times)':64}  {rel}")
        else:
            print(f"{hashlib.sha256(path.read_bytes()).hexdigest()}  {rel}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: python dev/output_digest.py OUTDIR SWEEP.toml")
    main(Path(sys.argv[1]), sys.argv[2])
