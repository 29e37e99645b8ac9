"""Trials on a continuous-state arm: the linear learner (``learning.linear``) over tile coding.

The arm is any ``Mover`` placed at the task's start (``ik.continuous.ContinuousArm.place``);
the methods are those paid on labels alone (``learning.cells.CELL_METHODS``). Trial k of every
method draws from ``experiment.trial_rng(seed, k)``, as the tabular trials do, so the methods
meet the same random streams trial by trial and the results are the tabular ones' kind
(``trial_result.TrialResult`` in a ``MethodResult``): ``experiment.summarize``, the metrics and the
survival statistics apply unchanged. Trials run one after the other (one MuJoCo data per arm).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from html import escape
from typing import TYPE_CHECKING

import armtransfer.checks as checks
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments.experiment import MethodResult, summarize, trial_rng
from armtransfer.experiments.stored_form import leave_out
from armtransfer.experiments import frames, tables
from armtransfer.learning import cells, linear
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.tiles import MAX_TABLE_BITS, TileCoding
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.catalog import Task
from armtransfer.worlds.resolve import is_default, world_name

if TYPE_CHECKING:
    import pandas as pd


CLOCK_NOTE = ("no good-path clock on a continuous target: its shortest path is not known (the table robot's "
              "shortest path counts moves between cell centres, which an arm placed off them by IK and moved with "
              "actuation noise is not held to), so good_path_steps and settled_ratio are null and its trials stop "
              "on any settled greedy path")
"""Why a continuous target's trials record no good-path clock (``learning.clock``)."""

SPATIAL_TABLE_BITS = 18
"""The hashed table (2**18 features per action) ``armtransfer.transfer`` gives a spatial arm's
tiles: its three moved joints' box at 2-step tiles has ~4 million dense tiles over 8 tilings."""
NOISE_STREAM = 2
"""``trial_rng``'s stream of a trial's actuation noise (0: the learner's, 1: the source robot's)."""


@dataclass(frozen=True)
class Approximation:
    """How the linear learner sees the arm's configuration: tile coding and traces."""

    tilings: int = 8
    width: float = 2.0
    """A tile's width in joint steps (the arm's ``step``)."""
    traces: str = "accumulating"
    greedy_cap: int = linear.LinearConfig().greedy_cap
    table_bits: int = 0
    """0: dense tiles; k > 0: hashed into a table of 2**k features per action (``tiles``)."""

    def __post_init__(self) -> None:
        checks.whole(self.tilings, "tilings", 1, 64)
        checks.whole(self.table_bits, "table_bits (0: dense tiles)", 0, MAX_TABLE_BITS)
        checks.real(self.width, "the tile width (joint steps)", 0.0, 1000.0, lo_open=True)
        linear.LinearConfig(self.traces, self.greedy_cap)  # its checks

    def coding(self, arm) -> TileCoding:
        """Tiles over the configurations the arm can reach from its start (``arm.bounds``)."""
        lo, hi = arm.bounds
        return TileCoding.over(lo, hi, self.width * arm.step, self.tilings, table_bits=self.table_bits)

    def linear(self) -> linear.LinearConfig:
        return linear.LinearConfig(self.traces, self.greedy_cap)

    def to_json(self) -> dict:
        return leave_out({"tilings": self.tilings, "tile_width_steps": self.width, "traces": self.traces,
                          "table_bits": self.table_bits}, {"table_bits": 0})  # dense tiles: none


def approximation_for(arm) -> Approximation:
    """The tile coding ``armtransfer.transfer`` gives ``arm``: hashed tiles
    (:data:`SPATIAL_TABLE_BITS`) for a spatial arm over the 3D workspace, dense ones otherwise."""
    # a spatial arm's joint box is 3 joints of up to 2 pi each: hashed tiles keep its weights small
    return Approximation(table_bits=SPATIAL_TABLE_BITS) if getattr(arm, "levels", 0) else Approximation()


def run_method(method: str, arm, goal_cell: int, trajs: Sequence[Trajectory] | None, trials: int, seed: int,
               config: LearnerConfig, K: float | str = "auto", approx: Approximation = Approximation(),
               on_trial: Callable[[], None] | None = None, first_trial: int = 0) -> MethodResult:
    """``trials`` trials of ``method`` on ``arm`` (placed at the start) towards ``goal_cell``;
    they are numbered from ``first_trial`` (their random streams), so trial k run alone is trial k
    of a run of them all."""
    cells.check_method(method)
    if trials < 1:
        raise InvalidParameterError(f"trials must be a positive integer, got {trials}")
    if isinstance(first_trial, bool) or not isinstance(first_trial, int) or first_trial < 0:
        raise InvalidParameterError(f"first_trial must be an integer >= 0, got {first_trial!r}")
    shaping = cells.cell_shaping(method, arm.layout, trajs, K, config, int(getattr(arm, "levels", 1)))
    coding, lin = approx.coding(arm), approx.linear()
    out = MethodResult(method)
    noise = float(getattr(arm, "noise", 0.0))
    from armtransfer.experiments import fastloop  # MuJoCo from numba: imported when a run needs it

    steps_by = fastloop.episode_steps(arm)
    for trial in range(first_trial, first_trial + trials):
        if noise > 0.0:  # the arm's own stream, trial by trial (the learner's is trial_rng(seed, trial))
            arm.seed_noise(trial_rng(seed, trial, stream=NOISE_STREAM))
        out.trials.append(linear.learn(arm, goal_cell, coding, config, trial_rng(seed, trial), shaping, lin, steps_by))
        if on_trial is not None:
            on_trial()
    for t in out.trials:
        t.clock_note = CLOCK_NOTE
    out.extra["state"] = "continuous"
    out.extra["clock_note"] = CLOCK_NOTE
    out.extra["approximation"] = {**approx.to_json(), "features": coding.size}
    if noise > 0.0:
        out.extra["noise"] = noise
    if shaping is not None:
        out.extra["K"] = shaping.K
    return out


