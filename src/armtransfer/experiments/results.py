"""The typed result of one transfer experiment (what ``armtransfer.transfer`` returns).

A :class:`TransferResult` holds the task, the robots, the transferred trajectories, the
learner's settings and, per method, a :class:`~armtransfer.experiments.experiment.MethodResult`
with every trial (:class:`~armtransfer.learning.trial_result.TrialResult`). Control runs (a method
given a shuffled or random trajectory) are kept apart, under ``controls[kind][method]``.

``to_json()`` is exactly what ``armtransfer rooms --json`` and ``armtransfer arms`` write;
``to_frame()`` is a tidy pandas DataFrame, one row per trial (``armtransfer.experiments.frames``).
``repr()`` is a few lines (task, robots, each method's headline numbers), and in Jupyter the
result shows the table ``armtransfer rooms`` prints.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from armtransfer.experiments import frames, tables
from armtransfer.experiments.experiment import MethodResult, summary_of
from armtransfer.experiments.stored_form import leave_out
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.mapping import ActionMapping
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import Task
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.resolve import is_default, world_name

if TYPE_CHECKING:
    import pandas as pd

JSON_DEFAULTS = {"world": None, "learner": "sarsa"}
"""The fields a result's JSON leaves out at these values (``stored_form``): the paper's rooms, sarsa."""


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


@dataclass(frozen=True, eq=False, repr=False)
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
    learner: str = "sarsa"
    """Who learned on the target: ``sarsa``, the compiled kernel, or an outside learner
    (``armtransfer.LEARNERS``; the JSON names it then, and only then)."""

    @property
    def start_cell(self) -> int:
        return self.task.cells()[0]

    @property
    def goal_cell(self) -> int:
        return self.task.cells()[1]

    def _summary(self) -> dict:
        runs = [*self.methods.values(), *(r for by in self.controls.values() for r in by.values())]
        return summary_of(runs, self.target, self.start_cell, self.goal_cell)

    def runs(self) -> list[MethodResult]:
        """Every method's runs: on the real trajectory, then each control's."""
        return [*self.methods.values(), *(r for by in self.controls.values() for r in by.values())]

    def __repr__(self) -> str:
        """A few lines: the task and robots, then per method (and control) its mean exploration
        steps with their 95% CI, how many trials reached the goal, and the mean improvement."""
        out = self.to_json()
        rows = [["method", "mean exploration steps [95% CI]", "reached", "improvement"]]
        for run, e in zip(self.runs(), self._entries(out)):
            imp = e.get("improvement_percent")
            rows.append([run.label, f"{tables.fmt_mean(e)} {tables.fmt_ci(e['ci95'])}", tables.fmt_reached(e),
                         "" if imp is None else f"{imp:+.1f}%"])
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        lines = ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        return f"<TransferResult {tables.transfer_heading(out)}\n" + "\n".join(lines) + ">"

    def _repr_markdown_(self) -> str:
        """What Jupyter shows: the heading and table ``armtransfer rooms`` prints."""
        out = self.to_json()
        text = f"**{tables.transfer_heading(out)}**\n\n{tables.transfer_table(out)}"
        return text + (f"\n\n{tables.CONTROLS_NOTE}" if out["controls"] else "")

    def _entries(self, out: dict) -> list[dict]:
        """The summary entries of :meth:`runs`, in that order."""
        return [*out["results"].values(), *(e for by in out["controls"].values() for e in by.values())]

    def to_frame(self) -> "pd.DataFrame":
        """A tidy pandas DataFrame: one row per trial of every method and control (``control``
        names it, ``"none"`` for the real trajectory), every per-trial metric a column (exploration,
        total and greedy steps, convergence, episodes, the K used, Taylor and Stone's transfer
        metrics, the mapped share for ``mapping``), then the run's settings (task, robots,
        seed, wind, trajectory length, every learner setting). A trial that never reached the
        goal has ``reached`` False and ``exploration_steps`` missing, censored at ``step_cap``.
        Needs pandas (``pip install 'armtransfer[frames]'``)."""
        frames.pandas()
        out = self.to_json()
        t = self.task
        settings = {"task": t.name, "start": list(t.start), "goal": list(t.goal), "source": self.source.name,
                    "target": self.target.name, "distance": self.distance, "seed": self.seed,
                    "trials": self.trials, "wind": self.wind, "trajectory_length": out["trajectory_length"],
                    **self.config.to_dict()}
        rows = []
        for run, entry in zip(self.runs(), self._entries(out)):
            rows += frames.trial_rows(run.method, run.control, frames.per_trial_columns(entry, self.config.max_total_steps),
                                     settings)
        return frames.frame(rows)

    def to_json(self) -> dict:
        summary = self._summary()
        t = self.task
        layout = self.target.layout
        return leave_out({
            "task": {"name": t.name, "start": list(t.start), "goal": list(t.goal)},
            "world": None if is_default(layout) else world_name(layout),
            "distance": self.distance,
            "source": self.source.name,
            "target": self.target.name,
            "trajectory": None if not self.trajectories else self.trajectories[0].to_json(layout),
            "trajectories": [tr.to_json(layout) for tr in self.trajectories],
            "trajectory_length": None if not self.trajectories else len(self.trajectories[0]),
            "seed": self.seed,
            "trials": self.trials,
            "wind": self.wind,
            "config": self.config.to_dict(),
            "learner": self.learner,
            "mapping": None if self.mapping is None else self.mapping.to_json(),
            "results": {m: summary[r.label] for m, r in self.methods.items()},
            "controls": {kind: {m: summary[r.label] for m, r in by.items()} for kind, by in self.controls.items()},
        }, JSON_DEFAULTS)
