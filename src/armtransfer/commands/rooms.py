"""armtransfer rooms: transfer between robots in a world (the paper's grid robots in its rooms by default)."""

from __future__ import annotations

import argparse

from armtransfer import api
from armtransfer.commands import common
from armtransfer.io import check_distinct_outputs, check_writable, write_json_atomic
from armtransfer.experiments import experiment

from armtransfer.experiments import tables
HELP = ("Transfer a trajectory between two grid robots in a world (the paper's rooms by default; --world: rooms11, "
        "rooms15, generated:SEED or your layout file) and print its Table II-style table.")
EXAMPLE = "armtransfer rooms --task 2 --trials 5"


def add_arguments(p: argparse.ArgumentParser, source: str = "coarse", target: str = "fine") -> None:
    common.add_task_arguments(p)
    p.add_argument("--source", default=source, help=f"robot that solved the task (default {source})")
    p.add_argument("--target", default=target, help=f"robot that learns (default {target})")
    common.add_method_arguments(p)
    common.add_learning_arguments(p)
    common.add_probe_timeout_argument(p)
    p.add_argument("--json", default=None, metavar="PATH", help="write the results as JSON here")


def run(args: argparse.Namespace) -> int:
    common.check_learner(args)
    check_distinct_outputs({"--json": args.json, "--mapping": args.mapping})
    if args.json:
        check_writable(args.json)
    total = experiment.count_trials(args.method, args.trials, not args.no_controls and args.learner == "sarsa")
    with common.progress_bar(total, "learning") as bar:
        result = api.transfer(args.source, args.target, progress=bar.update, **common.transfer_kwargs(args))
    common.print_warnings(result)
    out = result.to_json()
    print_results(out)
    if args.json:
        write_json_atomic(args.json, out)
    return 0


results_table = tables.transfer_table


def print_results(out: dict) -> None:
    print(tables.transfer_heading(out))
    print(results_table(out))
    if out.get("controls"):
        print(tables.CONTROLS_NOTE)
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
