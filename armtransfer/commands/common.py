"""Arguments and steps shared by the experiment commands."""

from __future__ import annotations

import argparse
import sys

from armtransfer.tasks.catalog import Task, custom_task, parse_xy, table_task
from armtransfer.errors import ArmModelError, InvalidParameterError, InvalidTaskError
from armtransfer.learning.config import LearnerConfig


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}")
    return value


def probability(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a probability in [0, 1], got {text!r}") from None
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"must be a probability in [0, 1], got {text!r}")
    return value


def k_value(text: str) -> float | str:
    if text == "auto":
        return text
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number >= 0 or 'auto', got {text!r}") from None
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be a number >= 0 or 'auto', got {text!r}")
    return value


def add_method_arguments(p: argparse.ArgumentParser, default: list[str] | None = None) -> None:
    from armtransfer.learning import mapping as mappings
    from armtransfer.learning import potentials
    from armtransfer.learning.experiment import METHODS

    default = default or ["none", "pseudo"]
    p.add_argument("--method", nargs="+", default=default, metavar="METHOD",
                   help=f"one or more of: {', '.join(METHODS)} (default: {' '.join(default)})")
    p.add_argument("--trajectory", action="append", default=None, metavar="KIND|PATH",
                   help="the transferred trajectory: optimal (the source's shortest path; default), "
                        "learned (its greedy path after learning), shuffled or random (controls), or a "
                        "JSON file; give it more than once to transfer several trajectories")
    p.add_argument("--no-controls", action="store_true",
                   help="skip the control runs (each transfer method again with a shuffled and a "
                        "random trajectory)")
    p.add_argument("--beta", type=float, default=potentials.DENSE_BETA,
                   help=f"method dense: indices lost per cell from the trajectory (default {potentials.DENSE_BETA})")
    p.add_argument("--mapping", default=None, metavar="PATH",
                   help="with --method mapping: the action sequence mapping to reuse (created when "
                        "absent) and to update, after the run, from every converged trial")
    p.add_argument("--max-span", type=positive_int, default=mappings.DEFAULT_MAX_SPAN,
                   help="longest source key learned from non-consecutive matches "
                        f"(default {mappings.DEFAULT_MAX_SPAN})")


TRAJECTORY_KINDS = ("optimal", "learned", "shuffled", "random")


def trajectory_specs(args: argparse.Namespace) -> list[str]:
    return args.trajectory or ["optimal"]


def task_for(args: argparse.Namespace) -> Task:
    """The task from --task/--start/--goal; a trajectory file alone also names its task."""
    from armtransfer.tasks.layout import ROOMS
    from armtransfer.learning import trajectory as trajectories

    files = [s for s in trajectory_specs(args) if s not in TRAJECTORY_KINDS]
    if args.task is None and args.start is None and args.goal is None and files:
        traj = trajectories.load(files[0])
        return Task("trajectory file", ROOMS.xy(traj.start), ROOMS.xy(traj.goal))
    return task_from_args(args)


def resolve_trajectories(specs: list[str] | None, source, task: Task, config, seed: int) -> list:
    """Each --trajectory: a kind made from the source robot, or a JSON file for this task."""
    from armtransfer.learning import experiment
    from armtransfer.learning import trajectory as trajectories

    start, goal = task.cells()
    out = []
    for spec in specs or ["optimal"]:
        if spec in ("optimal", "learned"):
            out.append(experiment.source_trajectory(spec, source, start, goal, config, seed))
        elif spec in ("shuffled", "random"):
            real = experiment.source_trajectory("optimal", source, start, goal, config, seed)
            out.extend(experiment.control_trajectories(spec, source, [real], seed))
        else:
            traj = trajectories.load(spec)
            trajectories.check_task(traj, start, goal)
            out.append(traj)
    return out


def add_task_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--task", type=int, default=None, help="Table I task 1-4 (default 1)")
    p.add_argument("--start", default=None, metavar="X,Y", help="start cell (with --goal)")
    p.add_argument("--goal", default=None, metavar="X,Y", help="goal cell (with --start)")


def task_from_args(args: argparse.Namespace) -> Task:
    if args.start is not None or args.goal is not None:
        if args.task is not None:
            raise InvalidTaskError("give either --task or --start/--goal, not both")
        if args.start is None or args.goal is None:
            raise InvalidTaskError("--start and --goal go together")
        return custom_task(parse_xy(args.start, "--start"), parse_xy(args.goal, "--goal"))
    return table_task(1 if args.task is None else args.task)


def add_learning_arguments(p: argparse.ArgumentParser, trials: int = 10) -> None:
    d = LearnerConfig()
    p.add_argument("--trials", type=positive_int, default=trials, help=f"trials per method (default {trials})")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--wind", type=probability, default=0.0, help="wind probability (paper: 0.01; default 0)")
    p.add_argument("--K", type=k_value, default="auto",
                   help="pseudo reward scale; 'auto' = half the farming bound -step_reward/n (default)")
    p.add_argument("--alpha", type=float, default=d.alpha, help=f"learning rate (default {d.alpha})")
    p.add_argument("--gamma", type=float, default=d.gamma, help=f"discount (default {d.gamma})")
    p.add_argument("--lam", type=float, default=d.lam, help=f"trace decay lambda (default {d.lam})")
    p.add_argument("--epsilon", type=float, default=d.epsilon, help=f"exploration rate (default {d.epsilon})")
    p.add_argument("--step-reward", type=float, default=d.step_reward, help=f"reward per step (default {d.step_reward})")
    p.add_argument("--goal-reward", type=float, default=d.goal_reward, help=f"reward at the goal (default {d.goal_reward})")
    p.add_argument("--max-episodes", type=positive_int, default=d.max_episodes,
                   help=f"episodes per trial at most (default {d.max_episodes})")
    p.add_argument("--patience", type=positive_int, default=d.patience,
                   help=f"episodes the greedy path must stay the same to count as converged (default {d.patience})")


def config_from_args(args: argparse.Namespace) -> LearnerConfig:
    return LearnerConfig(
        alpha=args.alpha,
        gamma=args.gamma,
        lam=args.lam,
        epsilon=args.epsilon,
        step_reward=args.step_reward,
        goal_reward=args.goal_reward,
        max_episodes=args.max_episodes,
        patience=args.patience,
    )


def interactive() -> bool:
    """Progress output only on a terminal."""
    return sys.stderr.isatty()


class phase:
    """A progress bar for one step of unknown length (compiling, rendering): it shows the
    step and, when done, how long it took; silent when not on a terminal."""

    def __init__(self, desc: str) -> None:
        self.desc = desc

    def __enter__(self):
        self.bar = progress_bar(1, self.desc)
        self.bar.__enter__()
        return self.bar

    def __exit__(self, *exc):
        if exc[0] is None:
            self.bar.update()
        return self.bar.__exit__(*exc)


def progress_bar(total: int, desc: str):
    """A tqdm bar on a terminal, nothing otherwise."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, disable=not sys.stderr.isatty(), leave=False)


def check_methods(methods: list[str], valid: tuple[str, ...]) -> None:
    for m in methods:
        if m not in valid:
            raise InvalidParameterError(f"unknown method {m!r}; valid methods: {', '.join(valid)}")


def parse_base_pos(text: str | None):
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
        if len(values) != 3:
            raise ValueError
    except ValueError:
        raise ArmModelError(f"--base-pos must be three numbers 'X,Y,Z', got {text!r}") from None
    return values
