"""Arguments and steps shared by the experiment commands."""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import fields

from armtransfer.api import TRAJECTORY_KINDS
from armtransfer.checks import MAX_COUNT, integer_text
from armtransfer.errors import ArmModelError, ArmTransferError, InvalidParameterError, InvalidTaskError
from armtransfer.experiments.learner_trial import refuse_methods
from armtransfer.ik.tool import parse_held, parse_offset
from armtransfer.learning import mapping as mappings, methods, potentials, presets
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.learners import LEARNERS, SARSA, get
from armtransfer.learning.method import MAX_K, check_k
from armtransfer.learning.plugin_calls import MAX_PROBE_SECONDS, PROBE_SECONDS, probe_seconds
from armtransfer.tasks.arms import check_arm_name
from armtransfer.tasks.catalog import Task, custom_task, parse_xy, world_task
from armtransfer.worlds.layout import Layout
from armtransfer.worlds.resolve import DEFAULT_WORLD, VALID, is_default, world


def _integer_at_least(lo: int, what: str):
    def parse(text: str) -> int:
        value = integer_text(text.strip())  # the one grammar of an integer: no '²', no 10,000 digits
        if value is None or not lo <= value <= MAX_COUNT:
            raise argparse.ArgumentTypeError(f"must be {what} (at most {MAX_COUNT:,}), got {text[:40]!r}")
        return value

    return parse


positive_int = _integer_at_least(1, "a positive integer")
non_negative_int = _integer_at_least(0, "an integer >= 0")


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
        return check_k(float(text))
    except (ValueError, ArmTransferError):
        raise argparse.ArgumentTypeError(f"must be 'auto' or a number in [0, {MAX_K:g}], got {text!r}") from None


def probe_timeout(text: str) -> float:
    try:
        return probe_seconds(float(text))
    except (ValueError, ArmTransferError):
        raise argparse.ArgumentTypeError(f"must be a number of seconds in (0, {MAX_PROBE_SECONDS:g}], "
                                         f"got {text!r}") from None


def add_probe_timeout_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--probe-timeout", type=probe_timeout, default=PROBE_SECONDS, metavar="SECONDS",
                   help="the time limit of each plugin's probe (a method's potential built once, an outside learner "
                        "learning a few steps) before anything is run; a plugin that overruns it is named in one line "
                        f"(default {PROBE_SECONDS:g})")


def add_method_arguments(p: argparse.ArgumentParser, default: list[str] | None = None) -> None:
    default = default or ["none", "pseudo"]
    listing = "; ".join(f"{m.name}: {m.description}" for m in methods.METHODS.values())
    p.add_argument("--method", nargs="+", default=default, metavar="METHOD",
                   help=f"one or more methods (default: {' '.join(default)}). {listing}")
    p.add_argument("--trajectory", action="append", default=None, metavar="KIND|PATH",
                   help=f"the transferred trajectory: one of {', '.join(TRAJECTORY_KINDS)} (learned: the "
                        "source's converged greedy path, the paper's protocol and the default; optimal: its "
                        "shortest path; shuffled, random: controls), or a JSON file; give it more than once "
                        "to transfer several trajectories")
    p.add_argument("--no-controls", action="store_true",
                   help="skip the control runs (each reward-only method again with a shuffled and a "
                        "random trajectory)")
    p.add_argument("--beta", type=non_negative_float, default=potentials.DENSE_BETA,
                   help=f"method dense: indices lost per cell from the trajectory (default {potentials.DENSE_BETA})")
    p.add_argument("--mapping", default=None, metavar="PATH",
                   help="with --method mapping: the action sequence mapping to reuse (created when "
                        "absent) and to update, after the run, from every converged trial")
    p.add_argument("--max-span", type=positive_int, default=mappings.DEFAULT_MAX_SPAN,
                   help="longest source key learned from non-consecutive matches "
                        f"(default {mappings.DEFAULT_MAX_SPAN})")


def add_world_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--world", default=None, metavar="NAME|PATH",
                   help=f"the world the robots move in (default {DEFAULT_WORLD}, the paper's 51 x 51 rooms): "
                        f"{VALID} (docs/worlds.md)")


def world_of(args: argparse.Namespace):
    """The world --world names (the paper's rooms without it), checked: a one-line error for
    an unknown name or a bad layout file."""
    return world(getattr(args, "world", None))


def refuse_world(args: argparse.Namespace, command: str, why: str) -> None:
    """``command`` runs on the paper's rooms only: any other world is a one-line error saying
    ``why`` (a world that does not load names its own fault first)."""
    if getattr(args, "world", None) is not None and not is_default(world_of(args)):
        raise InvalidParameterError(f"--world {str(args.world)[:100]} does not apply to {command}: {why}; "
                                    f"valid worlds: {DEFAULT_WORLD}")


