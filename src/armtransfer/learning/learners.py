"""Learners from outside the package: what a researcher writes, and how it is found.

A learner is a :class:`Learner`: a name, a one-line description and ``make(env, seed)``, which
returns a :class:`Model` learning on the Gymnasium environment ``env`` (the case's
``armtransfer/Rooms-v0`` or ``armtransfer/ArmRooms-v0`` environment, wrapped in
``armtransfer.TransferReward`` when the method has a reward term), seeded by ``seed`` alone.
A model is what stable-baselines3 users know: ``learn(total_timesteps)`` goes on learning
for that many *more* environment steps, ``predict(observation, deterministic=True)`` returns
``(action, state)``. The benchmark's harness (``armtransfer.experiments.learner_trial``) counts
the steps and episodes itself, from the environment it hands over; a learner never reports
its own numbers.

A package makes its learner known under the entry-point group ``armtransfer.learners`` (the
entry point's name is the learner's name, its object the :class:`Learner`); it is read on the
first use of :data:`LEARNERS`. A notebook calls :func:`register_learner` instead. A plugin that
cannot be imported, is not a :class:`Learner`, is named otherwise than its entry point or takes
a name already taken is left out with a warning, and refused in one line
(:class:`~armtransfer.errors.PluginError`) naming it and the fault when it is named; one whose
``make``, ``learn`` or ``predict`` raises anything, does not return within the probe's time
limit, or whose actions are not actions of the environment, is refused by the harness's probe
(``experiments.learner_trial.probe``) before a run learns or writes anything.

The built-in learner, ``sarsa``, is SARSA(lambda) (Algorithm 1) in the compiled kernel: the
benchmark runs it directly, not through ``make``.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from dataclasses import replace as with_fields
from typing import Any, Protocol

import gymnasium

from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.learning.lazy_registry import Registry, read_entry_points
from armtransfer.learning.learner_names import SARSA as SARSA  # the built-in learner's name
from armtransfer.learning.plugins import NAME

GROUP = "armtransfer.learners"
"""The entry-point group installed packages declare their learners under."""

RUN_TIME = "registered at run time"
"""``Learner.origin`` of a learner given to :func:`register_learner`."""

BUILTIN_ORIGIN = "armtransfer"



class Model(Protocol):
    """A model learning on one environment, as stable-baselines3 users know it."""

    def learn(self, total_timesteps: int) -> object:
        """Go on learning for ``total_timesteps`` more environment steps."""
        ...

    def predict(self, observation: Any, deterministic: bool = True) -> tuple[Any, Any]:
        """``(action, state)`` for ``observation``; ``state`` is the model's recurrent state (None)."""
        ...


@dataclass(frozen=True)
class Transfer:
    """What a learner with ``Learner.transfer`` is handed beside its environment: the method of
    the trial, robot 1's trajectories as (x, y) cells (each an (m, 2) int64 array, its start
    first and its goal last; none for a method that reads none or when robot 1 handed nothing
    over), and the shaping the method built for this robot (``learning.shaping.Shaping``: its
    ``phi`` per state for a potential method, bounded as the kernel's; None for ``none``). The
    environment already pays the method's reward term; a learner may use these to carry its own
    transfer (an initial Q, an exploration bias)."""

    method: str
    trajectories: tuple
    shaping: Any = None


@dataclass(frozen=True)
class Learner:
    """A learner: ``make(env, seed)`` is a :class:`Model` learning on ``env``, every random draw
    of it from ``seed``.

    ``options``: the settings ``make`` uses (a JSON-able mapping, e.g. ``{"alpha": 0.5}``): they
    are in each of its benchmark runs' configuration and key, so a changed option runs anew
    instead of resuming the old runs. ``transfer``: ``make`` is called ``make(env, seed,
    transfer)`` with the trial's :class:`Transfer`."""

    name: str
    description: str
    make: Callable[..., Model]
    origin: str = RUN_TIME
    """Where it comes from: ``armtransfer``, an installed plugin (named), or registered at run time."""
    options: Mapping[str, Any] | None = field(default=None, hash=False)  # a dict: a Learner stays hashable
    transfer: bool = False


def _sarsa_make(env: gymnasium.Env, seed: int) -> Model:
    raise InvalidParameterError("the built-in learner 'sarsa' runs in armtransfer's compiled kernel "
                                "(armtransfer.transfer, the benchmark), not as a model made on an environment")


_BUILTIN = {SARSA: Learner(SARSA, "SARSA(lambda), Algorithm 1, in the compiled kernel, with the method's shaping "
                                  "and its own convergence test (the greedy path unchanged for `patience` episodes)",
                           _sarsa_make, origin=BUILTIN_ORIGIN)}


