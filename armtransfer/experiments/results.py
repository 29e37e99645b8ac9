"""The typed result of one transfer experiment (what ``armtransfer.transfer`` returns).

A :class:`TransferResult` holds the task, the robots, the transferred trajectories, the
learner's settings and, per method, a :class:`~armtransfer.experiments.experiment.MethodResult`
with every trial (:class:`~armtransfer.learning.sarsa.TrialResult`). Control runs (a method
given a shuffled or random trajectory) are kept apart, under ``controls[kind][method]``.

``to_json()`` is exactly what ``armtransfer rooms --json`` and ``armtransfer arms`` write.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from armtransfer.learning.config import LearnerConfig
from armtransfer.experiments.experiment import MethodResult, summary_of
from armtransfer.learning.mapping import ActionMapping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import Task
from armtransfer.tasks.robot import DiscreteRobot


@dataclass(frozen=True)
class MappingInfo:
    """What method ``mapping`` had and learned."""

    path: str | None
    """The mapping file it read and, when ``saved``, updated; None: an empty mapping."""
    entries_before: int
    entries_after: int
    macro_states: int
    """Trajectory cells at which a mapped macro could start."""
    saved: bool

    def to_json(self) -> dict:
        return {"path": self.path, "entries_before": self.entries_before, "entries_after": self.entries_after,
                "macro_states": self.macro_states, "saved": self.saved}


@dataclass(frozen=True, eq=False)
class TransferResult:
    task: Task
    source: DiscreteRobot
    target: DiscreteRobot
    distance: int
    """The target's optimal number of steps from start to goal."""
    trajectories: list[Trajectory]
    seed: int
    trials: int
    wind: float
    config: LearnerConfig
    methods: dict[str, MethodResult]
    """Per method, on the real trajectory, in the order asked for."""
    controls: dict[str, dict[str, MethodResult]] = field(default_factory=dict)
    """Per control kind (``shuffled``, ``random``), per method."""
    mapping: MappingInfo | None = None
    learned_mapping: ActionMapping | None = None
    """For ``mapping``: the mapping updated from this run's converged trials (not in the JSON)."""

    @property
    def start_cell(self) -> int:
        return self.task.cells()[0]

    @property
    def goal_cell(self) -> int:
        return self.task.cells()[1]

    def _summary(self) -> dict:
        runs = [*self.methods.values(), *(r for by in self.controls.values() for r in by.values())]
        return summary_of(runs, self.target, self.start_cell, self.goal_cell)

    def to_json(self) -> dict:
        summary = self._summary()
        t = self.task
        return {
            "task": {"name": t.name, "start": list(t.start), "goal": list(t.goal)},
            "distance": self.distance,
            "source": self.source.name,
            "target": self.target.name,
            "trajectory": None if not self.trajectories else self.trajectories[0].to_json(),
            "trajectories": [tr.to_json() for tr in self.trajectories],
            "trajectory_length": None if not self.trajectories else len(self.trajectories[0]),
            "seed": self.seed,
            "trials": self.trials,
            "wind": self.wind,
            "config": self.config.to_dict(),
            "mapping": None if self.mapping is None else self.mapping.to_json(),
            "results": {m: summary[r.label] for m, r in self.methods.items()},
            "controls": {kind: {m: summary[r.label] for m, r in by.items()} for kind, by in self.controls.items()},
        }
