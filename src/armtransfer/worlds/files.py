"""Layout files: a world as data, in TOML or JSON, written by hand.

    name = "corridor"                # optional; default: the file's stem
    description = "two rooms"        # optional
    grid = \"\"\"
    .......
    .......
    ...#...
    ###D###
    ...#...
    .......
    .......
    \"\"\"

    [tasks]                          # at least one; the first is the default
    1 = { start = [0, 2], goal = [0, -2] }
    across = { start = [-2, 2], goal = [2, -2] }

The grid's characters and coordinates are :mod:`armtransfer.worlds.grid`'s; in JSON the grid
is one string or a list of row strings. Every task must be solvable (``worlds.check``).
"""

from __future__ import annotations

import numbers
import os
from pathlib import Path

from armtransfer.errors import InvalidWorldError
from armtransfer.io import parse_user_file_bytes
from armtransfer.worlds.check import check_world
from armtransfer.worlds.grid import grid_rows, layout_from_rows
from armtransfer.worlds.layout import Layout, NamedTask

KEYS = ("name", "description", "grid", "tasks")
MAX_BYTES = 1 << 20
"""A layout file larger than this is refused (a 201 x 201 grid is about 41 kB)."""


def load_layout(path: str | os.PathLike) -> Layout:
    """The world of a layout file (``.toml`` or ``.json``), checked; a one-line
    :class:`InvalidWorldError` naming the file and the fault otherwise."""
    p = Path(path)
    shown = str(p) if len(str(p)) <= 120 else f"{str(p)[:50]}...{str(p)[-50:]}"
    where = f"world file {shown!r}"
    if p.suffix.lower() not in (".toml", ".json"):
        raise InvalidWorldError(f"{where}: a layout file ends in .toml or .json")
    try:
        if not p.is_file():
            raise InvalidWorldError(f"{where}: no such file" if not p.exists() else f"{where}: not a regular file")
        if p.stat().st_size > MAX_BYTES:
            raise InvalidWorldError(f"{where}: larger than {MAX_BYTES:,} bytes")
        raw = p.read_bytes()
    except (OSError, ValueError) as err:  # ValueError: a path with a NUL byte
        raise InvalidWorldError(f"{where}: cannot be read: {getattr(err, 'strerror', None) or err}") from None
    try:
        data = parse_user_file_bytes(raw, p.suffix)
    except ValueError as err:
        raise InvalidWorldError(f"{where} {err}") from None
    return parse_layout(data, p.stem, where)


def parse_layout(data: object, default_name: str, where: str) -> Layout:
    """The world of a layout file's parsed content (see the module's docstring)."""
    if not isinstance(data, dict):
        raise InvalidWorldError(f"{where}: a layout is a table of {', '.join(KEYS)}")
    unknown = sorted(str(k) for k in data if k not in KEYS)
    if unknown:
        raise InvalidWorldError(f"{where}: unknown key {unknown[0]!r}; valid keys: {', '.join(KEYS)}")
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name.strip() or len(name) > 100 or not name.isprintable():
        raise InvalidWorldError(f"{where}: name must be a printable string of 1 to 100 characters, got {name!r}")
    if not isinstance(data.get("description", ""), str):
        raise InvalidWorldError(f"{where}: description must be a string")
    grid = data.get("grid")
    if isinstance(grid, list) and all(isinstance(row, str) for row in grid):
        grid = "\n".join(grid)
    if not isinstance(grid, str):
        raise InvalidWorldError(f"{where}: grid must be the rows of the world as text ('.' free, '#' wall, 'D' door)")
    rows = grid_rows(grid, where)
    tasks = parse_tasks(data.get("tasks"), where)
    return check_world(layout_from_rows(rows, name.strip(), tasks), where)


def parse_tasks(tasks: object, where: str) -> tuple[NamedTask, ...]:
    """``{name: {start: [x, y], goal: [x, y]}}`` as named tasks, in the file's order."""
    if not isinstance(tasks, dict) or not tasks:
        raise InvalidWorldError(f"{where}: tasks must be a table of at least one task, each with a start and a goal")
    out = []
    for name, task in tasks.items():
        if not (0 < len(name) <= 40 and name.isprintable() and name == name.strip()):
            raise InvalidWorldError(f"{where}: a task's name must be 1 to 40 printable characters without spaces at "
                                    f"its ends, got {name[:40]!r}")
        if not isinstance(task, dict) or sorted(task) != ["goal", "start"]:
            raise InvalidWorldError(f"{where}: task {name!r} must have exactly a start and a goal, each [x, y]")
        out.append((str(name), _xy(task["start"], f"{where}: task {name!r}: start"),
                    _xy(task["goal"], f"{where}: task {name!r}: goal")))
    return tuple(out)


def _xy(value: object, what: str) -> tuple[int, int]:
    if (not isinstance(value, list) or len(value) != 2
            or any(isinstance(v, bool) or not isinstance(v, numbers.Integral) for v in value)):
        raise InvalidWorldError(f"{what} must be two integers [x, y], got {value!r}")
    return int(value[0]), int(value[1])


def layout_data(layout: Layout) -> dict:
    """A world as the content of a layout file (name, grid rows, tasks): what a sweep's runs
    carry, so that a run names its world by content and any worker can rebuild it."""
    rows = layout.ascii({door: "D" for door in layout.doors}).splitlines()
    return {"name": layout.name, "grid": rows,
            "tasks": {name: {"start": list(start), "goal": list(goal)} for name, start, goal in layout.tasks}}

