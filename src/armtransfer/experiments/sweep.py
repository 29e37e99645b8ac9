"""Sweep files: a TOML grid of (task x robot pair x method x seed x parameter) runs.

A sweep file has one table, ``[sweep]``; every key but ``name``, ``trials`` and
``trajectory`` takes a value or a list of values, and the sweep is their product::

    [sweep]
    name = "table-ii"
    tasks = [1, 2, 3, 4]                 # Table I tasks, and/or
    start_goal = [["0,0", "-20,-20"]]    # explicit (start, goal) cells
    pairs = [["coarse", "fine"]]         # (source, target) robots; arms as "ARM:ACTIONS"
    methods = ["none", "pseudo"]
    seeds = [0, 1, 2]
    trials = 10                          # trials per run
    trajectory = "optimal"               # or "learned"
    K = ["auto"]
    epsilon = [0.1]
    lam = [0.9]
    alpha = [0.1]
    gamma = [0.99]
    wind = [0.0, 0.01]

Bring-your-own arms (MJCF files, MuJoCo Menagerie ones as they are) are named in tables of
their own and then used by name in ``pairs``, as ``NAME`` or ``NAME:ACTIONS``::

    [arms.ur5e]
    xml = "mujoco_menagerie/universal_robots_ur5e/ur5e.xml"   # relative to the sweep file
    tip_site = "attachment_site"         # or tip_body = "hand"
    tip_offset = [0, 0, 0.12]            # metres, in the site's or body's frame
    tool = "stylus:0.05"                 # optional: a pen held at the tool point
    # base_pos = [0, -0.4, 0]; base_yaw = 1.5708   (default: chosen automatically)

Who learns on the target is ``learner`` (a name or a list, default ``"sarsa"``, the compiled
kernel): a learner of ``armtransfer.LEARNERS`` from outside the package runs every method of
the sweep through the benchmark's harness (``experiments.learner_transfer``), ``none`` run by it
the baseline of its methods; it runs ``none`` and the reward-term methods, within
``max_total_steps`` steps a trial of robot 2 (a scalar; give an outside learner a budget; robot
1 learns its trajectory with its own cap, as in the benchmark). Its runs carry
``learner`` (and ``max_total_steps`` when given); sarsa's runs carry neither and keep their keys.

A sweep runs in one world, ``world = "rooms11"`` (a built-in name, ``generated:SEED[:SIDE]`` or
a layout file, relative to the sweep file; default the paper's ``rooms``); ``tasks`` are then
the world's task names. Every run carries the world's content (grid and tasks), so its key
changes when the world does; the rooms' runs carry none and keep their keys.

One *run* is one combination: ``trials`` trials of one method, seeded by its seed. Its
content key is a hash of its full, normalised configuration, so the same run is never done
twice (``none`` ignores K, so its runs are shared by every K).
"""

from __future__ import annotations

import itertools
import json
import math
import os
from dataclasses import dataclass
from pathlib import Path

from armtransfer.ik.tool import parse_held
from armtransfer.models import ARMS
from armtransfer.tasks.catalog import TABLE_I, parse_xy, world_task
from armtransfer.tasks.grid_robots import GRID_ROBOTS
from armtransfer.tasks.specs import CUSTOM
from armtransfer.worlds.files import layout_data
from armtransfer.worlds.resolve import is_default, layout_of_data
from armtransfer.worlds.layout import ROOMS
from armtransfer.worlds.resolve import world as resolve_world
from armtransfer.errors import ArmTransferError
from armtransfer.io import parse_toml_bytes, read_input
from armtransfer.tasks.arms import ARM_NAME, ARM_NAME_FORM
from armtransfer.learning import methods as _methods
from armtransfer.learning.method import MAX_K
from armtransfer.learning import presets as _presets
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.lazy_registry import Names
from armtransfer.learning.learner_names import SARSA
from armtransfer.experiments.run import SWEEP_FORMAT, SweepRun, content_key as content_key
from armtransfer.experiments.stored_form import fill_in, leave_out

