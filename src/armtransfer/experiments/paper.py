"""The paper's experimental protocol and the numbers it reports, for side-by-side reports.

Tables are transcribed from the paper's text (its figures are not available). ``None``
stands for the paper's "NA".
"""

from __future__ import annotations

Row = dict[str, float | None]


TABLE_II: dict[int, Row] = {
    # task: A (no transfer), B (transfer), C (% improvement), D (transfer + mapping),
    #       E (% of mapped sequences in the final path), F (% improvement with mapping)
    1: {"A": 9777.80, "B": 5200.1, "C": 46.82, "D": 3152.4, "E": None, "F": None},
    2: {"A": 7338.3, "B": 3841.7, "C": 47.65, "D": 1039.6, "E": 34.38, "F": 85.83},
    3: {"A": 11797.5, "B": 6467.8, "C": 45.18, "D": 2880.10, "E": 56.82, "F": 75.59},
    4: {"A": 9222.2, "B": 8282.9, "C": 10.19, "D": 11419.4, "E": 0.0, "F": -23.83},
}
"""Table II: coarse (larger) -> fine robot, deterministic, 10 trials."""

TABLE_V: dict[int, Row] = {
    # task: A (no transfer), B (transfer), C (% improvement), D (transfer + mapping),
    #       E (% improvement with mapping)
    1: {"A": 3365.89, "B": 331.89, "C": 90.14, "D": 371.0, "E": None},
    2: {"A": 1967.3, "B": 1277.4, "C": 35.07, "D": 1333.2, "E": 32.23},
    3: {"A": 2544.8, "B": 1468.6, "C": 42.29, "D": 2133.1, "E": 16.17},
    4: {"A": 3126.7, "B": 2652.0, "C": 15.18, "D": 2480.2, "E": 20.67},
}
"""Table V: fine (finer) -> coarse robot, deterministic, 10 trials."""

TABLE_IV: dict[str, Row] = {
    # row: distance of the transferred path, A (exploration steps with transfer),
    #      B (% improvement), C (greedy steps of the converged policy), D (% improvement of C)
    "no transfer": {"distance": None, "A": 7338.80, "B": None, "C": 104.4, "D": None},
    "optimal": {"distance": 24, "A": 3841.7, "B": 47.65, "C": 80.2, "D": 23.18},
    "set 1": {"distance": 32, "A": 7256.6, "B": 1.12, "C": 89.2, "D": 14.56},
    "set 2": {"distance": 48, "A": 5081.2, "B": 30.76, "C": 54.0, "D": 48.28},
    "set 3": {"distance": 56, "A": 3772.2, "B": 48.6, "C": 68.0, "D": 34.87},
}
"""Table IV: task 2, coarse -> fine, with the optimal and three longer trajectories."""

TABLE_IV_WAYPOINTS = {
    "optimal": [],
    "set 1": [(8, 6)],  # a detour to the right inside room 1
    "set 2": [(-10, 14), (0, 8)],  # into room 2, back out to room 1, then on: a loop
    "set 3": [(14, -4), (16, 16)],  # round the far side of room 1
}
"""Our sub-optimal trajectories for Table IV: the coarse robot's shortest paths through
these waypoints (the paper does not give its sets, only their lengths)."""

WIND = 0.01
"""Section IV.C: wind from left to right with probability 0.01."""

PAPER_TRIALS = 10
