"""Arm-to-arm transfer end to end: ``armtransfer arms --source ... --target ...``.

The source arm solves the task (it learns with SARSA(lambda), or plans with breadth-first
search), its trajectory of (cell, action index) is transferred, the target arm learns with
each method; then the results, a Table II-style table, learning curves, a top-down map and
a physics-replay video of both arms go into one output directory.

The video needs offscreen OpenGL: before anything is compiled or learned the command checks
that a backend works here (``armtransfer.ik.offscreen``) and stops in one line naming the
system packages to install and ``--no-video`` when none does. A render that fails after the
learning anyway costs the video only: the results, table and figures are written, one line
says the video was not, and the exit code is 1.

Nothing half-written is left as if complete: every output is first written into a hidden
temporary directory beside ``--out``, which is renamed into place only when all of them are.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import sys
import time
from pathlib import Path
from typing import Any


from armtransfer import api
from armtransfer.commands import common
from armtransfer.commands.rooms import print_results, results_table
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.experiments.reports import figures
from armtransfer.ik import offscreen
from armtransfer.ik.offscreen import OffscreenError
from armtransfer.io import check_distinct_outputs, check_writable, copy_atomic, staged_directory, write_json_atomic, write_text_atomic
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.tasks.specs import CUSTOM, resolve

DEFAULT_SOURCE = "planar2:joint"
DEFAULT_TARGET = "ur5e_like:cartesian"
DEFAULT_METHODS = ["none", "pseudo", "dense"]
TIMINGS = ("seconds", "fps_achieved", "render_seconds", "encode_seconds")
"""Wall-clock figures of the rendering, kept out of results.json (in timings.json)."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    common.add_task_arguments(p)
    p.add_argument("--source", default=DEFAULT_SOURCE, metavar="ARM[:ACTIONS]",
                   help=f"the arm that solves the task (default {DEFAULT_SOURCE}); "
                        f"'{CUSTOM}[:ACTIONS]' or 'NAME[:ACTIONS]' (its name, as 'arms list' prints it) is the "
                        "arm of --arm-xml")
    p.add_argument("--target", default=DEFAULT_TARGET, metavar="ARM[:ACTIONS]",
                   help=f"the arm that learns (default {DEFAULT_TARGET})")
    p.add_argument("--source-planner", choices=["learn", "bfs"], default="learn",
                   help="how the source solves the task: SARSA(lambda) without transfer (default) or "
                        "breadth-first search")
    common.add_method_arguments(p, default=DEFAULT_METHODS)
    common.add_learning_arguments(p)
    common.add_probe_timeout_argument(p)
    p.add_argument("--json", default=None, metavar="PATH", help="also write the results JSON here")
    p.add_argument("--render", default=None, metavar="PATH",
                   help="also write the rollout video here (.mp4, or .gif)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="output directory (default runs/<timestamp>); must not exist or be empty")
    p.add_argument("--no-video", action="store_true", help="skip the rollout video in --out")
    p.add_argument("--fast", action="store_true",
                   help="a quick smoke run: 2 trials, convergence after 5 unchanged episodes, no controls, "
                        "a small low-rate video")


def arm_options(args: argparse.Namespace) -> dict:
    """The bring-your-own arm's options (for ``custom[:ACTIONS]`` or its name) and the cell size."""
    options = dict(cell_size=args.cell_size, cache=not args.no_cache)
    if getattr(args, "arm_xml", None):
        options.update(common.arm_file_options(args))
    return options


FAST_CAPS = {"trials": 2, "patience": 5}
"""What --fast caps (a smaller value given is kept)."""


def _fast_overrides(args: argparse.Namespace) -> dict:
    """--fast: 2 trials, convergence after 5 unchanged episodes, no controls."""
    if not args.fast:
        return {}
    given = {k: getattr(args, k) for k in FAST_CAPS}  # a learner flag not given is None (the preset's value)
    return dict({k: cap if given[k] is None else min(given[k], cap) for k, cap in FAST_CAPS.items()}, controls=False)


def _check_fast(args: argparse.Namespace) -> None:
    """A value given above what --fast caps would be silently cut: an error instead."""
    if not args.fast:
        return
    defaults = {a.dest: a.default for a in common.options_of(args)}
    for dest, cap in FAST_CAPS.items():
        value = getattr(args, dest)
        if value != defaults.get(dest) and value > cap:
            raise InvalidParameterError(f"--{dest} {value} does not apply with --fast (it runs at most {cap}); "
                                        f"drop --fast to run {value}")


def run(args: argparse.Namespace) -> int:
    t0 = time.perf_counter()
    common.check_learner(args)
    _check_fast(args)
    out = Path(args.out) if args.out else Path("runs") / _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    check_distinct_outputs({"--json": args.json, "--render": args.render, "--mapping": args.mapping},
                           {"--out": out})
    for extra in (args.json, args.render):
        if extra:
            check_writable(extra)
    if args.render:
        from armtransfer.ik.render import video_format  # MuJoCo: not on --help's path

        video_format(args.render, None)
    common.check_arm_flags(args)
    renders = not args.no_video or bool(args.render)
    if renders:  # before anything is compiled or learned: a machine without OpenGL is told what to install
        offscreen.require(_without(args))
    where = common.world_and_task(args)  # the world and its task, checked once, before compiling
    layout = where[0]
    with common.phase("compiling arms"):  # before anything is written: a bad arm writes nothing
        options = arm_options(args)
        source = resolve(args.source, xml_path=args.arm_xml, progress=common.interactive(), layout=layout,
                         **options)
        target = resolve(args.target, xml_path=args.arm_xml, progress=common.interactive(), layout=layout,
                         **options)
        scenes: dict = {}  # the checked scenes, rendered from: each is built once
        if renders:  # a replay that cannot be made fails now, not after learning
            from armtransfer.ik.replay import check_replayable  # MuJoCo: not on --help's path

            for robot in (source, target):
                if robot.arm is not None:
                    scenes[id(robot)] = check_replayable(robot)
    with staged_directory(out) as tmp:
        result = _run_into(args, where, tmp, source, target, out, scenes)
        if args.json:
            write_json_atomic(args.json, result["json"])
        if args.render and result["video"]:
            tmp_video = tmp / result["video"]
            render = Path(args.render)
            if render.suffix.lower() == tmp_video.suffix.lower():
                copy_atomic(tmp_video, render)
            else:
                result["no_video"] = _try_video(result, args, render, scenes)
    print(f"wrote {out}/ ({', '.join(sorted(p.name for p in out.iterdir()))}) in {time.perf_counter() - t0:.0f} s")
    if result["no_video"]:
        print(f"armtransfer arms: wrote the results, table and figures but not the video: {result['no_video']}",
              file=sys.stderr)
        return 1
    return 0


def _without(args: argparse.Namespace) -> str:
    """How this run goes on without OpenGL."""
    return "run with --no-video" + (" and without --render" if args.render else "")


def _try_video(result: dict, args, path: Path, scenes: dict | None) -> str | None:
    """Render the video to ``path``; None when written, else why not (the render failed after
    the learning, e.g. the GL context could not be made, and the run keeps everything else)."""
    try:
        result["stats"] = _video(result, args, path, scenes)
    except OffscreenError as err:
        return str(err)
    return None


def _run_into(args: argparse.Namespace, where: tuple, tmp: Path, source: DiscreteRobot, target: DiscreteRobot,
              final: Path, scenes: dict | None = None) -> dict:
    """Everything into ``tmp``, which becomes ``final`` when complete (paths in results.json name ``final``).
    ``where``: the world and task (``common.world_and_task``); ``scenes``: the robots' checked
    scenes by ``id(robot)``, rendered from."""
    kwargs = {**common.transfer_kwargs(args, where), **_fast_overrides(args)}
    if args.source_planner == "learn" and not args.trajectory:
        kwargs["trajectory"] = ["learned"]
    elif not args.trajectory:
        kwargs["trajectory"] = ["optimal"]
    total = experiment.count_trials(args.method, kwargs["trials"], kwargs["controls"] and "learner" not in kwargs)
    with common.progress_bar(total, "learning") as bar:
        result = api.transfer(source, target, progress=bar.update, **kwargs)
    common.print_warnings(result)
    out_json = result.to_json()
    out_json["arms"] = {label: arm_json(r) for label, r in (("source", source), ("target", target))
                        if r.arm is not None}
    for label, r in (("source", source), ("target", target)):
        if r.arm is not None and (note := r.arm.clearance_note()):
            print(f"{label} {r.arm.name}: {note}")
    for label, arm in out_json["arms"].items():
        if arm["mount_source"] == "automatic":
            print(f"{label} {arm['name']}: automatic mount --base-pos={','.join(f'{v:.4g}' for v in arm['mount'])} "
                  f"--base-yaw={arm['yaw']:.4g} (reaches {100 * arm['reach']:.1f}% of the free cells)")
    print_results(out_json)
    write_json_atomic(tmp / "results.json", out_json)
    write_text_atomic(tmp / "table.md", _table_md(out_json))
    curves = {m: [t.episode_steps.tolist() for t in r.trials] for m, r in result.methods.items()}
    greedy = {m: r.column("greedy_steps") for m, r in result.methods.items()}
    figures.learning_curves(curves, f"{source.name} -> {target.name}: steps per episode", tmp / "learning_curves.png",
                            greedy=greedy)
    paths = _paths(result, source, target)
    layout = target.layout
    traj_xy = [list(layout.xy(c % layout.n_cells)) for c in paths["trajectory_cells"]] + [list(result.task.goal)]
    figures.mapping_paths(layout.wall_mask, layout.lo, traj_xy, paths["target_xy"] or traj_xy, [],
                          f"{source.name} (dashed) -> {target.name} (solid)", tmp / "map.png")
    video, no_video = None, None
    if not args.no_video:
        rendered: dict[str, Any] = {"paths": paths, "source": source, "target": target}
        no_video = _try_video(rendered, args, tmp / "rollout.mp4", scenes)
    if not args.no_video and no_video is None:
        video, stats = "rollout.mp4", rendered["stats"]
        # results.json stays the same for the same seed: wall-clock timings go to timings.json
        out_json["rollout"] = {k: v for k, v in stats.items() if k not in TIMINGS} | {"video": str(final / video)}
        write_json_atomic(tmp / "timings.json", {"rollout": {k: stats[k] for k in TIMINGS if k in stats}})
        write_json_atomic(tmp / "results.json", out_json)
        for label, rp in zip(("source", "target"), stats["replays"]):
            own = rp.get("file_servos")
            servos = (f" (the scene's own servos: the file's tracked {own['max_tracking_error_cells']:.2f} cell off"
                      f"{'' if own['reached_goal'] else ' and missed the goal'})" if own else "")
            motors = " (the file's torque motors, by computed torque)" if rp.get("torque_motors") else ""
            print(f"replay {label}: largest tip deviation {rp['max_deviation_cells']:.2f} cell, "
                  f"reached the goal cell: {'yes' if rp['reached_goal'] else 'no'}{servos}{motors}")
            if not rp["reached_goal"]:
                print(f"replay {label} missed the goal: {rp['shortfall']}")
    return {"json": out_json, "video": video, "paths": paths, "source": source, "target": target,
            "no_video": no_video}


def arm_json(robot: DiscreteRobot) -> dict:
    """What results.json says of an arm robot: its name, joints, tool, mount and reach."""
    arm = robot.arm
    assert arm is not None  # results.json describes arm robots only
    return {"name": arm.name, "robot": robot.name, "dof": arm.dof, "chain": list(arm.chain),
            "held": {n: v for n, v in arm.held}, "tool": arm.tool.key(), "mount": list(arm.mount),
            "yaw": arm.yaw, "mount_source": arm.mount_source, "reach": round(arm.reach, 6),
            "xml": arm.xml_path if arm.kind == "custom" else None}


def _paths(result, source: DiscreteRobot, target: DiscreteRobot) -> dict:
    """The source's transferred path and the target's converged greedy path (first
    converged trial of the first transfer method, named as ``target_method``; the target's
    shortest path when none converged), as states and cells, from the transfer's typed result."""
    layout = target.layout
    start, goal = layout.cell(*result.task.start), layout.cell(*result.task.goal)
    first = result.trajectories[0] if result.trajectories else None
    traj_cells = list(first.cells) if first is not None else []  # a voxel above the table: cell + level * cells
    if first is not None:
        traj = Trajectory(tuple(traj_cells), tuple(first.actions), goal, source=source.name)
        source_states = trajectories.states_along(source, traj)
    else:
        source_states = [source.start_state(start)]
    target_states, target_method = None, "shortest path"
    for method, run in result.methods.items():
        if method != "none":
            for trial in run.trials:
                if trial.greedy_path:
                    target_states, target_method = [int(s) for s, _ in trial.greedy_path], method
                    break
        if target_states:
            break
    if target_states is None:
        path = target.shortest_path(target.start_state(start), goal)
        assert path is not None  # run_transfer has checked that the target reaches the goal
        target_states = [s for s, _ in path]
    return {
        "trajectory_cells": traj_cells,
        "goal": goal,
        "source_states": source_states,
        "target_states": target_states,
        "target_method": target_method,
        "target_xy": [list(layout.xy(int(target.label[s]) % layout.n_cells)) for s in target_states],
    }


def _video(result: dict, args, path: Path, scenes: dict | None = None) -> dict:
    from armtransfer.ik.render import rollout_video  # MuJoCo: not on --help's path

    paths = result["paths"]
    fps = 10.0 if args.fast else 30.0
    size = (160, 120) if args.fast else (320, 240)
    with common.phase("rendering the rollout"):
        return rollout_video(
            [(result["source"], paths["source_states"]), (result["target"], paths["target_states"])],
            path, trajectory_cells=paths["trajectory_cells"], goal_cell=paths["goal"],
            width=size[0], height=size[1], fps=fps,
            scenes=[(scenes or {}).get(id(result[k])) for k in ("source", "target")], without=_without(args),
            labels=[[result["source"].name, "source: hands its path"],
                    [result["target"].name, f"target: {paths['target_method']}"]],
        )


def _table_md(out_json: dict) -> str:
    t = out_json["task"]
    return (
        f"# {out_json['source']} -> {out_json['target']}\n\n"
        + (f"world {out_json['world']}, " if out_json.get("world") else "")
        + f"{t['name']}: {tuple(t['start'])} -> {tuple(t['goal'])}; target's optimal distance "
        f"{out_json['distance']}; {out_json['trials']} trials, seed {out_json['seed']}"
        + (f", wind {out_json['wind']}" if out_json["wind"] else "")
        + (f", learner {out_json['learner']}" if out_json.get("learner") else "")
        + "\n\n" + results_table(out_json) + "\n"
    )
