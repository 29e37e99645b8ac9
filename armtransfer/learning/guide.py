"""Method ``guided``: robot 2 learns, while it explores, what its own actions do to its label,
and uses that to move towards the next cells of the transferred trajectory.

Why: with Q = 0 at the start and a step reward of -1, every untried action ties at the top of
Q, so at a new state Algorithm 1 does not know which of its actions leads on along the
trajectory until it has tried them there. Even a perfect state potential (``oracle``) leaves
that choice to chance at every new state.

The model (all of it from what robot 2 observes):
  * After every move s --a--> s' it records the displacement of its label, xy(label[s']) -
    xy(label[s]), for the pair (s, a) (a running mean: with wind the push is part of what it
    sees), and remembers s among the last ``memory`` states at which it tried a.
  * The predicted displacement of a at s is the recorded mean when (s, a) was tried; else the
    mean over the ``knn`` states nearest to s, in robot 2's own configuration space, at which
    a was tried (for an arm its joint configuration ``arm.qpos``; for a grid robot its cell):
    the same action moves the tip by about the same cells in neighbouring configurations, and
    for a joint-space arm the effect changes smoothly with the configuration.
  * The tip model, for a robot whose actions move a joint (``joint`` action model; ``tip``): one
    move shifts the tip by a fraction of a cell, so the label rarely changes and a move tried
    at a state mostly records "no effect". Robot 2 therefore also learns *where its tip is* as a
    smooth function of its own joint configuration q: ridge least squares of the label's xy on
    products of cos and sin of up to ``TIP_ORDER`` of its moving joints (exact for any planar
    chain of up to 3 joints; learned one recursive step per newly visited state, in the
    exploration phase). A move not yet tried at s is predicted as tip(q_s + the mean joint
    displacement robot 2 observed for that action) - tip(q_s): a sub-cell displacement; it is
    predicted blocked (no displacement) when it was blocked at each of the ``TIP_NEAREST``
    remembered states nearest to s where it was tried (a joint limit, a wall). With
    ``TIP_ANCHOR`` the score starts from the model's estimate of the tip inside the current cell
    (clamped to the cell) instead of the cell's centre. A move tried at s keeps its own
    observed displacement, as above.
  * The fill (with the tip model; ``FILL``), learning real-time search (Korf's LRTA*) on the
    score: a joint-space robot has many states per cell, so where the trajectory's next cells
    cannot be reached straight on (the arm must first move away from them) the score has wide
    local minima. Robot 2 keeps, per state and only until a trajectory's progress next moves,
    an increment h(s) in cells: a move's score is its predicted score plus h of the state that
    move led to when tried at s; choosing at s raises h(s) to (the smallest of its moves'
    scores) + the fill - (the score at s), so a basin fills as it is visited, a fill per visit at
    most, instead of one SARSA(lambda) update at a time.
  * Progress along a trajectory: the furthest index whose cell the label came within
    ``reach`` cells of in this episode; after ``give_up`` moves without progress the next
    cell is given up on (it may be out of reach), and after ``give_up`` moves at the last one,
    s_tg, without the episode ending, the trajectory is (its goal is not this task's: a control
    trajectory, or a wrong one), and once every trajectory is, Algorithm 1 chooses alone. The score of a predicted label position q is
    min over the trajectory cells c_j ahead of that index, within ``window`` cells of
    trajectory length, of |q - c_j| + (the trajectory's length from c_j to its end); lower is
    better. With several trajectories the smallest score counts.

Planning, after every episode (``plan``): robot 2 also counts, for every pair (s, a) it has
tried, the states s' it observed after it (with wind, how often each), and runs value iteration
over those pairs on those counts: Q(s, a) = sum over s' of P(s' | s, a) (r + gamma max Q(s', .)).
A pair never tried gets Q = UNTRIED, just above 0, an optimistic bound (every return is <= 0)
that wins ties, so the planned
greedy policy leads to the untried pairs that could still shorten the way, and once the greedy
path reaches the goal no untried pair could make it shorter: the path is a shortest one (in
expectation, with wind). Why: SARSA(lambda) evaluates the wandering policy that tried a pair,
so pairs tried in long early episodes keep values far below their optimal ones and the greedy
path never comes back to them; on planar2:joint it converged to paths 9-21% longer than the
shortest (Table I tasks, 20 trials). Planning uses robot 2's own observed moves only.

How it chooses, in the exploration phase only (the first ``episodes`` episodes; 1: until the
goal is first reached): epsilon-greedy over Q(s, a) - weight * score(predicted label of a).
An action never tried anywhere counts as the best, one tried at s and blocked every time as
the worst. A wrong prediction (a wall, a joint limit, a cell it cannot reach) costs a step:
the pair is then tried, its Q falls and its own observed effect replaces the prediction, so
the learner's own exploration takes over there. After the exploration phase Algorithm 1's
epsilon-greedy chooses alone on Q: SARSA(lambda)'s updates during an episode, the plan after it;
the displacement model never biases the greedy path. The model never reads the robot's transition
table nor the map; the kernel reads ``next_state`` only to take the move chosen (a test
changes every transition not tried in a run of several episodes and gets the same run,
bit for bit; the convergence check after each episode, the experimenter's, follows the
greedy path through the table as for every method)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numba
import numpy as np

from armtransfer.errors import InvalidParameterError
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.learning.trajectory import Trajectory

WINDOW = 2.0
"""Cells of trajectory length ahead of the progress index that the score looks at."""
REACH = 1.0
"""A trajectory cell counts as reached when the label comes within this many cells."""
KNN = 8
"""Neighbours in configuration space a prediction for an untried pair averages."""
MEMORY = 256
"""States per action remembered for the neighbour search (the most recent)."""
WEIGHT = 2.0
"""Preference per cell of predicted progress, in units of Q (one step costs -1; after one try
a pair's Q is about -alpha)."""
BLOCKED = True
"""Whether a blocked move (the robot did not move) is generalised to neighbouring states like any
other observed effect (True), or kept to its own state (False)."""
GIVE_UP = 100
"""Moves without progress after which the next trajectory cell is given up on (0: never).
On the held-out pairs 25 and 50 give up too early (worst pair 18.9x and 4.6x the optimal
distance), 100 and 200 change nothing (1.79x, 1.80x, against 1.80x never); 100 is chosen as
the smallest harmless value. It matters where a trajectory cell is out of robot 2's reach:
coarse -> a bring-your-own SCARA (tests/conftest.py, cartesian, Table I task 4's optimal
trajectory, 6 of its 38 cells unreachable) needs about 3,700x without it and about 260x
with it, 5 trials. The same count at the last cell, s_tg, gives up on the whole trajectory:
before that rule a trajectory whose goal was not the task's (a random walk, ending where it
ended) held robot 2 at its end, and guided ran 2 of 2 trials on coarse -> fine task 4 to the
20,000,000-step cap."""
EPISODES = 1
"""The model chooses in this many first episodes (1: until the goal is first reached, the
exploration phase); afterwards Algorithm 1's epsilon-greedy chooses alone.

WEIGHT, WINDOW, REACH, KNN and BLOCKED were chosen together on held-out start/goal pairs for
coarse <-> fine and planar2:joint <-> ur5e_like:cartesian (``research/select_defaults.py
--method guided``: the smallest mean first exposure of the worst robot pair, 1.96x the optimal
distance), never on Table I; EPISODES is the exploration phase, as for the mapping's macros;
MEMORY was not tuned.

TIP_ANCHOR, TIP_RIDGE and TIP_NEAREST were chosen after them (``research/select_defaults.py
--method guided-tip``) on the held-out start/goal pairs of ur5e_like:cartesian ->
planar2:joint, the robot pair of that grid whose target moves its joints, and on 8 more held-out
pairs of it whose trajectory has cells the arm cannot reach (at most a quarter of them):
the smallest worse of the two means, 1.70x the optimal distance on both (without the tip model
1.79x and 3.23x; 1.79x and 5.76x since the give-up at a trajectory's last cell); never on Table I. TIP_ORDER was not tuned. FILL_COST was chosen after them on
the same two sets (``--method guided-fill``): 1.65x (1.70x without the fill)."""
PLAN = True
"""Whether robot 2 plans over the moves it has tried, after every episode (see :func:`plan`)."""
PLAN_TOL = 1e-12
"""A state's planned value that changes by at most this does not re-plan its predecessors.
Without wind the values converge exactly (a change is never this small); with wind they
converge geometrically. A numerical guard, not a tuned parameter: with 0 here one planning
in 3 windy trials (wind 0.05) of ur5e_like:cartesian -> planar2:joint, Table I task 1, ran
into PLAN_CAP, with 1e-12 none did; on 3 held-out pairs x 3 windy trials of that robot pair
and of coarse -> fine neither ran into it (all 36 trials converged)."""
PLAN_CAP = 1000
"""Backups per planning at most, in units of robot 2's number of states (a guard: with gamma = 1
a state whose every tried move loops has no finite value)."""
UNTRIED = 1e-9
"""The Q a plan gives every pair not yet tried: just above 0, the bound on every return, so that
where a route through an untried pair ties with a tried one (the untried pair counts as ending
the way at no cost) the untried one is preferred, by the greedy path and by epsilon-greedy
alike, and gets tried. With 0 the lowest-index greedy path could keep such a pair while the
episodes' uniform tie-breaking seldom took it: on the held-out pairs of ur5e_like:cartesian ->
planar2:joint one trial in 40 never converged and one converged 1 step long (47 for 48). Far
below any real difference: routes of L and L + 1 steps differ by gamma^L (0.0067 at L = 500)."""
SUCCESSORS = 4
"""Distinct observed successors kept per pair (a move and its wind push are at most 2)."""
TIP = None
"""Whether robot 2 also learns where its tip is from its joint configuration (the tip model,
see the module docstring): None chooses it for robots whose actions move a joint (the ``joint``
action model), where one move shifts the tip by a fraction of a cell."""
TIP_ANCHOR = True
"""Whether the score starts from the tip model's estimate of where the tip is inside the current
cell (clamped to the cell) instead of the cell's centre."""
FILL = None
"""The fill's cost per move, in cells (see the module docstring); None: ``FILL_COST`` with the tip
model, 0 (off) without it."""
FILL_COST = 0.25
"""Chosen on the held-out pairs of the tip model (``research/select_defaults.py --method
guided-fill``) from 0 (off), 0.1, 0.25, 0.5, 1 and 2, never on Table I."""
TIP_ORDER = 3
"""The tip model's features are products of cos and sin of at most this many of the moving
joints (3: exact for the tip of any planar chain of up to 3 joints and any 2-joint arm)."""
TIP_RIDGE = 1e-3
"""Ridge penalty of the tip model's least squares (the prior: the tip stays where it started)."""
TIP_NEAREST = 8
"""A move not yet tried at a state is predicted blocked when it was blocked at each of this many
states nearest in configuration space where it was tried (a joint limit, a wall)."""


@dataclass(frozen=True, eq=False)
class Guide:
    """The arrays the kernel's tie-breaking model reads (see the module docstring)."""

    feat: np.ndarray  # float64 [S, D]: robot 2's own configuration of each of its states
    lxy: np.ndarray  # float64 [S, 2]: the xy of the label robot 2 perceives at each state
    tx: np.ndarray  # float64 [T]: the trajectory cells' x (its goal last), trajectories one after another
    ty: np.ndarray  # float64 [T]
    trem: np.ndarray  # float64 [T]: trajectory length (cells) from this cell to its end
    tstart: np.ndarray  # int64 [n_traj + 1]: where each trajectory starts in tx/ty/trem
    params: np.ndarray  # float64 [15]: window, reach, knn, memory, weight, episodes, blocked (0/1), give_up,
    #                    plan (0/1), plan tolerance, tip model (0/1), tip ridge, tip nearest, tip anchor (0/1),
    #                    fill (cells per move; 0: off)
    tq: np.ndarray  # float64 [S, C]: the moving joints of each state (the tip model's input; [0, 1] without it)
    fj: np.ndarray  # int64 [F, TIP_ORDER]: the joints (columns of tq) each feature multiplies, -1 past its last
    fk: np.ndarray  # int64 [F, TIP_ORDER]: 0 for the cosine of that joint, 1 for its sine

    @property
    def memory(self) -> int:
        return int(self.params[3])

    @property
    def tip(self) -> bool:
        return bool(self.params[10] > 0.0)


def tip_features(n_joints: int, order: int = TIP_ORDER) -> tuple[np.ndarray, np.ndarray]:
    """(fj, fk) of the tip model: the constant 1, then for k = 1 .. order every set of k joints
    (in index order) times every choice of cos or sin for each of them. Any serial chain of
    revolute joints has a tip whose coordinates are sums of such products of all its joints; up to
    ``order`` joints at a time this is exact for up to ``order`` joints and a smooth basis beyond."""
    fj, fk = [[-1] * order], [[0] * order]
    for k in range(1, min(order, n_joints) + 1):
        for joints in itertools.combinations(range(n_joints), k):
            for kinds in itertools.product((0, 1), repeat=k):
                fj.append(list(joints) + [-1] * (order - k))
                fk.append(list(kinds) + [0] * (order - k))
    return np.array(fj, np.int64), np.array(fk, np.int64)


def uses_tip(robot: DiscreteRobot) -> bool:
    """Whether the tip model is on by default: robots whose actions move a joint."""
    return robot.arm is not None and robot.arm.joint_step is not None


def build(robot: DiscreteRobot, trajs: list[Trajectory], window: float = WINDOW, reach: float = REACH,
          knn: int = KNN, memory: int = MEMORY, weight: float = WEIGHT, episodes: int = EPISODES,
          blocked: bool = BLOCKED, give_up: int = GIVE_UP, plan: bool = PLAN, tip: bool | None = TIP,
          tip_ridge: float = TIP_RIDGE, tip_nearest: int = TIP_NEAREST, tip_anchor: bool = TIP_ANCHOR,
          fill: float | None = FILL) -> Guide:
    """The guide for ``robot`` following ``trajs`` (one or several). ``tip`` None: the tip
    model for robots whose actions move a joint (:func:`uses_tip`)."""
    for name, v in (("window", window), ("reach", reach), ("weight", weight)):
        if not (np.isfinite(v) and v >= 0):
            raise InvalidParameterError(f"{name} must be a non-negative number, got {v}")
    if not (np.isfinite(give_up) and give_up >= 0):
        raise InvalidParameterError(f"give_up must be a non-negative number of moves, got {give_up}")
    if int(knn) < 1 or int(memory) < 1 or int(episodes) < 1:
        raise InvalidParameterError(f"knn, memory and episodes must be positive integers, got {knn}, {memory}, {episodes}")
    if not (np.isfinite(tip_ridge) and tip_ridge > 0):
        raise InvalidParameterError(f"tip_ridge must be a positive number, got {tip_ridge}")
    if int(tip_nearest) < 1:
        raise InvalidParameterError(f"tip_nearest must be a positive integer, got {tip_nearest}")
    if fill is not None and not (np.isfinite(fill) and fill >= 0):
        raise InvalidParameterError(f"fill must be a non-negative number of cells, got {fill}")
    layout = robot.layout
    lxy = layout.xy_of(robot.label).astype(np.float64).reshape(-1, 2)
    if robot.arm is not None:
        feat = np.asarray(robot.arm.qpos, dtype=np.float64).reshape(robot.n_states, -1)
    else:
        feat = lxy.copy()
    xs, ys, rem, starts = [], [], [], [0]
    for t in trajs:
        cells = [*t.cells, t.goal]  # s_t0 .. s_tn and the goal s_tg
        c = np.array([layout.xy(int(cell)) for cell in cells], dtype=np.float64).reshape(-1, 2)
        seg = np.sqrt(((c[1:] - c[:-1]) ** 2).sum(axis=1))
        r = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]]) if len(seg) else np.zeros(1)
        xs.append(c[:, 0])
        ys.append(c[:, 1])
        rem.append(r)
        starts.append(starts[-1] + len(c))
    tip = uses_tip(robot) if tip is None else bool(tip)
    if tip:  # the joints that move (a held finger is constant over the states)
        tq = feat[:, np.ptp(feat, axis=0) > 0] if len(feat) else feat
        fj, fk = tip_features(tq.shape[1])
    else:
        tq, fj, fk = np.zeros((0, 1)), np.zeros((0, TIP_ORDER), np.int64), np.zeros((0, TIP_ORDER), np.int64)
    return Guide(
        feat=np.ascontiguousarray(feat), lxy=np.ascontiguousarray(lxy),
        tx=np.concatenate(xs), ty=np.concatenate(ys), trem=np.concatenate(rem),
        tstart=np.array(starts, np.int64),
        params=np.array([float(window), float(reach), float(int(knn)), float(int(memory)), float(weight),
                         float(int(episodes)), 1.0 if blocked else 0.0, float(int(give_up)),
                         1.0 if plan else 0.0, PLAN_TOL, 1.0 if tip else 0.0, float(tip_ridge),
                         float(int(tip_nearest)), 1.0 if tip_anchor else 0.0,
                         (FILL_COST if tip else 0.0) if fill is None else float(fill)]),
        tq=np.ascontiguousarray(tq, dtype=np.float64), fj=fj, fk=fk,
    )


