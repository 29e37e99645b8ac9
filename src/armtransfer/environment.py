"""The environment variables the package reads, checked before a command does anything: a bad
value is one line naming the variable, exit 2, and nothing written (a bad value found later,
in a sweep's workers, failed every run and left their records behind).

The variables: ``ARMTRANSFER_NO_PLUGINS`` (1: read no installed plugin, a way round a broken
one, :mod:`armtransfer.learning.lazy_registry`), ``ARMTRANSFER_CPUS`` (threads per process, :mod:`armtransfer.cpus`),
``ARMTRANSFER_CACHE`` and, without it, ``XDG_CACHE_HOME`` (the arm cache's folder,
:func:`armtransfer.ik.cache.cache_dir`). ``MUJOCO_GL`` is checked where it is used
(:mod:`armtransfer.ik.offscreen` falls back from a backend that cannot be loaded).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from armtransfer.cpus import ENV as CPUS_ENV
from armtransfer.cpus import cpus
from armtransfer.errors import InvalidParameterError
from armtransfer.learning.lazy_registry import SKIP_ENV, plugins_skipped

CACHE_ENV = "ARMTRANSFER_CACHE"
XDG_ENV = "XDG_CACHE_HOME"
VARIABLES = (SKIP_ENV, CPUS_ENV, CACHE_ENV, XDG_ENV)
"""Every environment variable of the package's own (``MUJOCO_GL`` is MuJoCo's)."""


def check_environment() -> None:
    """Raise ``InvalidParameterError`` (one line naming the variable) for a bad value of any
    variable in :data:`VARIABLES`; reads, never writes."""
    plugins_skipped()
    try:
        cpus()
    except InvalidParameterError as err:
        raise InvalidParameterError(f"environment variable {err}") from None
    for name in (CACHE_ENV, XDG_ENV):
        value = os.environ.get(name, "")
        if value:
            _check_folder(name, value)
        if name == CACHE_ENV and value:
            break  # XDG_CACHE_HOME is not used


def _check_folder(name: str, value: str) -> None:
    """``value`` can be a folder: it is one, or it is absent below a folder (a file where a
    folder belongs, a name too long or with a NUL byte, a loop of links are refused)."""
    shown = value if len(value) <= 120 else f"{value[:60]}...{value[-40:]} ({len(value)} characters)"
    if "\0" in value:
        raise InvalidParameterError(f"environment variable {name} holds a NUL byte: {shown!r}")
    path = Path(value).expanduser()
    probe = path
    while True:
        try:
            st = os.stat(probe)
        except FileNotFoundError:
            if probe.parent == probe:
                return
            probe = probe.parent
            continue
        except OSError as err:
            raise InvalidParameterError(f"environment variable {name}: cannot use {shown!r}: "
                                        f"{err.strerror or err}") from None
        break
    if not stat.S_ISDIR(st.st_mode):
        what = "is not a folder" if probe == path else f"is below {str(probe)!r}, which is not a folder"
        raise InvalidParameterError(f"environment variable {name} must name a folder; {shown!r} {what}")
