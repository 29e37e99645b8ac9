"""Tidy tables of trials for pandas (and seaborn, rliable, ... that read tidy frames).

One row per trial of a method (and of a control: a method given a shuffled or random
trajectory), every per-trial metric a column, ``control`` a label on every row (``"none"`` for
the trajectory the run was given, so a default ``groupby`` keeps those rows), the run's settings as columns too, so that
``df.groupby(["target", "method"]).exploration_steps.describe()`` or a plot reads it as it is.

A trial that never reached the goal is kept, never dropped: its ``reached`` is False and its
``exploration_steps`` is missing (``pd.NA``); ``step_cap`` is where it was censored, the
value the project's statistics count it at. pandas is an optional dependency, installed by
the ``frames`` extra (``pip install 'armtransfer[frames]'``).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import TYPE_CHECKING

from armtransfer.errors import MissingExtraError  # noqa: F401  (kept importable from here)

if TYPE_CHECKING:
    import pandas as pd  # the frames extra

EXTRA = "frames"
COUNTS = ("exploration_steps", "total_steps", "greedy_steps", "episodes", "step_cap", "good_path_steps",
          "shortest_path_steps", "optimal", "good_len", "steps_run")
"""Whole-number columns that may be missing (pandas' nullable ``Int64``)."""
LEAD = ("method", "control", "trial", "reached", "good_path_steps", "settled_ratio", "exploration_steps", "converged",
        "total_steps", "greedy_steps", "episodes")
"""The columns a frame starts with, in this order; the other metrics and the settings follow."""
NO_CONTROL = "none"
"""The ``control`` of a run on the trajectory it was given (not a control's): a label, not a
missing value, which pandas' ``groupby`` and plots would drop."""


def pandas():
    """The ``pandas`` module, or a one-line :class:`MissingExtraError` naming the extra."""
    try:
        import pandas as pd  # the frames extra
    except ImportError:
        raise MissingExtraError(f"to_frame() needs pandas: pip install 'armtransfer[{EXTRA}]'") from None
    return pd


def settings_columns(settings: dict) -> dict:
    """A run's settings as flat columns: a cell (x, y) becomes ``NAME_x``, ``NAME_y``; a nested
    value (e.g. a sweep's arm definitions) becomes its JSON text."""
    out: dict[str, object] = {}
    for name, value in settings.items():
        if name in ("start", "goal") and isinstance(value, (list, tuple)) and len(value) == 2:
            out[f"{name}_x"], out[f"{name}_y"] = int(value[0]), int(value[1])
        elif isinstance(value, (dict, list, tuple)):
            out[name] = json.dumps(value, sort_keys=True)
        else:
            out[name] = value
    return out


def trial_rows(method: str, control: str | None, per_trial: dict[str, Sequence], settings: dict) -> list[dict]:
    """One row per trial: ``per_trial`` maps each metric to its list over the trials (a
    scalar is the same for every trial); ``settings`` are the run's columns. ``control`` None
    (the given trajectory) is labelled :data:`NO_CONTROL`."""
    lists = {k: v for k, v in per_trial.items() if isinstance(v, (list, tuple))}
    n = len(per_trial["exploration_steps"])
    if any(len(v) != n for v in lists.values()):
        raise ValueError(f"per-trial lists of different lengths for {method}: "
                         f"{ {k: len(v) for k, v in lists.items()} }")
    flat = settings_columns(settings)
    rows = []
    for trial in range(n):
        row: dict[str, object] = {"method": method, "control": NO_CONTROL if control is None else control,
                                  "trial": trial}
        for name, value in per_trial.items():
            row[name] = value[trial] if name in lists else value
        row["reached"] = row["exploration_steps"] is not None
        rows.append({**row, **{k: v for k, v in flat.items() if k not in row}})
    return rows


def frame(rows: list[dict]) -> "pd.DataFrame":
    """The rows as a DataFrame: :data:`LEAD` columns first, counts as nullable integers."""
    pd = pandas()
    df = pd.DataFrame.from_records(rows)
    for name in COUNTS:
        if name in df:
            df[name] = df[name].astype("Int64")
    lead = [c for c in LEAD if c in df]
    return df[lead + [c for c in df.columns if c not in lead]]


PER_TRIAL = ("exploration_steps", "converged", "total_steps", "greedy_steps", "episodes", "mapped_fraction",
             "macro_steps_first_episode", "good_path_steps", "shortest_path_steps", "settled_ratio", "final_ratio",
             "optimal", "good_len", "steps_run")
"""The per-trial lists of a summary entry that a frame takes as columns."""


def per_trial_columns(entry: dict, cap: int) -> dict:
    """A summary entry's per-trial metrics by column name (the K used, the step cap, ``cap``
    where the entry names none, and the transfer metrics included)."""
    out = {name: entry[name] for name in PER_TRIAL if name in entry}
    if "K" in entry:
        out["K_used"] = entry["K"]
    out["step_cap"] = entry.get("cap") or cap
    for name, block in entry.get("transfer_metrics", {}).items():
        if isinstance(block, dict) and "per_trial" in block:
            out[name] = block["per_trial"]
    return out
