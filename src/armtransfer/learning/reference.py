"""Algorithm 1, line by line, in plain Python with dense traces: the reference the
compiled learner (``learning.sarsa``) is tested against. Slow; for tests and benchmarks.

It draws from the random stream exactly as ``learning.sarsa`` documents, so with the
same generator and ``trace_cutoff=0`` the two give bit-identical Q tables. Method ``guided``'s
model is written out one class per mechanism of ``learning.guide`` (``Displacement``, ``Tip``,
``Progress``, ``Fill``, ``Planner``), reading the same ``guide.Guide`` record, and
``GuideModel`` composes them and chooses as ``guide.choice`` does.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import guide as guide_module
from armtransfer.learning.guide import Guide
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


@dataclass
class Effect:
    """What the moves of one pair did to the label: summed displacement and their number."""

    dx: float = 0.0
    dy: float = 0.0
    n: int = 0


class Displacement:
    """``guide.displacement``, written out plainly: what each move did to the label, and its
    generalisation to untried pairs by the nearest states where the action was tried."""

    def __init__(self, g: Guide, n_actions: int):
        self.g = g
        self.sums: dict[tuple[int, int], Effect] = {}
        self.tried_at: list[list[int]] = [[] for _ in range(n_actions)]  # states, in order
        self.generalised: set[tuple[int, int]] = set()  # pairs whose effect is generalised
        self.moved: set[tuple[int, int]] = set()  # pairs seen to move at least once

    def record(self, s: int, a: int, s2: int) -> None:
        g = self.g
        effect = self.sums.setdefault((s, a), Effect())
        if s2 != s:
            self.moved.add((s, a))
        if (s2 != s or g.params.blocked) and (s, a) not in self.generalised:  # blocked: only if asked
            self.generalised.add((s, a))
            self.tried_at[a].append(s)
        effect.dx += g.lxy[s2][0] - g.lxy[s][0]
        effect.dy += g.lxy[s2][1] - g.lxy[s][1]
        effect.n += 1

    def recent(self, a: int) -> list[int]:
        """The most recent ``memory`` states a was tried at, in the kernel's ring-buffer slot order."""
        slots: dict[int, int] = {}
        for i, u in enumerate(self.tried_at[a]):
            slots[i % self.g.params.memory] = u
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
        near = self.nearest(s, a, self.g.params.tip_nearest)
        return bool(near) and all((u, a) not in self.moved for u in near)

    def predict(self, s: int, a: int):
        if (s, a) in self.sums:
            e = self.sums[(s, a)]
            return e.dx / e.n, e.dy / e.n
        near = self.nearest(s, a, self.g.params.knn)
        if not near:
            return None
        sx = sy = 0.0
        for u in near:
            e = self.sums[(u, a)]
            sx += e.dx / e.n
            sy += e.dy / e.n
        return sx / len(near), sy / len(near)


class Tip:
    """``guide.tip``, written out plainly: ridge least squares of the label on the joints'
    features, one recursive step per new state."""

    def __init__(self, g: Guide, n_actions: int):
        self.g = g
        n_f = g.fj.shape[0]
        ridge = float(g.params.tip_ridge)
        self.P = [[(1.0 if i == j else 0.0) / ridge for j in range(n_f)] for i in range(n_f)]
        self.W = [[0.0, 0.0] for _ in range(n_f)]
        self.first: tuple[float, float] | None = None  # the first label the tip model learned from
        self.seen: set[int] = set()
        n_j = g.tq.shape[1] if n_f else 0
        self.dq = [[0.0] * n_j for _ in range(n_actions)]  # summed joint displacement of each action's moves
        self.dqn = [0] * n_actions

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

    def learn(self, s: int) -> None:
        """One recursive least-squares step towards s's label (relative to the first one)."""
        if s in self.seen:
            return
        self.seen.add(s)
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

    def observe(self, s: int, a: int, s2: int) -> None:
        g = self.g
        if s2 != s:
            for c in range(g.tq.shape[1]):
                self.dq[a][c] += g.tq[s2, c] - g.tq[s, c]
            self.dqn[a] += 1
        self.learn(s2)

    def at(self, f: list[float]) -> tuple[float, float]:
        x = y = 0.0
        for i in range(len(f)):
            x += f[i] * self.W[i][0]
            y += f[i] * self.W[i][1]
        return x, y

    def move(self, s: int, a: int, x0: float, y0: float) -> tuple[float, float]:
        if self.dqn[a] == 0:
            return 0.0, 0.0
        q = [float(self.g.tq[s, c]) + self.dq[a][c] / self.dqn[a] for c in range(self.g.tq.shape[1])]
        x1, y1 = self.at(self.features(q))
        return x1 - x0, y1 - y0


