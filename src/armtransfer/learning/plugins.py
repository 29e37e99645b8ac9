"""Transfer methods from outside the package: what a researcher writes, and how it is found.

A method of one's own is a few lines of numpy over cells, made a :class:`Method` by one of

* :func:`potential_method` -- ``potential(cells, trajectory) -> phi``: potential-based shaping
  F = gamma * K * phi(s') - K * phi(s) (Ng, Harada and Russell), run by the compiled kernel's
  potential mode, like the built-in ``potential`` and ``dense``;
* :func:`bonus_method` -- ``bonus(cells, trajectory) -> b``: a bonus K * b(s') paid on every
  arrival at s', like the paper's pseudo reward, which a loop can farm: it gets ``pseudo``'s
  farming checks.

``cells`` is an (n, 2) int64 array, the (x, y) of the cell each of robot 2's n states perceives
(its label); ``trajectory`` an (m, 2) int64 array, the transferred trajectory's cells in order,
its start first and its goal last. The function returns n finite numbers, one per state, in
units of K (K='auto' is ``auto_k`` times -step_reward). With several trajectories, each state
takes the largest value over them. Both kinds have ``none`` as their baseline.

A package makes its method known under the entry-point group ``armtransfer.methods`` (the entry
point's name is the method's name, its object the :class:`Method`); it is imported on the first
use of the registry (:func:`load_entry_points`), and none of its code runs then. A notebook calls
:func:`register_method` instead. A method is tried once (:func:`probe`, in a child process under
a time limit, ``plugin_calls.within``) before a run uses it, on each target robot (one registered
at run time: on the paper's rooms, when it is registered); a plugin that cannot be imported,
raises anything, returns the wrong shape, a non-finite or complex number, does not return in
time, or takes a name already taken is refused in one line
(:class:`~armtransfer.errors.PluginError`) naming it and the fault.
"""

from __future__ import annotations

import numbers
import re
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from armtransfer.errors import InvalidParameterError, PluginError
from armtransfer.learning import plugin_calls
from armtransfer.learning import shaping as modes
from armtransfer.learning.lazy_registry import read_entry_points
from armtransfer.learning.method import MAX_K, Method
from armtransfer.learning.shaping import Shaping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot, cell_robot
from armtransfer.worlds.layout import ROOMS

GROUP = "armtransfer.methods"
"""The entry-point group installed packages declare their methods under."""

RUN_TIME = "registered at run time"
"""``Method.origin`` of a method given to :func:`register_method`."""

NAME = re.compile(r"[a-z0-9][a-z0-9_.-]{0,63}")
"""A method's name: lower case letters, digits, '_', '.', '-', starting with a letter or digit
(it is typed on command lines and written in file names and sweep files)."""

MAX_VALUE = 1e12
"""The largest magnitude of a plugin's value, and of a shaping value after the multiplication by
K: far beyond any useful shaping, and far from where float64 sums lose every step reward."""

CellFunction = Callable[[np.ndarray, np.ndarray], object]
"""``f(cells, trajectory)``: (n, 2) and (m, 2) int64 arrays of (x, y) -> n numbers."""


def potential_method(name: str, description: str, potential: CellFunction, auto_k: float = 1.0) -> Method:
    """A method that shapes with the potential ``K * potential(cells, trajectory)``.

    It runs in the compiled kernel's potential mode at the built-in methods' speed; its
    potential is bounded like theirs (``potentials.bounded``), so no move that leaves a state
    unchanged pays. ``auto_k``: K='auto' in units of -step_reward (default 1: phi in steps)."""
    _check_definition(name, description, potential, "potential", auto_k)
    return Method(name, description.strip(), paper=False, build=_potential_builder(name, potential),
                  auto_k=float(auto_k), baselines=("none",), origin=RUN_TIME)


def bonus_method(name: str, description: str, bonus: CellFunction) -> Method:
    """A method that pays ``K * bonus(cells, trajectory)[s']`` on every arrival at state s', a
    state bonus like the paper's pseudo reward. Values must be >= 0. A loop can farm it, so it
    gets ``pseudo``'s checks: K='auto' is verified safe by value iteration on the task, and a K
    that can be farmed, or that pays a move leaving the state unchanged, is refused."""
    _check_definition(name, description, bonus, "bonus", None)
    per_k = _bonus_per_k(name, bonus)
    return Method(name, description.strip(), paper=False, build=_bonus_builder(name, per_k), farmable=True,
                  baselines=("none",), bonus_per_k=per_k, origin=RUN_TIME)