RUN_FORMAT = SWEEP_FORMAT
METHODS = Names(_methods.METHODS, lambda name, m: not m.macros)
"""Every method (a plugin's too) but `mapping`, whose protocol (tasks in order, one mapping carried from task
to task) is not a grid of independent runs: use `armtransfer rooms --method mapping --mapping PATH`."""

# key -> (default, is a list axis)
_AXES: dict[str, list] = {
    "tasks": [],
    "start_goal": [],
    "pairs": [["coarse", "fine"]],
    "methods": ["none", "pseudo"],
    "seeds": [0],
    "K": ["auto"],
    "epsilon": [LearnerConfig.epsilon],
    "lam": [LearnerConfig.lam],
    "alpha": [LearnerConfig.alpha],
    "gamma": [LearnerConfig.gamma],
    "wind": [0.0],
}
_SCALARS = {"name": "sweep", "trials": 10, "trajectory": "optimal", "patience": LearnerConfig.patience,
            "max_episodes": LearnerConfig.max_episodes, "preset": _presets.DEFAULT}
_FROM_PRESET = ("epsilon", "lam", "alpha", "gamma", "patience", "max_episodes")
"""The keys whose default is the preset's value when the sweep names a preset."""


class SweepFileError(ArmTransferError):
    """A sweep file is unreadable, malformed, or names an unknown key or value."""


@dataclass(frozen=True)
class Sweep:
    name: str
    spec: dict
    """The normalised sweep (lists everywhere; the keys at their ``SPEC_DEFAULTS`` left out)."""
    runs: tuple[SweepRun, ...]

    @property
    def key(self) -> str:
        return content_key(self.spec)


def _as_list(name: str, value: object) -> list:
    return value if isinstance(value, list) else [value]


def _check_number(where: str, value: object, lo: float, hi: float, integer: bool = False) -> float | int:
    if not isinstance(value, bool) and (isinstance(value, int) or (not integer and isinstance(value, float))) \
            and lo <= value <= hi:
        return value
    kind = "an integer" if integer else "a number"
    raise SweepFileError(f"{where}: must be {kind} in [{lo:g}, {hi:g}], got {value!r}")


MAX_RUNS = 100_000
"""A sweep larger than this is refused unless the limit is raised (``--max-runs``)."""


def size(spec: dict) -> int:
    """How many runs a normalised spec has, without listing them (at most; ``none`` ignores K)."""
    n = len(spec["tasks"]) + len(spec["start_goal"])
    for key in _AXES:
        if key not in ("tasks", "start_goal"):
            n *= len(spec[key])
    return n * len(learners_of(spec))


ARM_KEYS: dict[str, type | tuple[type, ...]] = {"xml": str, "tip_site": str, "tip_body": str, "tip_offset": list, "tool": str,
            "base_pos": list,
            "base_yaw": (int, float)}
"""The keys of an ``[arms.NAME]`` table and their types."""


def _arms(raw: object, where: str, base: Path | None) -> dict:
    """The ``[arms.NAME]`` tables, checked; ``xml`` made absolute (relative to the sweep file)."""
    if not isinstance(raw, dict):
        raise SweepFileError(f"{where}: arms must be tables [arms.NAME]")
    out = {}
    for name, body in raw.items():
        w = f"{where}: arms.{name}"
        if not name or ":" in name or not isinstance(body, dict):
            raise SweepFileError(f"{w}: an arm is a table [arms.NAME] with a NAME without ':'")
        if not ARM_NAME.fullmatch(name):
            raise SweepFileError(f"{where}: arms.{name!r}: an arm's NAME must be {ARM_NAME_FORM}")
        for key, value in body.items():
            if key not in ARM_KEYS:
                raise SweepFileError(f"{w}: unknown key {key!r}; valid keys: {', '.join(ARM_KEYS)}")
            if isinstance(value, bool) or not isinstance(value, ARM_KEYS[key]):
                raise SweepFileError(f"{w}: {key} has the wrong type ({type(value).__name__})")
        if "xml" not in body:
            raise SweepFileError(f"{w}: needs xml = \"PATH\" (the arm's MJCF file)")
        if "tip_site" in body and "tip_body" in body:
            raise SweepFileError(f"{w}: give tip_site or tip_body, not both")
        for key in ("tip_offset", "base_pos"):
            if key in body and not (len(body[key]) == 3 and all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in body[key])):
                raise SweepFileError(f"{w}: {key} must be three finite numbers [X, Y, Z] (metres)")
        if "tool" in body:
            try:
                parse_held(body["tool"])
            except ArmTransferError as err:
                raise SweepFileError(f"{w}: tool: {err}") from None
        if "base_yaw" in body and not math.isfinite(body["base_yaw"]):
            raise SweepFileError(f"{w}: base_yaw must be a finite number of radians")
        arm = dict(body)
        xml = Path(arm["xml"]).expanduser()
        arm["xml"] = str(xml if xml.is_absolute() or base is None else (base / xml).resolve())
        out[name] = arm
    return out