def add_task_arguments(p: argparse.ArgumentParser) -> None:
    add_world_argument(p)
    p.add_argument("--task", default=None, metavar="NAME",
                   help="a task of the world: Table I task 1-4 on rooms (default: the world's first task)")
    p.add_argument("--start", default=None, metavar="X,Y", help="start cell (with --goal)")
    p.add_argument("--goal", default=None, metavar="X,Y", help="goal cell (with --start)")


def add_learning_arguments(p: argparse.ArgumentParser, trials: int = 10) -> None:
    """--trials, --seed, --wind, --K, --preset and one flag per settable LearnerConfig field."""
    p.add_argument("--trials", type=positive_int, default=trials, help=f"trials per method (default {trials})")
    p.add_argument("--seed", type=non_negative_int, default=0, help="random seed, an integer >= 0 (default 0)")
    p.add_argument("--wind", type=probability, default=0.0, help="wind probability (paper: 0.01; default 0)")
    p.add_argument("--K", type=k_value, default="auto",
                   help="pseudo reward scale; 'auto' = the method's default (pseudo: half the farming "
                        "bound -step_reward/n)")
    add_config_arguments(p)
    add_learner_argument(p)


def add_learner_argument(p: argparse.ArgumentParser, several: bool = False) -> None:
    """--learner: who learns on the target, the built-in sarsa or a learner of
    ``armtransfer.LEARNERS`` (its installed plugins read now, so that --help lists them)."""
    learned = "; ".join(f"{name}: {lr.description}" for name, lr in LEARNERS.items())
    p.add_argument("--learner", default=SARSA, metavar="NAME[,NAME...]" if several else "NAME",
                   help=("the learners, comma-separated, each running every method beside the none it runs"
                         if several else "the learner of the target, each method beside the none it runs")
                        + " (an outside learner runs none and the reward-term methods through the benchmark's "
                        "harness, within --max-total-steps steps a trial: give it a budget; no controls; docs/extending.md); "
                        f"default {SARSA}. Learners: {learned}")


def check_learner(args: argparse.Namespace, flag: str = "--method") -> None:
    """--learner checked before anything is built: a known learner (a typo lists them) that
    runs every method of ``flag`` (else one line listing the methods it runs)."""
    learner = get(args.learner)
    if learner.name != SARSA:
        refuse_methods(learner, getattr(args, flag.lstrip("-")))


def add_preset_argument(p: argparse.ArgumentParser) -> None:
    """--preset: a named set of learner settings (``learning.presets``) that the flags override."""
    p.add_argument("--preset", type=preset_name, default=presets.DEFAULT, metavar="NAME",
                   help=f"learner settings by name, which the learner's flags override: {', '.join(presets.names())} "
                        "(default: default; paper-calibrated: fitted to the paper's no-transfer columns, "
                        "docs/methods.md)")


def preset_name(text: str) -> str:
    if text not in presets.PRESETS:
        raise argparse.ArgumentTypeError(f"unknown preset {text!r}; valid presets: {', '.join(presets.names())}")
    return text


def add_config_arguments(p: argparse.ArgumentParser) -> None:
    """--preset and one flag per LearnerConfig field, made from the field (name, type, default,
    help). A flag not given is None, so that the preset's value (or the field's default) holds."""
    add_preset_argument(p)
    for f in fields(LearnerConfig):
        if not f.metadata.get("cli"):
            continue
        integer = f.type in (int, "int")
        p.add_argument(f"--{f.name.replace('_', '-')}", dest=f.name, default=None,
                       type=positive_int if integer else finite_float,
                       help=f"{f.metadata['help']} (default {f.default:,})" if integer
                       else f"{f.metadata['help']} (default {f.default:g})")


def non_negative_float(text: str) -> float:
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text!r}")
    return value


def finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def config_options(args: argparse.Namespace) -> dict:
    """The LearnerConfig fields the command line set, and its preset, as API keyword options."""
    out = {f.name: getattr(args, f.name) for f in fields(LearnerConfig)
           if f.metadata.get("cli") and getattr(args, f.name) is not None}
    return {"preset": args.preset, **out}


def _cells(args: argparse.Namespace) -> tuple[tuple[int, int], tuple[int, int]] | None:
    """--start and --goal as cells (None when neither is given), checked against --task."""
    if args.start is None and args.goal is None:
        return None
    if args.task is not None:
        raise InvalidTaskError("give either --task or --start/--goal, not both")
    if args.start is None or args.goal is None:
        raise InvalidTaskError("--start and --goal go together")
    return parse_xy(args.start, "--start"), parse_xy(args.goal, "--goal")


