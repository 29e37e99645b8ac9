"""A name -> entry mapping that reads its installed plugins on first use, and live views of it.

``armtransfer.learning.methods.METHODS`` is one: its built-in entries are there from the start;
the entries other packages declare (Python entry points, ``armtransfer.learning.plugins``) are
read the first time anything looks in the mapping, never at import, so that importing the package
stays cheap and a plugin's import cost is paid only by a run that reads the registry. Reading
runs no code of a plugin's beyond its import (which is given :data:`IMPORT_SECONDS`). A plugin
that cannot be used (it fails to import, is not an entry of the kind, is named otherwise than its
entry point, or takes a name already taken) is left out: it breaks only itself, with one warning
(:class:`PluginWarning`; the command line prints it as one line naming it and the
``pip uninstall`` that removes it), and looking it up raises its one-line error. ``ARMTRANSFER_NO_PLUGINS=1``
reads no installed plugin.

:class:`Names` is a tuple-like view of the names whose entry passes a test, computed on every
use, so a module can hold, say, "the reward-only methods" as a constant and still see a method
registered later.
"""

from __future__ import annotations

import os
import signal
import threading
import time
import warnings
from collections.abc import Callable, Iterator, MutableMapping, Sequence
from importlib.metadata import entry_points
from typing import Generic, TypeVar, overload

from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.learning.plugin_calls import fault

V = TypeVar("V")

IMPORT_SECONDS = 60.0
"""An installed plugin that takes longer than this to import is left out (a warning line): a
plugin that hangs as it is imported cannot hang ``--help``."""

SKIP_ENV = "ARMTRANSFER_NO_PLUGINS"
"""Set to 1, no installed plugin is read (0 or unset: they are). Any other value is refused."""


class PluginWarning(UserWarning):
    """An installed plugin that cannot be used is left out (one line naming it and how to remove it)."""


def plugins_skipped() -> bool:
    """Whether :data:`SKIP_ENV` says to read no installed plugin (a bad value: one line)."""
    value = os.environ.get(SKIP_ENV, "").strip()
    if value not in ("", "0", "1"):
        raise InvalidParameterError(f"environment variable {SKIP_ENV} must be 1 (read no installed plugin) or 0, "
                                    f"got {value[:40]!r}")
    return value == "1"


class Registry(MutableMapping[str, V], Generic[V]):
    """The built-in entries, then (on first use) what ``load(registry)`` adds."""

    def __init__(self, builtin: dict[str, V], load: Callable[["Registry[V]"], None] | None = None) -> None:
        self._entries: dict[str, V] = dict(builtin)
        self.broken: dict[str, tuple[str, str]] = {}
        """Installed plugins left out: their name -> (the one-line error naming them, the warning)."""
        self.builtin: frozenset[str] = frozenset(builtin)
        self._load = load
        self._state = "unloaded"  # -> "loading" -> "loaded"
        self._lock = threading.RLock()  # another thread waits for the load; the loading one sees its entries

    def ensure_loaded(self) -> None:
        """Run the loader once; while it runs (its plugins may look in the registry) only the
        entries so far are seen."""
        if self._state == "loaded" or self._load is None:
            return
        with self._lock:
            if self._state != "unloaded":  # loaded meanwhile, or this thread's loader looking in
                return
            self._state = "loading"
            try:
                self._load(self)
            except BaseException:
                self._state = "unloaded"
                raise
            self._state = "loaded"

    def add(self, name: str, value: V) -> None:
        """Add an entry without reading the plugins first (what the loader itself uses)."""
        self._entries[name] = value

    def peek(self) -> dict[str, V]:
        """The entries so far, without reading the plugins."""
        return dict(self._entries)

    def __getitem__(self, name: str) -> V:
        self.ensure_loaded()
        if name not in self._entries and isinstance(name, str) and name in self.broken:
            raise PluginError(self.broken[name][0])
        return self._entries[name]

    def leave_out(self, name: str, error: str, warning: str) -> None:
        """Record the installed plugin ``name`` as broken: looking it up raises ``error``; the
        command line prints ``warning`` (a Python user gets it as a :class:`PluginWarning`)."""
        if name not in self.builtin:
            self._entries.pop(name, None)
        self.broken[name] = (error, warning)
        warnings.warn(warning, PluginWarning, stacklevel=2)

    def __setitem__(self, name: str, value: V) -> None:
        self.ensure_loaded()
        self._entries[name] = value

    def __delitem__(self, name: str) -> None:
        self.ensure_loaded()
        del self._entries[name]

    def __iter__(self) -> Iterator[str]:
        self.ensure_loaded()
        return iter(list(self._entries))

    def __len__(self) -> int:
        self.ensure_loaded()
        return len(self._entries)

    def __contains__(self, name: object) -> bool:
        self.ensure_loaded()
        return name in self._entries

    def __repr__(self) -> str:
        return f"Registry({list(self._entries)!r}, {self._state})"


