"""Transfer metrics of the field (Taylor and Stone, 2009), on learning curves of steps.

A learning curve here is the number of steps per episode (fewer is better), so the
performance of an episode is minus its steps. Per trial, given the no-transfer trials of
the same task as the baseline:

  jumpstart           mean steps of the baseline's first episode minus this trial's first
                      episode (positive: transfer starts better)
  time_to_threshold   total steps until the first episode no longer than ``threshold`` x the
                      target robot's optimal distance (None: never)
  area                area under the curve: total steps of the first ``horizon`` episodes
                      (an episode beyond the trial's end counts as its last greedy length)
  transfer_ratio      (area of the baseline's mean curve - area) / area of the baseline's
                      mean curve: the fraction of the area that transfer saves
  asymptotic          the mean steps of the last ``tail`` episodes
"""

from __future__ import annotations

import numpy as np

THRESHOLD = 2.0
HORIZON = 100
TAIL = 10


def curve(episode_steps, greedy_steps: int | None, horizon: int = HORIZON) -> np.ndarray:
    """The first ``horizon`` episodes' steps, padded with the converged greedy length (an
    unconverged trial: its last episode's steps). The one definition of a trial's learning
    curve: ``figures.learning_curves`` averages these, so a converged trial keeps counting."""
    steps = np.abs(np.asarray(episode_steps, dtype=np.float64))[:horizon]
    if len(steps) < horizon:
        pad = greedy_steps if greedy_steps is not None else (steps[-1] if len(steps) else 0.0)
        steps = np.concatenate([steps, np.full(horizon - len(steps), float(pad))])
    return steps


def time_to_threshold(episode_steps, optimal: int, threshold: float = THRESHOLD) -> int | None:
    steps = np.abs(np.asarray(episode_steps, dtype=np.int64))
    hit = np.flatnonzero(steps <= threshold * optimal)
    return None if len(hit) == 0 else int(steps[: hit[0] + 1].sum())


def trial_metrics(
    episode_steps, greedy_steps: int | None, optimal: int, baseline_first: float, baseline_area: float,
    horizon: int = HORIZON, tail: int = TAIL,
) -> dict:
    c = curve(episode_steps, greedy_steps, horizon)
    area = float(c.sum())
    steps = np.abs(np.asarray(episode_steps, dtype=np.float64))
    return {
        "jumpstart": float(baseline_first - c[0]),
        "time_to_threshold": time_to_threshold(episode_steps, optimal),
        "area": area,
        "transfer_ratio": (baseline_area - area) / baseline_area if baseline_area else None,
        "asymptotic": float(steps[-tail:].mean()) if len(steps) else None,
    }


def baseline_reference(baseline_trials: list[tuple[list, int | None]], horizon: int = HORIZON) -> tuple[float, float]:
    """(mean first-episode steps, area of the mean curve) of the no-transfer trials."""
    curves = np.array([curve(e, g, horizon) for e, g in baseline_trials])
    mean_curve = curves.mean(axis=0)
    return float(mean_curve[0]), float(mean_curve.sum())
