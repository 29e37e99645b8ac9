"""Suite files: a benchmark suite as data, in TOML or JSON, so a researcher's own cases on their
own world get the built-in suites' paired report (``armtransfer benchmark --suite FILE``).

    name = "zigzag"
    world = "zigzag.toml"          # rooms (default), rooms11, rooms15, generated:SEED[:SIDE], or a layout file
    methods = ["pseudo", "dense"]  # optional: the methods run, each with its baselines (default: all)
    learners = ["sarsa"]           # optional
    source_seeds = 10
    trials = 2
    max_total_steps = 500000

    [[cases]]
    source = "coarse"
    target = "fine"                # any robot spec: planar3:joint, gen:planar:3:1:joint, ...
    task = 1                       # a task of the world, or start = [x, y] and goal = [x, y]
    wind = 0.0                     # optional

Cases may instead be grouped in ``[[sections]]`` (each with a ``name`` and its own
``[[sections.cases]]``; a section's keys override the file's). A case with neither ``task`` nor
``start``/``goal`` draws its task per source seed (``distance = [low, high]`` or ``[low]``, ``cells
= "any" | "even" | "odd"``). ``include = ["paper", ...]`` takes the sections of built-in suites.
``source_seeds`` defaults to 10 (the fewest a report makes a claim from) and ``trials`` to 2;
``max_total_steps`` is required. ``version``, ``held_out`` and ``description`` describe the suite
in its report. A layout file is
read relative to the suite file; the suite carries the world's content (``Suite.worlds``) under an
id naming the world and a hash of that content, so its runs are keyed by the world itself and
``armtransfer summarize`` needs no file. Every fault is one line naming the file and the key.

The built-in suites are such files, shipped in ``armtransfer/experiments/suite_data/``.
"""

from __future__ import annotations

import hashlib
import json
import numbers
import re
import tomllib
from pathlib import Path
from typing import Any

from armtransfer.errors import ArmTransferError, InvalidParameterError, InvalidWorldError
from armtransfer.experiments import suite_model as suites
from armtransfer.io import parse_user_file_bytes
from armtransfer.learning import learners, methods
from armtransfer.models import ARMS
from armtransfer.tasks.arms import parse_robot_spec
from armtransfer.tasks.catalog import custom_task, world_task
from armtransfer.tasks.grid_robots import GRID_ROBOTS
from armtransfer.tasks.specs import resolve
from armtransfer.worlds.files import layout_data
from armtransfer.worlds.generate import PREFIX
from armtransfer.worlds.resolve import FILE_WORLDS, VALID, world

DATA = Path(__file__).resolve().parent / "suite_data"
MAX_BYTES = 1 << 20

TOP = ("name", "version", "held_out", "description", "include", "cases", "sections")
SHARED = ("world", "methods", "learners", "source_seeds", "trials", "max_total_steps")
SECTION = ("name", "description", "cases", *SHARED)
CASE = ("source", "target", "task", "start", "goal", "wind", "world", "distance", "cells", "state", "noise")


DEFAULT_TRIALS = 2
"""Trials of every method per source seed when a file gives none: two, so the spread within a
source seed is seen beside the spread between them."""

NAME = re.compile(r"[a-z0-9][a-z0-9_.-]{0,63}")
"""A suite's name, as a method's: it is typed on command lines and written in file names."""


class SuiteFileError(InvalidParameterError):
    """A suite file that cannot be read or is not a suite: one line naming it and the fault."""


def is_file_name(text: str) -> bool:
    """Whether ``--suite TEXT`` names a file rather than a built-in suite."""
    return text.lower().endswith((".toml", ".json")) or "/" in text


def load(path: str | Path, builtin: dict[str, suites.Suite] | None = None) -> suites.Suite:
    """The suite of the file ``path``, every key, world, robot name and method checked;
    ``builtin``: the built-in suites (which ``include`` may name, and whose names are taken)."""
    p = Path(path)
    where = f"suite file {str(p)[:120]!r}"
    if p.suffix.lower() not in (".toml", ".json"):
        raise SuiteFileError(f"{where}: a suite file ends in .toml or .json")
    try:
        if not p.is_file():
            raise SuiteFileError(f"{where}: no such file" if not p.exists() else f"{where}: not a regular file")
        raw = p.read_bytes()[:MAX_BYTES + 1]
    except (OSError, ValueError) as err:
        raise SuiteFileError(f"{where}: cannot be read: {getattr(err, 'strerror', None) or err}") from None
    if len(raw) > MAX_BYTES:
        raise SuiteFileError(f"{where}: larger than {MAX_BYTES:,} bytes")
    try:  # the shared readers: UTF-8, syntax, digits and magnitudes of numbers, as every user file
        data = parse_user_file_bytes(raw, p.suffix)
    except ValueError as err:
        raise SuiteFileError(f"{where}: {err}") from None
    return parse(data, where, p.parent, builtin=builtin)


