"""armtransfer reproduce: the paper's Tables II-V and Fig. 4-7 on our rooms world."""

from __future__ import annotations

import argparse
import datetime as _dt
import time
from pathlib import Path

from armtransfer.commands import common
from armtransfer.learning import beyond, figures
from armtransfer.learning import paper, reproduce_report
from armtransfer.learning import reproduce as rep
from armtransfer.tasks.layout import ROOMS
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.mapping import ActionMapping
from armtransfer.io import check_output_dir, staged_directory, write_json_atomic, write_text_atomic

HELP = "Reproduce the paper's tables and figures on the rooms world; writes report.md."


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default=None,
                   help="output directory, absent or empty; written whole or not at all "
                        "(default runs/reproduce-<timestamp>)")
    p.add_argument("--trials", type=common.positive_int, default=30,
                   help="trials per table cell (default 30; the paper used 10)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--max-total-steps", type=common.positive_int, default=LearnerConfig.max_total_steps,
                   help="steps per trial at most, over all its episodes; a trial that has not reached "
                        f"the goal by then counts as not reached (default {LearnerConfig.max_total_steps:,})")


def _bars(res: dict, key: str) -> dict:
    groups = sorted(res)
    series = {}
    for method, label in (("none", "no transfer"), ("pseudo", "transfer")):
        series[label] = (
            [res[t]["results"][method]["mean"] for t in groups],
            [res[t]["results"][method]["ci95"] for t in groups],
        )
    return series


def run(args: argparse.Namespace) -> int:
    final = Path(args.out) if args.out else Path("runs") / _dt.datetime.now().strftime("reproduce-%Y%m%d-%H%M%S")
    check_output_dir(final)
    config = LearnerConfig(max_total_steps=args.max_total_steps)
    t0 = time.perf_counter()
    with common.progress_bar(rep.plan(args.trials), "reproduce") as bar:
        res = rep.run_all(args.trials, args.seed, config, tick=bar.update)
    with staged_directory(final) as out:
        names = _write(res, out)
    print(f"wrote {final / 'report.md'} ({time.perf_counter() - t0:.0f} s)")
    print(reproduce_report.table_ii_markdown(res["table_ii"], paper.TABLE_II, "Table II A-C: coarse -> fine"))
    print()
    print(reproduce_report.table_ii_mapping_markdown(res))
    print()
    print(beyond.methods_markdown(res["methods"]))
    return 0


def _write(res: dict, out: Path) -> dict[str, str]:
    """Every figure, the mappings, results.json and report.md, into ``out``."""
    groups = [f"task {t}" for t in rep.TASKS]
    names = {"fig4": "fig4_coarse_to_fine.png", "fig5": "fig5_fine_to_coarse.png", "fig6": "fig6_wind.png",
             "fig7": "fig7_mapping.png", "methods": "fig_methods.png"}
    figures.bar_chart(groups, _bars(res["table_ii"], "table_ii"),
                      "Fig. 4 analog: coarse -> fine", "exploration steps to the goal", out / names["fig4"])
    figures.bar_chart(groups, _bars(res["table_v"], "table_v"),
                      "Fig. 5 analog: fine -> coarse", "exploration steps to the goal", out / names["fig5"])
    figures.bar_chart(groups, _bars(res["wind"], "wind"),
                      "Fig. 6 analog: coarse -> fine, wind 0.01", "exploration steps to the goal", out / names["fig6"])
    methods = res["methods"]
    figures.bar_chart(groups, {m: ([methods[t]["results"][m]["mean"] for t in rep.TASKS],
                                   [methods[t]["results"][m]["ci95"] for t in rep.TASKS])
                               for m in beyond.METHODS},
                      "All methods, coarse -> fine", "exploration steps to the goal (log)",
                      out / names["methods"], log=True)
    fig = res["mapping_coarse_fine"]["figure"]
    if fig is not None:
        figures.mapping_paths(ROOMS.wall_mask, ROOMS.lo, fig["source_cells"], fig["target_cells"], fig["segments"],
                              f"Fig. 7 analog: task {fig['task']}, coarse -> fine, mapped fragments",
                              out / names["fig7"])
    for key in ("mapping_coarse_fine", "mapping_fine_coarse", "mapping_wind"):
        ActionMapping.from_json(res[key]["mapping"]).save(out / f"{key}.json")
    write_json_atomic(out / "results.json", res)
    # report.md last: its presence means everything else was written
    write_text_atomic(out / "report.md", reproduce_report.report_markdown(res, names))
    return names
