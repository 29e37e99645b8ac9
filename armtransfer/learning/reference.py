"""Algorithm 1, line by line, in plain Python with dense traces: the reference the
compiled learner (``transfer.sarsa``) is tested against. Slow; for tests and benchmarks.

It draws from the random stream exactly as ``transfer.sarsa`` documents, so with the
same generator and ``trace_cutoff=0`` the two give bit-identical Q tables.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from armtransfer.learning import guide as guide_module
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trajectory import Trajectory


def _egreedy(q_row: np.ndarray, eps: float, rng: np.random.Generator) -> int:
    n_actions = len(q_row)
    if rng.random() < eps:
        return int(rng.random() * n_actions)
    best = q_row.max()
    ties = [a for a in range(n_actions) if q_row[a] == best]
    if len(ties) == 1:
        return ties[0]
    return ties[int(rng.random() * len(ties))]


class GuideModel:
    """The model of method ``guided`` (``transfer.guide``), written out plainly: what robot 2
    learns of its own actions, its predictions and its tie-breaking."""

    def __init__(self, guide, n_states: int, n_actions: int):
        self.g = guide
        self.window, self.reach = guide.params[0], guide.params[1]
        self.knn, self.memory = int(guide.params[2]), int(guide.params[3])
        self.episodes = int(guide.params[5])
        self.sums: dict[tuple[int, int], list[float]] = {}  # (s, a) -> [sum dx, sum dy, count]
        self.tried_at: list[list[int]] = [[] for _ in range(n_actions)]  # states, in order
        self.generalised: set[tuple[int, int]] = set()  # pairs whose effect is generalised
        self.moved: set[tuple[int, int]] = set()  # pairs seen to move at least once
        self.n_traj = len(guide.tstart) - 1
        self.prog = [0] * self.n_traj
        self.plans = guide.params[8] > 0
        self.successors: dict[tuple[int, int], list[list[int]]] = {}  # (s, a) -> [[s2, count], ...] first seen first
        self.preds: dict[int, list[int]] = {}  # s2 -> the states of the pairs it followed, first seen first
        # the tip model (transfer.guide.tip_learn): ridge least squares, one recursive step per new state
        self.tip = guide.params[10] > 0
        n_f = guide.fj.shape[0]
        ridge = float(guide.params[11])
        self.P = [[(1.0 if i == j else 0.0) / ridge for j in range(n_f)] for i in range(n_f)]
        self.W = [[0.0, 0.0] for _ in range(n_f)]
        self.first: tuple[float, float] | None = None  # the first label the tip model learned from
        self.tip_seen: set[int] = set()
        n_j = guide.tq.shape[1] if n_f else 0
        self.dq = [[0.0] * n_j for _ in range(n_actions)]  # summed joint displacement of each action's moves
        self.dqn = [0] * n_actions
        # the fill (transfer.guide: learning real-time search): h per state, valid in one epoch
        self.fill = float(guide.params[14])
        self.h: dict[int, float] = {}
        self.h_epoch: dict[int, int] = {}
        self.epoch = 0  # +1 at an episode's start and whenever a trajectory's progress moves
        self.last: dict[tuple[int, int], int] = {}  # (s, a) -> the state observed after it last

    def cells(self, t: int) -> range:
        return range(int(self.g.tstart[t]), int(self.g.tstart[t + 1]))

    def start_episode(self, s: int, guided: bool) -> None:
        self.prog = [int(self.g.tstart[t]) for t in range(self.n_traj)]
        self.wait = [0] * self.n_traj
        self.epoch += 1
        if guided and self.tip:
            self.tip_learn(s)
        self.reached(s)

    def features(self, q) -> list[float]:
        g = self.g
        out = []
        for i in range(g.fj.shape[0]):
            v = 1.0
            for k in range(g.fj.shape[1]):
                j = int(g.fj[i, k])
                if j < 0:
                    break
                v *= math.cos(float(q[j])) if g.fk[i, k] == 0 else math.sin(float(q[j]))
            out.append(v)
        return out

    def tip_learn(self, s: int) -> None:
        """One recursive least-squares step towards s's label (relative to the first one)."""
        if s in self.tip_seen:
            return
        self.tip_seen.add(s)
        lx, ly = float(self.g.lxy[s][0]), float(self.g.lxy[s][1])
        if self.first is None:
            self.first = (lx, ly)
        f = self.features(self.g.tq[s])
        n = len(f)
        px = []
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += self.P[i][j] * f[j]
            px.append(acc)
        denom = 1.0
        for i in range(n):
            denom += f[i] * px[i]
        for c, target in enumerate((lx - self.first[0], ly - self.first[1])):
            fit = 0.0
            for i in range(n):
                fit += f[i] * self.W[i][c]
            err = target - fit
            for i in range(n):
                self.W[i][c] += px[i] / denom * err
        for i in range(n):
            k = px[i] / denom
            for j in range(n):
                self.P[i][j] -= k * px[j]

    def tip_at(self, f: list[float]) -> tuple[float, float]:
        x = y = 0.0
        for i in range(len(f)):
            x += f[i] * self.W[i][0]
            y += f[i] * self.W[i][1]
        return x, y

    def tip_move(self, s: int, a: int, x0: float, y0: float) -> tuple[float, float]:
        if self.dqn[a] == 0:
            return 0.0, 0.0
        q = [float(self.g.tq[s, c]) + self.dq[a][c] / self.dqn[a] for c in range(self.g.tq.shape[1])]
        x1, y1 = self.tip_at(self.features(q))
        return x1 - x0, y1 - y0

    def recent(self, a: int) -> list[int]:
        """The most recent ``memory`` states a was tried at, in the kernel's ring-buffer slot order."""
        slots: dict[int, int] = {}
        for i, u in enumerate(self.tried_at[a]):
            slots[i % self.memory] = u
        return [slots[k] for k in sorted(slots)]

    def nearest(self, s: int, a: int, k: int) -> list[int]:
        """The k of those states nearest to s in configuration space (ties: the earlier slot)."""
        recent = self.recent(a)
        f = self.g.feat

        def dist(u: int) -> float:
            d = 0.0
            for c in range(f.shape[1]):
                d += (f[u, c] - f[s, c]) * (f[u, c] - f[s, c])
            return d

        order = sorted(range(len(recent)), key=lambda i: (dist(recent[i]), i))
        return [recent[i] for i in order[: min(k, len(recent))]]

    def near_blocked(self, s: int, a: int) -> bool:
        near = self.nearest(s, a, int(self.g.params[12]))
        return bool(near) and all((u, a) not in self.moved for u in near)

    def reached(self, s: int) -> None:
        g = self.g
        x, y = g.lxy[s]
        for t in range(self.n_traj):
            i0 = self.prog[t]
            if i0 > self.cells(t)[-1]:
                continue  # the whole trajectory given up on
            for j in self.cells(t):
                if j <= i0:
                    continue
                if g.trem[i0] - g.trem[j] > self.window + self.reach:
                    break
                if np.sqrt((g.tx[j] - x) * (g.tx[j] - x) + (g.ty[j] - y) * (g.ty[j] - y)) <= self.reach:
                    self.prog[t] = j
            if self.prog[t] != i0:
                self.wait[t] = 0
                self.epoch += 1
            else:
                self.wait[t] += 1
                if g.params[7] > 0 and self.wait[t] >= g.params[7]:  # past the last cell: the trajectory
                    self.prog[t] += 1
                    self.wait[t] = 0
                    self.epoch += 1

    def exhausted(self) -> bool:
        """Every trajectory given up on, its goal s_tg included: Algorithm 1 chooses alone."""
        return all(self.prog[t] > self.cells(t)[-1] for t in range(self.n_traj))

    def observe(self, s: int, a: int, s2: int, guided: bool) -> None:
        g = self.g
        entry = self.sums.get((s, a))
        if entry is None:
            entry = self.sums[(s, a)] = [0.0, 0.0, 0]
        if s2 != s:
            self.moved.add((s, a))
        if self.fill > 0:
            self.last[(s, a)] = s2
        if guided and self.tip:
            if s2 != s:
                for c in range(g.tq.shape[1]):
                    self.dq[a][c] += g.tq[s2, c] - g.tq[s, c]
                self.dqn[a] += 1
            self.tip_learn(s2)
        if (s2 != s or g.params[6] > 0) and (s, a) not in self.generalised:  # blocked: only if asked
            self.generalised.add((s, a))
            self.tried_at[a].append(s)
        entry[0] += g.lxy[s2][0] - g.lxy[s][0]
        entry[1] += g.lxy[s2][1] - g.lxy[s][1]
        entry[2] += 1
        if self.plans:
            seen = self.successors.setdefault((s, a), [])
            for item in seen:
                if item[0] == s2:
                    item[1] += 1
                    break
            else:
                if len(seen) >= guide_module.SUCCESSORS:
                    raise ValueError("more distinct successors of one move than the planner keeps")
                seen.append([s2, 1])
                self.preds.setdefault(s2, []).append(s)

    def plan(self, Q: np.ndarray, label: np.ndarray, goal: int, config: LearnerConfig) -> None:
        """Value iteration over the tried pairs on their observed successors, with a queue of
        states (``transfer.guide.plan``, written out plainly)."""
        tol = self.g.params[9]
        n_states, n_actions = Q.shape
        for x in range(n_states):
            for a in range(n_actions):
                if (x, a) not in self.successors:
                    Q[x, a] = guide_module.UNTRIED
        v = [float(Q[x].max()) for x in range(n_states)]
        queue = deque(sorted({s for s, _ in self.successors}))
        queued = set(queue)
        backups = 0
        while queue and backups < guide_module.PLAN_CAP * n_states:
            x = queue.popleft()
            queued.discard(x)
            for a in range(n_actions):
                seen = self.successors.get((x, a))
                if seen is None:
                    continue
                n = sum(c for _, c in seen)
                total = 0.0
                for y, c in seen:
                    w = c / n
                    if label[y] == goal:
                        total += w * (config.step_reward + config.goal_reward)
                    else:
                        total += w * (config.step_reward + config.gamma * v[y])
                Q[x, a] = total
                backups += 1
            best = float(Q[x].max())
            if abs(best - v[x]) > tol:
                v[x] = best
                for p in self.preds.get(x, []):
                    if p not in queued:
                        queue.append(p)
                        queued.add(p)

    def predict(self, s: int, a: int):
        if (s, a) in self.sums:
            sx, sy, n = self.sums[(s, a)]
            return sx / n, sy / n
        near = self.nearest(s, a, self.knn)
        if not near:
            return None
        sx = sy = 0.0
        for u in near:
            ex, ey, n = self.sums[(u, a)]
            sx += ex / n
            sy += ey / n
        return sx / len(near), sy / len(near)

    def score(self, x: float, y: float) -> float:
        g = self.g
        best = np.inf
        for t in range(self.n_traj):
            i0 = self.prog[t]
            for j in self.cells(t):
                if j < i0:
                    continue
                if g.trem[i0] - g.trem[j] > self.window:
                    break
                v = np.sqrt((g.tx[j] - x) * (g.tx[j] - x) + (g.ty[j] - y) * (g.ty[j] - y)) + g.trem[j]
                best = min(best, v)
        return best

    def egreedy(self, q_row: np.ndarray, s: int, eps: float, rng: np.random.Generator) -> int:
        n_actions = len(q_row)
        if rng.random() < eps:
            return int(rng.random() * n_actions)
        x, y = self.g.lxy[s]
        w = self.g.params[4]
        x0 = y0 = 0.0
        if self.tip:
            x0, y0 = self.tip_at(self.features(self.g.tq[s]))
            if self.g.params[13] > 0:  # anchored: the tip model's estimate, kept inside the cell
                lx, ly = self.g.lxy[s]
                x = min(max(self.first[0] + x0, lx - 0.5), lx + 0.5)
                y = min(max(self.first[1] + y0, ly - 0.5), ly + 0.5)
        fill = self.fill > 0
        here = self.score(x, y) if self.tip or fill else 0.0  # the score where the tip is now
        if fill and self.h_epoch.get(s) != self.epoch:
            self.h_epoch[s] = self.epoch
            self.h[s] = 0.0
        val = []
        heads = []  # each action's predicted score (plus h of its known successor), None when unknown
        for a in range(n_actions):
            ha = None
            if (s, a) in self.sums and (s, a) not in self.moved:
                v = -np.inf  # blocked at every try here
            elif self.tip and (s, a) not in self.sums:  # the tip model predicts a pair not tried here
                if not self.tried_at[a]:
                    v = np.inf
                elif self.near_blocked(s, a):
                    ha = here + self.h[s] if fill else here
                    v = q_row[a] - w * ha
                else:
                    dx, dy = self.tip_move(s, a, x0, y0)
                    ha = self.score(x + dx, y + dy)
                    v = q_row[a] - w * ha
            else:
                p = self.predict(s, a)
                if p is None:
                    v = np.inf
                else:
                    ha = self.score(x + p[0], y + p[1])
                    if fill and (s, a) in self.sums:
                        u = self.last[(s, a)]
                        if self.h_epoch.get(u) == self.epoch:
                            ha += self.h[u]
                    v = q_row[a] - w * ha
            val.append(v)
            heads.append(ha)
        known = [ha for ha in heads if ha is not None]
        if fill and known:  # learning real-time search: raise h(s) to the best neighbour's + the fill
            raise_to = min(known) + self.fill - here
            if raise_to > self.h[s]:
                self.h[s] = raise_to
        best = max(val)
        keep = [a for a in range(n_actions) if val[a] == best]
        if len(keep) == 1:
            return keep[0]
        return keep[int(rng.random() * len(keep))]


