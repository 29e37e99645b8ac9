"""Planning after every episode, over the moves robot 2 has tried.

Robot 2 counts, for every pair (s, a) it has tried, the states s' it observed after it (with
wind, how often each), and runs value iteration over those pairs on those counts: Q(s, a) = sum
over s' of P(s' | s, a) (r + gamma max Q(s', .)). A pair never tried gets Q = ``UNTRIED``, just
above 0, an optimistic bound (every return is <= 0) that wins ties, so the planned greedy policy
leads to the untried pairs that could still shorten the way, and once the greedy path reaches
the goal no untried pair could make it shorter: the path is a shortest one (in expectation,
with wind). Why: SARSA(lambda) evaluates the wandering policy that tried a pair, so pairs tried
in long early episodes keep values far below their optimal ones and the greedy path never comes
back to them. Planning reads robot 2's own observed moves only, never the robot's table."""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from armtransfer.learning.guide.params import PLAN_CAP, SUCCESSORS


class Planner(NamedTuple):
    """The observed successors and predecessors, and the planning's scratch (``new``)."""

    succ: np.ndarray
    """int64 [S*A, SUCCESSORS]: the distinct states observed after each pair s * A + a."""
    count: np.ndarray  # type: ignore[assignment]  # a field shadowing tuple.count: the name is read in numba-compiled bodies
    """int64 [S*A, SUCCESSORS]: how often each was observed."""
    n_succ: np.ndarray
    """int64 [S*A]: how many distinct successors each pair has."""
    head: np.ndarray
    """int64 [S]: the first edge into each state (-1: none); edges form a list, first seen first."""
    tail: np.ndarray
    """int64 [S]: the last edge into each state (-1: none)."""
    next: np.ndarray
    """int64 [S*A*SUCCESSORS]: the edge after each edge into the same state (-1: none)."""
    pair: np.ndarray
    """int64 [S*A*SUCCESSORS]: the pair each edge comes from."""
    n_edges: np.ndarray
    """int64 [1]: edges used."""
    value: np.ndarray
    """float64 [S]: scratch, the planned values V."""
    queue: np.ndarray
    """int64 [S]: scratch, the queue of states to back up (a ring)."""
    queued: np.ndarray
    """bool [S]: scratch, whether a state is in the queue."""
    has_pair: np.ndarray
    """bool [S]: the state has a tried pair."""
    plannings: np.ndarray
    """int64 [1]: plannings so far."""
    most_backups: np.ndarray
    """int64 [1]: the most backups in one planning."""
    capped: np.ndarray
    """int64 [1]: plannings that hit the cap (``PLAN_CAP``)."""


def new(n_states: int, n_actions: int) -> Planner:
    """A planner that has observed nothing."""
    pairs = n_states * n_actions
    return Planner(np.zeros((pairs, SUCCESSORS), np.int64), np.zeros((pairs, SUCCESSORS), np.int64),
                   np.zeros(pairs, np.int64), np.full(n_states, -1, np.int64), np.full(n_states, -1, np.int64),
                   np.full(pairs * SUCCESSORS, -1, np.int64), np.zeros(pairs * SUCCESSORS, np.int64),
                   np.zeros(1, np.int64), np.zeros(n_states), np.zeros(n_states, np.int64),
                   np.zeros(n_states, np.bool_), np.zeros(n_states, np.bool_), np.zeros(1, np.int64),
                   np.zeros(1, np.int64), np.zeros(1, np.int64))


@numba.njit(cache=True)
def observe(pl, sa, s, s2):
    """Count s2 as an observed successor of the pair sa (at state s); a new one makes sa a
    predecessor of s2."""
    succ, scnt, nsucc = pl.succ, pl.count, pl.n_succ
    pl.has_pair[s] = True
    for j in range(nsucc[sa]):
        if succ[sa, j] == s2:
            scnt[sa, j] += 1
            return
    j = nsucc[sa]
    if j >= succ.shape[1]:
        raise ValueError("more distinct successors of one move than the planner keeps (guide.SUCCESSORS)")
    succ[sa, j] = s2
    scnt[sa, j] = 1
    nsucc[sa] = j + 1
    e = pl.n_edges[0]
    pl.n_edges[0] = e + 1
    pl.pair[e] = sa
    if pl.tail[s2] < 0:
        pl.head[s2] = e
    else:
        pl.next[pl.tail[s2]] = e
    pl.tail[s2] = e


@numba.njit(cache=True)
def plan(g, pl, Q, label, goal, gamma, r_step, r_goal):
    """Value iteration over the pairs robot 2 has tried, on what it observed of them, after an
    episode: Q(s, a) = sum over the observed successors s' of (count / tries) * (r + gamma V(s')),
    r = r_step (+ r_goal when s' is labelled the goal, where V = 0), V(s') = max over a' of
    Q(s', a'). A pair never tried at x gets Q = g.untried[x] (UNTRIED, or less away from the
    trajectories: ``model.corridor_prior``). Returns the number of backups.

    Order: every state with a tried pair, in index order, is queued; a state taken from the
    front of the queue gets its tried pairs (in action order) backed up from the planned values
    V of their successors; when its own V changes by more than ``plan_tol``, V is set and every
    predecessor not already queued is queued, in the order first observed. V starts as max Q."""
    tol = g.params.plan_tol
    succ, scnt, nsucc = pl.succ, pl.count, pl.n_succ
    head, enext, epair = pl.head, pl.next, pl.pair
    vp, queue, inq, has_pair = pl.value, pl.queue, pl.queued, pl.has_pair
    n_states, n_actions = Q.shape
    for x in range(n_states):
        for a in range(n_actions):
            if nsucc[x * n_actions + a] == 0:
                Q[x, a] = g.untried[x]
        best = Q[x, 0]
        for a in range(1, n_actions):
            if Q[x, a] > best:
                best = Q[x, a]
        vp[x] = best
    qh = 0
    qn = 0
    for x in range(n_states):
        if has_pair[x]:
            queue[(qh + qn) % n_states] = x
            inq[x] = True
            qn += 1
    backups = 0
    cap = PLAN_CAP * n_states
    while qn > 0 and backups < cap:
        x = queue[qh]
        qh = (qh + 1) % n_states
        qn -= 1
        inq[x] = False
        for a in range(n_actions):
            sa = x * n_actions + a
            k = nsucc[sa]
            if k == 0:
                continue
            n = 0
            for j in range(k):
                n += scnt[sa, j]
            acc = 0.0
            for j in range(k):
                y = succ[sa, j]
                w = scnt[sa, j] / n  # exactly 1.0 for a single successor: equal paths get equal values
                if label[y] == goal:
                    acc += w * (r_step + r_goal)
                else:
                    acc += w * (r_step + gamma * vp[y])
            Q[x, a] = acc
            backups += 1
        best = Q[x, 0]
        for a in range(1, n_actions):
            if Q[x, a] > best:
                best = Q[x, a]
        if abs(best - vp[x]) > tol:
            vp[x] = best
            e = head[x]
            while e >= 0:
                p = epair[e] // n_actions
                if not inq[p]:
                    queue[(qh + qn) % n_states] = p
                    inq[p] = True
                    qn += 1
                e = enext[e]
    pl.plannings[0] += 1
    pl.most_backups[0] = max(pl.most_backups[0], backups)
    if qn > 0:
        pl.capped[0] += 1
    while qn > 0:  # the cap was hit: leave the queue empty for the next planning
        inq[queue[qh]] = False
        qh = (qh + 1) % n_states
        qn -= 1
    return backups