def _check_arm_names(arms: dict, pairs: list, where: str) -> None:
    """Every ``[arms.NAME]`` table is used by a pair, and no NAME is a robot's name already
    (a table named ``fine`` would silently lose to the grid robot)."""
    taken = {*GRID_ROBOTS, *ARMS, CUSTOM, "gen"}
    used = {spec.partition(":")[0] for pair in pairs for spec in pair}
    for name in arms:
        if name in taken or name.endswith(".xml"):
            raise SweepFileError(f"{where}: arms.{name} has the name of a robot already; choose a name other than "
                                 f"{', '.join(sorted(taken))}")
        if name not in used:
            raise SweepFileError(f"{where}: arms.{name} is not used by any pair; pairs name "
                                 f"{', '.join(sorted(used))}")


def normalise(raw: dict, where: str = "sweep file", max_runs: int = MAX_RUNS, base: Path | None = None) -> dict:
    """Validate a parsed sweep file; returns the spec in its stored form, every key filled in but
    those at their :data:`SPEC_DEFAULTS` (``base``: the folder that relative arm files are found in)."""
    if not set(raw) <= {"sweep", "arms"} or not isinstance(raw.get("sweep"), dict):
        extra = sorted(set(raw) - {"sweep", "arms"})
        what = f"unknown table {extra[0]!r}" if extra else "missing the [sweep] table"
        raise SweepFileError(f"{where}: {what}; a sweep file has one table [sweep] and may name arms in "
                             "[arms.NAME] tables")
    arms = _arms(raw.get("arms", {}), where, base)
    body = raw["sweep"]
    valid = sorted([*_AXES, *_SCALARS, *_OPTIONAL])
    for key in body:
        if key not in _AXES and key not in _SCALARS and key not in _OPTIONAL:
            raise SweepFileError(f"{where}: unknown key {key!r}; valid keys: {', '.join(valid)}")
    spec: dict = {}
    preset = body.get("preset", _presets.DEFAULT)
    if not isinstance(preset, str) or preset not in _presets.PRESETS:
        raise SweepFileError(f"{where}: unknown preset {preset!r}; valid presets: {', '.join(_presets.names())}")
    chosen = _presets.values(preset)
    for key, default in _SCALARS.items():
        spec[key] = body.get(key, chosen[key] if key in _FROM_PRESET else default)
    for key, default in _AXES.items():
        spec[key] = _as_list(key, body[key]) if key in body else ([chosen[key]] if key in _FROM_PRESET else list(default))
    w = where
    if not isinstance(spec["name"], str) or not spec["name"]:
        raise SweepFileError(f"{w}: name must be a non-empty string")
    _check_number(f"{w}: trials", spec["trials"], 1, 10_000, integer=True)
    _check_number(f"{w}: patience", spec["patience"], 1, 100_000, integer=True)
    _check_number(f"{w}: max_episodes", spec["max_episodes"], 1, 1_000_000, integer=True)
    if spec["trajectory"] not in ("optimal", "learned"):
        raise SweepFileError(f"{w}: trajectory must be 'optimal' or 'learned', got {spec['trajectory']!r}")
    layout = _world(body.get("world"), w, base)
    spec["world"] = None if layout is None else layout_data(layout)
    names = [t[0] for t in layout.tasks] if layout is not None else None
    for t in spec["tasks"]:
        if names is not None:
            if isinstance(t, bool) or not isinstance(t, (int, str)) or str(t) not in names:
                raise SweepFileError(f"{w}: unknown task {t!r} in world {layout.name}; valid tasks: {', '.join(names)}")
        elif isinstance(t, bool) or t not in TABLE_I:
            raise SweepFileError(f"{w}: unknown task {t!r}; valid tasks: {', '.join(map(str, TABLE_I))}")
    pairs = []
    for sg in spec["start_goal"]:
        if not (isinstance(sg, list) and len(sg) == 2 and all(isinstance(x, str) for x in sg)):
            raise SweepFileError(f"{w}: start_goal entries must be [\"X,Y\", \"X,Y\"], got {sg!r}")
        try:
            pairs.append([list(parse_xy(sg[0], "start")), list(parse_xy(sg[1], "goal"))])
        except ArmTransferError as err:
            raise SweepFileError(f"{w}: start_goal: {err}") from None
    spec["start_goal"] = pairs
    if not spec["tasks"] and not spec["start_goal"]:
        raise SweepFileError(f"{w}: give tasks or start_goal (or both)")
    for p in spec["pairs"]:
        if not (isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) and x for x in p)):
            raise SweepFileError(f"{w}: pairs entries must be [\"SOURCE\", \"TARGET\"], got {p!r}")
    _check_arm_names(arms, spec["pairs"], w)
    for m in spec["methods"]:
        if m not in METHODS:
            if isinstance(m, str) and m in _methods.METHODS.broken:  # an installed plugin left out: its own line
                raise SweepFileError(f"{w}: method {m!r}: {_methods.METHODS.broken[m][0]}")
            raise SweepFileError(f"{w}: unknown method {m!r}; valid methods: {', '.join(METHODS)}")
    for s in spec["seeds"]:
        _check_number(f"{w}: seeds", s, 0, 2**63 - 1, integer=True)
    for k in spec["K"]:
        if k != "auto":
            _check_number(f"{w}: K", k, 0, MAX_K)
    for key, lo, hi in (("epsilon", 0, 1), ("lam", 0, 1), ("gamma", 0, 1), ("wind", 0, 1), ("alpha", 1e-12, 1)):
        for v in spec[key]:
            _check_number(f"{w}: {key}", v, lo, hi)
    for key in _AXES:
        if len(spec[key]) != len({json.dumps(v) for v in spec[key]}):
            raise SweepFileError(f"{w}: {key} lists a value twice")
        if not spec[key] and key not in ("tasks", "start_goal"):
            raise SweepFileError(f"{w}: {key} is empty; give at least one value")
    spec["arms"] = arms
    _learners(body, spec, w)
    n = size(spec)
    if n > max_runs:
        raise SweepFileError(f"{w}: the sweep has {n:,} runs, over the limit of {max_runs:,}; "
                             "raise it with --max-runs")
    return leave_out(spec, SPEC_DEFAULTS)