def _fail(where: str, what: str) -> SuiteFileError:
    return SuiteFileError(f"{where}: {what}")


def _check_keys(table: object, valid: tuple[str, ...], where: str) -> dict:
    if not isinstance(table, dict):
        raise _fail(where, f"must be a table of keys, got {type(table).__name__}")
    for key in table:
        if key not in valid:
            raise _fail(where, f"unknown key {str(key)[:40]!r}; valid keys: {', '.join(valid)}")
    return table


def _int(value: object, where: str, key: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < low:
        raise _fail(where, f"{key} must be an integer >= {low}, got {value!r}")
    return int(value)


def _number(value: object, where: str, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 <= float(value) < 1:
        raise _fail(where, f"{key} must be a number in [0, 1), got {value!r}")
    return float(value)


def _text(value: object, where: str, key: str) -> str:
    if not isinstance(value, str) or not value.strip() or "\n" in value.strip():
        raise _fail(where, f"{key} must be one line of text, got {value!r}")
    return value.strip()


def _names(value: object, where: str, key: str) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
        raise _fail(where, f"{key} must be a list of names, got {value!r}")
    return tuple(dict.fromkeys(value))


def _xy(value: object, where: str, key: str) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2 or not all(
            isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in value):
        raise _fail(where, f"{key} must be a cell [x, y] of two integers, got {value!r}")
    return int(value[0]), int(value[1])


def world_id(name: str, data: dict) -> str:
    """The id a layout file's world goes by in a suite: its name and a hash of its content."""
    digest = hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:12]
    return f"{name}#{digest}"


class _Worlds:
    """The worlds a file names, each checked once: a built-in or generated name stays a name; a
    layout file becomes an id and its content (``Suite.worlds``)."""

    def __init__(self, base: Path | None, known: dict[str, dict] | None = None, check: bool = True) -> None:
        self.base = base
        self.check = check
        self.seen: dict[str, str] = {}
        self.content: dict[str, dict] = dict(known or {})
        self.layouts: dict[str, Any] = {}

    def __call__(self, value: object, where: str) -> str:
        if isinstance(value, str) and (value in self.seen or value in self.content or (
                not self.check and not value.lower().endswith((".toml", ".json")))):
            return self.seen.get(value, value)  # a world the suite carries, or a name of a shipped suite's
        if not isinstance(value, str) or not value:
            raise _fail(where, f"world must be a name or a layout file; valid worlds: {VALID}; got {value!r}")
        builtin = value == suites.DEFAULT_WORLD or value in FILE_WORLDS or value.split(":")[0] == PREFIX
        spec: Any = value if builtin or self.base is None else str(self.base / value)
        try:
            layout = world(spec)
        except InvalidWorldError as err:
            raise _fail(where, str(err)) from None
        if builtin:
            out = value
        else:
            data = layout_data(layout)
            out = world_id(layout.name or Path(value).stem, data)
            self.content[out] = data
        self.seen[value] = out
        self.layouts[out] = layout
        return out

    def task(self, world: str, case: suites.Case, where: str) -> None:
        """``case``'s task or cells checked on its world (when this file's worlds were loaded)."""
        layout = self.layouts.get(world)
        if layout is None:
            return
        try:
            if case.start is not None and case.goal is not None:
                custom_task(case.start, case.goal, layout)
            elif case.task is not None:
                world_task(layout, case.task)
        except ArmTransferError as err:
            raise _fail(where, str(err)) from None


def _case(table: object, where: str, world: str, worlds: _Worlds, check: bool) -> suites.Case:
    t = _check_keys(table, CASE, where)
    for key in ("source", "target"):
        if key not in t:
            raise _fail(where, f"a case needs {key} (a robot: fine, coarse, planar3:joint, ...)")
    source, target = (_robot(t[k], where, k, check) for k in ("source", "target"))
    task: int | str | None = t.get("task")
    if task is not None and (isinstance(task, bool) or not isinstance(task, (str, numbers.Integral))):
        raise _fail(where, f"task must be a task name or number of the world, got {task!r}")
    if isinstance(task, numbers.Integral):
        task = int(task)
    start = goal = None
    if ("start" in t) != ("goal" in t):
        raise _fail(where, "a case gives both start and goal, or neither")
    if "start" in t:
        if task is not None:
            raise _fail(where, "a case gives a task or start and goal, not both")
        start, goal = _xy(t["start"], where, "start"), _xy(t["goal"], where, "goal")
    distance = None
    if "distance" in t:
        d = t["distance"]
        if not isinstance(d, list) or len(d) not in (1, 2) or not all(
                v is None or (isinstance(v, numbers.Integral) and not isinstance(v, bool) and int(v) >= 1) for v in d) \
                or d[0] is None or (len(d) == 2 and d[1] is not None and int(d[1]) <= int(d[0])):
            raise _fail(where, f"distance must be [low] or [low, high] with 1 <= low < high, got {d!r}")
        distance = (int(d[0]), None if len(d) == 1 or d[1] is None else int(d[1]))
    cells = t.get("cells", "any")
    if cells not in suites.CELLS:
        raise _fail(where, f"unknown cells {cells!r}; valid cells: {', '.join(suites.CELLS)}")
    if (distance is not None or cells != "any") and (task is not None or start is not None):
        raise _fail(where, "distance and cells apply to a drawn task (a case with no task, start or goal)")
    state = t.get("state", "discrete")
    try:
        case = suites.Case(source, target, task, _number(t.get("wind", 0.0), where, "wind"), distance, cells,
                           worlds(t.get("world", world), where), state, _noise(t.get("noise", 0.0), where),
                           start, goal)
    except InvalidParameterError as err:
        raise _fail(where, str(err)) from None
    if check:
        worlds.task(case.world, case, where)
    return case


def _noise(value: object, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 <= float(value) <= 1:
        raise _fail(where, f"noise must be a number in [0, 1], got {value!r}")
    return float(value)


def _robot(value: object, where: str, key: str, check: bool = True) -> str:
    """A robot spec, its name checked now (an arm is compiled only when the suite is planned)."""
    if not isinstance(value, str) or not value:
        raise _fail(where, f"{key} must be a robot name, got {value!r}")
    if not check:
        return value
    try:
        if value.partition(":")[0] in ARMS:
            parse_robot_spec(value)
        elif value not in GRID_ROBOTS and not value.startswith("gen:") and ".xml" not in value:
            resolve(value)  # not a robot: its one-line error, listing the valid ones
    except ArmTransferError as err:
        raise _fail(where, f"{key}: {err}") from None
    return value


def _shared(t: dict, where: str, inherited: dict, check: bool) -> dict:
    out = dict(inherited)
    for key in ("source_seeds", "trials", "max_total_steps"):
        if key in t:
            out[key] = _int(t[key], where, key, 1)
    if "methods" in t:
        out["methods"] = _methods(t["methods"], where) if check else _names(t["methods"], where, "methods")
    if "learners" in t:
        out["learners"] = _learners(t["learners"], where) if check else _names(t["learners"], where, "learners")
    if "world" in t:
        out["world"] = t["world"]
    return out


def _methods(value: object, where: str) -> tuple[str, ...]:
    names = _names(value, where, "methods")
    try:
        return tuple(methods.get(n).name for n in names)
    except InvalidParameterError as err:
        raise _fail(where, str(err)) from None


def _learners(value: object, where: str) -> tuple[str, ...]:
    try:
        return learners.parse(list(_names(value, where, "learners")))
    except InvalidParameterError as err:
        raise _fail(where, str(err)) from None


def _section(t: dict, where: str, inherited: dict, worlds: _Worlds, default_name: str | None,
             check: bool) -> suites.Section:
    s = _shared(t, where, inherited, check)
    name = _text(t["name"], where, "name") if "name" in t else default_name
    if name is None:
        raise _fail(where, "a section needs a name")
    where = f"{where.split(': ')[0]}: section {name!r}" if default_name is None else where
    s.setdefault("source_seeds", suites.MIN_SEEDS_FOR_CLAIM)  # the fewest a report makes a claim from
    s.setdefault("trials", DEFAULT_TRIALS)
    if "max_total_steps" not in s:
        raise _fail(where, "needs max_total_steps, a trial's step cap (in the section or at the top of the file)")
    cases = t.get("cases")
    if not isinstance(cases, list) or not cases:
        raise _fail(where, "needs at least one case ([[cases]] with source, target and a task)")
    world = s.get("world", suites.DEFAULT_WORLD)
    made = tuple(_case(c, f"{where}, case {i + 1}", world, worlds, check) for i, c in enumerate(cases))
    description = _text(t["description"], where, "description") if "description" in t else \
        f"{len(made)} case{'s' * (len(made) != 1)}: " + "; ".join(c.label for c in made)
    return suites.Section(name, description, made, s["source_seeds"], s["trials"], s["max_total_steps"],
                          s.get("learners", suites.DEFAULT_LEARNERS), s.get("methods"))


def parse(data: object, where: str, base: Path | None = None, known_worlds: dict[str, dict] | None = None,
          builtin: dict[str, suites.Suite] | None = None, check: bool = True) -> suites.Suite:
    """The suite of a suite file's content (``base``: the directory its layout files are read
    from; ``known_worlds``: the worlds a stored suite carries; ``builtin``: the suites ``include``
    may name; ``check``: the methods and learners named are looked up in the registries, which
    reads the installed plugins)."""
    t = _check_keys(data, TOP + SHARED, where)
    if "name" not in t:
        raise _fail(where, "needs a name")
    name = _text(t["name"], where, "name")
    if not NAME.fullmatch(name):
        raise _fail(where, f"a suite's name is lower-case letters, digits, '_', '.' or '-', got {name!r}")
    have = builtin or {}
    if check and name in have:
        raise _fail(where, f"name {name!r} is a built-in suite's; name yours otherwise (built-in suites: "
                           f"{', '.join(have)})")
    version = _int(t.get("version", 1), where, "version", 1)
    held_out = t.get("held_out", False)
    if not isinstance(held_out, bool):
        raise _fail(where, f"held_out must be true or false, got {held_out!r}")
    worlds = _Worlds(base, known_worlds, check)
    inherited = _shared(t, where, {}, check)
    sections: list[suites.Section] = []
    if "include" in t:
        for other in _names(t["include"], where, "include"):
            if other not in have:
                raise _fail(where, f"include: unknown suite {other!r}; valid suites: {', '.join(have)}")
            sections += have[other].sections
    if "cases" in t:
        sections.append(_section(t, where, inherited, worlds, name, check))
    for i, sec in enumerate(t.get("sections") or []):
        sections.append(_section(_check_keys(sec, SECTION, f"{where}: section {i + 1}"),
                                 f"{where}: section {i + 1}", inherited, worlds, None, check))
    if "sections" in t and not isinstance(t["sections"], list):
        raise _fail(where, "sections must be a list of tables ([[sections]])")
    if not sections:
        raise _fail(where, "has no case: give [[cases]], [[sections]] or include")
    names = [s.name for s in sections]
    if len(set(names)) != len(names):
        raise _fail(where, f"two sections are named {next(n for n in names if names.count(n) > 1)!r}")
    description = _text(t["description"], where, "description") if "description" in t else \
        "; ".join(s.description for s in sections)
    return suites.Suite(name, version, held_out, description, tuple(sections),
                        methods=inherited.get("methods"), worlds=worlds.content)


def from_dict(data: dict, where: str) -> suites.Suite:
    """The suite a store or a results file holds (``Suite.to_dict``'s content), made again."""
    if not isinstance(data, dict) or not isinstance(data.get("sections"), list):
        raise SuiteFileError(f"{where}: not a suite")
    top: dict[str, Any] = {k: data[k] for k in ("name", "version", "held_out", "description") if k in data}
    if data.get("methods") != list(suites.METHODS):
        top["methods"] = data.get("methods")
    top["sections"] = []
    for sec in data["sections"]:
        if not isinstance(sec, dict):
            raise SuiteFileError(f"{where}: not a suite")
        s = {k: sec[k] for k in ("name", "description", "source_seeds", "trials", "max_total_steps", "methods",
                                 "learners") if k in sec}
        s["cases"] = [{k: v for k, v in (c.items() if isinstance(c, dict) else ()) if v is not None or k == "task"}
                      for c in sec.get("cases") or []]
        for c in s["cases"]:
            if c.get("task") is None:
                c.pop("task", None)
            if isinstance(c.get("distance"), list) and c["distance"][-1] is None:
                c["distance"] = c["distance"][:1]
            if c.get("cells") == "any":
                del c["cells"]
        top["sections"].append(s)
    worlds = data.get("worlds") or {}
    if not isinstance(worlds, dict):
        raise SuiteFileError(f"{where}: not a suite")
    suite = parse(top, where, None, worlds, builtin={}, check=False)
    if data.get("budget_factor", suites.BUDGET_FACTOR) != suites.BUDGET_FACTOR:
        raise SuiteFileError(f"{where}: a success budget of {data.get('budget_factor')!r}x the shortest path; this "
                             f"build's is {suites.BUDGET_FACTOR}x")
    return suite


def builtin() -> dict[str, suites.Suite]:
    """The suites shipped with the package, by name, in the order of ``suite_data/ORDER``."""
    order = (DATA / "ORDER").read_text().split()
    out: dict[str, suites.Suite] = {}
    for name in order:
        path = DATA / f"{name}.toml"
        data = tomllib.loads(path.read_text())
        out[name] = parse(data, f"built-in suite file {path.name!r}", DATA, builtin=out, check=False)
    return out