def inactive(n_actions: int) -> tuple:
    """(guide tuple, model tuple) for a trial without a guide: empty arrays of the right types."""
    g = (np.zeros((0, 1)), np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.zeros(0),
         np.zeros(1, np.int64), np.array([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0]),
         np.zeros((0, 1)), np.zeros((0, TIP_ORDER), np.int64), np.zeros((0, TIP_ORDER), np.int64))
    return g, model_arrays(0, n_actions, 1, 1)


def as_tuple(g: Guide) -> tuple:
    return (g.feat, g.lxy, g.tx, g.ty, g.trem, g.tstart, g.params, g.tq, g.fj, g.fk)


def model_arrays(n_states: int, n_actions: int, memory: int, n_traj: int, n_features: int = 0,
                 n_joints: int = 0, fill: bool = False) -> tuple:
    """What the model learns during a trial: (displacement sums [S, A, 2], counts [S, A],
    remembered states [A, memory], pushes per action [A], progress index per trajectory,
    generalised [S, A], moved [S, A], moves without progress per trajectory), then what
    :func:`plan` reads: the observed successors of each pair s * A + a (states [S*A, M], counts
    [S*A, M], how many [S*A]), the observed predecessors of each state as a linked list in the
    order first seen (head [S], tail [S], next [S*A*M], pair [S*A*M], edges used [1]), and
    planning scratch (values [S], queue [S], queued [S], has a tried pair [S]) and its counts
    (plannings, most backups in one, plannings that hit the cap); then the tip model's (empty
    without it): P [F, F] (the inverse of the ridge normal matrix), W [F, 2] (its weights), the
    first label seen [2] and whether it was [1], states already learned from [S], summed joint
    displacement per action [A, C] and moves summed [A], and scratch (features [F] twice, P times
    features [F], a configuration [C]); then the fill's (empty without it, but for the epoch): h
    [S], the epoch each h was set in [S], the epoch [1] (+1 at an episode's start and whenever a
    trajectory's progress moves), and the state last observed after each pair [S, A] (-1: none)."""
    n_fill = n_states if fill else 0
    pairs = n_states * n_actions
    return (np.zeros((n_states, n_actions, 2)), np.zeros((n_states, n_actions), np.int64),
            np.zeros((n_actions, memory), np.int64), np.zeros(n_actions, np.int64),
            np.zeros(max(n_traj, 1), np.int64), np.zeros((n_states, n_actions), np.bool_),
            np.zeros((n_states, n_actions), np.bool_), np.zeros(max(n_traj, 1), np.int64),
            np.zeros((pairs, SUCCESSORS), np.int64), np.zeros((pairs, SUCCESSORS), np.int64),
            np.zeros(pairs, np.int64), np.full(n_states, -1, np.int64), np.full(n_states, -1, np.int64),
            np.full(pairs * SUCCESSORS, -1, np.int64), np.zeros(pairs * SUCCESSORS, np.int64),
            np.zeros(1, np.int64), np.zeros(n_states), np.zeros(n_states, np.int64),
            np.zeros(n_states, np.bool_), np.zeros(n_states, np.bool_), np.zeros(3, np.int64),
            np.eye(n_features), np.zeros((n_features, 2)), np.zeros(2), np.zeros(1, np.bool_),
            np.zeros(n_states if n_features else 0, np.bool_), np.zeros((n_actions, n_joints)),
            np.zeros(n_actions, np.int64), np.zeros(n_features), np.zeros(n_features), np.zeros(n_features),
            np.zeros(n_joints),
            np.zeros(n_fill), np.full(n_fill, -1, np.int64), np.zeros(1, np.int64),
            np.full((n_fill, n_actions), -1, np.int64))


