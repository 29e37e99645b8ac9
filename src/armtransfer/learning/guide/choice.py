"""How the guide chooses, in the exploration phase only: epsilon-greedy over
Q(s, a) - weight * score(the label's predicted position after a).

An action never tried anywhere counts as the best, one tried at s and blocked every time as the
worst. A wrong prediction (a wall, a joint limit, a cell it cannot reach) costs a step: the pair
is then tried, its Q falls and its own observed effect replaces the prediction, so the
learner's own exploration takes over there. With the tip model a move not yet tried at s is
predicted by it (``tip.move``), or predicted blocked when it was blocked at each of the
``tip_nearest`` remembered states nearest to s where it was tried; with ``tip_anchor`` the score
starts from the tip model's estimate inside the current cell (clamped to the cell) instead of
the cell's centre. With the fill each move's score adds h of the state it led to, and the
choice raises h(s) (``fill``)."""

from __future__ import annotations

import numba
import numpy as np

from armtransfer.learning.guide import displacement, fill as fill_, progress, tip as tip_


@numba.njit(cache=True)
def egreedy(Q, s, eps, rng, g, m):
    """Epsilon-greedy over Q plus the model's preference, in the exploration phase.

    Draws: u; if u < eps one more draw picks floor(u2 * n_actions) (Algorithm 1's random
    step). Otherwise the action of largest Q(s, a) - weight * score(predicted label of a)
    is taken; an action never tried anywhere counts as the best (it is tried once early), and
    one tried at s that was blocked every time (the robot did not move) as the worst.
    When m > 1 actions tie for the largest value, one more draw picks the floor(u2 * m)-th
    of them in index order."""
    n_actions = Q.shape[1]
    if rng.random() < eps:
        return int(rng.random() * n_actions)
    lxy, params = g.lxy, g.params
    d, p, t, f = m.displacement, m.progress, m.tip, m.fill
    w = params.weight
    x = lxy[s, 0]
    y = lxy[s, 1]
    val = np.empty(n_actions)
    best = -np.inf
    tip = params.tip
    x0 = 0.0
    y0 = 0.0
    if tip:
        x0, y0 = tip_.here(g, t, s)
        if params.tip_anchor:
            first = t.first
            x = min(max(first[0] + x0, lxy[s, 0] - 0.5), lxy[s, 0] + 0.5)
            y = min(max(first[1] + y0, lxy[s, 1] - 0.5), lxy[s, 1] + 0.5)
    cost = params.fill
    epoch = p.epoch[0]
    here = 0.0  # the score where the tip is now (what a move predicted blocked keeps)
    if tip or cost > 0.0:
        here = progress.score(g, p, x, y)
    if cost > 0.0:
        fill_.visit(f, epoch, s)
    low = np.inf
    for a in range(n_actions):
        ha = np.nan
        if d.tries[s, a] > 0 and not d.moved[s, a]:
            v = -np.inf  # tried here and blocked every time: a wasted step, never the model's choice
        elif tip and d.tries[s, a] == 0:  # the tip model predicts a pair not tried here
            if d.pushes[a] == 0:
                v = np.inf  # tried nowhere yet
            elif displacement.near_blocked(g, d, s, a):
                ha = here + f.h[s] if cost > 0.0 else here
                v = Q[s, a] - w * ha
            else:
                dx, dy = tip_.move(g, t, s, a, x0, y0)
                ha = progress.score(g, p, x + dx, y + dy)
                v = Q[s, a] - w * ha
        else:
            known, dx, dy = displacement.predict(g, d, s, a)
            if known:
                ha = progress.score(g, p, x + dx, y + dy)
                if cost > 0.0 and d.tries[s, a] > 0:
                    valid, hu = fill_.ahead(f, epoch, s, a)
                    if valid:
                        ha += hu
                v = Q[s, a] - w * ha
            else:
                v = np.inf
        if cost > 0.0 and not np.isnan(ha) and ha < low:
            low = ha
        val[a] = v
        if v > best:
            best = v
    if cost > 0.0 and low < np.inf:  # learning real-time search: the basin fills as it is visited
        fill_.raise_at(f, s, low, cost, here)
    n_best = 0
    first_best = -1
    for a in range(n_actions):
        if val[a] == best:
            if first_best < 0:
                first_best = a
            n_best += 1
    if n_best == 1:
        return first_best
    k = int(rng.random() * n_best)
    for a in range(n_actions):
        if val[a] == best:
            if k == 0:
                return a
            k -= 1
    return n_actions - 1  # unreachable