def _check_definition(name: object, description: object, fn: object, what: str, auto_k: float | None) -> None:
    if not isinstance(name, str) or not NAME.fullmatch(name):
        raise PluginError(f"a method's name is lower-case letters, digits, '_', '.' or '-' (at most 64), got {name!r}")
    if not isinstance(description, str) or not description.strip() or "\n" in description.strip():
        raise PluginError(f"method {name!r}: its description must be one line of text, got {description!r}")
    if not callable(fn):
        raise PluginError(f"method {name!r}: its {what} must be a function (cells, trajectory) -> values, got {fn!r}")
    if auto_k is not None and (isinstance(auto_k, (bool, np.bool_)) or not isinstance(auto_k, numbers.Real)
                               or not np.isfinite(float(auto_k)) or not 0 <= float(auto_k) <= MAX_K):
        raise PluginError(f"method {name!r}: auto_k must be a number in [0, {MAX_K:g}], got {auto_k!r}")


def trajectory_xy(traj: Trajectory, robot: DiscreteRobot) -> np.ndarray:
    """The (m, 2) int64 (x, y) of ``traj``'s cells in order, its goal last."""
    return robot.layout.xy_of(np.array([*traj.cells, traj.goal], dtype=np.int64) % robot.layout.n_cells)


def _values(name: str, fn: CellFunction, robot: DiscreteRobot, trajs: list[Trajectory], what: str) -> np.ndarray:
    """``fn`` over the robot's states for each trajectory, the largest per state, checked."""
    cells = robot.layout.xy_of(robot.label % robot.layout.n_cells)  # a voxel label: the cell under it
    n = robot.n_states
    out = None
    for traj in trajs:
        given_cells = cells.copy()  # the plugin may write into what it is handed; the robot stays as it is
        raw = plugin_calls.call(f"method {name!r}", what, fn, given_cells, trajectory_xy(traj, robot))
        values = _numbers(name, what, raw, n)
        out = values if out is None else np.maximum(out, values)
    assert out is not None  # the registry hands at least one trajectory to a method that uses them
    return out


def _numbers(name: str, what: str, raw: object, n: int) -> np.ndarray:
    """What a plugin returned as n finite real numbers; anything else (an object whose
    ``__array__`` raises, complex or non-finite numbers, the wrong shape) is one line."""
    said = f"method {name!r}: its {what} returned"
    try:
        values = np.asarray(raw)
        kind = values.dtype.kind
        if kind == "O":
            values = np.asarray(raw, dtype=np.float64)
            kind = values.dtype.kind
    except KeyboardInterrupt:
        raise
    except BaseException as err:  # noqa: BLE001 - the plugin's object cannot be read as numbers
        raise PluginError(f"{said} {_type_name(raw)}, which cannot be read as numbers ({plugin_calls.fault(err)})"
                          ) from None
    if kind == "c":
        raise PluginError(f"{said} complex numbers; it must return {n} real numbers")
    if kind not in "biuf":
        raise PluginError(f"{said} {_type_name(raw)}, not {n} numbers")
    if values.shape != (n,):
        raise PluginError(f"{said} shape {values.shape} for {n} states; it must "
                          f"return one number per state, shape ({n},)")
    values = values.astype(np.float64)
    bad = ~np.isfinite(values) | (np.abs(values) > MAX_VALUE)
    if bad.any():
        raise PluginError(f"{said} {values[bad][0]} for {int(bad.sum())} of {n} states; every value must be a "
                          f"finite number of magnitude at most {MAX_VALUE:g}")
    return values


def _type_name(obj: object) -> str:
    try:
        return str(type(obj).__name__)
    except BaseException:  # noqa: BLE001
        return "an object"


