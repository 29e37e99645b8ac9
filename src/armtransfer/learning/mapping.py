"""Action sequence mapping (the paper's section III.C): which sequence of the target robot's
actions does what a sequence of the source robot's action indices did.

Learning
--------
After the target robot has converged, its greedy path ``(s_0, b_0) ... (s_m, b_m), s_g`` is
set beside the transferred trajectory ``(s_t0, a_t0) ... (s_tn, a_tn), s_tg``. Two states are
*equivalent* when they carry the same shared label (cell). The goal is index n+1 of the
trajectory and index m+1 of the path, so starts and goals always match.

Matching rule. A *chain* is a list of equivalent pairs (i, j) with i strictly increasing and
j non-decreasing. We take a longest chain (dynamic programming over all equivalent pairs).
Allowing equal j is what maps a loop of the source to the empty sequence: when the source
leaves cell c at i and comes back to it at k, both (i, j) and (k, j) pair with the target's
single visit j. Among longest chains, the chain is rebuilt backwards from the goal taking,
at each step, the predecessor with the largest i, then the largest j; so a loop is bypassed
(mapped to "no action") rather than matched through, and the result is deterministic.

Every two chain pairs (i, j) < (k, l) with k - i <= ``max_span`` give an entry: the source
key ``a_ti .. a_t(k-1)`` maps to the target sequence ``b_j .. b_(l-1)``. Consecutive chain
pairs always give an entry, however long their key.

Keeping. When a key is seen again its count goes up and the *shorter* target sequence is
kept (on equal length, the one seen first). A loop's empty sequence therefore always wins.

Reuse
-----
:class:`MacroTable` turns a mapping and a new task's transferred trajectory into the macros
the learner's kernel runs (``armtransfer.learning.sarsa``): for each trajectory position i, the keys
``a_ti .. a_t(i+L-1)`` for L = ``longest key`` down to 1 are looked up and the *longest key
with a non-empty target sequence* is chosen (the longest key covers most of the path; an
empty sequence cannot be run). Every target state labelled s_ti then has that target
sequence as its macro. When a cell occurs at several positions (a loop in the trajectory)
the largest position with a mapped key wins, as for pseudo rewards: the loop is bypassed.
The kernel runs the macro with probability 1 - epsilon at such a state, each primitive step
being an ordinary SARSA(lambda) step, and abandons it when a step is blocked.

Macros are offered during the *exploration phase*, the first episode (until the goal is
first reached; ``MacroTable(episodes=...)`` changes this). Offered in every episode they
stop learning from converging: Q starts at 0 and every step costs, so the greedy path
prefers untried actions; following macros 90% of the time, the robot hardly ever tries
the other actions along the mapped path, its greedy path keeps turning into them and
loops. On Table I tasks 2-4 (coarse -> fine, seed 0) none of 10 trials per task converged
within 2000 episodes that way; with macros in the first episode only, every trial did.

Across tasks and trials (``armtransfer.experiments.experiment.run_mapping``): every trial of a task uses
the mapping of the earlier tasks only, so trials stay independent and deterministic; the
mapping is then updated from each converged trial's greedy path, in trial order.

Mapped fraction (Table II column E)
-----------------------------------
``mapped_fraction`` of a converged greedy path is the fraction of its primitive steps
``b_0 .. b_m`` that lie inside a *mapped segment*: a segment ``b_j .. b_(j+L-1)`` that starts
at a state whose label has a macro in this task's :class:`MacroTable` and equals that macro's
target sequence. With no macros at all it is undefined (None), as the paper's "NA" for task 1.

File format (``--mapping PATH``)::

    {"format": "armtransfer-mapping/1", "source": "coarse", "target": "fine",
     "source_actions": ["1", "2", "3", "4"], "target_actions": ["F", "B", "R", "L"],
     "entries": [{"key": [0], "target": [0, 0], "count": 7,
                  "key_names": "1", "target_names": "F F"}, ...]}

``key_names``/``target_names`` are for people and ignored when reading. Action indices are
0-based, as in trajectory files.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from armtransfer.errors import InvalidMappingError
from armtransfer.io import read_json, write_text_atomic
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

FORMAT = "armtransfer-mapping/1"

DEFAULT_MAX_SPAN = 6
"""Longest source key learned from non-consecutive chain pairs (the paper's Table III has
keys of up to 6 actions)."""

MACRO_EPISODES: int | None = 1
"""Macros are offered in this many first episodes (None: in every episode). The default, 1,
is the exploration phase: until the goal is first reached. See the module docstring."""

Path_ = list[tuple[int, int]]
"""A robot's path: [(state, action), ..., (goal state, -1)], as ``trial_result.TrialResult.greedy_path``."""


@dataclass
class Entry:
    target: tuple[int, ...]
    count: int = 1


