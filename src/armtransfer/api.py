"""The Python API: one call runs what ``armtransfer rooms`` and ``armtransfer arms`` run.

    import armtransfer
    r = armtransfer.transfer(source="coarse", target="fine", task=1,
                             methods=["none", "pseudo"], trials=3, seed=1)
    r.methods["pseudo"].column("exploration_steps")   # per trial
    r.to_json()                                        # what `rooms --json` writes

Robots are specs (``"coarse"``, ``"planar2:joint"``, ``"custom:cartesian"`` with ``arm_xml=``)
or ``DiscreteRobot`` objects. Every bad input raises an ``armtransfer.errors.ArmTransferError``
with a one-line message before any learning starts.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import armtransfer.checks as checks
from armtransfer.errors import InvalidCellError, InvalidParameterError, InvalidTaskError
from armtransfer.experiments import continuous as runs, engines, experiment, learner_trial
from armtransfer.experiments.continuous import ContinuousResult
from armtransfer.experiments.learner_trial import refuse_methods
from armtransfer.experiments.results import MappingInfo, TransferResult
from armtransfer.io import check_writable
from armtransfer.learning import learners, potentials, presets
from armtransfer.learning import methods as registry
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.cells import CELL_METHODS, check_method
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.controls import CONTROLS
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.mapping import DEFAULT_MAX_SPAN, ActionMapping
from armtransfer.learning.mapping import load_for as load_mapping
from armtransfer.learning.method import check_k
from armtransfer.learning.plugin_calls import probe_seconds
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.arms import walls_cause
from armtransfer.tasks.catalog import Task, as_xy, custom_task, table_task, world_task
from armtransfer.tasks.continuous import ARM_KEYWORDS, continuous_arm
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.tasks.specs import resolve
from armtransfer.tasks.unreachable import hint
from armtransfer.worlds.layout import ROOMS, Layout
from armtransfer.worlds.resolve import world as resolve_world

TRAJECTORY_KINDS = ("optimal", "learned", "shuffled", "random")
"""``learned``: the source's converged greedy path after SARSA(lambda), the paper's protocol
(the default); ``optimal``: its shortest path; ``shuffled``/``random``: control trajectories."""

TrajectorySpec = str | Trajectory

STATES = engines.STATES
"""How the target robot's state is known: ``discrete``, its table of states (the tabular
learner); ``continuous``, its joint configuration with MuJoCo at every move and the linear
learner over tile coding (``ik.continuous``, ``learning.linear``; planar arms, the ``joint``
action model)."""


def transfer(
    source: str | DiscreteRobot = "coarse",
    target: str | DiscreteRobot = "fine",
    *,
    task: int | str | Task | None = None,
    start: tuple[int, int] | str | None = None,
    goal: tuple[int, int] | str | None = None,
    methods: Sequence[str] = ("none", "pseudo"),
    trials: int = 10,
    seed: int = 0,
    wind: float = 0.0,
    K: float | str = "auto",
    beta: float | None = None,
    trajectory: TrajectorySpec | Sequence[TrajectorySpec] | None = None,
    controls: bool = True,
    baselines: bool = True,
    mapping: str | Path | ActionMapping | None = None,
    save_mapping: bool = False,
    max_span: int = DEFAULT_MAX_SPAN,
    arm_xml: str | Path | None = None,
    arm_options: dict | None = None,
    progress: Callable[[], None] | None = None,
    state: str = "discrete",
    world: str | Path | Layout | None = None,
    preset: str = "default",
    noise: float = 0.0,
    learner: str = "sarsa",
    probe_timeout: float = 60.0,
    **learner_options,
) -> TransferResult | ContinuousResult:
    """Transfer a trajectory from ``source`` to ``target`` and learn with each method.

    ``task`` is a Table I task (1-4) or give ``start`` and ``goal`` cells; with neither, a
    trajectory file names its task, else task 1. A :class:`~armtransfer.tasks.catalog.Task`
    (the command line's, checked once there) is taken as it is, in its own world. ``trajectory`` is one or several of
    :data:`TRAJECTORY_KINDS`, trajectory JSON files or :class:`Trajectory` objects (default
    ``learned``). ``controls`` also runs every reward-only method with a shuffled and a
    random trajectory, each trial with its own draw (``experiment.run_control``). ``baselines``
    also runs the baselines sharing their learners (``learning.methods.with_baselines``).
    ``mapping`` (method ``mapping``) is a mapping or its JSON file, updated with ``save_mapping``.
    ``learner_options`` are :class:`LearnerConfig` fields (``alpha``, ``epsilon``, ...), over
    the settings of ``preset`` (``learning.presets``: ``default`` or ``paper-calibrated``).
    ``progress`` is called after every trial.

    ``world`` is where the robots move: ``"rooms"`` (the paper's, the default), ``"rooms11"``,
    ``"rooms15"``, ``"generated:SEED[:SIDE]"``, a layout file or a ``Layout``
    (:mod:`armtransfer.worlds`); ``task`` is then one of its task names. Robots given as
    ``DiscreteRobot`` objects bring their own world when ``world`` is None.

    ``state="continuous"``: the target is an arm (``"planar3:joint"``; a spatial arm such as
    ``"ur5e_like:joint"`` moves its joint robot's three joints over the 3D workspace, with
    hashed tiles; an arm file ``"PATH.xml"``, or ``"custom"`` with ``arm_xml=``) whose state is its joint configuration,
    learned by linear SARSA(lambda) over tile coding (:data:`STATES`); the methods are those
    paid on labels alone (``learning.cells.CELL_METHODS``), no controls or mapping are run, and
    the result is an ``experiments.continuous.ContinuousResult``. ``noise`` (continuous only) is
    the arm's actuation noise sigma (``ik.continuous``: each move turns delta * (1 + eps)).

    ``learner`` is who learns on the target: ``sarsa`` (the default), the compiled SARSA(lambda)
    kernel, or a learner of ``armtransfer.LEARNERS`` from outside the package (an installed
    plugin's, or one given to ``armtransfer.register_learner``). An outside learner runs each
    method through the benchmark's harness (``experiments.learner_transfer``) on the same case
    and seeds, ``none`` (run by it too) its baseline, within ``max_total_steps`` steps a trial;
    it runs ``none`` and the reward-term methods (another is refused in one line listing them)
    and no controls (a control trajectory ends elsewhere than the task's goal), and is probed
    before anything else is learned, so a learner that raises is refused in one line naming it.

    ``probe_timeout``: the time limit in seconds of the probe of each plugin (a method's potential
    or bonus built once on the target, an outside learner made, learning a few steps and
    predicting), run before anything is learned in a child process that is then ended; a plugin
    that overruns it is named in one line with the call that overran. With ``progress`` given, an
    outside learner's trial that runs longer than 30 s says how far it has got on stderr every 30 s.
    """
    req = _checked(dict(locals()))
    if req.engine.name == engines.CONTINUOUS:
        return _transfer_continuous(req)
    src, tgt, distance = _discrete_pair(req)
    if req.engine.name == engines.OUTSIDE:
        return _transfer_outside(req, src, tgt, distance)
    return _transfer_tabular(req, src, tgt, distance)


@dataclass(frozen=True)
class _Request:
    """A transfer's inputs, each checked once, in :func:`transfer`'s terms."""

    source: str | DiscreteRobot
    target: str | DiscreteRobot
    task: Task
    methods: list[str]
    trials: int
    seed: int
    wind: float
    K: float | str
    beta: float | None
    specs: list
    controls: bool
    mapping: str | Path | ActionMapping | None
    save_mapping: bool
    uses_mapping: bool
    max_span: int
    arm_xml: str | None
    options: dict
    progress: Callable[[], None] | None
    state: str
    config: LearnerConfig
    noise: float
    outside: Any
    probe_timeout: float
    engine: engines.Engine
    """Who learns (``experiments.engines``): the kernel, the continuous learner or the outside one."""


def _checked(a: dict[str, Any]) -> _Request:
    """:func:`transfer`'s arguments ``a`` checked, each once and in this order (the first fault
    is the one line raised), before anything is built or learned."""
    state = a["state"]
    if not isinstance(state, str) or state not in STATES:
        raise InvalidParameterError(f"unknown state {state!r}; valid states: {', '.join(STATES)}")
    config = presets.config(a["preset"], a["learner_options"])
    method_names = [registry.get(m).name for m in _as_sequence(a["methods"], "methods")]
    if not method_names:
        raise InvalidParameterError(f"give at least one method; valid methods: {', '.join(registry.METHODS)}")
    outside = _outside_learner(a["learner"])
    engine = engines.engine_for(SARSA if outside is None else outside.name, state)
    if engine.name == engines.OUTSIDE:
        refuse_methods(outside, method_names)
    if state == "continuous":  # the methods asked for, before their baselines join them
        for m in method_names:
            check_method(m)
    if checks.flag(a["baselines"], "baselines"):
        method_names = registry.with_baselines(method_names)
    trials = checks.whole(a["trials"], "trials", 1, checks.MAX_TRIALS)
    seed = checks.whole(a["seed"], "seed", 0)
    wind = checks.probability(a["wind"], "wind")
    max_span = checks.whole(a["max_span"], "max_span", 1)
    controls = checks.flag(a["controls"], "controls")
    save_mapping = checks.flag(a["save_mapping"], "save_mapping")
    progress = a["progress"]
    if progress is not None and not callable(progress):
        raise InvalidParameterError(f"progress must be a function called after every trial, got {progress!r}")
    K = check_k(a["K"])
    probe_timeout = probe_seconds(a["probe_timeout"])
    beta = None if a["beta"] is None else checks.real(a["beta"], "beta", 0.0)
    arm_xml = None if a["arm_xml"] is None else checks.path(a["arm_xml"], "arm_xml")
    options = _arm_options(a["arm_options"])
    world = a["task"].layout if a["world"] is None and isinstance(a["task"], Task) else a["world"]
    layout = _world(world, a["source"], a["target"])
    specs = list(_as_sequence(a["trajectory"], "trajectory")) if a["trajectory"] is not None else ["learned"]
    uses_mapping = any(registry.get(m).macros for m in method_names)
    mapping = a["mapping"]
    if mapping is not None and not uses_mapping:
        raise InvalidParameterError("a mapping goes with method 'mapping'")
    if mapping is not None and not isinstance(mapping, ActionMapping):
        mapping = checks.path(mapping, "mapping")
    if save_mapping and not isinstance(mapping, (str, Path)):
        raise InvalidParameterError("save_mapping needs the mapping's file path")
    the_task = _task(a["task"], a["start"], a["goal"], specs, layout)
    the_task.cells()
    noise = checks.real(a["noise"], "noise (the actuation noise sigma)", 0.0, 0.5)
    if noise and state != "continuous":
        raise InvalidParameterError("noise (actuation noise) applies to a continuous target; a discrete one has "
                                    "wind; valid noise: 0")
    if state == "continuous":
        if wind:
            raise InvalidParameterError("a continuous target has no wind; valid wind: 0")
        if mapping is not None or uses_mapping:
            raise InvalidParameterError("the action sequence mapping needs a discrete target; valid methods for a "
                                        "continuous one: " + ", ".join(CELL_METHODS))
    return _Request(a["source"], a["target"], the_task, method_names, trials, seed, wind, K, beta, specs, controls,
                    mapping, save_mapping, uses_mapping, max_span, arm_xml, options, progress, state, config, noise,
                    outside, probe_timeout, engine)


def _discrete_pair(req: _Request) -> tuple[DiscreteRobot, DiscreteRobot, int]:
    """(source, target, the target's shortest path in steps): both robots built in the task's world,
    the task's start and goal checked for both, both able to reach the goal (the source must solve
    the task too, to hand over its path), and every plugin the methods use probed on the target."""
    layout = req.task.layout
    src = resolve(req.source, xml_path=req.arm_xml, layout=layout, **req.options)
    tgt = resolve(req.target, xml_path=req.arm_xml, layout=layout, **req.options)
    start_cell, goal_cell = req.task.cells()
    for robot in (src, tgt):
        try:
            robot.start_state(start_cell)
            robot.start_state(goal_cell, what="goal")
        except InvalidCellError as err:
            raise InvalidCellError(_with_walls_cause(str(err), robot)) from None
    paths: dict[str, list[tuple[int, int]]] = {}
    for robot in (tgt, src):
        found = robot.shortest_path(robot.start_state(start_cell), goal_cell)
        if found is None:
            raise InvalidTaskError(_with_walls_cause(
                f"robot {robot.name} cannot reach the goal {req.task.goal} from {req.task.start}", robot))
        paths[robot.name] = found
    registry.probe_on(req.methods, [tgt], req.probe_timeout)  # a plugin's fault or overrun: one line, now
    return src, tgt, len(paths[tgt.name]) - 1


def _transfer_tabular(req: _Request, src: DiscreteRobot, tgt: DiscreteRobot, distance: int) -> TransferResult:
    """``transfer`` by the compiled SARSA(lambda) kernel: every method, then (``controls``) every
    reward-only method with each control's stand-ins, then the action sequence mapping saved;
    each a :class:`~armtransfer.experiments.work.Work` for the engine."""
    start_cell, goal_cell = req.task.cells()
    mapping_obj, mapping_path = None, None
    if req.uses_mapping:
        if isinstance(req.mapping, ActionMapping):
            mapping_obj = req.mapping
        elif req.mapping is not None:
            mapping_path = str(req.mapping)
            if req.save_mapping:
                check_writable(mapping_path)
            mapping_obj = load_mapping(mapping_path, src, tgt)
        if mapping_obj is not None:
            mapping_obj.check_new_task(start_cell, goal_cell, tgt.layout)
    shaped = any(registry.get(m).shaped and registry.get(m).uses_trajectory for m in req.methods)
    trajs = resolve_trajectories(req.specs, src, req.task, req.config, req.seed) if shaped else []
    # every method's shaping, made before any learning and used by its run: a farmable method's
    # K checked by value iteration over the shaped task (refused in one line naming the largest
    # safe K; 'auto' is verified), the controls given the same K
    beta = potentials.DENSE_BETA if req.beta is None else req.beta
    shapings = {}
    for m in req.methods:
        made = experiment.method_shaping(m, tgt, tgt.start_state(start_cell), goal_cell, trajs, req.K, req.config,
                                         req.wind, beta)
        if made is not None:
            shapings[m] = made
    experiment.check_trajectories(req.methods, trajs)
    entries_before = 0 if mapping_obj is None else len(mapping_obj)
    if req.uses_mapping and mapping_obj is None:
        mapping_obj = ActionMapping.for_robots(src, tgt)

    def work(m: str, control: str | None = None) -> engines.Work:
        return engines.Work(m, tgt.name, req.task.start, req.task.goal, req.trials, req.seed, req.config,
                            wind=req.wind, K=shapings[m].K if m in shapings else "auto", beta=beta,
                            on_trial=req.progress, control=control, source=src,
                            shaping=None if control else shapings.get(m),
                            mapping=mapping_obj if registry.get(m).macros and not control else None,
                            max_span=req.max_span)

    works = [work(m) for m in req.methods]
    if req.controls:  # the same K as the real trajectory's
        works += [work(m, kind) for kind in CONTROLS for m in req.methods if m in experiment.SHAPING_METHODS]
    runs = [req.engine.trials(w, tgt, trajs if registry.get(w.method).shaped else None) for w in works]
    by_method, by_control = _by_method_and_control(runs)
    learned = next((r.learned_mapping for r in reversed(runs) if r.learned_mapping is not None), None)
    info = None
    if req.uses_mapping:
        assert learned is not None  # a method given a mapping returns it updated
        info = MappingInfo(path=mapping_path, entries_before=entries_before, entries_after=len(learned),
                           macro_states=int(by_method["mapping"].extra["macro_states"]),
                           saved=bool(req.save_mapping))
        if req.save_mapping:
            assert mapping_path is not None  # save_mapping was refused without the mapping's file path
            learned.save(mapping_path)
    return TransferResult(
        task=req.task, source=src, target=tgt, distance=distance, trajectories=trajs, seed=req.seed,
        trials=req.trials, wind=req.wind, config=req.config, methods=by_method, controls=by_control,
        mapping=info, learned_mapping=learned,
    )


def _by_method_and_control(runs) -> tuple[dict, dict]:
    """The runs of a transfer by method, and the control runs by control and method."""
    by_method = {r.method: r for r in runs if r.control is None}
    by_control: dict[str, dict] = {}
    for r in runs:
        if r.control is not None:
            by_control.setdefault(r.control, {})[r.method] = r
    return by_method, by_control


def _outside_learner(learner: object):
    """The outside learner ``learner`` names (None: the built-in ``sarsa``); an unknown name is
    one line listing the learners."""
    if not isinstance(learner, str):
        raise InvalidParameterError(f"learner is a learner's name; valid learners: {', '.join(learners.LEARNERS)}")
    found = learners.get(learner)
    return None if found.name == learners.SARSA else found


def _transfer_outside(req: _Request, src: DiscreteRobot, tgt: DiscreteRobot, distance: int) -> TransferResult:
    """``transfer`` by an outside learner (see its docstring): probed first, then every method
    through the harness; no controls (``controls`` is not read)."""
    learner, the_task = req.outside, req.task
    start, goal = list(the_task.start), list(the_task.goal)
    learner_trial.probe(learner, tgt, start, goal, req.probe_timeout)  # a learner that raises: one line, before anything is learned
    shaped = any(registry.get(m).shaped and registry.get(m).uses_trajectory for m in req.methods)
    trajs = resolve_trajectories(req.specs, src, the_task, req.config, req.seed) if shaped else []
    start_cell, goal_cell = the_task.cells()
    verified: dict[str, float] = {}
    for m in req.methods:  # a K that can be farmed is refused in one line, and 'auto' verified, as for the kernel
        made = experiment.method_shaping(m, tgt, tgt.start_state(start_cell), goal_cell, trajs, req.K, req.config,
                                         req.wind, potentials.DENSE_BETA if req.beta is None else req.beta)
        if made is not None:
            verified[m] = made.K
    learner_trial.refuse_methods(learner, req.methods)  # the baselines too, before any is learned
    runs = [req.engine.trials(engines.Work(m, tgt.name, the_task.start, the_task.goal, req.trials, req.seed, req.config,
                                           wind=req.wind, K=verified.get(m, "auto"), beta=req.beta,
                                           learner=learner.name, on_trial=req.progress,
                                           heartbeat=req.progress is not None),  # a long trial says how far it has got
                              tgt, trajs) for m in req.methods]
    by_method, by_control = _by_method_and_control(runs)
    return TransferResult(task=the_task, source=src, target=tgt, distance=distance, trajectories=trajs, seed=req.seed,
                          trials=req.trials, wind=req.wind, config=req.config, methods=by_method, controls=by_control,
                          learner=learner.name)


def _transfer_continuous(req: _Request) -> ContinuousResult:
    """``transfer`` with a continuous-state target (see its docstring)."""
    source, target, the_task, method_names, specs = req.source, req.target, req.task, req.methods, req.specs
    trials, seed, K, config, arm_xml, options = req.trials, req.seed, req.K, req.config, req.arm_xml, req.options
    progress, noise = req.progress, req.noise
    if isinstance(target, DiscreteRobot) or not isinstance(target, str):
        raise InvalidParameterError("a continuous target is named by a string: an arm such as "
                                    f"'planar3:joint' or 'ur5e_like:joint', PATH.xml or 'custom' with arm_xml, "
                                    f"got {target!r}")
    unknown = sorted(k for k in options if k not in ARM_KEYWORDS)
    if unknown:
        raise InvalidParameterError(f"arm option {unknown[0]!r} does not apply to a continuous target; valid "
                                    f"options: {', '.join(ARM_KEYWORDS)}")
    if target.partition(":")[0] == "custom":
        if arm_xml is None:
            raise InvalidParameterError("target 'custom' needs arm_xml")
        arm = continuous_arm(None, xml_path=arm_xml, layout=the_task.layout, noise=noise, **options)
    else:
        arm = continuous_arm(target, layout=the_task.layout,
                             **{k: v for k, v in options.items() if k in ("joint_step", "cell_size")}, noise=noise)
    start_cell, goal_cell = the_task.cells(arm.layout)
    approx = runs.approximation_for(arm)  # hashed tiles for a spatial arm
    arm.place(start_cell)  # the task's start must be reachable before the source learns anything
    src = resolve(source, xml_path=arm_xml, layout=the_task.layout, **options)
    for cell, what in ((start_cell, "start"), (goal_cell, "goal")):
        src.start_state(cell, what=what)
    shaped = any(registry.get(m).shaped for m in method_names)
    trajs = resolve_trajectories(specs, src, the_task, config, seed) if shaped else []
    # the arm is placed over the start already (above), handed to the engine with the work
    results = [req.engine.trials(engines.Work(m, target, the_task.start, the_task.goal, trials, seed, config, K=K,
                                              state="continuous", noise=noise, on_trial=progress, arm=arm), None, trajs)
               for m in method_names]
    return runs.ContinuousResult(task=the_task, source=src.name, target=f"{target} (continuous)", trajectories=trajs,
                                 seed=seed, trials=trials, config=config, approximation=approx,
                                 methods={r.method: r for r in results})


def resolve_trajectories(specs: Sequence[TrajectorySpec], source: DiscreteRobot, task: Task,
                         config: LearnerConfig, seed: int) -> list[Trajectory]:
    """Each spec: a :data:`TRAJECTORY_KINDS` kind made from the source robot, a trajectory JSON
    file for this task, or a :class:`Trajectory`."""
    start, goal = task.cells()
    layout = task.layout
    out: list[Trajectory] = []
    for spec in specs:
        if isinstance(spec, Trajectory):
            trajectories.check_task(spec, start, goal, layout)
            trajectories.check_source(spec, source)
            out.append(spec)
        elif spec in ("optimal", "learned"):
            out.append(experiment.source_trajectory(spec, source, start, goal, config, seed))
        elif spec in ("shuffled", "random"):
            real = experiment.source_trajectory("optimal", source, start, goal, config, seed)
            out.extend(experiment.control_trajectories(spec, source, [real], seed))
        elif isinstance(spec, (str, Path)):
            traj = trajectories.load(spec, layout)
            trajectories.check_task(traj, start, goal, layout)
            trajectories.check_source(traj, source)
            out.append(traj)
        else:
            raise InvalidParameterError(
                f"a trajectory is one of {', '.join(TRAJECTORY_KINDS)}, a JSON file or a Trajectory, got {spec!r}")
    return out


def _world(world, source, target) -> Layout:
    """The world of a transfer: ``world`` resolved, or the world robots given as objects bring."""
    if world is None:
        given = [r.layout for r in (source, target) if isinstance(r, DiscreteRobot)]
        return given[0] if given else ROOMS
    return resolve_world(world)


def _task(task, start, goal, specs, layout: Layout = ROOMS) -> Task:
    if isinstance(task, Task) and start is None and goal is None:
        if task.layout != layout:
            raise InvalidTaskError(f"the task {task.name!r} is of another world than the transfer's")
        return task  # checked where it was made
    if start is not None or goal is not None:
        if task is not None:
            raise InvalidTaskError("give either a task or start/goal cells, not both")
        if start is None or goal is None:
            raise InvalidTaskError("start and goal go together")
        return custom_task(as_xy(start, "start"), as_xy(goal, "goal"), layout)
    if task is None:
        files = [s for s in specs if isinstance(s, (str, Path)) and s not in TRAJECTORY_KINDS]
        if files:
            traj = trajectories.load(files[0], layout)
            return Task("trajectory file", layout.xy(traj.start), layout.xy(traj.goal), layout=layout)
        if not layout.tasks:  # a bare Layout: Table I's first task, as before worlds had tasks
            return table_task(1)
        return world_task(layout, None)
    if isinstance(task, bool) or not isinstance(task, (numbers.Integral, str)):
        raise InvalidTaskError(f"a task is a Table I task number or a task name of the world, got {task!r}")
    if not layout.tasks:
        return table_task(int(task)) if isinstance(task, numbers.Integral) else table_task(task)
    return world_task(layout, task)


def _as_sequence(value, what: str) -> Sequence:
    if isinstance(value, (str, Path, Trajectory)):
        return [value]
    try:
        return list(value)
    except TypeError:
        raise InvalidParameterError(f"{what} must be a name or a list of them, got {value!r}") from None


def _with_walls_cause(message: str, robot: DiscreteRobot) -> str:
    """``message``, and why, when an arm misses cells because its geometry meets the walls."""
    if robot.arm is None:
        return message + hint(robot)
    cause = walls_cause(robot)
    return (f"{message}: it reaches {robot.arm.reach:.1%} of the free cells; {cause}" if cause else message) \
        + hint(robot)


ARM_OPTIONS = ("tip_site", "tip_body", "tip_offset", "tool", "arm_name", "base_pos", "base_yaw", "cell_size", "joint_step",
               "tip_down", "cache")
"""The keys of ``arm_options``: how an arm file is mounted and where its tool point is."""


def _arm_options(arm_options) -> dict:
    """``arm_options`` checked: a dict of :data:`ARM_OPTIONS` keys (the arm's own checks follow)."""
    if arm_options is None:
        return {}
    if not isinstance(arm_options, dict):
        raise InvalidParameterError(f"arm_options must be a dict of {', '.join(ARM_OPTIONS)}, got {arm_options!r}")
    unknown = sorted(str(k) for k in arm_options if k not in ARM_OPTIONS)
    if unknown:
        raise InvalidParameterError(f"unknown arm option {unknown[0]!r}; valid options: {', '.join(ARM_OPTIONS)}")
    return dict(arm_options)
