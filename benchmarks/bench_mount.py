"""Wall time of the automatic mount search for the arm files the tests build, from an empty cache.

    MUJOCO_GL=egl python benchmarks/bench_mount.py [--runs 1] [--baseline SRC] [ARM ...]

Each run is a fresh Python process with a fresh empty cache directory that writes the arm
files (``tests/menagerie_like.py``) and times ``automatic_mount`` alone (imports and
writing the files excluded): wall seconds and the process's CPU seconds (on a machine
other jobs share, wall time grows with their load; CPU time does not). ARM is a name of
``menagerie_like.ALL`` with its tool point from ``menagerie_like.SUGGESTED``, or one of
``VARIANTS``, an arm of ``ALL`` as a test searches its mount otherwise (a held tool, wider
cells, a joint limited so that no pose reaches the table), or one of ``FILES``, an arm file
another test module writes (the SCARA of ``conftest.py``, the low-link arm of
``test_unreachable_causes.py``, the pen gripper of ``test_arm_files.py``) with that test's
tool point; the default is all of them. ``--baseline SRC`` also times the package at SRC (a checkout of
another commit: ``armtransfer`` imported from there, not the installed one) in the same
runs, alternating.
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

VARIANTS = {
    "ur5e_wide_gripper+stylus": ("ur5e_wide_gripper", {"tool": "stylus"}),  # tests/test_held_tool.py
    "planar5_wide_pen@0.016": ("planar5_wide_pen", {"cell_size": 0.016}),   # tests/test_held_tool.py
    "ur5e_stiff": ("ur5e", {"replace": [  # tests/test_unreachable_causes.py: no pose reaches the table
        '<joint name="elbow_joint" class="ur5e/size3_limited"/>',
        '<joint name="elbow_joint" class="ur5e/size3_limited" range="-0.2 0.2"/>']}),
}
"""Arms of ``menagerie_like.ALL`` as tests search their mount otherwise: (fixture, options)."""

FILES = {
    # tests/test_hostile_caches.py searches its mount (its mount choice cached, then re-chosen)
    "scara": {"text": ["conftest", "SCARA_XML"], "tip": {"tip_site": "pen_tip"}},
    # tests/test_unreachable_causes.py: the search fails, naming link2 in the table
    "lowlink": {"text": ["test_unreachable_causes", "LOW_LINK"], "tip": {"tip_site": "tip"}},
    # tests/test_arm_files.py gives this arm its mount (-0.1, 0, 0); timed for comparison only
    "gripper_scara": {"text": ["test_arm_files", "GRIPPER_SCARA"],
                      "tip": {"tip_body": "pen", "tip_offset": [0.0, 0.0, -0.116]}},
}
"""Arm files other test modules write (``module``, its constant holding the MJCF) with the tool
point those tests give: the name's ``text`` is imported from ``tests/`` (never copied)."""

CHILD = r"""
import json, os, sys, time
from pathlib import Path
source = os.environ.get("BENCH_SOURCE")
if source:  # the baseline checkout, ahead of the installed (editable) package
    sys.meta_path[:] = [f for f in sys.meta_path if not getattr(f, "__module__", "").startswith("__editable__")]
    sys.path.insert(0, source)
    import armtransfer
    assert armtransfer.__file__.startswith(source), armtransfer.__file__
sys.path.insert(0, sys.argv[3])
import menagerie_like as ml
from armtransfer.errors import ArmTransferError
from armtransfer.tasks.arms import automatic_mount, make_tool
name, extra = sys.argv[1], json.loads(sys.argv[4])
if "text" in extra:  # an arm file another test module writes, from its own constant
    import importlib
    module, attribute = extra["text"]
    path = Path(sys.argv[2]) / f"{name}.xml"
    path.write_text(getattr(importlib.import_module(module), attribute))
else:
    path = ml.ALL[name](Path(sys.argv[2]))
if "replace" in extra:  # the test's edit of the file, written beside it
    old, new = extra["replace"]
    assert old in path.read_text()
    edited = path.with_name(path.stem + "_edited.xml")
    edited.write_text(path.read_text().replace(old, new))
    path = edited
tip = extra.get("tip") or {k: v for k, v in ml.SUGGESTED[name].items() if k.startswith("tip")}
held = {"tool": extra["tool"]} if "tool" in extra else {}
tool = make_tool(tip.get("tip_site"), tip.get("tip_body"), tip.get("tip_offset"), **held)
t0, c0 = time.perf_counter(), time.process_time()
try:
    pose = automatic_mount(path, tool, **({"cell_size": extra["cell_size"]} if "cell_size" in extra else {}))
    out = {"pose": pose.describe()}
except ArmTransferError as err:
    out = {"error": str(err)}
out["seconds"] = time.perf_counter() - t0
out["cpu"] = time.process_time() - c0
print(json.dumps(out))
"""


def _run(name: str, source: str | None) -> dict:
    fixture, extra = VARIANTS.get(name, (name, FILES.get(name, {})))
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as files:
        env = dict(os.environ, ARMTRANSFER_CACHE=cache, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"))
        if source:
            env["BENCH_SOURCE"] = source
        out = subprocess.run([sys.executable, "-c", CHILD, fixture, files, str(ROOT / "tests"), json.dumps(extra)],
                             env=env,
                             check=True, cwd=ROOT, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    sys.path.insert(0, str(ROOT / "tests"))
    import menagerie_like as ml

    parser = script.parser(__doc__)
    valid = [n for n in ml.ALL if n in ml.SUGGESTED] + list(VARIANTS) + list(FILES)
    parser.add_argument("arms", nargs="*", default=valid)
    parser.add_argument("--runs", type=int, default=1)
    parser.add_argument("--baseline", default=None, help="a checkout of the baseline commit")
    args = parser.parse_args()
    unknown = [name for name in args.arms if name not in valid]
    if unknown:
        parser.error(f"unknown arm {unknown[0]!r}; valid arms: {', '.join(valid)}")
    if args.runs < 1:
        parser.error(f"--runs must be at least 1, not {args.runs}")
    print("| arm | code | wall s (median) | CPU s (median) | runs (wall/CPU) | result |")
    print("|---|---|---:|---:|---|---|")
    for name in args.arms:
        runs: dict[str, list] = {"this": [], "baseline": []}
        for _ in range(args.runs):
            runs["this"].append(_run(name, None))
            if args.baseline:
                runs["baseline"].append(_run(name, args.baseline))
        for code, rows in runs.items():
            if not rows:
                continue
            wall, cpu = [r["seconds"] for r in rows], [r["cpu"] for r in rows]
            result = rows[0].get("pose") or rows[0].get("error")
            print(f"| {name} | {code} | {statistics.median(wall):.1f} | {statistics.median(cpu):.1f} | "
                  f"{', '.join(f'{w:.1f}/{c:.1f}' for w, c in zip(wall, cpu))} | {result} |", flush=True)


if __name__ == "__main__":
    script.exit_with(main)
