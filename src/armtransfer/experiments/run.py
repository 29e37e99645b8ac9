"""A run: one unit of work of the result store, a frozen value checked once when it is made.

Three kinds share the base :class:`Run` (the robots, the task's start and goal cells, the seed,
the learner and the world):

- :class:`SweepRun` (``armtransfer sweep``, ``armtransfer matrix``): ``trials`` trials of one
  method with flat learner settings;
- :class:`SourceRun` (``armtransfer benchmark``): robot 1 learning a case's task, handing its
  converged path over;
- :class:`TrialRun` (``armtransfer benchmark``): one trial of one method on robot 2.

A run is stored as :meth:`Run.to_dict` and read back with :meth:`Run.from_dict`; its store key
is :meth:`Run.key` (:func:`key_of`), a hash of that dict. **Schema version 1** is the form every store written
so far holds, and the key form by definition: a field at its default (:attr:`Run.DEFAULTS`) is
left out of the stored dict, so a run of a field's default keeps the key it had before the field
existed, and the version itself is implied: it is neither written nor hashed. A later schema
writes ``"schema": N`` into the dict (so into its key); :func:`migrate` turns any older stored
dict into the current fields, in one place.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

from armtransfer.errors import ArmTransferError
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning import presets
from armtransfer.learning.learner_names import SARSA
from armtransfer.worlds.resolve import DEFAULT_WORLD as DEFAULT_WORLD  # the world a run names when it names none

SCHEMA = 1
"""The schema version of the runs this build writes (version 1: implied, not hashed)."""

SWEEP_FORMAT = "armtransfer-run/1"
SOURCE_FORMAT = "armtransfer-benchmark-source/1"
TRIAL_FORMAT = "armtransfer-benchmark-trial/1"

STATES = ("discrete", "continuous")
"""How the target robot's state is known: its table of states, or its joint configuration."""

TRAJECTORY_KINDS = ("optimal", "learned")
"""The trajectory a sweep run's robot 1 hands over: its shortest path, or its learned greedy path."""



class RunError(ArmTransferError):
    """A run's configuration is malformed (an unknown format, state or field, a bad value)."""


def key_of(stored: dict, schema: int = SCHEMA) -> str:
    """The store key of a run stored as ``stored`` under schema ``schema``: schema 1 hashes the
    stored dict as it is (the key every store written so far holds); a later schema hashes it with
    its version, ``"schema": N``, so no two schemas share a key."""
    return content_key(stored if schema == 1 else {**stored, "schema": schema})


def content_key(obj: object) -> str:
    """The store key of a JSON-able value: the first 20 hex digits of the SHA-256 of its
    canonical JSON (sorted keys, no spaces)."""
    text = json.dumps(obj, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:20]


def _cell(value: object, what: str) -> tuple[int, int]:
    if not (isinstance(value, (list, tuple)) and len(value) == 2
            and all(isinstance(v, int) and not isinstance(v, bool) for v in value)):
        raise RunError(f"a run's {what} must be a cell [X, Y] of two integers, got {value!r:.60}")
    return int(value[0]), int(value[1])


def _whole(value: object, what: str, lo: int = 0) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < lo:
        raise RunError(f"a run's {what} must be an integer >= {lo}, got {value!r:.60}")
    return value


