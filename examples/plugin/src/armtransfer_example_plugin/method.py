"""``breadcrumbs``: a potential from the progress along the transferred trajectory.

A state's potential is the index of the trajectory cell nearest to the cell it perceives (how
far along the route that cell is) minus the distance to it (in cells): robot 2 is drawn to the
route and along it towards the goal. It is potential-based shaping, so armtransfer runs it in
its compiled kernel and bounds it like its own potentials; its baseline is ``none``.
"""

from __future__ import annotations

import numpy as np

import armtransfer


def breadcrumbs(cells: np.ndarray, trajectory: np.ndarray) -> np.ndarray:
    """cells: (n, 2) int (x, y) of each state's cell; trajectory: (m, 2) int (x, y), start to goal."""
    distance = np.full(len(cells), np.inf)
    index = np.zeros(len(cells))
    for i, point in enumerate(trajectory):  # one pass per trajectory cell: memory O(n)
        d = np.hypot(*(cells - point).T)
        nearer = d <= distance  # ties go to the later cell: further along the route
        index[nearer], distance[nearer] = i, d[nearer]
    return index - distance


BREADCRUMBS = armtransfer.potential_method(
    "breadcrumbs", "example plugin: phi = the index of the nearest trajectory cell minus the distance to it",
    breadcrumbs)