class Progress:
    """``guide.progress``, written out plainly: how far along each trajectory robot 2 has come,
    giving up on a cell (or, at its last one, the trajectory) after ``give_up`` moves."""

    def __init__(self, g: Guide):
        self.g = g
        self.n_traj = len(g.tstart) - 1
        self.prog = [0] * self.n_traj
        self.wait = [0] * self.n_traj
        self.epoch = 0  # +1 at an episode's start and whenever a trajectory's progress moves

    def cells(self, t: int) -> range:
        return range(int(self.g.tstart[t]), int(self.g.tstart[t + 1]))

    def reset(self) -> None:
        self.prog = [int(self.g.tstart[t]) for t in range(self.n_traj)]
        self.wait = [0] * self.n_traj
        self.epoch += 1

    def update(self, s: int) -> None:
        g = self.g
        window, reach, give_up = g.params.window, g.params.reach, g.params.give_up
        x, y = g.lxy[s]
        for t in range(self.n_traj):
            i0 = self.prog[t]
            if i0 > self.cells(t)[-1]:
                continue  # the whole trajectory given up on
            for j in self.cells(t):
                if j <= i0:
                    continue
                if g.trem[i0] - g.trem[j] > window + reach:
                    break
                if np.sqrt((g.tx[j] - x) * (g.tx[j] - x) + (g.ty[j] - y) * (g.ty[j] - y)) <= reach:
                    self.prog[t] = j
            if self.prog[t] != i0:
                self.wait[t] = 0
                self.epoch += 1
            else:
                self.wait[t] += 1
                if give_up > 0 and self.wait[t] >= give_up:  # past the last cell: the trajectory
                    self.prog[t] += 1
                    self.wait[t] = 0
                    self.epoch += 1

    def exhausted(self) -> bool:
        """Every trajectory given up on, its goal s_tg included: Algorithm 1 chooses alone."""
        return all(self.prog[t] > self.cells(t)[-1] for t in range(self.n_traj))

    def score(self, x: float, y: float) -> float:
        g = self.g
        best = np.inf
        for t in range(self.n_traj):
            i0 = self.prog[t]
            for j in self.cells(t):
                if j < i0:
                    continue
                if g.trem[i0] - g.trem[j] > g.params.window:
                    break
                v = np.sqrt((g.tx[j] - x) * (g.tx[j] - x) + (g.ty[j] - y) * (g.ty[j] - y)) + g.trem[j]
                best = min(best, v)
        return best


class Fill:
    """``guide.fill``, written out plainly: learning real-time search, h per state, valid in the
    progress epoch it was set in."""

    def __init__(self, g: Guide):
        self.cost = float(g.params.fill)
        self.h: dict[int, float] = {}
        self.h_epoch: dict[int, int] = {}
        self.last: dict[tuple[int, int], int] = {}  # (s, a) -> the state observed after it last

    def observe(self, s: int, a: int, s2: int) -> None:
        self.last[(s, a)] = s2

    def visit(self, epoch: int, s: int) -> None:
        if self.h_epoch.get(s) != epoch:
            self.h_epoch[s] = epoch
            self.h[s] = 0.0

    def ahead(self, epoch: int, s: int, a: int) -> float | None:
        u = self.last[(s, a)]
        return self.h[u] if self.h_epoch.get(u) == epoch else None

    def raise_at(self, s: int, low: float, here: float) -> None:
        """Raise h(s) to the best neighbour's score + the fill - the score at s."""
        raise_to = low + self.cost - here
        if raise_to > self.h[s]:
            self.h[s] = raise_to


class Planner:
    """``guide.planner``, written out plainly: value iteration over the tried pairs on their
    observed successors, with a queue of states."""

    def __init__(self, g: Guide):
        self.g = g
        self.successors: dict[tuple[int, int], dict[int, int]] = {}  # (s, a) -> {s2: count}, first seen first
        self.preds: dict[int, list[int]] = {}  # s2 -> the states of the pairs it followed, first seen first

    def observe(self, s: int, a: int, s2: int) -> None:
        seen = self.successors.setdefault((s, a), {})
        if s2 in seen:
            seen[s2] += 1
            return
        if len(seen) >= guide_module.SUCCESSORS:
            raise ValueError("more distinct successors of one move than the planner keeps")
        seen[s2] = 1
        self.preds.setdefault(s2, []).append(s)

    def plan(self, Q: np.ndarray, label: np.ndarray, goal: int, config: LearnerConfig) -> None:
        tol = self.g.params.plan_tol
        n_states, n_actions = Q.shape
        for x in range(n_states):
            for a in range(n_actions):
                if (x, a) not in self.successors:
                    Q[x, a] = self.g.untried[x]  # UNTRIED, or less away from the route (corridor_prior)
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
                n = sum(seen.values())
                total = 0.0
                for y, c in seen.items():
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


