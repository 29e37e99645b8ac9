"""armtransfer rooms: transfer between robots in the rooms world (the paper's grid robots by default)."""

from __future__ import annotations

import argparse

from armtransfer import api
from armtransfer.commands import common
from armtransfer.io import check_writable, write_json_atomic
from armtransfer.experiments import experiment, report

HELP = "Transfer a trajectory from one grid robot to another in the rooms world (Table II style)."


def add_arguments(p: argparse.ArgumentParser, source: str = "coarse", target: str = "fine") -> None:
    common.add_task_arguments(p)
    p.add_argument("--source", default=source, help=f"robot that solved the task (default {source})")
    p.add_argument("--target", default=target, help=f"robot that learns (default {target})")
    common.add_method_arguments(p)
    common.add_learning_arguments(p)
    p.add_argument("--json", default=None, metavar="PATH", help="write the results as JSON here")


def run(args: argparse.Namespace) -> int:
    if args.json:
        check_writable(args.json)
    total = experiment.count_trials(args.method, args.trials, not args.no_controls)
    with common.progress_bar(total, "learning") as bar:
        result = api.transfer(args.source, args.target, progress=bar.update, **common.transfer_kwargs(args))
    out = result.to_json()
    print_results(out)
    if args.json:
        write_json_atomic(args.json, out)
    return 0


def results_table(out: dict) -> str:
    """The methods, then their control runs, as one Table II-style table."""
    rows = dict(out["results"])
    for kind, by in out.get("controls", {}).items():
        rows.update({f"{m} [{kind}]": entry for m, entry in by.items()})
    return report.method_table(rows)


def print_results(out: dict) -> None:
    t = out["task"]
    print(
        f"{t['name']}: {tuple(t['start'])} -> {tuple(t['goal'])}, {out['source']} -> {out['target']}, "
        f"target's optimal distance {out['distance']}, {out['trials']} trials, seed {out['seed']}"
        + (f", wind {out['wind']}" if out["wind"] else "")
    )
    print(results_table(out))
    if out.get("controls"):
        print("[shuffled] and [random] are controls: the same method given the trajectory's cells in a "
              "random order, or a random walk of the source robot of the same length, a new draw each "
              "trial, neither ending at the task's goal.")
    info = out["mapping"]
    if info is not None:
        if info["macro_states"] == 0:
            why = "no mapping file given" if info["path"] is None else (
                f"{info['path']} has no entries yet" if info["entries_before"] == 0
                else f"none of the {info['entries_before']} entries in {info['path']} matches this trajectory"
            )
            print(f"mapping: no mapping was available ({why}), so method 'mapping' equals 'pseudo'")
        else:
            fr = [f for f in out["results"]["mapping"]["mapped_fraction"] if f is not None]
            share = f"{100 * sum(fr) / len(fr):.1f}%" if fr else "n/a"
            print(f"mapping: {info['entries_before']} entries, macros at {info['macro_states']} trajectory "
                  f"cells; mapped share of the final greedy paths {share}")
        if info["saved"]:
            print(f"mapping: {info['entries_after']} entries after this run, saved to {info['path']}")
        else:
            print(f"mapping: {info['entries_after']} entries learned, not saved (give --mapping PATH to keep them)")
