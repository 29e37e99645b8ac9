"""Numba's on-disk cache, kept honest across files.

Numba keys a cached kernel on its own file's time stamp and its own bytecode, not on the jitted
functions it calls from other files. So after an edit to a guide module alone, ``sarsa.py``'s
cached trial kernels (which inline the guide's functions) would load, still running the old
guide, and a run would silently measure code that is no longer there.

:func:`invalidate_stale` closes that gap: the caller names its cached kernels and the files they
call into; a digest of those files is kept beside the kernels' cache, and when it differs the
kernels' cache index is emptied, so they compile afresh on first use."""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from pathlib import Path

from armtransfer.errors import OutputError
from armtransfer.io import write_text_atomic

STAMP = "{module}.deps"
"""The digest's file name in the kernels' cache directory."""


def digest(files: Iterable[str | Path]) -> str:
    """SHA-256 over the files' names and bytes, in the given order."""
    h = hashlib.sha256()
    for f in files:
        p = Path(f)
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def invalidate_stale(module: str, kernels: Iterable, deps: Iterable[str | Path]) -> bool:
    """Empty the cache index of ``kernels`` (numba dispatchers of ``module``, ``cache=True``)
    when the digest of ``deps`` changed since it was last recorded; returns whether it did.

    Where the cache directory cannot be written numba does not cache either; then nothing is
    recorded and the check runs again at the next import."""
    kernels = [k for k in kernels if getattr(k, "_cache", None) is not None]
    if not kernels:
        return False
    new = digest(deps)
    stamp = Path(kernels[0]._cache.cache_path) / STAMP.format(module=module.rsplit(".", 1)[-1])
    try:
        if stamp.read_text() == new:
            return False
    except OSError:
        pass
    for k in kernels:
        try:
            k._cache.flush()
        except OSError:
            pass
    try:
        write_text_atomic(stamp, new)
    except OutputError:
        pass
    return True