def pseudo_reward(robot: DiscreteRobot, traj: Trajectory | None, K: float, s2: int) -> float:
    """r'(s') = i*K if s' is labelled s_ti, i = 1..n (the largest such i), else 0."""
    if traj is None:
        return 0.0
    value = 0.0
    for i in range(1, len(traj.cells)):
        if robot.label[s2] == traj.cells[i]:
            value = i * K
    return value


def learn(
    robot: DiscreteRobot,
    start_state: int,
    goal_cell: int,
    config: LearnerConfig,
    rng: np.random.Generator,
    episodes: int,
    traj: Trajectory | None = None,
    K: float = 0.0,
    wind: float = 0.0,
    macros=None,
    guide=None,
    trace: list | None = None,
) -> tuple[np.ndarray, list[int]]:
    """Run ``episodes`` episodes; returns (Q, steps per episode).

    ``macros`` (a ``transfer.mapping.MacroTable``): at a state with a macro, when none is
    running, one draw u and the macro's target sequence runs when u < 1 - epsilon; its
    steps are ordinary steps; it is abandoned when a step is blocked (the robot did not move,
    observed after wind), and then the next
    action is epsilon-greedy without a macro draw.

    ``guide`` (a ``transfer.guide.Guide``, method ``guided``): its model breaks the ties of
    epsilon-greedy (:class:`GuideModel`). ``trace``, when given, gets every state visited.
    """
    model = None if guide is None else GuideModel(guide, robot.n_states, robot.n_actions)
    seq_at: dict[int, list[int]] = {}
    if macros is not None:
        m_start, m_len, m_actions = macros.arrays(robot)
        for s in range(robot.n_states):
            if m_len[s] > 0:
                seq_at[s] = [int(x) for x in m_actions[m_start[s] : m_start[s] + m_len[s]]]

    def choose(s: int, pending: list[int], may_start: bool) -> tuple[int, list[int], bool]:
        """The next action, what remains of the running macro, and whether the action is
        a macro's."""
        if pending:
            return pending[0], pending[1:], True
        if may_start and s in seq_at and rng.random() < 1.0 - config.epsilon:
            seq = seq_at[s]
            return seq[0], seq[1:], True
        if model is not None and episode < model.episodes and not model.exhausted():
            return model.egreedy(Q[s], s, config.epsilon, rng), [], False
        return _egreedy(Q[s], config.epsilon, rng), [], False

    alpha, gamma = config.alpha, config.gamma
    decay = gamma * config.lam
    Q = np.zeros((robot.n_states, robot.n_actions))
    steps_per_episode = []
    for episode in range(episodes):
        e = np.zeros_like(Q)  # Initialize e(s, a) = 0 for all s, a
        s = start_state  # Initialize s, a
        if model is not None:
            model.start_episode(s, episode < model.episodes)
        if trace is not None:
            trace.append(s)
        a, pending, from_macro = choose(s, [], True)
        steps = 0
        while True:  # repeat
            # Take action a and observe next state s' and reward r
            s2 = int(robot.next_state[s, a])
            if wind > 0.0 and rng.random() < wind:
                s2 = int(robot.wind_state[s2])
            blocked = s2 == s  # observed: the robot did not move (after wind)
            steps += 1
            if model is not None:
                model.observe(s, a, s2, episode < model.episodes)
                model.reached(s2)
            if trace is not None:
                trace.append(s2)
            terminal = robot.label[s2] == goal_cell
            r = config.step_reward + (config.goal_reward if terminal else 0.0)
            # Choose a' from s' using the epsilon-greedy policy derived from Q
            if terminal:
                a2, q_next = 0, 0.0
            else:
                abandoned = from_macro and blocked
                if abandoned:
                    pending = []
                a2, pending, from_macro = choose(s2, pending, not abandoned)
                q_next = Q[s2, a2]
            # delta <- r' + r + gamma Q(s', a') - Q(s, a)  (r' = 0 off the trajectory)
            r_prime = pseudo_reward(robot, traj, K, s2)
            delta = (r + r_prime if traj is not None else r) + gamma * q_next - Q[s, a]
            e[s, a] += 1.0
            Q += alpha * delta * e  # for all (s, a)
            e *= decay
            s, a = s2, a2
            if terminal:  # until s is terminal
                break
        if model is not None and model.plans:  # robot 2 plans over the moves it has tried
            model.plan(Q, robot.label, goal_cell, config)
        steps_per_episode.append(steps)
    return Q, steps_per_episode