def chain(
    labels_src: Sequence[int], labels_tgt: Sequence[int]
) -> list[tuple[int, int]]:
    """The longest chain of equivalent pairs (i, j): i strictly increasing, j non-decreasing.

    ``labels_src`` are s_t0 .. s_tn, s_tg and ``labels_tgt`` s_0 .. s_m, s_g. Ties between
    longest chains: rebuilt from the last pair, predecessors with the largest i, then j.
    """
    where: dict[int, list[int]] = {}
    for j, c in enumerate(labels_tgt):
        where.setdefault(int(c), []).append(j)
    pairs = [(i, j) for i, c in enumerate(labels_src) for j in where.get(int(c), ())]
    if not pairs:
        return []
    length = [1] * len(pairs)
    for p, (i, j) in enumerate(pairs):
        for q in range(p):
            iq, jq = pairs[q]
            if iq < i and jq <= j and length[q] + 1 > length[p]:
                length[p] = length[q] + 1
    best = max(length)
    # end: the longest chain ending at the largest (i, j) (the goal pair when it matches)
    p = max(k for k in range(len(pairs)) if length[k] == best)
    out = [pairs[p]]
    while length[p] > 1:
        i, j = pairs[p]
        cands = [q for q in range(p) if length[q] == length[p] - 1 and pairs[q][0] < i and pairs[q][1] <= j]
        p = max(cands, key=lambda q: pairs[q])
        out.append(pairs[p])
    out.reverse()
    return out


def observe(
    target_robot: DiscreteRobot,
    greedy_path: Path_,
    trajectory: Trajectory,
    max_span: int = DEFAULT_MAX_SPAN,
) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """The (source key, target sequence) pairs one converged path yields, in chain order."""
    if len(greedy_path) < 1 or greedy_path[-1][1] != -1:
        raise InvalidMappingError("a greedy path must end with (goal state, -1)")
    src_labels = [*trajectory.cells, trajectory.goal]
    tgt_labels = [int(target_robot.label[s]) for s, _ in greedy_path]
    b = [int(a) for _, a in greedy_path[:-1]]
    a = [int(x) for x in trajectory.actions]
    pairs = chain(src_labels, tgt_labels)
    out = []
    for u in range(len(pairs)):
        for v in range(u + 1, len(pairs)):
            (i, j), (k, l) = pairs[u], pairs[v]
            if v > u + 1 and k - i > max_span:
                break
            out.append((tuple(a[i:k]), tuple(b[j:l])))
    return out


