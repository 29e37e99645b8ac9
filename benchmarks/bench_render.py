"""Frames per second of rendered rollouts on this machine (median of N runs).

    MUJOCO_GL=egl python benchmarks/bench_render.py [--runs 3] [--task 1]
        [--source planar2:joint] [--target ur5e_like:cartesian]

One run = the whole video pipeline for the source and target arms side by side on a
Table I task's shortest paths: physics replay of both paths (``mj_step``), offscreen
rendering of both panels (EGL, CPU) and H.264 encoding to an MP4 in a temporary folder.
Reported fps = video frames / wall-clock seconds of that pipeline (robot compile/load
and imports excluded; both robots are loaded once before timing).

Measured in the same run:
  - 320x240 per panel (the target: >= 25 fps), default settings (4x MSAA, no shadows);
  - baseline: the same pipeline at 640x480 per panel (ratio = fps 320 / fps 640);
  - for reference, 320x240 with shadows on (MuJoCo's default lighting).
"""

from __future__ import annotations

import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from armtransfer import script

os.environ.setdefault("MUJOCO_GL", "egl")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def pipeline(rollouts, out: Path, width: int, height: int, shadows: bool = False) -> dict:
    from armtransfer.ik.render import RolloutPanel, render_rollouts
    from armtransfer.ik.replay import replay

    t0 = time.perf_counter()
    replays = [replay(r, states) for r, states in rollouts]
    t1 = time.perf_counter()
    goal = replays[0].goal_cell
    cells = [int(c) for c in rollouts[0][0].label[rollouts[0][1]]]
    panels = [RolloutPanel(rp, cells, goal) for rp in replays]
    stats = render_rollouts(panels, out, width=width, height=height, fps=30, shadows=shadows)
    total = time.perf_counter() - t0
    return {"frames": stats.frames, "seconds": total, "fps": stats.frames / total,
            "replay_s": t1 - t0, "render_s": stats.render_seconds,
            "encode_s": stats.encode_seconds, "replays": [rp.report() for rp in replays]}


def main() -> int:
    parser = script.parser(__doc__)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--task", type=int, default=1)
    parser.add_argument("--source", default="planar2:joint")
    parser.add_argument("--target", default="ur5e_like:cartesian")
    args = parser.parse_args()

    from armtransfer.tasks.arms import robot
    from armtransfer.tasks.catalog import table_task

    s, g = table_task(args.task).cells()
    rollouts = []
    for spec in (args.source, args.target):
        r = robot(spec)
        path = r.shortest_path(r.start_state(s), g)
        if path is None:
            raise SystemExit(f"{spec} cannot reach the goal of task {args.task}")
        rollouts.append((r, [st for st, _ in path]))

    configs = {"320x240": (320, 240, False), "640x480": (640, 480, False),
               "320x240 shadows": (320, 240, True)}
    results: dict[str, list[dict]] = {k: [] for k in configs}
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(args.runs):
            for name, (w, h, shadows) in configs.items():
                res = pipeline(rollouts, Path(tmp) / f"bench{run}.mp4", w, h, shadows)
                results[name].append(res)
                print(f"run {run + 1} {name}: {res['frames']} frames in {res['seconds']:.2f} s "
                      f"= {res['fps']:.1f} fps (replay {res['replay_s']:.2f} s, render "
                      f"{res['render_s']:.2f} s, encode {res['encode_s']:.2f} s)",
                      file=sys.stderr, flush=True)
    med = {k: statistics.median(r["fps"] for r in v) for k, v in results.items()}
    summary = {
        "source": args.source, "target": args.target, "task": args.task,
        "frames": results["320x240"][0]["frames"],
        "median_fps": {k: round(v, 1) for k, v in med.items()},
        "ratio_320_over_640": round(med["320x240"] / med["640x480"], 2),
        "ratio_320_over_shadows": round(med["320x240"] / med["320x240 shadows"], 2),
        "replays": results["320x240"][0]["replays"],
        "nproc": os.cpu_count(),
    }
    print(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    script.exit_with(main)
