"""The stored form of a spec: every field at its default left out, filled back in when read.

A sweep's spec, a benchmark plan's, a suite's sections and cases and a result's JSON are
stored (and hashed into a store's key) without the fields that equal their defaults, so a
field added later changes no byte or key of what was stored before it. Each kind names its
defaults in one table (a ``DEFAULTS`` mapping) and goes through these two functions: one
leaves the defaults out when writing, one fills them in when reading; no other code compares
a field with its default to decide whether it is written.

A *group* of fields (a tuple of names, with a tuple of defaults) is left out only all at once,
when every one of them is at its default (a continuous case keeps a noise of 0; a case given by
cells keeps both of them).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

Defaults = Mapping[Any, Any]
"""A kind's defaults: a field's name and its default, or a group's names and their defaults."""


def _groups(defaults: Defaults) -> list[tuple[tuple[str, ...], tuple]]:
    return [((name,), (default,)) if isinstance(name, str) else (name, tuple(default))
            for name, default in defaults.items()]


def leave_out(values: Mapping[str, Any], defaults: Defaults) -> dict:
    """``values`` in their order, without every field (or group of fields) equal to its
    default (``==``, so an integer equal to a default float is left out too)."""
    out = dict(values)
    for names, defaults_of in _groups(defaults):
        if all(name in out and out[name] == default for name, default in zip(names, defaults_of)):
            for name in names:
                del out[name]
    return out


def fill_in(stored: Mapping[str, Any], defaults: Defaults) -> dict:
    """``stored`` with every field it leaves out at its default (added after the stored ones)."""
    out = dict(stored)
    for names, defaults_of in _groups(defaults):
        for name, default in zip(names, defaults_of):
            out.setdefault(name, copy.deepcopy(default))
    return out