def run_all(arm, start_cell: int, goal_cell: int, method_names: Sequence[str], trajs: Sequence[Trajectory],
            trials: int, seed: int, config: LearnerConfig, K: float | str | dict = "auto",
            approx: Approximation = Approximation(), tick: Callable[[], None] | None = None) -> list[MethodResult]:
    """Every method on one task, the arm placed over ``start_cell`` first (IK)."""
    for m in method_names:
        cells.check_method(m)
    arm.place(start_cell)
    return [run_method(m, arm, goal_cell, trajs, trials, seed, config,
                       K.get(m, "auto") if isinstance(K, dict) else K, approx, tick) for m in method_names]


@dataclass
class ContinuousResult:
    """What ``armtransfer.transfer(..., state="continuous")`` returns: the methods' trials on a
    continuous-state target, summarised as the tabular runs are (``experiment.summarize``)."""

    task: Task
    source: str
    target: str
    trajectories: list[Trajectory]
    seed: int
    trials: int
    config: LearnerConfig
    approximation: Approximation
    methods: dict[str, MethodResult]

    def to_json(self) -> dict:
        summary = summarize(list(self.methods.values()), baseline="none" if "none" in self.methods else "")
        t = self.task
        return leave_out({
                "state": "continuous", "task": {"name": t.name, "start": list(t.start), "goal": list(t.goal)},
                "world": None if is_default(t.layout) else world_name(t.layout), "source": self.source,
                "target": self.target,
                "trajectories": [tr.to_json(t.layout) for tr in self.trajectories], "seed": self.seed, "trials": self.trials,
                "config": self.config.to_dict(),
                "approximation": self.approximation.to_json(),
                "results": {m: summary[r.label] for m, r in self.methods.items()}}, {"world": None})

    def _rows(self, out: dict) -> list[list[str]]:
        """The table of :meth:`__repr__` and :meth:`_repr_html_`: a header, then per method its
        mean exploration steps with their 95% CI, how many trials reached the goal and
        converged, and the improvement over ``none``."""
        rows = [["method", "mean exploration steps [95% CI]", "reached", "converged", "improvement"]]
        for m, e in out["results"].items():
            imp = e.get("improvement_percent")
            conv = e.get("converged", [])
            rows.append([m, f"{tables.fmt_mean(e)} {tables.fmt_ci(e['ci95'])}", tables.fmt_reached(e),
                         f"{sum(bool(c) for c in conv)}/{len(conv)}", "" if imp is None else f"{imp:+.1f}%"])
        return rows

    def _heading(self) -> str:
        t = self.task
        return (f"{t.name}: {tuple(t.start)} -> {tuple(t.goal)}, {self.source} -> {self.target}, "
                f"{self.trials} trials, seed {self.seed}")

    def __repr__(self) -> str:
        """A few lines: the task and robots (the target's name says it is continuous), then a
        row per method."""
        rows = self._rows(self.to_json())
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        lines = ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        return f"<ContinuousResult {self._heading()}\n" + "\n".join(lines) + ">"

    def _repr_html_(self) -> str:
        """What Jupyter shows: the heading and the table of :meth:`__repr__`, as HTML."""
        rows = self._rows(self.to_json())
        head = "".join(f"<th>{escape(c)}</th>" for c in rows[0])
        body = "".join("<tr>" + "".join(f"<td>{escape(c)}</td>" for c in r) + "</tr>" for r in rows[1:])
        return (f"<p><b>{escape(self._heading())}</b></p>"
                f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def to_frame(self) -> "pd.DataFrame":
        """A tidy pandas DataFrame, as ``TransferResult.to_frame``'s: one row per trial of every
        method (``control`` is ``"none"``: a continuous run has no controls), every per-trial
        metric a column, then the run's settings (task, robots, seed, trajectory length, the
        tile coding, every learner setting). A trial that never reached the goal has
        ``reached`` False and ``exploration_steps`` missing, censored at ``step_cap``. Needs
        pandas (``pip install 'armtransfer[frames]'``)."""
        frames.pandas()
        out = self.to_json()
        t = self.task
        settings = {"task": t.name, "start": list(t.start), "goal": list(t.goal), "source": self.source,
                    "target": self.target, "state": "continuous", "seed": self.seed, "trials": self.trials,
                    "trajectory_length": len(self.trajectories[0]) if self.trajectories else None,
                    **{f"approximation_{k}": v for k, v in self.approximation.to_json().items()},
                    **self.config.to_dict()}
        rows = []
        for m, entry in out["results"].items():
            rows += frames.trial_rows(m, None, frames.per_trial_columns(entry, self.config.max_total_steps), settings)
        return frames.frame(rows)