_OPTIONAL = ("world", "learner", "max_total_steps")
"""Keys a sweep file may give beside the axes and scalars."""

SPEC_DEFAULTS: dict[str, object] = {"preset": _presets.DEFAULT, "world": None, "learner": [SARSA],
                                    "learner_options": {}, "max_total_steps": None}
"""The fields a stored spec leaves out at these values (``stored_form``): a sweep of the default
preset, the paper's rooms, sarsa alone, learners without settings and the preset's step cap."""


def spec_fields(spec: dict) -> dict:
    """A stored (normalised) spec with every field it leaves out filled in at its default."""
    return fill_in(spec, SPEC_DEFAULTS)


def _learners(body: dict, spec: dict, where: str) -> None:
    """``learner`` and ``max_total_steps`` of a sweep file into ``spec``: every learner known
    (a typo lists them), every method run by every learner (else one line naming the learner
    and the methods it runs)."""
    from armtransfer.learning import learners  # start-up: the registry loads Gymnasium

    names = _as_list("learner", body.get("learner", SARSA))
    if not names or len(names) != len(set(map(str, names))):
        raise SweepFileError(f"{where}: learner " + ("is empty; give at least one" if not names
                                                     else "lists a value twice"))
    for name in names:
        if isinstance(name, str) and name not in learners.LEARNERS and name in learners.LEARNERS.broken:
            raise SweepFileError(f"{where}: learner {name!r}: {learners.LEARNERS.broken[name][0]}")
        if not isinstance(name, str) or name not in learners.LEARNERS:
            raise SweepFileError(f"{where}: unknown learner {name!r}; valid learners: {', '.join(learners.LEARNERS)}")
    outside = [n for n in names if n != SARSA]
    if outside:
        from armtransfer.experiments.learner_trial import refuse_methods  # start-up: Gymnasium, for outside learners

        for name in outside:
            try:
                refuse_methods(learners.LEARNERS[name], spec["methods"])
            except ArmTransferError as err:
                raise SweepFileError(f"{where}: {err}") from None
    spec["learner"] = names
    spec["learner_options"] = {n: learners.options_of(n) for n in outside if learners.options_of(n)}
    spec["max_total_steps"] = None if "max_total_steps" not in body else _check_number(
        f"{where}: max_total_steps", body["max_total_steps"], 1,
        LearnerConfig.__dataclass_fields__["max_total_steps"].metadata["hi"], integer=True)