def _task_in(layout: Layout, args: argparse.Namespace, cells) -> Task | None:
    """The task --task or --start/--goal (``cells``) name in the world ``layout``; None when
    neither is given (the API's default: a trajectory file's task, else the world's first)."""
    if args.task is not None:
        return world_task(layout, args.task)
    if cells is not None:
        return custom_task(cells[0], cells[1], layout)
    return None


def world_and_task(args: argparse.Namespace) -> tuple[Layout, Task | None]:
    """The world --world names and the task of --task or --start/--goal in it, each checked once
    (a one-line error naming the flag) and handed down typed: the API checks them no more."""
    cells = _cells(args)
    layout = world_of(args)
    return layout, _task_in(layout, args, cells)


def transfer_kwargs(args: argparse.Namespace, where: tuple[Layout, Task | None] | None = None) -> dict:
    """The keyword arguments of ``armtransfer.transfer`` that the common flags give. The world
    and task are ``where`` (:func:`world_and_task`, when the command checked them already) or
    checked here, so that errors name the flags."""
    cells = _cells(args) if where is None else None
    if args.mapping is not None and "mapping" not in args.method:
        raise InvalidParameterError("--mapping goes with --method mapping")
    refuse_unused_method_options(args)
    if where is None:
        layout = world_of(args)
        where = layout, _task_in(layout, args, cells)  # an unknown task is named before anything is done
    world, task = where
    return dict(
        world=world, task=task, methods=args.method, trials=args.trials, seed=args.seed,
        wind=args.wind, K=args.K, beta=args.beta, trajectory=args.trajectory, controls=not args.no_controls,
        mapping=args.mapping, save_mapping=args.mapping is not None, max_span=args.max_span,
        probe_timeout=getattr(args, "probe_timeout", 60.0),
        **({} if args.learner == "sarsa" else {"learner": args.learner}), **config_options(args),
    )


def refuse_unused_method_options(args: argparse.Namespace, flag: str = "--method") -> None:
    """A method's option given (different from its default) while no method of ``flag``
    uses it is an error naming the methods that do, instead of being silently ignored."""
    names = getattr(args, flag.lstrip("-"))
    chosen = [methods.get(m) for m in names]
    users = {
        "--beta": ("beta", [m for m in methods.METHODS.values() if m.name == "dense"]),
        "--max-span": ("max_span", [m for m in methods.METHODS.values() if m.macros]),
        "--K": ("K", [m for m in methods.METHODS.values() if m.shaped]),
        "--trajectory": ("trajectory", [m for m in methods.METHODS.values() if m.shaped and m.uses_trajectory]),
    }
    parser_defaults = {a.dest: a.default for a in options_of(args)}
    for option, (dest, using) in users.items():
        if dest in parser_defaults and getattr(args, dest) != parser_defaults[dest] \
                and not any(m in using for m in chosen):
            raise InvalidParameterError(
                f"{option} does not apply to {flag} {' '.join(names)}; it goes with the methods "
                f"{', '.join(m.name for m in using)}")


def _flag(action: argparse.Action) -> str:
    return action.option_strings[-1] if action.option_strings else str(action.metavar or action.dest)


def options_of(args: argparse.Namespace) -> list[argparse.Action]:
    """The options and positionals of the parser that made ``args`` (none without one)."""
    parser = getattr(args, "_parser", None)
    return [a for a in (parser._actions if parser else []) if a.dest not in ("help", argparse.SUPPRESS)]


def refuse_empty(args: argparse.Namespace) -> None:
    """An empty or blank value is an error, never "not given" (``--json ''`` wrote nothing)."""
    for action in options_of(args):
        value = getattr(args, action.dest, None)
        values = value if isinstance(value, list) else [value]
        if any(isinstance(v, str) and not v.strip() for v in values):
            raise InvalidParameterError(f"{_flag(action)} must not be empty")


def refuse_other_options(args: argparse.Namespace, allowed: set[str], mode: str) -> None:
    """Options given (different from their default) that ``mode`` does not use are an error
    listing the options it does use, instead of being silently ignored."""
    actions = options_of(args)
    for action in actions:
        if action.option_strings and action.dest not in allowed \
                and getattr(args, action.dest, action.default) != action.default:
            valid = ", ".join(_flag(a) for a in actions if a.dest in allowed and a.option_strings)
            raise InvalidParameterError(f"{_flag(action)} does not apply to {mode}; its options: {valid}")


def print_warnings(result) -> None:
    """One ``warning:`` line on stderr for each distinct warning of a transfer's methods (a
    potential of one's own that the bound squashed, constant or not 0 at the goal)."""
    said = dict.fromkeys(w for m in result.methods.values() for w in m.extra.get("warnings", ()))
    for line in said:
        print(f"warning: {line}", file=sys.stderr)


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
    from tqdm import tqdm  # start-up: only when a bar is shown

    return tqdm(total=total, desc=desc, disable=not sys.stderr.isatty(), leave=False)