def _scaled(name: str, what: str, k: float, values: np.ndarray) -> np.ndarray:
    """``k * values``, checked after the multiplication: every product finite and within
    :data:`MAX_VALUE` (a K too large for the plugin's values is one line)."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = k * values
    bad = ~np.isfinite(out) | (np.abs(out) > MAX_VALUE)
    if bad.any():
        raise InvalidParameterError(f"method {name!r}: K={k:g} times its {what} gives {out[bad][0]:g} at "
                                    f"{int(bad.sum())} states; the shaping's values must be finite and at most "
                                    f"{MAX_VALUE:g} in magnitude: use a smaller K")
    return out


def _potential_builder(name: str, potential: CellFunction):
    def build(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
        phi = _values(name, potential, robot, trajs, "potential")
        return Shaping.potential(_scaled(name, "potential", k, phi), k)

    return build


def _bonus_per_k(name: str, bonus: CellFunction):
    def per_k(robot: DiscreteRobot, trajs: list[Trajectory]) -> np.ndarray:
        b = _values(name, bonus, robot, trajs, "bonus")
        if (b < 0).any():
            raise PluginError(f"method {name!r}: its bonus returned {b[b < 0][0]:g} at {int((b < 0).sum())} states; "
                              "a state bonus must be >= 0 (a potential may be negative: use potential_method)")
        return b

    return per_k


def _bonus_builder(name: str, per_k: Callable[[DiscreteRobot, list[Trajectory]], np.ndarray]):
    def build(robot: DiscreteRobot, trajs: list[Trajectory], k: float, beta: float) -> Shaping:
        n = robot.n_states
        return Shaping(modes.MODE_PSEUDO, _scaled(name, "bonus", k, per_k(robot, trajs)), np.full(n, -1, np.int64),
                       np.zeros(n), k)

    return build


def _probe_trajectory() -> Trajectory:
    """A transferred trajectory on the rooms: Table I task 1's start (0, 0) west along y = 0, then
    north, to the goal (-8, 12) (a path through the room's free cells)."""
    xy = [(x, 0) for x in range(0, -9, -1)] + [(-8, y) for y in range(1, 12)]
    cells = tuple(ROOMS.cell(x, y) for x, y in xy)
    return Trajectory(cells, (0,) * len(cells), ROOMS.cell(-8, 12), source="probe")


def _trajectory_on(robot: DiscreteRobot) -> Trajectory:
    """A trajectory over the first distinct cells the robot's states perceive (up to 20), ending
    at another: cells of the robot's own world, whatever its layout."""
    labels = list(dict.fromkeys(int(c) for c in robot.label[:10_000]))[:21]
    cells = tuple(labels[:-1]) if len(labels) > 1 else tuple(labels)
    return Trajectory(cells, (0,) * len(cells), labels[-1], source="probe")


def probe(method: Method, where: str, robot: DiscreteRobot | None = None,
          seconds: float = plugin_calls.PROBE_SECONDS) -> None:
    """Build ``method``'s shaping once, on ``robot`` with a trajectory over its own cells, or (None)
    on the paper's rooms (every cell a state) with a short path, in a child process under a time
    limit of ``seconds`` (``plugin_calls.within``): a plugin that raises anything, returns the wrong
    shape, non-finite or complex numbers, or does not return in time, is refused now, in one line
    naming ``where`` it came from and the call, rather than in the middle of a run."""
    build = method.build
    if build is None:
        return

    def work() -> None:
        traj = _probe_trajectory() if robot is None else _trajectory_on(robot)
        on = cell_robot(ROOMS) if robot is None else robot
        if method.bonus_per_k is not None:
            method.bonus_per_k(on, [traj])
        build(on, [traj], 1.0, 1.0)

    try:
        plugin_calls.within(seconds, f"method {method.name!r}: its probe", work)
    except PluginError as err:
        said, named = str(err), f"method {method.name!r}: "
        if where.startswith(named[:-2]) and said.startswith(named):  # name the method once
            said = said[len(named):]
        raise PluginError(f"{where}: {said}") from None


def load_entry_points(registry) -> None:
    """Add every method installed packages declare under :data:`GROUP` to ``registry`` (a
    ``lazy_registry.Registry``): importing them runs no code of theirs beyond the import (the
    probe runs before a run that uses one, ``methods.probe_on``). A plugin that cannot be used is
    left out with one warning line, and naming it is its one-line error (``lazy_registry``)."""
    found = read_entry_points(GROUP, registry, "method", _a_method, lambda m: m.name, _with_origin)
    for name, method in found.items():
        registry.add(name, method)


def _a_method(obj: object, where: str) -> Method:
    if not isinstance(obj, Method):
        raise PluginError(f"{where} is {type(obj).__name__}, not a method; make it with "
                          "armtransfer.potential_method(...) or armtransfer.bonus_method(...)")
    return obj


def _with_origin(method: Method, origin: str) -> Method:
    return replace(method, origin=origin)


def register(registry, method: object, replace: bool = False,
             seconds: float = plugin_calls.PROBE_SECONDS) -> Method:
    """Add ``method`` (from :func:`potential_method` or :func:`bonus_method`) to ``registry`` in
    this process (a notebook's way; an installed package declares an entry point instead).
    ``replace``: an earlier run-time registration of the same name is replaced (a notebook cell
    run again), never a built-in or an installed plugin's method."""
    if not isinstance(method, Method):
        raise PluginError(f"register_method takes a method made by armtransfer.potential_method(...) or "
                          f"armtransfer.bonus_method(...), got {type(method).__name__}")
    where = f"method {method.name!r} ({RUN_TIME})"
    if method.name in registry:
        old = registry[method.name]
        if not (replace and old.origin == RUN_TIME):
            raise PluginError(f"{where}: the name is taken by a method of {old.origin}; rename it"
                              + ("" if old.origin != RUN_TIME else ", or pass replace=True"))
    method = _with_origin(method, RUN_TIME)
    probe(method, where, seconds=seconds)
    registry[method.name] = method
    return method