def learners_of(spec: dict) -> list[str]:
    """The learners of a normalised spec (sarsa when it names none)."""
    return list(spec_fields(spec)["learner"])


def check_stored(spec: object, where: str) -> dict:
    """A spec read back from a store (``sweep.json``), checked as a sweep file is: a table with
    every key of a normalised spec and nothing else, each value valid and already in normal
    form; else ``SweepFileError``, one line naming ``where`` and the field."""
    if not isinstance(spec, dict):
        raise SweepFileError(f"{where}: field 'spec' " + ("is missing" if spec is None else f"must be a table, got {type(spec).__name__}"))
    optional = set(SPEC_DEFAULTS)  # written only when not the default
    keys = {*_SCALARS, *_AXES, "arms"} - optional
    for key in sorted(keys - set(spec)):
        raise SweepFileError(f"{where}: field 'spec' has no {key!r}")
    for key in sorted(set(spec) - keys - optional, key=str):
        raise SweepFileError(f"{where}: field 'spec' has an unknown key {key!r}; valid keys: "
                             f"{', '.join(sorted(keys | optional))}")
    # a world is stored as its layout's data; learner_options are the installed learners' (compared below)
    body = {k: v for k, v in spec.items() if k not in ("arms", "learner_options")}
    if isinstance(spec["start_goal"], list):  # stored as cells; a sweep file writes "X,Y"
        body["start_goal"] = [[f"{c[0]},{c[1]}" if isinstance(c, list) and len(c) == 2 else c for c in sg]
                              if isinstance(sg, list) else sg for sg in spec["start_goal"]]
    again = normalise({"sweep": body, "arms": spec["arms"]}, f"{where}: field 'spec'", max_runs=2**62)
    if json.dumps(again.get("learner_options")) != json.dumps(spec.get("learner_options")):
        raise SweepFileError(f"{where}: its runs' learners had the options {spec.get('learner_options') or {}!r:.120}, "
                             f"the installed ones have {again.get('learner_options') or {}!r:.120}: a store holds one "
                             "learner's settings; choose a new --out, or install the learner as it was")
    for key in sorted(optional & set(spec)):
        if json.dumps(again.get(key)) != json.dumps(spec[key]):
            raise SweepFileError(f"{where}: field 'spec': {key} is not as a sweep writes it ({spec[key]!r:.80})")
    for key in sorted(keys):
        if again[key] != spec[key] or json.dumps(again[key]) != json.dumps(spec[key]):
            raise SweepFileError(f"{where}: field 'spec': {key} is not as a sweep writes it ({spec[key]!r:.80})")
    return spec