def add_arm_file_arguments(parser: argparse.ArgumentParser) -> None:
    """--arm-xml and its options: a bring-your-own arm, named ``custom`` or by its name."""
    parser.add_argument("--arm-xml", metavar="PATH",
                        help="a bring-your-own MJCF arm (a MuJoCo Menagerie file works as it is); its "
                             "robot is 'custom[:ACTIONS]' or 'NAME[:ACTIONS]', NAME its --arm-name or else "
                             "its MJCF model attribute, as 'arms list' prints it")
    parser.add_argument("--tip-site", metavar="NAME", default=None,
                        help="the tool point of --arm-xml is this site (default: a site named tip)")
    parser.add_argument("--tip-body", metavar="NAME", default=None,
                        help="the tool point of --arm-xml is this body's origin (instead of --tip-site)")
    parser.add_argument("--tip-offset", metavar="X,Y,Z", default=None,
                        help="the tool point is this far (m) from the tip site or body, in its own frame; "
                             "the tool's axis, kept pointing down, runs along it (e.g. 0,0,0.12)")
    parser.add_argument("--tool", metavar="stylus[:LENGTH[:RADIUS]]", default=None,
                        help="a pen held at the tool point of --arm-xml along its axis, LENGTH and RADIUS in "
                             "metres (default 0.05 and 0.0015): a gripper then rides above the walls, and the "
                             "cell is read at the pen's end (a spatial arm, its tool kept pointing down)")
    parser.add_argument("--arm-name", metavar="NAME", default=None,
                        help="the name of --arm-xml in tables, plots, JSON and the cache (default: its "
                             "MJCF model attribute)")
    parser.add_argument("--base-pos", metavar="X,Y,Z", default=None,
                        help="base position of --arm-xml in the table frame, metres (tabletop z=0, "
                             "table centre at the origin); default: chosen automatically, the pose that "
                             "reaches the most cells; write negative values as --base-pos=-0.1,0,0")
    parser.add_argument("--base-yaw", metavar="RAD", type=float, default=None,
                        help="rotation of --arm-xml's base about z (rad); default: facing the table")


def parse_base_pos(text: str | None):
    if text is None:
        return None
    try:
        values = tuple(float(v) for v in text.split(","))
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise ValueError
    except ValueError:
        raise ArmModelError(f"--base-pos must be three finite numbers 'X,Y,Z' (metres), got {text!r}") from None
    return values


def check_arm_flags(args: argparse.Namespace) -> None:
    """The arm flags of ``arms``: a finite positive cell size, and the bring-your-own arm's
    options only with --arm-xml (they would be silently ignored otherwise)."""
    if getattr(args, "cell_size", None) is not None and not (math.isfinite(args.cell_size) and args.cell_size > 0):
        raise ArmModelError(f"--cell-size must be a positive number of metres, got {args.cell_size!r}")
    flags = (("--base-pos", "base_pos"), ("--base-yaw", "base_yaw"), ("--tip-site", "tip_site"),
             ("--tip-body", "tip_body"), ("--tip-offset", "tip_offset"), ("--tool", "tool"),
             ("--arm-name", "arm_name"))
    if not getattr(args, "arm_xml", None):
        given = [flag for flag, attr in flags if getattr(args, attr, None) is not None]
        if given:
            raise ArmModelError(f"{given[0]} goes with --arm-xml PATH (a bring-your-own arm)")
    else:
        arm_file_options(args)
    if args.base_yaw is not None and not math.isfinite(args.base_yaw):
        raise ArmModelError(f"--base-yaw must be a finite number of radians, got {args.base_yaw!r}")


def arm_file_options(args: argparse.Namespace) -> dict:
    """The bring-your-own arm's options as ``arm_robot`` keywords, checked."""
    if args.tip_site is not None and args.tip_body is not None:
        raise ArmModelError("give --tip-site or --tip-body, not both")
    if args.arm_name is not None and not args.arm_name.strip():
        raise ArmModelError("--arm-name must not be empty")
    if args.arm_name is not None:
        check_arm_name(args.arm_name, "--arm-name")
    return dict(tip_site=args.tip_site, tip_body=args.tip_body,
                tip_offset=parse_offset(args.tip_offset) if args.tip_offset is not None else None,
                tool=parse_held(args.tool).spec() if getattr(args, "tool", None) is not None else None,
                arm_name=args.arm_name, base_pos=parse_base_pos(args.base_pos), base_yaw=args.base_yaw)