@dataclass
class ActionMapping:
    """Equivalences from ``source``'s action index sequences to ``target``'s action sequences."""

    source: str
    target: str
    source_actions: tuple[str, ...] = ()
    target_actions: tuple[str, ...] = ()
    entries: dict[tuple[int, ...], Entry] = field(default_factory=dict)
    tasks: list[tuple[int, int]] = field(default_factory=list)
    """The (start cell, goal cell) of every task the entries were learned on: reusing the mapping
    on one of them would evaluate transfer with knowledge of the task itself."""

    def learned_on(self, start_cell: int, goal_cell: int) -> None:
        if (start_cell, goal_cell) not in self.tasks:
            self.tasks.append((int(start_cell), int(goal_cell)))

    def check_new_task(self, start_cell: int, goal_cell: int, layout) -> None:
        """One line refusing a task this mapping was learned on."""
        if (start_cell, goal_cell) in self.tasks:
            raise InvalidMappingError(
                f"the mapping was learned on this task, {layout.xy(start_cell)} -> {layout.xy(goal_cell)}, so "
                "reusing it would evaluate transfer with knowledge of the task itself; use it on another task "
                "or start a new mapping file")

    @staticmethod
    def for_robots(source: DiscreteRobot, target: DiscreteRobot) -> "ActionMapping":
        return ActionMapping(source.name, target.name, tuple(source.action_names), tuple(target.action_names))

    def __len__(self) -> int:
        return len(self.entries)

    def get(self, key: Iterable[int]) -> tuple[int, ...] | None:
        e = self.entries.get(tuple(key))
        return None if e is None else e.target

    def add(self, key: Sequence[int], target: Sequence[int], count: int = 1) -> None:
        """Record that ``key`` was seen mapped to ``target``: keep the shorter target sequence."""
        key, target = tuple(int(x) for x in key), tuple(int(x) for x in target)
        if not key:
            raise InvalidMappingError("a mapping key needs at least one source action")
        e = self.entries.get(key)
        if e is None:
            self.entries[key] = Entry(target, count)
            return
        e.count += count
        if len(target) < len(e.target):
            e.target = target

    def learn_from(
        self,
        target_robot: DiscreteRobot,
        greedy_path: Path_,
        trajectory: Trajectory,
        max_span: int = DEFAULT_MAX_SPAN,
    ) -> int:
        """Add what one converged greedy path of the target robot teaches; returns the number
        of (key, sequence) observations."""
        self.check_target(target_robot)
        found = observe(target_robot, greedy_path, trajectory, max_span)
        for key, seq in found:
            self.add(key, seq)
        return len(found)

    def merge(self, other: "ActionMapping") -> "ActionMapping":
        """Add every entry of ``other`` (counts add up, the shorter sequence wins); returns self."""
        self.check_pair(other.source, other.target)
        for key, e in other.entries.items():
            self.add(key, e.target, e.count)
        return self

    def copy(self) -> "ActionMapping":
        return ActionMapping(
            self.source, self.target, self.source_actions, self.target_actions,
            {k: Entry(e.target, e.count) for k, e in self.entries.items()}, list(self.tasks),
        )

    # -- robot pair checks -------------------------------------------------------------

    def check_pair(self, source: str, target: str) -> None:
        if (source, target) != (self.source, self.target):
            raise InvalidMappingError(
                f"the mapping is for {self.source} -> {self.target}, not {source} -> {target}; "
                "use a separate mapping file for each robot pair"
            )

    def check_target(self, robot: DiscreteRobot) -> None:
        if robot.name != self.target:
            raise InvalidMappingError(f"the mapping's target robot is {self.target}, not {robot.name}")
        for e in self.entries.values():
            if e.target and max(e.target) >= robot.n_actions:
                raise InvalidMappingError(
                    f"the mapping uses target action {max(e.target)} but robot {robot.name} "
                    f"has {robot.n_actions} actions"
                )

    def check_source(self, robot: DiscreteRobot) -> None:
        """Every key is a sequence of the source robot's action indices."""
        for k in self.entries:
            if k and max(k) >= robot.n_actions:
                raise InvalidMappingError(
                    f"the mapping uses source action {max(k)} but robot {robot.name} has {robot.n_actions} actions"
                )

    # -- names and JSON ------------------------------------------------------------------

    def names(self, seq: Sequence[int], side: str) -> str:
        """Action names, e.g. ``F F R``; ``-`` for the empty sequence ("no action")."""
        names = self.source_actions if side == "source" else self.target_actions
        if not seq:
            return "-"
        return " ".join(names[a] if a < len(names) else str(a) for a in seq)

    def sorted_entries(self) -> list[tuple[tuple[int, ...], Entry]]:
        return sorted(self.entries.items(), key=lambda kv: (len(kv[0]), kv[0]))

    def to_json(self) -> dict:
        return {
            "format": FORMAT,
            "source": self.source,
            "target": self.target,
            "source_actions": list(self.source_actions),
            "target_actions": list(self.target_actions),
            "tasks": [list(t) for t in self.tasks],
            "entries": [
                {
                    "key": list(k),
                    "target": list(e.target),
                    "count": e.count,
                    "key_names": self.names(k, "source"),
                    "target_names": self.names(e.target, "target"),
                }
                for k, e in self.sorted_entries()
            ],
        }

    @staticmethod
    def from_json(data: object, where: str = "mapping") -> "ActionMapping":
        """Validate and convert the JSON form; every problem is a one-line error."""
        if not isinstance(data, dict):
            raise InvalidMappingError(f"{where}: expected a JSON object")
        if data.get("format") != FORMAT:
            raise InvalidMappingError(f"{where}: 'format' must be {FORMAT!r}, got {data.get('format')!r}")
        for side in ("source", "target"):
            if not isinstance(data.get(side), str) or not data[side]:
                raise InvalidMappingError(f"{where}: {side!r} must name a robot")

        def names(key: str) -> tuple[str, ...]:
            v = data.get(key, [])
            if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
                raise InvalidMappingError(f"{where}: {key!r} must be a list of action names")
            return tuple(v)

        def indices(v: object, what: str, allow_empty: bool) -> tuple[int, ...]:
            if (
                not isinstance(v, list)
                or not all(isinstance(x, int) and not isinstance(x, bool) and x >= 0 for x in v)
                or (not v and not allow_empty)
            ):
                kind = "a list of action indices >= 0" + ("" if allow_empty else " (at least one)")
                raise InvalidMappingError(f"{where}: {what} must be {kind}, got {v!r}")
            return tuple(v)

        m = ActionMapping(data["source"], data["target"], names("source_actions"), names("target_actions"))
        tasks = data.get("tasks", [])
        if not isinstance(tasks, list) or not all(
                isinstance(t, list) and len(t) == 2 and all(isinstance(c, int) and not isinstance(c, bool) and c >= 0
                                                            for c in t) for t in tasks):
            raise InvalidMappingError(f"{where}: 'tasks' must be a list of [start cell, goal cell] ids")
        m.tasks = [tuple(t) for t in tasks]
        entries = data.get("entries")
        if not isinstance(entries, list):
            raise InvalidMappingError(f"{where}: 'entries' must be a list")
        for n, e in enumerate(entries):
            if not isinstance(e, dict) or not {"key", "target", "count"} <= set(e):
                raise InvalidMappingError(f"{where}: entry {n} needs 'key', 'target' and 'count'")
            key = indices(e["key"], f"entry {n} key", allow_empty=False)
            target = indices(e["target"], f"entry {n} target", allow_empty=True)
            count = e["count"]
            if not isinstance(count, int) or isinstance(count, bool) or count < 1:
                raise InvalidMappingError(f"{where}: entry {n} count must be an integer >= 1, got {count!r}")
            if key in m.entries:
                raise InvalidMappingError(f"{where}: entry {n} repeats the key {list(key)}")
            m.entries[key] = Entry(target, count)
        return m

    def save(self, path: str | os.PathLike) -> None:
        """Write the JSON form atomically, one entry per line (easy to read and diff)."""
        data = self.to_json()
        entries = data.pop("entries")
        head = ",\n".join(f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in data.items())
        lines = [json.dumps(e) for e in entries]
        body = ",\n    ".join(lines)
        text = "{\n" + head + ',\n  "entries": [' + ("\n    " + body + "\n  " if lines else "") + "]\n}\n"
        write_text_atomic(path, text)

    @staticmethod
    def load(path: str | os.PathLike) -> "ActionMapping":
        data = read_json(path, "mapping file", InvalidMappingError)
        return ActionMapping.from_json(data, where=f"mapping file {str(Path(path))!r}")


