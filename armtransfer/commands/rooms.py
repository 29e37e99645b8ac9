"""armtransfer rooms: transfer between the paper's grid robots in the rooms world."""

from __future__ import annotations

import argparse
from pathlib import Path

from armtransfer.commands import common
from armtransfer.robots import resolve
from tasks.catalog import Task
from tasks.errors import InvalidParameterError
from tasks.layout import ROOMS
from transfer import experiment, report
from transfer import mapping as mappings
from transfer import trajectory as trajectories
from transfer.io import check_writable, write_json_atomic

HELP = "Transfer a trajectory from one grid robot to another in the rooms world (Table II style)."
METHODS = ("none", "pseudo", "first-visit", "potential", "progress", "mapping")


def add_arguments(p: argparse.ArgumentParser) -> None:
    common.add_task_arguments(p)
    p.add_argument("--source", default="coarse", help="robot that solved the task (default coarse)")
    p.add_argument("--target", default="fine", help="robot that learns (default fine)")
    p.add_argument("--method", nargs="+", default=["none", "pseudo"], metavar="METHOD",
                   help=f"one or more of: {', '.join(METHODS)} (default: none pseudo)")
    p.add_argument("--trajectory", default="optimal", metavar="optimal|learned|PATH",
                   help="the transferred trajectory: the source's shortest path (default), its "
                        "learned greedy path, or a JSON file")
    p.add_argument("--mapping", default=None, metavar="PATH",
                   help="with --method mapping: the action sequence mapping to reuse (created when "
                        "absent) and to update, after the run, from every converged trial")
    p.add_argument("--max-span", type=common.positive_int, default=mappings.DEFAULT_MAX_SPAN,
                   help="longest source key learned from non-consecutive matches "
                        f"(default {mappings.DEFAULT_MAX_SPAN})")
    common.add_learning_arguments(p)
    p.add_argument("--json", default=None, metavar="PATH", help="write the results as JSON here")


def load_trajectory(spec: str, source, task: Task, config, seed: int) -> trajectories.Trajectory:
    start, goal = task.cells()
    if spec in ("optimal", "learned"):
        return experiment.source_trajectory(spec, source, start, goal, config, seed)
    traj = trajectories.load(spec)
    trajectories.check_task(traj, start, goal)
    return traj


def task_for(args: argparse.Namespace) -> Task:
    """The task from --task/--start/--goal; a trajectory file alone also names its task."""
    if (
        args.task is None and args.start is None and args.goal is None
        and args.trajectory not in ("optimal", "learned")
    ):
        traj = trajectories.load(args.trajectory)
        return Task("trajectory file", ROOMS.xy(traj.start), ROOMS.xy(traj.goal))
    return common.task_from_args(args)


def run_experiment(args: argparse.Namespace, methods_valid=METHODS) -> dict:
    common.check_methods(args.method, methods_valid)
    config = common.config_from_args(args)
    task = task_for(args)
    start, goal = task.cells()
    source = resolve(args.source)
    target = resolve(args.target)
    target.start_state(start)
    target.start_state(goal, what="goal")
    if target.shortest_path(target.start_state(start), goal) is None:
        raise InvalidParameterError(f"robot {target.name} cannot reach the goal {task.goal} from {task.start}")
    mapping = None
    mapping_info = None
    if args.mapping is not None and "mapping" not in args.method:
        raise InvalidParameterError("--mapping goes with --method mapping")
    if "mapping" in args.method:
        if args.mapping is not None:
            check_writable(args.mapping)
            mapping = mappings.load_for(args.mapping, source, target)
        else:
            mapping = mappings.ActionMapping.for_robots(source, target)
    traj = None
    if any(m != "none" for m in args.method):
        traj = load_trajectory(args.trajectory, source, task, config, args.seed)
    results = []
    with common.progress_bar(len(args.method) * args.trials, f"{task.name}") as bar:
        for method in args.method:
            if method == "mapping":
                res, learned = experiment.run_mapping(
                    target, start, goal, traj, mapping, args.trials, args.seed, config,
                    wind=args.wind, K=args.K, on_trial=bar.update, max_span=args.max_span,
                )
                mapping_info = {
                    "path": args.mapping,
                    "entries_before": len(mapping),
                    "entries_after": len(learned),
                    "macro_states": res.extra["macro_states"],
                    "saved": args.mapping is not None,
                }
                if args.mapping is not None:
                    learned.save(args.mapping)
                results.append(res)
                continue
            results.append(
                experiment.run_method(
                    method, target, start, goal, traj, args.trials, args.seed, config,
                    wind=args.wind, K=args.K, on_trial=bar.update,
                )
            )
    baseline = "none" if "none" in args.method else None
    target_path = target.shortest_path(target.start_state(start), goal)
    return {
        "task": {"name": task.name, "start": list(task.start), "goal": list(task.goal)},
        "distance": len(target_path) - 1,
        "source": source.name,
        "target": target.name,
        "trajectory": None if traj is None else traj.to_json(),
        "trajectory_length": None if traj is None else len(traj),
        "seed": args.seed,
        "trials": args.trials,
        "wind": args.wind,
        "config": config.to_dict(),
        "mapping": mapping_info,
        "results": experiment.summarize(results, baseline=baseline or ""),
    }


def run(args: argparse.Namespace) -> int:
    if args.json:
        check_writable(args.json)
    out = run_experiment(args)
    t = out["task"]
    print(
        f"{t['name']}: {tuple(t['start'])} -> {tuple(t['goal'])}, {out['source']} -> {out['target']}, "
        f"target's optimal distance {out['distance']}, {out['trials']} trials, seed {out['seed']}"
        + (f", wind {out['wind']}" if out["wind"] else "")
    )
    print(report.method_table(out["results"]))
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
    if args.json:
        write_json_atomic(Path(args.json), out)
    return 0
