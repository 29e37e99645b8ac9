"""A world from what a user types: a built-in name, ``generated:SEED[:SIDE]`` or a layout file.

``rooms`` (the default) is the paper's 51 x 51 world with Table I's four tasks
(:data:`armtransfer.worlds.layout.ROOMS`); ``rooms11`` and ``rooms15`` are smaller four-room
worlds shipped as layout files in ``armtransfer/worlds/data/``; ``generated:SEED`` draws one
(:mod:`armtransfer.worlds.generate`); any other ``PATH.toml`` or ``PATH.json`` is a layout file
(:mod:`armtransfer.worlds.files`).
"""

from __future__ import annotations

import os
from functools import lru_cache
from pathlib import Path

from armtransfer.errors import InvalidWorldError
from armtransfer.worlds.files import layout_data, load_layout, parse_layout
from armtransfer.worlds.generate import PREFIX, generated_world, parse_generated
from armtransfer.worlds.layout import ROOMS, Layout

DEFAULT_WORLD = "rooms"
DATA = Path(__file__).resolve().parent / "data"
FILE_WORLDS = ("rooms11", "rooms15")
"""The built-in worlds shipped as layout files (``DATA/NAME.toml``)."""
WORLDS = (DEFAULT_WORLD, *FILE_WORLDS)
"""The built-in worlds' names; ``generated:SEED[:SIDE]`` and layout files are worlds too."""
VALID = f"{', '.join(WORLDS)}, {PREFIX}:SEED[:SIDE], or a layout file PATH.toml or PATH.json"


def world(spec: str | os.PathLike | Layout | None = None) -> Layout:
    """The world ``spec`` names (see the module's docstring); None is :data:`DEFAULT_WORLD`.
    A :class:`Layout` passes through unchanged. A one-line :class:`InvalidWorldError` for an
    unknown name or a bad layout file."""
    if spec is None:
        return ROOMS
    if isinstance(spec, Layout):
        return spec
    if isinstance(spec, os.PathLike):
        return _user_file(spec)
    if not isinstance(spec, str):
        raise InvalidWorldError(f"a world is a name or a layout file; valid worlds: {VALID}; got {spec!r}")
    if spec == DEFAULT_WORLD:
        return ROOMS
    if spec in FILE_WORLDS:
        return _shipped(spec)
    if spec.split(":")[0] == PREFIX:
        return _generated(*parse_generated(spec))
    if spec.lower().endswith((".toml", ".json")) or os.sep in spec or "/" in spec:
        return _user_file(spec)
    raise InvalidWorldError(f"unknown world {spec[:100]!r}; valid worlds: {VALID}")


def world_name(layout: Layout) -> str:
    """The name a world goes by in outputs (``rooms`` for the paper's layout)."""
    return layout.name or ("rooms" if layout == ROOMS else "unnamed")


def is_default(layout: Layout) -> bool:
    """True for the paper's rooms world, whose outputs name no world (they are the bytes they
    were before worlds could be chosen)."""
    return layout is ROOMS or layout == ROOMS


def layout_of_data(data: dict, where: str) -> Layout:
    """The world of ``worlds.files.layout_data``'s content: a built-in or generated world by
    its name when its content is the same (so it is the very layout the commands build),
    else the world of that content, checked as a layout file's."""
    name = data.get("name") if isinstance(data, dict) else None
    if isinstance(name, str) and (name in FILE_WORLDS or name.split(":")[0] == PREFIX):
        try:
            named = world(name)
        except InvalidWorldError:
            named = None
        if named is not None and layout_data(named) == data:
            return named
    refuse_reserved(name, where)
    return parse_layout(data, str(name), where)


@lru_cache(maxsize=None)
def _shipped(name: str) -> Layout:
    return load_layout(DATA / f"{name}.toml")


def _user_file(spec: str | os.PathLike) -> Layout:
    """A user's layout file; one that names itself as a built-in or generated world (its results
    would be indistinguishable from that world's) is one line."""
    layout = load_layout(spec)
    refuse_reserved(layout.name, f"world file {str(spec)[:120]!r}")
    return layout


def refuse_reserved(name: object, where: str) -> None:
    """A world named as a built-in world, or as a generated one, that is not it: one line."""
    if isinstance(name, str) and (name.strip().lower() in WORLDS or name.split(":")[0].strip().lower() == PREFIX):
        raise InvalidWorldError(f"{where}: name {name!r} is a built-in world's ({', '.join(WORLDS)}, "
                                f"{PREFIX}:SEED[:SIDE]); results would claim that world: give it a name of its own")


@lru_cache(maxsize=64)
def _generated(seed: int, side: int) -> Layout:
    return generated_world(seed, side)
