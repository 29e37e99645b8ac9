"""What one trial of a learner measured: the one result type every learner of a trial returns
(the compiled SARSA(lambda) kernel, the linear learner over tile coding, and through the
benchmark's harness an outside learner)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class TrialResult:
    """What one trial of :func:`learn` measured."""

    exploration_steps: int | None
    """Steps of the first episode, i.e. until the goal is first reached (None: never)."""
    converged: bool
    total_steps: int | None
    """Steps until the greedy path stopped changing (through its first episode)."""
    greedy_steps: int | None
    """Length of the converged greedy path (None when not converged)."""
    episodes: int
    episode_steps: np.ndarray
    """Steps per episode (negative: the episode hit a cap before the goal)."""
    greedy_lengths: np.ndarray
    """Greedy path length after each episode (-1: the greedy path misses the goal)."""
    macro_steps: np.ndarray
    """Primitive steps taken inside mapped macros, per episode."""
    greedy_path: list[tuple[int, int]] = field(default_factory=list)
    """The converged greedy path as (state, action) pairs ending with (goal state, -1)."""
    first_path: list[tuple[int, int]] = field(default_factory=list)
    """The first episode's path (until the goal was first reached) with its loops erased, as
    (state, action) pairs ending with (goal state, -1); empty when the goal was not reached.
    What the online action sequence mapping learns from (``mapping.ActionMapping.learn_from``)."""
    Q: np.ndarray | None = None
    optimal: int | None = None
    """The target's shortest path from the start (steps), as the harness measured it; None: not
    measured (robot 1's learning, or a learner run alone)."""
    good_len: int | None = None
    """The longest good path, ``clock.good_length(quality, optimal)``; the trial ended only on a
    settled path at most this long, or at a cap (None: on any settled path)."""
    good_path_steps: int | None = None
    """Steps until the greedy path was at most ``good_len`` long and stayed so to the end of the
    trial (``clock.good_path_steps``); None: never, censored at ``steps_run``."""
    shortest_path_steps: int | None = None
    """The same clock at quality 1.0: steps until the greedy path was a shortest one and stayed so."""
    settled_ratio: float | None = None
    """The first settled greedy path's length over the shortest (``greedy_steps / optimal``)."""
    final_ratio: float | None = None
    """The greedy path's length at the end of the trial over the shortest (None: it misses the goal)."""
    steps_run: int = 0
    """Every step the trial took."""
    clock_note: str | None = None
    """Why the good-path clock is not measured, where a learner cannot measure it (None: it is, or
    no shortest path was handed over)."""
