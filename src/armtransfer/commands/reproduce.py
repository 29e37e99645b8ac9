"""armtransfer reproduce: the paper's Tables I-V and Fig. 3-7 on our rooms world.

Everything is written into a hidden temporary directory beside ``--out``, renamed into
place only when complete: ``--out`` never holds half a run. A non-empty ``--out`` is refused.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import time
from pathlib import Path

from armtransfer.commands import common
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.experiments import beyond
from armtransfer.experiments.reports import figures
from armtransfer.experiments import reproduce as rep
from armtransfer.experiments.reports import reproduce_report as rr
from armtransfer.learning import presets
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.mapping import ActionMapping
from armtransfer.tasks.catalog import TABLE_I
from armtransfer.worlds.layout import ROOMS

HELP = "Reproduce the paper's tables and figures on the rooms world into one report.md."
EXAMPLE = "armtransfer reproduce --trials 5 --out runs/paper"

NAMES = {"fig3": "fig3_layout.png", "fig4": "fig4_coarse_to_fine.png", "fig5": "fig5_fine_to_coarse.png",
         "fig6": "fig6_wind.png", "fig7": "fig7_mapping.png", "methods": "fig_methods.png"}


def add_arguments(p: argparse.ArgumentParser) -> None:
    common.add_world_argument(p)
    p.add_argument("--out", default=None,
                   help="output directory, absent or empty; written whole or not at all "
                        "(default runs/reproduce-<timestamp>)")
    p.add_argument("--trials", type=common.positive_int, default=30,
                   help="trials per table cell (default 30; the paper used 10)")
    p.add_argument("--seed", type=common.non_negative_int, default=0, help="random seed, >= 0 (default 0)")
    common.add_preset_argument(p)
    p.add_argument("--max-total-steps", type=common.positive_int, default=None,
                   help="steps per trial at most, over all its episodes; a trial that has not reached "
                        f"the goal by then counts at this cap (default {LearnerConfig.max_total_steps:,})")
    p.add_argument("--trajectory", choices=rep.TRAJECTORIES, default="learned",
                   help="the trajectory handed over: the source robot's converged greedy path after "
                        "learning (learned, the paper's; default) or its shortest path (optimal); "
                        "the other is run too and reported beside it")
    p.add_argument("--mapping-from", choices=rep.MAPPING_FROM, default="single",
                   help="learn each task's mapping from one converged trial (single, the paper's; "
                        "default) or from all of them (pooled); the other is reported beside it")


def _bars(res: dict, extra: dict | None = None) -> tuple[dict, dict]:
    groups = sorted(res)
    series, lower = {}, {}
    for method, label in (("none", "no transfer"), ("pseudo", "transfer")):
        entries = [res[t]["results"][method] for t in groups]
        series[label] = ([e["mean"] for e in entries], [e["ci95"] for e in entries])
        lower[label] = [bool(e.get("mean_is_lower_bound")) for e in entries]
    if extra is not None:
        entries = [extra["tasks"][t] for t in groups]
        series["transfer + mapping"] = ([e["mean"] for e in entries], [e["ci95"] for e in entries])
        lower["transfer + mapping"] = [bool(e.get("mean_is_lower_bound")) for e in entries]
    return series, lower


def _write(res: dict, tmp: Path) -> None:
    groups = [f"task {t}" for t in rep.TASKS]
    figures.task_layout(ROOMS.wall_mask, ROOMS.lo,
                        [(f"task {t}", TABLE_I[t].start, TABLE_I[t].goal) for t in rep.TASKS],
                        "Fig. 3 analog: rooms and the Table I tasks", tmp / NAMES["fig3"])
    s, lb = _bars(res["table_ii"])
    figures.bar_chart(groups, s, "Fig. 4 analog: coarse -> fine", "exploration steps to the goal",
                      tmp / NAMES["fig4"], lower_bound=lb)
    s, lb = _bars(res["table_v"], res["mapping_fine_coarse"])
    figures.bar_chart(groups, s, "Fig. 5 analog: fine -> coarse", "exploration steps to the goal",
                      tmp / NAMES["fig5"], lower_bound=lb)
    s, lb = _bars(res["wind"])
    figures.bar_chart(groups, s, "Fig. 6 analog: coarse -> fine, wind 0.01", "exploration steps to the goal",
                      tmp / NAMES["fig6"], lower_bound=lb)
    methods = res["methods"]
    figures.bar_chart(groups, {m: ([methods[t]["results"][m]["mean"] for t in rep.TASKS],
                                   [methods[t]["results"][m]["ci95"] for t in rep.TASKS])
                               for m in beyond.METHODS},
                      "All methods, coarse -> fine", "exploration steps to the goal (log)",
                      tmp / NAMES["methods"], log=True,
                      lower_bound={m: [bool(methods[t]["results"][m].get("mean_is_lower_bound")) for t in rep.TASKS]
                                   for m in beyond.METHODS})
    fig = res["mapping_coarse_fine"]["figure"]
    if fig is not None:
        figures.mapping_paths(ROOMS.wall_mask, ROOMS.lo, fig["source_cells"], fig["target_cells"], fig["segments"],
                              f"Fig. 7 analog: task {fig['task']}, coarse -> fine, mapped fragments",
                              tmp / NAMES["fig7"])
    for key in ("mapping_coarse_fine", "mapping_fine_coarse", "mapping_wind"):
        ActionMapping.from_json(res[key]["mapping"]).save(tmp / f"{key}.json")
    write_json_atomic(tmp / "results.json", res)
    write_text_atomic(tmp / "report.md", rr.report_markdown(res, NAMES))


def run(args: argparse.Namespace) -> int:
    common.refuse_world(args, "reproduce", "the paper's Tables I-V and figures are set in its rooms world")
    out = Path(args.out) if args.out else Path("runs") / _dt.datetime.now().strftime("reproduce-%Y%m%d-%H%M%S")
    check_output_dir(out)  # before the long run, not after
    config = presets.config(args.preset, {} if args.max_total_steps is None else
                            {"max_total_steps": args.max_total_steps})
    t0 = time.perf_counter()
    with staged_directory(out) as tmp:  # out appears only complete; a second run into it is refused now
        with common.progress_bar(rep.plan(args.trials, args.preset), "reproduce") as bar:
            res = rep.run_all(args.trials, args.seed, config, tick=bar.update,
                              trajectory=args.trajectory, mapping_from=args.mapping_from, preset=args.preset)
        _write(res, tmp)
    print(f"wrote {out / 'report.md'} ({time.perf_counter() - t0:.0f} s)")
    print(rr.table_ii_markdown(res["table_ii"], rr.paper.TABLE_II, "Table II A-C: coarse -> fine"))
    print()
    print(rr.table_ii_mapping_markdown(res))
    print()
    print(beyond.methods_markdown(res["methods"]))
    return 0
