"""armtransfer rooms: transfer between robots in the rooms world (the paper's grid robots by default)."""

from __future__ import annotations

import argparse
from pathlib import Path

from armtransfer.commands import common
from armtransfer.robots import resolve
from armtransfer.errors import InvalidParameterError
from armtransfer.learning import experiment, report
from armtransfer.learning import mapping as mappings
from armtransfer.io import check_writable, write_json_atomic

HELP = "Transfer a trajectory from one grid robot to another in the rooms world (Table II style)."
METHODS = experiment.METHODS


def add_arguments(p: argparse.ArgumentParser, source: str = "coarse", target: str = "fine") -> None:
    common.add_task_arguments(p)
    p.add_argument("--source", default=source, help=f"robot that solved the task (default {source})")
    p.add_argument("--target", default=target, help=f"robot that learns (default {target})")
    common.add_method_arguments(p)
    common.add_learning_arguments(p)
    p.add_argument("--json", default=None, metavar="PATH", help="write the results as JSON here")


def run_experiment(args: argparse.Namespace, source=None, target=None) -> tuple[dict, object]:
    """The experiment the arguments describe: the JSON dict, and the updated mapping (or None)."""
    common.check_methods(args.method, METHODS)
    config = common.config_from_args(args)
    task = common.task_for(args)
    start, goal = task.cells()
    source = source or resolve(args.source)
    target = target or resolve(args.target)
    source.start_state(start)
    source.start_state(goal, what="goal")
    target.start_state(start)
    target.start_state(goal, what="goal")
    target_path = target.shortest_path(target.start_state(start), goal)
    if target_path is None:
        raise InvalidParameterError(f"robot {target.name} cannot reach the goal {task.goal} from {task.start}")
    if args.mapping is not None and "mapping" not in args.method:
        raise InvalidParameterError("--mapping goes with --method mapping")
    mapping = None
    if "mapping" in args.method and args.mapping is not None:
        check_writable(args.mapping)
        mapping = mappings.load_for(args.mapping, source, target)
    trajs = []
    if any(m != "none" for m in args.method):
        trajs = common.resolve_trajectories(args.trajectory, source, task, config, args.seed)
    controls = not args.no_controls
    entries_before = None if mapping is None else len(mapping)
    with common.progress_bar(experiment.count_trials(args.method, args.trials, controls), task.name) as bar:
        results, learned = experiment.run_transfer(
            source, target, start, goal, args.method, trajs, args.trials, args.seed, config,
            wind=args.wind, K=args.K, beta=args.beta, mapping=mapping, max_span=args.max_span,
            controls=controls, tick=bar.update,
        )
    mapping_info = None
    if "mapping" in args.method:
        mapping_info = {
            "path": args.mapping,
            "entries_before": entries_before or 0,
            "entries_after": len(learned),
            "macro_states": results["mapping"]["macro_states"],
            "saved": args.mapping is not None,
        }
    out = {
        "task": {"name": task.name, "start": list(task.start), "goal": list(task.goal)},
        "distance": len(target_path) - 1,
        "source": source.name,
        "target": target.name,
        "trajectory": None if not trajs else trajs[0].to_json(),
        "trajectories": [t.to_json() for t in trajs],
        "trajectory_length": None if not trajs else len(trajs[0]),
        "seed": args.seed,
        "trials": args.trials,
        "wind": args.wind,
        "config": config.to_dict(),
        "mapping": mapping_info,
        "results": results,
    }
    return out, learned


def print_results(out: dict) -> None:
    t = out["task"]
    print(
        f"{t['name']}: {tuple(t['start'])} -> {tuple(t['goal'])}, {out['source']} -> {out['target']}, "
        f"target's optimal distance {out['distance']}, {out['trials']} trials, seed {out['seed']}"
        + (f", wind {out['wind']}" if out["wind"] else "")
    )
    print(report.method_table(out["results"]))
    if any("[" in m for m in out["results"]):
        print("[shuffled] and [random] are controls: the same method given the trajectory's cells in a "
              "random order, or a random walk of the source robot of the same length.")
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


def run(args: argparse.Namespace) -> int:
    if args.json:
        check_writable(args.json)
    out, learned = run_experiment(args)
    print_results(out)
    if out["mapping"] is not None and out["mapping"]["saved"]:
        learned.save(args.mapping)
    if args.json:
        write_json_atomic(Path(args.json), out)
    return 0