def model_arrays_for(g: Guide, n_states: int, n_actions: int) -> tuple:
    """:func:`model_arrays` sized for guide ``g`` (P starts as the identity over the ridge)."""
    f = g.fj.shape[0]
    gm = model_arrays(n_states, n_actions, g.memory, len(g.tstart) - 1, f, g.tq.shape[1] if f else 0,
                      fill=g.params[14] > 0.0)
    gm[21][...] /= g.params[11] if f else 1.0
    return gm


@numba.njit(cache=True)
def reset_progress(g, gm, s, guided):
    """At an episode's start: progress at each trajectory's first cell, then what s reaches;
    in the exploration phase (``guided``) the tip model learns from s."""
    tstart = g[5]
    prog, wait = gm[4], gm[7]
    for t in range(tstart.shape[0] - 1):
        prog[t] = tstart[t]
        wait[t] = 0
    gm[34][0] += 1
    if guided and g[6][10] > 0.0:
        tip_learn(g, gm, s)
    update_progress(g, gm, s)


@numba.njit(cache=True)
def features(g, q, out):
    """The tip model's features of joint configuration q (``tip_features``) into out."""
    fj, fk = g[8], g[9]
    for i in range(fj.shape[0]):
        v = 1.0
        for k in range(fj.shape[1]):
            j = fj[i, k]
            if j < 0:
                break
            if fk[i, k] == 0:
                v *= np.cos(q[j])
            else:
                v *= np.sin(q[j])
        out[i] = v