class Names(Sequence[str], Generic[V]):
    """The names of ``registry`` whose entry passes ``test``, in the registry's order, computed
    on every use (a tuple-like view: iterate it, index it, test ``in``, join it)."""

    def __init__(self, registry: Registry[V], test: Callable[[str, V], bool], doc: str = "") -> None:
        self._registry = registry
        self._test = test
        self.__doc__ = doc or None

    def _names(self) -> tuple[str, ...]:
        return tuple(name for name, entry in self._registry.items() if self._test(name, entry))

    @overload
    def __getitem__(self, i: int) -> str: ...

    @overload
    def __getitem__(self, i: slice) -> tuple[str, ...]: ...

    def __getitem__(self, i: int | slice) -> str | tuple[str, ...]:
        return self._names()[i]

    def __len__(self) -> int:
        return len(self._names())

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())

    def __contains__(self, name: object) -> bool:
        return name in self._names()

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Names):
            return self._names() == other._names()
        if isinstance(other, (tuple, list)):
            return self._names() == tuple(other)
        return NotImplemented

    def __hash__(self) -> int:
        return id(self)

    def __repr__(self) -> str:
        return repr(self._names())


def describe_entry_point(ep: object, group: str) -> str:
    """How an error names a plugin: its distribution, version and entry point."""
    dist = getattr(ep, "dist", None)
    who = f"{dist.metadata['Name']} {dist.version}" if dist is not None else "an unnamed distribution"
    return f"plugin {who} (entry point {getattr(ep, 'name')} = {getattr(ep, 'value')} in group {group})"


def read_entry_points(group: str, registry: Registry[V], kind: str, check: Callable[[object, str], V],
                      named: Callable[[V], str], with_origin: Callable[[V, str], V]) -> dict[str, V]:
    """Every entry installed packages declare under ``group``, loaded, passed through
    ``check(obj, where)`` (which raises the plugin's one-line error) and given its origin; the
    entry point's name must be the entry's own, and no name may be taken twice. A fault is a
    :class:`~armtransfer.errors.PluginError` naming the plugin, and then nothing is returned, so
    nothing is added. ``kind`` ("method", "learner") names the entries in the errors."""
    found: dict[str, V] = {}
    if plugins_skipped():
        return found
    claimed: dict[str, str] = {}  # a name -> the plugin that declared it first
    for ep in sorted(entry_points(group=group), key=lambda e: (e.name, e.value)):
        where = describe_entry_point(ep, group)
        try:
            entry = _read_one(ep, where, check, registry, kind, named, found, claimed)
        except PluginError as err:
            ep_name = str(getattr(ep, "name", "?"))
            found.pop(ep_name, None)
            registry.leave_out(ep_name, str(err), left_out(where, str(err), ep))
            continue
        found[ep.name] = with_origin(entry, where)
    return found


def _read_one(ep: object, where: str, check: Callable[[object, str], V], registry: Registry[V], kind: str,
              named: Callable[[V], str], found: dict[str, V], claimed: dict[str, str]) -> V:
    ep_name = str(getattr(ep, "name", "?"))
    first = claimed.setdefault(ep_name, where)
    if first != where:  # two plugins declare one name: neither is used
        raise PluginError(f"{where} is named {ep_name!r}, as a {kind} of {first} is; rename one of them")
    try:
        obj = _load_within(ep, IMPORT_SECONDS)
    except KeyboardInterrupt:
        raise
    except _ImportOverrun:
        raise PluginError(f"{where} did not import within {IMPORT_SECONDS:g} s") from None
    except BaseException as err:  # noqa: BLE001 - any failure to import is the plugin's, in one line
        raise PluginError(f"{where} fails to import: {fault(err)}") from None
    entry = check(obj, where)
    name = named(entry)
    if name != ep_name:
        raise PluginError(f"{where} is a {kind} named {name!r}; name the entry point as the {kind}")
    taken = registry.peek()
    if name in taken:
        other = getattr(taken[name], "origin")
        raise PluginError(f"{where} is named {name!r}, as a {kind} of {other} is; rename one of them")
    return entry


class _ImportOverrun(BaseException):
    """Raised into a plugin's import that overran (a BaseException: its ``except Exception`` cannot keep it)."""


def _load_within(ep: object, seconds: float) -> object:
    """``ep.load()``, interrupted after ``seconds`` by a timer signal in the main thread (a
    Python-level wait or loop is interrupted; the import then fails and leaves nothing behind).
    Elsewhere, or under a timer of the caller's due sooner, without a limit."""
    load = getattr(ep, "load")
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        return load()
    outer_delay, outer_interval = signal.getitimer(signal.ITIMER_REAL)
    if outer_delay and outer_delay <= seconds:
        return load()  # the caller's own timer is due first: it is left alone

    def overran(signum: int, frame: object) -> None:
        raise _ImportOverrun()

    previous = signal.signal(signal.SIGALRM, overran)
    t0 = time.monotonic()
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return load()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
        if outer_delay:  # the caller's timer, given back what is left of it
            signal.setitimer(signal.ITIMER_REAL, max(outer_delay - (time.monotonic() - t0), 1e-3), outer_interval)


def left_out(where: str, error: str, ep: object) -> str:
    """The one warning line of a plugin left out: what is wrong and how to remove it."""
    dist = getattr(ep, "dist", None)
    try:
        remove = f"pip uninstall {dist.metadata['Name']}" if dist is not None else "uninstall its distribution"
    except Exception:  # noqa: BLE001 - a distribution without a name
        remove = "uninstall its distribution"
    said = error[len(where):].lstrip(": ") if error.startswith(where) else error
    return (f"{where} is left out ({said}); remove it with '{remove}', or set {SKIP_ENV}=1 to read no "
            "installed plugin")
