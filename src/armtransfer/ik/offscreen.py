"""Which offscreen OpenGL backend works on this machine, found out before anything renders.

MuJoCo renders offscreen through the backend ``MUJOCO_GL`` names (``egl``: EGL, with a GPU or
Mesa's llvmpipe on the CPU; ``osmesa``: Mesa's software renderer; ``glfw``: a window system),
read once, when ``mujoco`` is first imported. A backend whose libraries are missing fails
deep inside PyOpenGL, sometimes at ``import mujoco`` itself, sometimes leaving the process
unable to try another; so each backend is tried in a child process that opens a one-pixel
context and renders it (:func:`probe`).

:func:`set_default` runs before the first ``import mujoco`` (``armtransfer.ik`` calls it): it
names EGL unless the user named a backend, and where the named backend's library is not
installed (or the name is not a backend) it imports MuJoCo without OpenGL instead, so that
everything but drawing (compiling arms, IK, physics, learning) still works and the first
drawing says what to install. :func:`require` is what every rendering entry point calls
first: with a backend named by the user it checks that one; with none named it tries EGL,
then OSMesa, and sets ``MUJOCO_GL`` to the first that works (while ``mujoco`` is not yet
imported). When none works it raises :class:`OffscreenError`: one line naming the backends
tried and why each failed, the system packages that provide EGL or OSMesa, and the caller's
way to go on without a picture.

This module never imports ``mujoco`` itself, so it can run before the backend is fixed.
"""

from __future__ import annotations

import ctypes.util
import os
import subprocess
import sys

from armtransfer.errors import ArmTransferError

VARIABLE = "MUJOCO_GL"
DEFAULT = "egl"
UNSET_ORDER = ("egl", "osmesa")
"""The backends tried, in order, when the user named none."""
WITHOUT_GL = "disable"
"""What ``mujoco`` is imported with when the named backend cannot even be imported."""
LIBRARIES = {"egl": "EGL", "osmesa": "OSMesa"}
"""The shared library each headless backend loads."""
KNOWN = ("egl", "osmesa", "glfw", "glx", "cgl", "wgl", "enable", "enabled", "on", "true", "1",
         "disable", "disabled", "off", "false", "0")
"""Every value of ``MUJOCO_GL`` that MuJoCo's Python bindings accept on some system."""
PACKAGES = ("EGL (Debian/Ubuntu: libegl1 libgl1; Fedora: mesa-libEGL) or OSMesa "
            "(Debian/Ubuntu: libosmesa6; Fedora: mesa-libOSMesa)")
"""The system packages that provide a headless backend, on the common distributions."""
PROBE_SECONDS = 120.0

_PROBE = """
import sys
try:
    import mujoco
    model = mujoco.MjModel.from_xml_string("<mujoco/>")
    renderer = mujoco.Renderer(model, 1, 1)
    renderer.render()
    renderer.close()
except BaseException as err:
    text = " ".join(str(err).split()) or "no message"
    sys.exit(f"{type(err).__name__}: {text}"[:200])
"""

_defaulted = False
"""True while the backend in ``MUJOCO_GL`` is this module's choice, not the user's."""
_replaced: str | None = None
"""The backend the user named that could not even be imported (``MUJOCO_GL`` now disables GL)."""
_probed: dict[str, str | None] = {}


class OffscreenError(ArmTransferError):
    """No offscreen OpenGL backend works here (the message says what to install)."""


def missing(backend: str) -> str | None:
    """Why ``backend`` cannot work here, known without trying it (None: it may)."""
    if backend not in KNOWN:
        return f"not a backend (valid: {', '.join(UNSET_ORDER)}, glfw)"
    library = LIBRARIES.get(backend)
    if library is not None and ctypes.util.find_library(library) is None:
        return f"lib{library} is not installed"
    return None


def set_default() -> None:
    """Before the first ``import mujoco``: name :data:`DEFAULT` in ``MUJOCO_GL`` unless the user
    named a backend, and import MuJoCo without OpenGL where the backend cannot be imported
    (its library is missing, or it is no backend), so that only drawing fails."""
    global _defaulted, _replaced
    if "mujoco" in sys.modules:
        return
    if not os.environ.get(VARIABLE, "").strip():
        os.environ[VARIABLE] = DEFAULT
        _defaulted = True
    backend = os.environ[VARIABLE].strip().lower()
    if backend != WITHOUT_GL and missing(backend) is not None:
        if not _defaulted:
            _replaced = backend
        os.environ[VARIABLE] = WITHOUT_GL


def named() -> str | None:
    """The backend the user named in ``MUJOCO_GL`` (None: none, :func:`set_default` chose)."""
    if _replaced is not None:
        return _replaced
    value = os.environ.get(VARIABLE, "").strip().lower()
    return None if _defaulted or not value else value


def imported_backend() -> str | None:
    """The backend ``mujoco`` was imported with in this process (None: not imported yet)."""
    mujoco = sys.modules.get("mujoco")
    if mujoco is None:
        return None
    context = getattr(mujoco, "GLContext", None)
    return WITHOUT_GL if context is None else context.__module__.split(".")[-1]


def probe(backend: str) -> str | None:
    """None when a one-pixel offscreen context works under ``backend``, else why not (one
    line). Tried in a child process, once per backend and process."""
    if backend not in _probed:
        why = missing(backend)
        if why is None:
            env = {**os.environ, VARIABLE: backend}
            try:
                proc = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True,
                                      timeout=PROBE_SECONDS)
            except subprocess.TimeoutExpired:
                why = f"no answer in {PROBE_SECONDS:.0f} s"
            else:
                lines = [line.strip() for line in proc.stderr.splitlines() if line.strip()]
                if proc.returncode != 0:
                    why = lines[-1] if lines else f"exit code {proc.returncode}"
        _probed[backend] = why
    return _probed[backend]


def candidates() -> tuple[str, ...]:
    """The backends :func:`require` tries: the one the user named, else EGL then OSMesa."""
    user = named()
    return UNSET_ORDER if user is None else (user,)


def require(without: str) -> str:
    """The backend that renders here, set in ``MUJOCO_GL`` when ``mujoco`` is not imported yet;
    :class:`OffscreenError` when none does. ``without`` ends the message: how the caller goes
    on without a picture (e.g. ``"run with --no-video"``)."""
    global _defaulted, _replaced
    tried = []
    for backend in candidates():
        why = probe(backend)
        imported = imported_backend()
        if why is None and imported not in (None, backend):
            why = f"works, but this process imported mujoco with {VARIABLE}={imported}; set it before the import"
        if why is None:
            if imported is None:
                os.environ[VARIABLE] = backend
                _defaulted, _replaced = False, None
            return backend
        tried.append(f"{VARIABLE}={backend}: {why}")
    raise OffscreenError(failure(tried, without))


def failure(tried: list[str], without: str) -> str:
    """The one-line message when no backend works."""
    return (f"offscreen rendering does not work here ({'; '.join(tried)}); install {PACKAGES} and set "
            f"{VARIABLE}=egl or {VARIABLE}=osmesa, or {without}")


def broken(err: BaseException, without: str) -> OffscreenError:
    """An :class:`OffscreenError` for a context that failed in this process after the probe."""
    text = " ".join(str(err).split())[:200] or "no message"
    backend = imported_backend() or os.environ.get(VARIABLE, "?")
    return OffscreenError(failure([f"{VARIABLE}={backend}: {type(err).__name__}: {text}"], without))


__all__ = ["OffscreenError", "PACKAGES", "broken", "candidates", "missing", "named", "probe", "require",
           "set_default"]