class GuideModel:
    """The model of method ``guided`` (``guide.model``), one object per mechanism as in the
    kernel, and its choice (``guide.choice``), written out plainly."""

    def __init__(self, guide: Guide, n_states: int, n_actions: int):
        self.g = guide
        self.episodes = guide.params.episodes
        self.plans = guide.params.plan
        self.tip = guide.params.tip
        self.displacement = Displacement(guide, n_actions)
        self.progress = Progress(guide)
        self.tip_model = Tip(guide, n_actions)
        self.fill = Fill(guide)
        self.planner = Planner(guide)

    def start_episode(self, s: int, guided: bool) -> None:
        self.progress.reset()
        if guided and self.tip:
            self.tip_model.learn(s)
        self.progress.update(s)

    def observe(self, s: int, a: int, s2: int, guided: bool) -> None:
        if self.fill.cost > 0:
            self.fill.observe(s, a, s2)
        if guided and self.tip:
            self.tip_model.observe(s, a, s2)
        self.displacement.record(s, a, s2)
        if self.plans:
            self.planner.observe(s, a, s2)
        self.progress.update(s2)

    def exhausted(self) -> bool:
        return self.progress.exhausted()

    def plan(self, Q: np.ndarray, label: np.ndarray, goal: int, config: LearnerConfig) -> None:
        self.planner.plan(Q, label, goal, config)

    def egreedy(self, q_row: np.ndarray, s: int, eps: float, rng: np.random.Generator) -> int:
        n_actions = len(q_row)
        if rng.random() < eps:
            return int(rng.random() * n_actions)
        g, d, tip, progress, fill = self.g, self.displacement, self.tip_model, self.progress, self.fill
        x, y = g.lxy[s]
        w = g.params.weight
        x0 = y0 = 0.0
        if self.tip:
            x0, y0 = tip.at(tip.features(g.tq[s]))
            if g.params.tip_anchor:  # anchored: the tip model's estimate, kept inside the cell
                if tip.first is None:
                    raise InvalidParameterError("the anchored tip model chose before it learned from any state")
                lx, ly = g.lxy[s]
                x = min(max(tip.first[0] + x0, lx - 0.5), lx + 0.5)
                y = min(max(tip.first[1] + y0, ly - 0.5), ly + 0.5)
        filling = fill.cost > 0
        epoch = progress.epoch
        here = progress.score(x, y) if self.tip or filling else 0.0  # the score where the tip is now
        if filling:
            fill.visit(epoch, s)
        val = []
        heads = []  # each action's predicted score (plus h of its known successor), None when unknown
        for a in range(n_actions):
            ha = None
            if (s, a) in d.sums and (s, a) not in d.moved:
                v = -np.inf  # blocked at every try here
            elif self.tip and (s, a) not in d.sums:  # the tip model predicts a pair not tried here
                if not d.tried_at[a]:
                    v = np.inf
                elif d.near_blocked(s, a):
                    ha = here + fill.h[s] if filling else here
                    v = q_row[a] - w * ha
                else:
                    dx, dy = tip.move(s, a, x0, y0)
                    ha = progress.score(x + dx, y + dy)
                    v = q_row[a] - w * ha
            else:
                p = d.predict(s, a)
                if p is None:
                    v = np.inf
                else:
                    dx, dy = p
                    ha = progress.score(x + dx, y + dy)
                    if filling and (s, a) in d.sums:
                        hu = fill.ahead(epoch, s, a)
                        if hu is not None:
                            ha += hu
                    v = q_row[a] - w * ha
            val.append(v)
            heads.append(ha)
        known = [ha for ha in heads if ha is not None]
        if filling and known:  # learning real-time search: raise h(s) to the best neighbour's + the fill
            fill.raise_at(s, min(known), here)
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
    paths: list | None = None,
) -> tuple[np.ndarray, list[int]]:
    """Run ``episodes`` episodes; returns (Q, steps per episode).

    ``macros`` (a ``learning.mapping.MacroTable``): at a state with a macro, when none is
    running, one draw u and the macro's target sequence runs when u < 1 - epsilon; its
    steps are ordinary steps; it is abandoned when a step is blocked (the robot did not move,
    observed after wind), and then the next
    action is epsilon-greedy without a macro draw.

    ``guide`` (a ``learning.guide.Guide``, method ``guided``): its model breaks the ties of
    epsilon-greedy (:class:`GuideModel`). ``trace``, when given, gets every state visited.
    ``paths``, when given, gets the greedy path after every episode (:func:`greedy_path`).
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
        if paths is not None:
            paths.append(greedy_path(robot, Q, start_state, goal_cell))
    return Q, steps_per_episode


def greedy_path(robot: DiscreteRobot, Q: np.ndarray, start_state: int, goal_cell: int) -> tuple[int, ...] | None:
    """The states of the greedy path from the start (argmax Q, the lowest index on ties, no
    wind) to the goal; None when it comes back to a state before reaching it."""
    seen: set[int] = set()
    s = start_state
    path = [s]
    while robot.label[s] != goal_cell:
        if s in seen:
            return None
        seen.add(s)
        s = int(robot.next_state[s, int(np.argmax(Q[s]))])
        path.append(s)
    return tuple(path)