def load_for(path: str | os.PathLike, source: DiscreteRobot, target: DiscreteRobot) -> ActionMapping:
    """The mapping in ``path`` (empty when the file does not exist), checked for this pair."""
    if not Path(path).exists():
        return ActionMapping.for_robots(source, target)
    m = ActionMapping.load(path)
    m.check_pair(source.name, target.name)
    m.check_source(source)
    m.check_target(target)
    return m


@dataclass(frozen=True)
class Macro:
    position: int
    """The trajectory index i whose key was chosen."""
    key: tuple[int, ...]
    actions: tuple[int, ...]


class MacroTable:
    """The macros of one task: a mapping applied to that task's transferred trajectory."""

    def __init__(
        self,
        mapping: ActionMapping,
        trajectory: Trajectory,
        robot: DiscreteRobot,
        episodes: int | None = MACRO_EPISODES,
    ):
        mapping.check_target(robot)
        self.episodes = episodes
        self.robot_name = robot.name
        longest = max((len(k) for k in mapping.entries), default=0)
        acts = trajectory.actions
        by_cell: dict[int, Macro] = {}
        for i, cell in enumerate(trajectory.cells):
            for L in range(min(longest, len(acts) - i), 0, -1):
                key = tuple(acts[i : i + L])
                seq = mapping.get(key)
                if seq:  # the longest key with a non-empty target sequence
                    by_cell[int(cell)] = Macro(i, key, seq)  # later positions overwrite
                    break
        self.by_cell = by_cell
        n = robot.n_states
        start = np.zeros(n, np.int64)
        length = np.zeros(n, np.int64)
        flat: list[int] = []
        for cell, macro in sorted(by_cell.items()):
            states = robot.states_at(cell)
            if len(states) == 0:
                continue
            start[states] = len(flat)
            length[states] = len(macro.actions)
            flat.extend(macro.actions)
        self._arrays = (start, length, np.asarray(flat, dtype=np.int64))

    def __len__(self) -> int:
        return len(self.by_cell)

    def arrays(self, robot: DiscreteRobot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(macro_start[S], macro_len[S], macro_actions[M]) for the learner's kernel."""
        if robot.name != self.robot_name or self._arrays[0].shape[0] != robot.n_states:
            raise InvalidMappingError(f"these macros were built for robot {self.robot_name}, not {robot.name}")
        return self._arrays

    def mapped_segments(self, robot: DiscreteRobot, path: Path_) -> list[tuple[int, int]]:
        """Segments [j, j + L) of the path's steps that equal the macro available at s_j."""
        b = [a for _, a in path[:-1]]
        out = []
        for j, (s, _) in enumerate(path[:-1]):
            macro = self.by_cell.get(int(robot.label[s]))
            if macro is not None and tuple(b[j : j + len(macro.actions)]) == macro.actions:
                out.append((j, j + len(macro.actions)))
        return out

    def mapped_fraction(self, robot: DiscreteRobot, path: Path_) -> float | None:
        """Fraction of the path's primitive steps inside a mapped segment (None: no macros)."""
        if not self.by_cell:
            return None
        steps = len(path) - 1
        if steps <= 0:
            return 0.0
        covered = np.zeros(steps, dtype=bool)
        for j0, j1 in self.mapped_segments(robot, path):
            covered[j0:j1] = True
        return float(covered.mean())