def _number(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise RunError(f"a run's {what} must be a number, got {value!r:.60}")
    return value


def _name(value: object, what: str) -> str:
    if not isinstance(value, str) or not value:
        raise RunError(f"a run's {what} must be a non-empty name, got {value!r:.60}")
    return value


def _one_of(value: object, valid: tuple[str, ...], what: str) -> str:
    if value not in valid:
        raise RunError(f"unknown {what} {value!r:.60} of a run; valid {what}s: {', '.join(valid)}")
    return str(value)


@dataclass(frozen=True, kw_only=True)
class Run:
    """What every run names: robot 1 (``source``), robot 2 (``target``), the task's cells
    (``start``, ``goal``: (x, y)), the seed, and who learns on robot 2 (``learner``)."""

    FORMAT: ClassVar[str] = ""
    ORDER: ClassVar[tuple[str, ...]] = ()
    """The stored dict's fields, in the order it is written (its bytes in the store)."""
    DEFAULTS: ClassVar[dict[str, Any]] = {}
    """The fields schema 1 leaves out of the stored dict (and so of the key) at these values."""
    LATER: ClassVar[tuple[str, ...]] = ()
    """Fields a kind writes after :attr:`ORDER`'s by a rule of its own (:meth:`to_dict`)."""

    source: str
    target: str
    start: tuple[int, int]
    goal: tuple[int, int]
    seed: int
    learner: str = SARSA
    _key: str = field(init=False, repr=False, compare=False, default="")

    def __post_init__(self) -> None:
        self._set("source", _name(self.source, "source"))
        self._set("target", _name(self.target, "target"))
        self._set("start", _cell(self.start, "start"))
        self._set("goal", _cell(self.goal, "goal"))
        _whole(self.seed, "seed")
        _name(self.learner, "learner")
        self.check()
        self._set("_key", key_of(self.to_dict()))

    def _set(self, name: str, value: object) -> None:
        object.__setattr__(self, name, value)

    def check(self) -> None:
        """The kind's own fields checked (a one-line :class:`RunError`)."""

    def key(self) -> str:
        """The run's store key: :func:`key_of` its :meth:`to_dict` under :data:`SCHEMA`."""
        return self._key

    def to_dict(self) -> dict:
        """The stored form (schema 1), without its key: every field of :attr:`ORDER` but those at
        their :attr:`DEFAULTS`; cells as lists."""
        out: dict[str, Any] = {"format": self.FORMAT}
        for name in self.ORDER:
            if name == "format":
                continue
            value = getattr(self, name)
            if name in self.DEFAULTS and _same(value, self.DEFAULTS[name]):
                continue
            out[name] = list(value) if name in ("start", "goal") else value
        return out

    def stored(self) -> dict:
        """:meth:`to_dict` with its ``key`` last: the run's ``config`` in the store's files."""
        return dict(self.to_dict(), key=self.key())

    @staticmethod
    def from_dict(data: dict) -> "Run":
        """The run a stored dict (of any schema, its ``key`` ignored) describes, by its format."""
        current = migrate(data)
        return KINDS[current.pop("format")](**current)


def _same(a: object, b: object) -> bool:
    return type(a) is type(b) and a == b if not isinstance(a, (dict, list)) else a == b


@dataclass(frozen=True, kw_only=True)
class SweepRun(Run):
    """``trials`` trials of ``method`` by the learner on robot 2 (a sweep's or a matrix's run):
    robot 1 hands over its ``trajectory`` kind of path; the learner's settings are flat, over
    ``preset``'s; ``world`` is the layout's data (None: the paper's rooms); ``arms`` the named
    arms the robots use (their definitions); ``K`` None for ``none`` (it ignores K)."""

    FORMAT = SWEEP_FORMAT
    ORDER = ("format", "world", "task", "start", "goal", "source", "target", "method", "seed", "trials",
             "trajectory", "K", "epsilon", "lam", "alpha", "gamma", "wind", "patience", "max_episodes", "preset",
             "max_total_steps", "learner", "learner_options", "arms")
    DEFAULTS = {"world": None, "preset": "default", "max_total_steps": None, "learner": SARSA,
                "learner_options": None, "arms": None}

    task: int | str | None
    method: str
    trials: int
    trajectory: str
    K: float | str | None
    epsilon: float
    lam: float
    alpha: float
    gamma: float
    wind: float
    patience: int
    max_episodes: int
    preset: str = "default"
    max_total_steps: int | None = None
    learner_options: dict | None = None
    world: dict | None = None
    arms: dict | None = None

    def check(self) -> None:
        _name(self.method, "method")
        _whole(self.trials, "trials", 1)
        _one_of(self.trajectory, TRAJECTORY_KINDS, "trajectory kind")
        if self.K is not None and self.K != "auto":
            _number(self.K, "K")
        for name in ("epsilon", "lam", "alpha", "gamma", "wind"):
            _number(getattr(self, name), name)
        _whole(self.patience, "patience", 1)
        _whole(self.max_episodes, "max_episodes", 1)
        _name(self.preset, "preset")
        if self.max_total_steps is not None:
            _whole(self.max_total_steps, "max_total_steps", 1)
        for name in ("learner_options", "world", "arms"):
            if getattr(self, name) is not None and not isinstance(getattr(self, name), dict):
                raise RunError(f"a run's {name} must be a table, got {getattr(self, name)!r:.60}")
            if not getattr(self, name):  # none: the key the run had before the field
                self._set(name, None)

    def learner_config(self, own_cap: bool = False) -> LearnerConfig:
        """The learner's settings: every setting the run names, over its preset's; ``own_cap``:
        without the run's ``max_total_steps`` (robot 1 learns with its own step cap)."""
        given = {name: getattr(self, name) for name in ("epsilon", "lam", "alpha", "gamma", "patience",
                                                        "max_episodes")}
        if self.max_total_steps is not None and not own_cap:
            given["max_total_steps"] = self.max_total_steps
        return presets.config(self.preset, given)


@dataclass(frozen=True, kw_only=True)
class SourceRun(Run):
    """Robot 1 (``source``) learning a benchmark case's task without transfer, with the learner
    settings ``config`` (``LearnerConfig.to_dict``), in ``world`` (a world's name)."""

    FORMAT = SOURCE_FORMAT
    ORDER: ClassVar[tuple[str, ...]] = ("format", "learner", "source", "target", "start", "goal", "seed", "config", "world")
    DEFAULTS = {"world": DEFAULT_WORLD}

    config: dict
    world: str = DEFAULT_WORLD

    def check(self) -> None:
        if not isinstance(self.config, dict):
            raise RunError(f"a run's config must be a table of learner settings, got {self.config!r:.60}")
        LearnerConfig(**self.config)  # its own one-line errors
        _name(self.world, "world")

    def learner_config(self) -> LearnerConfig:
        return LearnerConfig(**self.config)


@dataclass(frozen=True, kw_only=True)
class TrialRun(SourceRun):
    """Trial ``trial`` of ``method`` on robot 2 of a benchmark case. ``handed``: whether the
    method reads robot 1's result, ``trajectory`` (None: robot 1 handed nothing over, and
    ``source_failure`` says why; ``told_nothing`` then names the baseline the trial runs
    instead, None in a run written before that rule). ``state`` ``continuous``: robot 2 is
    ``target``'s continuous arm with actuation noise ``noise``."""

    FORMAT = TRIAL_FORMAT
    ORDER: ClassVar[tuple[str, ...]] = ("format", "learner", "method", "trial", "source", "target", "start", "goal", "wind", "seed", "config",
             "learner_options", "world", "state", "noise")
    DEFAULTS = {"learner_options": None, "world": DEFAULT_WORLD, "state": "discrete", "noise": None}
    LATER = ("trajectory", "source_failure", "told_nothing")

    method: str
    trial: int
    wind: float
    learner_options: dict | None = None
    state: str = "discrete"
    noise: float | None = None
    """The actuation noise of a continuous target (None: a discrete target, which has none)."""
    handed: bool = False
    trajectory: dict | None = None
    source_failure: str | None = None
    told_nothing: str | None = None

    def check(self) -> None:
        super().check()
        _name(self.method, "method")
        _whole(self.trial, "trial")
        _number(self.wind, "wind")
        _one_of(self.state, STATES, "state")
        if (self.state == "continuous") != (self.noise is not None):
            raise RunError(f"a run's noise goes with a continuous state (the arm's actuation noise), got state "
                           f"{self.state!r} with noise {self.noise!r}")
        if self.noise is not None:
            self._set("noise", float(_number(self.noise, "noise")))
        if self.learner_options is not None and not isinstance(self.learner_options, dict):
            raise RunError(f"a run's learner_options must be a table, got {self.learner_options!r:.60}")
        if not self.learner_options:  # no options: the key a learner had before learners had options
            self._set("learner_options", None)
        if not self.handed and (self.trajectory is not None or self.source_failure is not None
                                or self.told_nothing is not None):
            raise RunError("a run that reads no trajectory carries no trajectory, source_failure or told_nothing")
        if self.trajectory is not None and not isinstance(self.trajectory, dict):
            raise RunError(f"a run's trajectory must be a table, got {self.trajectory!r:.60}")

    def to_dict(self) -> dict:
        out = super().to_dict()
        if self.handed:  # a method reading the trajectory names what it was handed, None too
            out["trajectory"], out["source_failure"] = self.trajectory, self.source_failure
            if self.told_nothing is not None:
                out["told_nothing"] = self.told_nothing
        return out

    def as_baseline(self) -> "TrialRun":
        """The trial of :attr:`told_nothing`, the baseline told nothing, on this trial's case and seeds."""
        assert self.told_nothing is not None
        return TrialRun(**{**_init_fields(self), "method": self.told_nothing, "handed": False, "trajectory": None,
                           "source_failure": None, "told_nothing": None})


def _init_fields(run: Run) -> dict:
    return {f.name: getattr(run, f.name) for f in fields(run) if f.init}


KINDS: dict[str, type[Run]] = {SWEEP_FORMAT: SweepRun, SOURCE_FORMAT: SourceRun, TRIAL_FORMAT: TrialRun}


def migrate(data: dict) -> dict:
    """A stored run of any schema (``data``, its ``key`` ignored) as the current one's fields:
    schema 1 (no ``schema`` field) has every field at its default left out, filled in here;
    a trial run's ``trajectory`` and ``source_failure`` present or not is ``handed``. A format
    or schema this build does not know is a one-line :class:`RunError`."""
    if not isinstance(data, dict):
        raise RunError(f"a run is a table, got {type(data).__name__}")
    schema = data.get("schema", 1)
    if schema != SCHEMA:
        raise RunError(f"a run of schema {schema!r:.20}; this build reads schema {SCHEMA}")
    fmt = data.get("format")
    if fmt not in KINDS:
        raise RunError(f"unknown format {fmt!r:.60} of a run; valid formats: {', '.join(KINDS)}")
    kind = KINDS[fmt]
    out = {k: v for k, v in data.items() if k not in ("key", "schema")}
    valid = (*kind.ORDER, *kind.LATER)
    unknown = sorted(set(out) - set(valid), key=str)
    if unknown:
        raise RunError(f"unknown field {unknown[0]!r:.60} of a run of format {fmt}; valid fields: {', '.join(valid)}")
    for name, default in [*kind.DEFAULTS.items(), *((name, None) for name in kind.LATER)]:
        out.setdefault(name, default)
    if kind is TrialRun:
        out["handed"] = "trajectory" in data or "source_failure" in data
    return out