def _world(given: object, where: str, base: Path | None):
    """The sweep's world (``world = ...``), or None for the paper's rooms (its runs name none)."""
    if given is None:
        return None
    if isinstance(given, dict):  # a store's sweep.json holds the layout's own data
        try:
            layout = layout_of_data(given, f"{where}: world")
        except ArmTransferError as err:
            raise SweepFileError(str(err)) from None
        return None if is_default(layout) else layout
    if not isinstance(given, str) or not given.strip():
        raise SweepFileError(f"{where}: world must be a world's name or a layout file, got {given!r}")
    if base is not None and given.lower().endswith((".toml", ".json")) and not os.path.isabs(given):
        given = str(base / given)
    try:
        layout = resolve_world(given)
    except ArmTransferError as err:
        raise SweepFileError(f"{where}: world: {err}") from None
    return None if is_default(layout) else layout


def sweep_world(spec_or_run: dict | SweepRun):
    """The world of a normalised spec or one of its runs (the paper's rooms when it names none)."""
    data = spec_or_run.world if isinstance(spec_or_run, SweepRun) else spec_fields(spec_or_run)["world"]
    return ROOMS if data is None else layout_of_data(data, "the sweep's world")


def expand(spec: dict) -> list[SweepRun]:
    """Every run of the sweep, in a fixed order (a run ``none`` shares with every K once)."""
    spec = spec_fields(spec)
    if spec["world"] is None:
        tasks = [{"task": t, "start": list(TABLE_I[t].start), "goal": list(TABLE_I[t].goal)} for t in spec["tasks"]]
    else:
        layout = sweep_world(spec)
        found = [world_task(layout, t) for t in spec["tasks"]]
        tasks = [{"task": t, "start": list(f.start), "goal": list(f.goal)} for t, f in zip(spec["tasks"], found)]
    tasks += [{"task": None, "start": s, "goal": g} for s, g in spec["start_goal"]]
    runs: dict[str, SweepRun] = {}
    for learner, task, pair, method, seed, K, eps, lam, alpha, gamma, wind in itertools.product(
        learners_of(spec), tasks, spec["pairs"], spec["methods"], spec["seeds"], spec["K"], spec["epsilon"],
        spec["lam"], spec["alpha"], spec["gamma"], spec["wind"],
    ):
        used = {p.partition(":")[0] for p in pair} & set(spec["arms"])
        run = SweepRun(
            world=spec["world"], **task, source=pair[0], target=pair[1], method=method, seed=seed,
            trials=spec["trials"], trajectory=spec["trajectory"], K=None if method == "none" else K, epsilon=eps,
            lam=lam, alpha=alpha, gamma=gamma, wind=wind, patience=spec["patience"],
            max_episodes=spec["max_episodes"], preset=spec["preset"],
            max_total_steps=spec["max_total_steps"], learner=learner,
            learner_options=spec["learner_options"].get(learner),
            arms={name: spec["arms"][name] for name in sorted(used)},  # a named arm's definition keys the run
        )
        runs.setdefault(run.key(), run)
    return list(runs.values())


def load(path: str | os.PathLike, max_runs: int = MAX_RUNS) -> Sweep:
    p = Path(path)
    where = f"sweep file {str(p)!r}"
    data = read_input(p, "sweep file", SweepFileError)

    try:
        raw = parse_toml_bytes(data)
    except ValueError as err:
        raise SweepFileError(f"{where} {err}") from None
    spec = normalise(raw, where, max_runs, base=p.parent)
    return Sweep(spec["name"], spec, tuple(expand(spec)))


def group_key(run: dict) -> tuple:
    """Runs that differ only in seed are pooled; ``method`` is the column."""
    return (
        run["task"], tuple(run["start"]), tuple(run["goal"]), run["source"], run["target"],
        run["trajectory"], run["epsilon"], run["lam"], run["alpha"], run["gamma"], run["wind"],
        run["trials"], run["patience"], run["max_episodes"],
    )