@numba.njit(cache=True)
def tip_learn(g, gm, s):
    """The tip model learns from state s, once per state: one recursive least-squares step
    (Sherman-Morrison) towards label xy(s) - (the first label it learned from), on the
    features of s's moving joints. P stays the inverse of (ridge I + sum of f f^T)."""
    lxy, tq = g[1], g[7]
    P, W, y0, has0, seen, f, px = gm[21], gm[22], gm[23], gm[24], gm[25], gm[28], gm[30]
    if seen[s]:
        return
    seen[s] = True
    if not has0[0]:
        y0[0] = lxy[s, 0]
        y0[1] = lxy[s, 1]
        has0[0] = True
    features(g, tq[s], f)
    n = f.shape[0]
    denom = 1.0
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += P[i, j] * f[j]
        px[i] = acc
    for i in range(n):
        denom += f[i] * px[i]
    for c in range(2):
        fit = 0.0
        for i in range(n):
            fit += f[i] * W[i, c]
        err = (lxy[s, c] - y0[c]) - fit
        for i in range(n):
            W[i, c] += px[i] / denom * err
    for i in range(n):
        k = px[i] / denom
        for j in range(n):
            P[i, j] -= k * px[j]


@numba.njit(cache=True)
def tip_at(g, gm, f):
    """(x, y) the tip model predicts (relative to the first label) for features f."""
    W = gm[22]
    x = 0.0
    y = 0.0
    for i in range(f.shape[0]):
        x += f[i] * W[i, 0]
        y += f[i] * W[i, 1]
    return x, y