def check(learner: object, where: str) -> Learner:
    """``learner`` if it is a whole :class:`Learner`; else a one-line :class:`PluginError`
    beginning with ``where``."""
    if not isinstance(learner, Learner):
        raise PluginError(f"{where} is {type(learner).__name__}, not a learner; make it with "
                          "armtransfer.Learner(name, description, make)")
    if not isinstance(learner.name, str) or not NAME.fullmatch(learner.name):
        raise PluginError(f"{where}: a learner's name is lower-case letters, digits, '_', '.' or '-' (at most 64), "
                          f"got {learner.name!r}")
    d = learner.description
    if not isinstance(d, str) or not d.strip() or "\n" in d.strip():
        raise PluginError(f"{where}: learner {learner.name!r}: its description must be one line of text, got {d!r}")
    if not callable(learner.make):
        raise PluginError(f"{where}: learner {learner.name!r}: make must be a function (env, seed) -> model, "
                          f"got {learner.make!r}")
    if learner.options is not None:
        try:
            if not isinstance(learner.options, Mapping) or not all(isinstance(k, str) for k in learner.options):
                raise TypeError("not a mapping of names")
            json.dumps(dict(learner.options), allow_nan=False)
        except (TypeError, ValueError) as err:
            raise PluginError(f"{where}: learner {learner.name!r}: options must be a mapping of names to JSON "
                              f"values (numbers, strings, lists), got {learner.options!r:.80} ({err})") from None
    if not isinstance(learner.transfer, bool):
        raise PluginError(f"{where}: learner {learner.name!r}: transfer must be True or False")
    return learner


def options_of(name: str) -> dict | None:
    """The options of learner ``name`` as its runs record them (None: it has none)."""
    if name in BUILTIN:
        return None
    opts = get(name).options
    return dict(opts) if opts else None


def load_entry_points(registry: Registry[Learner]) -> None:
    """Add every learner installed packages declare under :data:`GROUP` to ``registry``; a bad
    one is a :class:`PluginError` naming it, and then none is added."""
    found = read_entry_points(GROUP, registry, "learner", check, lambda lr: lr.name,
                              lambda lr, where: with_fields(lr, origin=where))
    for name, learner in found.items():
        registry.add(name, learner)


LEARNERS: Registry[Learner] = Registry(_BUILTIN, load_entry_points)
"""Every learner, ``sarsa`` first: the built-in one, then those of installed plugins (read on
first use) and those registered in this process."""

BUILTIN = tuple(_BUILTIN)


def register_learner(learner: Learner, replace: bool = False) -> Learner:
    """Make ``learner`` a learner of this process (a notebook's way; an installed package
    declares an entry point instead). ``replace``: an earlier run-time registration of the same
    name is replaced (a notebook cell run again), never the built-in or an installed plugin's."""
    name = getattr(learner, "name", None)
    where = f"learner {name!r} ({RUN_TIME})"
    if not isinstance(learner, Learner):
        raise PluginError(f"register_learner takes an armtransfer.Learner(name, description, make), "
                          f"got {type(learner).__name__}")
    check(learner, where)
    if learner.name in LEARNERS:
        old = LEARNERS[learner.name]
        if not (replace and old.origin == RUN_TIME):
            raise PluginError(f"{where}: the name is taken by a learner of {old.origin}; rename it"
                              + ("" if old.origin != RUN_TIME else ", or pass replace=True"))
    learner = with_fields(learner, origin=RUN_TIME)
    LEARNERS[learner.name] = learner
    return learner


def get(name: str) -> Learner:
    """The learner called ``name``; an unknown name is a one-line error listing the valid ones."""
    try:
        return LEARNERS[name]
    except (KeyError, TypeError):
        raise InvalidParameterError(f"unknown learner {name!r}; valid learners: {', '.join(LEARNERS)}") from None


def parse(names: str | list[str] | tuple[str, ...]) -> tuple[str, ...]:
    """Learner names from ``NAME[,NAME...]`` (or a list of them), each checked, in order; an
    empty name (``sarsa,``) or a name given twice is a one-line error."""
    items = names.split(",") if isinstance(names, str) else [n for part in names for n in str(part).split(",")]
    items = [n.strip() for n in items]
    if not any(items):
        raise InvalidParameterError(f"no learner named; valid learners: {', '.join(LEARNERS)}")
    if not all(items):
        raise InvalidParameterError(f"an empty learner name in {names!r}; give NAME[,NAME...], valid learners: "
                                    f"{', '.join(LEARNERS)}")
    found = [get(n).name for n in items]
    twice = next((n for i, n in enumerate(found) if n in found[:i]), None)
    if twice is not None:
        raise InvalidParameterError(f"learner {twice!r} is named twice in {names!r}; name each learner once")
    return tuple(found)