@numba.njit(cache=True)
def update_progress(g, gm, s):
    """Advance each trajectory's progress index to the furthest cell within reach of s's
    label, looking up to ``window + reach`` cells of trajectory length ahead. After
    ``give_up`` moves without progress on a trajectory its next cell is given up on (robot 2
    may be unable to reach it: a wall, a joint limit, a cell out of its reach); after
    ``give_up`` moves at its last cell, s_tg, the trajectory itself is (its goal is not the
    task's, or out of reach): its progress goes one past its cells, and once every trajectory
    is given up on, :func:`egreedy` is Algorithm 1's own."""
    lxy, tx, ty, trem, tstart, params = g[1], g[2], g[3], g[4], g[5], g[6]
    prog, wait = gm[4], gm[7]
    reach = params[1]
    horizon = params[0] + reach
    give_up = params[7]
    x = lxy[s, 0]
    y = lxy[s, 1]
    for t in range(tstart.shape[0] - 1):
        i0 = prog[t]
        if i0 >= tstart[t + 1]:
            continue  # given up on
        for j in range(i0 + 1, tstart[t + 1]):
            if trem[i0] - trem[j] > horizon:
                break
            dx = tx[j] - x
            dy = ty[j] - y
            if np.sqrt(dx * dx + dy * dy) <= reach:
                prog[t] = j
        if prog[t] != i0:
            wait[t] = 0
            gm[34][0] += 1
        else:
            wait[t] += 1
            if give_up > 0.0 and wait[t] >= give_up:
                prog[t] += 1
                wait[t] = 0
                gm[34][0] += 1


@numba.njit(cache=True)
def exhausted(g, gm):
    """Every trajectory given up on (:func:`update_progress`): the model has nothing to say."""
    tstart, prog = g[5], gm[4]
    for t in range(tstart.shape[0] - 1):
        if prog[t] < tstart[t + 1]:
            return False
    return True


@numba.njit(cache=True)
def observe(g, gm, s, a, s2, guided):
    """Record the move s --a--> s2 (s2: the state whose label robot 2 perceives after it); in
    the exploration phase (``guided``) the tip model learns the move's joint displacement and
    where s2 is."""
    lxy, params = g[1], g[6]
    dsum, dcnt, buf, bufn, inbuf, moved = gm[0], gm[1], gm[2], gm[3], gm[5], gm[6]
    if s2 != s:
        moved[s, a] = True
    if params[14] > 0.0:
        gm[35][s, a] = s2
    if guided and params[10] > 0.0:
        tq, dq, dqn = g[7], gm[26], gm[27]
        if s2 != s:
            for c in range(tq.shape[1]):
                dq[a, c] += tq[s2, c] - tq[s, c]
            dqn[a] += 1
        tip_learn(g, gm, s2)
    dsum[s, a, 0] += lxy[s2, 0] - lxy[s, 0]
    dsum[s, a, 1] += lxy[s2, 1] - lxy[s, 1]
    dcnt[s, a] += 1
    if (s2 != s or params[6] > 0.0) and not inbuf[s, a]:  # generalise a blocked move only if asked
        inbuf[s, a] = True
        memory = int(params[3])
        buf[a, bufn[a] % memory] = s
        bufn[a] += 1
    if params[8] > 0.0:
        record_successor(gm, s * dcnt.shape[1] + a, s, s2)


@numba.njit(cache=True)
def record_successor(gm, sa, s, s2):
    """Count s2 as an observed successor of the pair sa (at state s); a new one makes sa a
    predecessor of s2."""
    succ, scnt, nsucc = gm[8], gm[9], gm[10]
    head, tail, enext, epair, nedge, has_pair = gm[11], gm[12], gm[13], gm[14], gm[15], gm[19]
    has_pair[s] = True
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
    e = nedge[0]
    nedge[0] = e + 1
    epair[e] = sa
    if tail[s2] < 0:
        head[s2] = e
    else:
        enext[tail[s2]] = e
    tail[s2] = e


@numba.njit(cache=True)
def plan(g, gm, Q, label, goal, gamma, r_step, r_goal):
    """Value iteration over the pairs robot 2 has tried, on what it observed of them, after an
    episode: Q(s, a) = sum over the observed successors s' of (count / tries) * (r + gamma V(s')),
    r = r_step (+ r_goal when s' is labelled the goal, where V = 0), V(s') = max over a' of
    Q(s', a'). A pair never tried gets Q = UNTRIED, just above 0 (all returns are <= 0, so it is
    an optimistic bound, and the plan leads to it). Returns the number of backups.

    Order: every state with a tried pair, in index order, is queued; a state taken from the
    front of the queue gets its tried pairs (in action order) backed up from the planned values
    V of their successors; when its own V changes by more than the tolerance, V is set and every
    predecessor not already queued is queued, in the order first observed. V starts as max Q.
    The transitions read are those observed (never the robot's table)."""
    params = g[6]
    tol = params[9]
    succ, scnt, nsucc = gm[8], gm[9], gm[10]
    head, enext, epair = gm[11], gm[13], gm[14]
    vp, queue, inq, has_pair = gm[16], gm[17], gm[18], gm[19]
    n_states, n_actions = Q.shape
    for x in range(n_states):
        for a in range(n_actions):
            if nsucc[x * n_actions + a] == 0:
                Q[x, a] = UNTRIED
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
    stats = gm[20]
    stats[0] += 1
    stats[1] = max(stats[1], backups)
    if qn > 0:
        stats[2] += 1
    while qn > 0:  # the cap was hit: leave the queue empty for the next planning
        inq[queue[qh]] = False
        qh = (qh + 1) % n_states
        qn -= 1
    return backups


@numba.njit(cache=True)
def predict(g, gm, s, a):
    """(known, dx, dy): the predicted label displacement of a at s; known is False when a
    was never tried anywhere."""
    dsum, dcnt = gm[0], gm[1]
    if dcnt[s, a] > 0:
        return True, dsum[s, a, 0] / dcnt[s, a], dsum[s, a, 1] / dcnt[s, a]
    near = nearest(g, gm, s, a, int(g[6][2]))
    k = near.shape[0]
    if k == 0:
        return False, 0.0, 0.0
    sx = 0.0
    sy = 0.0
    for u in near:
        sx += dsum[u, a, 0] / dcnt[u, a]
        sy += dsum[u, a, 1] / dcnt[u, a]
    return True, sx / k, sy / k


@numba.njit(cache=True)
def nearest(g, gm, s, a, k):
    """The (at most) k remembered states where a was tried that are nearest to s in robot 2's
    configuration space, nearest first (ties: the earlier ring-buffer slot)."""
    feat, params = g[0], g[6]
    buf, bufn = gm[2], gm[3]
    n = min(bufn[a], int(params[3]))
    k = min(k, n)
    dist = np.empty(n)
    for i in range(n):
        u = buf[a, i]
        d = 0.0
        for c in range(feat.shape[1]):
            diff = feat[u, c] - feat[s, c]
            d += diff * diff
        dist[i] = d
    taken = np.zeros(n, np.bool_)
    out = np.empty(k, np.int64)
    for j in range(k):
        best = -1
        for i in range(n):
            if not taken[i] and (best < 0 or dist[i] < dist[best]):
                best = i
        taken[best] = True
        out[j] = buf[a, best]
    return out


@numba.njit(cache=True)
def near_blocked(g, gm, s, a):
    """Whether a was blocked at each of the ``tip nearest`` remembered states nearest to s in
    configuration space where it was tried (ties: the earlier slot), i.e. a joint limit or a
    wall is predicted; False when a was tried nowhere."""
    near = nearest(g, gm, s, a, int(g[6][12]))
    if near.shape[0] == 0:
        return False
    moved = gm[6]
    for u in near:
        if moved[u, a]:
            return False
    return True


@numba.njit(cache=True)
def tip_move(g, gm, s, a, x0, y0):
    """(dx, dy): the tip model's displacement for a at s: the tip at s's joints plus a's mean
    observed joint displacement, minus (x0, y0), the tip at s; (0, 0) when a never moved."""
    tq, dq, dqn, f, q = g[7], gm[26], gm[27], gm[29], gm[31]
    if dqn[a] == 0:
        return 0.0, 0.0
    for c in range(tq.shape[1]):
        q[c] = tq[s, c] + dq[a, c] / dqn[a]
    features(g, q, f)
    x1, y1 = tip_at(g, gm, f)
    return x1 - x0, y1 - y0


@numba.njit(cache=True)
def score(g, gm, x, y):
    """How far (cells) a label at (x, y) is from the goal along the trajectories ahead."""
    tx, ty, trem, tstart, params = g[2], g[3], g[4], g[5], g[6]
    prog = gm[4]
    window = params[0]
    best = np.inf
    for t in range(tstart.shape[0] - 1):
        i0 = prog[t]
        for j in range(i0, tstart[t + 1]):
            if trem[i0] - trem[j] > window:
                break
            dx = tx[j] - x
            dy = ty[j] - y
            v = np.sqrt(dx * dx + dy * dy) + trem[j]
            if v < best:
                best = v
    return best


@numba.njit(cache=True)
def egreedy(Q, s, eps, rng, g, gm):
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
    lxy, params = g[1], g[6]
    w = params[4]
    x = lxy[s, 0]
    y = lxy[s, 1]
    val = np.empty(n_actions)
    best = -np.inf
    dcnt, moved, bufn = gm[1], gm[6], gm[3]
    tip = params[10] > 0.0
    x0 = 0.0
    y0 = 0.0
    if tip:
        features(g, g[7][s], gm[28])
        x0, y0 = tip_at(g, gm, gm[28])
        if params[13] > 0.0:
            first = gm[23]
            x = min(max(first[0] + x0, lxy[s, 0] - 0.5), lxy[s, 0] + 0.5)
            y = min(max(first[1] + y0, lxy[s, 1] - 0.5), lxy[s, 1] + 0.5)
    fill = params[14]
    h, hst, epoch, last = gm[32], gm[33], gm[34], gm[35]
    here = 0.0  # the score where the tip is now (what a move predicted blocked keeps)
    if tip or fill > 0.0:
        here = score(g, gm, x, y)
    if fill > 0.0 and hst[s] != epoch[0]:
        hst[s] = epoch[0]
        h[s] = 0.0
    low = np.inf
    for a in range(n_actions):
        ha = np.nan
        if dcnt[s, a] > 0 and not moved[s, a]:
            v = -np.inf  # tried here and blocked every time: a wasted step, never the model's choice
        elif tip and dcnt[s, a] == 0:  # the tip model predicts a pair not tried here
            if bufn[a] == 0:
                v = np.inf  # tried nowhere yet
            elif near_blocked(g, gm, s, a):
                ha = here + h[s] if fill > 0.0 else here
                v = Q[s, a] - w * ha
            else:
                dx, dy = tip_move(g, gm, s, a, x0, y0)
                ha = score(g, gm, x + dx, y + dy)
                v = Q[s, a] - w * ha
        else:
            known, dx, dy = predict(g, gm, s, a)
            if known:
                ha = score(g, gm, x + dx, y + dy)
                if fill > 0.0 and dcnt[s, a] > 0:
                    u = last[s, a]
                    if hst[u] == epoch[0]:
                        ha += h[u]
                v = Q[s, a] - w * ha
            else:
                v = np.inf
        if fill > 0.0 and not np.isnan(ha) and ha < low:
            low = ha
        val[a] = v
        if v > best:
            best = v
    if fill > 0.0 and low < np.inf:  # learning real-time search: the basin fills as it is visited
        raise_to = low + fill - here
        if raise_to > h[s]:
            h[s] = raise_to
    m = 0
    first = -1
    for a in range(n_actions):
        if val[a] == best:
            if first < 0:
                first = a
            m += 1
    if m == 1:
        return first
    k = int(rng.random() * m)
    for a in range(n_actions):
        if val[a] == best:
            if k == 0:
                return a
            k -= 1
    return n_actions - 1  # unreachable
