"""The exact farming check (learning/farming.py): value iteration over the shaped task."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.learning import farming, rewards, trajectory
from armtransfer.learning.config import LearnerConfig
from armtransfer.experiments.experiment import source_trajectory
from armtransfer.tasks.catalog import TABLE_I, custom_task
from armtransfer.tasks.grid_robots import grid_robot
from armtransfer.tasks.robot import DiscreteRobot

CFG = LearnerConfig()


@pytest.fixture(scope="module")
def robots():
    return {name: grid_robot(name) for name in ("coarse", "fine")}


def _wall_task(robots):
    """A coarse path straight up along the wall x = -3: its last state (-2, 8) is next to
    the wall, two fine steps from the goal (-2, 10)."""
    s, g = custom_task((-2, 0), (-2, 10)).cells()
    traj = trajectory.shortest(robots["coarse"], s, g)
    assert traj.xy()[-1] == (-2, 8)
    fine = robots["fine"]
    ss = fine.start_state(s)
    last = fine.start_state(traj.cells[-1])
    assert fine.next_state[last, 3] == last  # moving left bumps the wall
    return fine, ss, g, traj


def test_k_at_099_of_old_bound_next_to_a_wall_is_refused_naming_the_safe_bound(robots):
    fine, ss, g, traj = _wall_task(robots)
    old = rewards.farming_bound(CFG.step_reward, traj)
    k = 0.99 * old
    assert CFG.step_reward + traj.n * k < 0  # the old check would accept it
    with pytest.raises(InvalidParameterError) as err:
        farming.check_k("pseudo", fine, ss, g, traj, k, CFG)
    msg = str(err.value)
    assert "\n" not in msg and "largest safe K" in msg
    # analytically: bumping the wall forever at s_tn is worth (nK - 1)/(1 - gamma); walking
    # on is worth -1 - gamma (two steps, the middle cell pays nothing). Farmable iff
    # nK - 1 >= -(1 + gamma)(1 - gamma).
    gamma = CFG.gamma
    exact = (1 - (1 + gamma) * (1 - gamma)) / traj.n
    safe = farming.largest_safe_k(fine, ss, g, traj, CFG)
    assert safe.monotone
    assert exact * (1 - 2e-3) <= safe.k < exact
    assert f"{safe.k:.6g}" in msg
    # just below the exact threshold it is accepted, and returned unchanged
    assert farming.check_k("pseudo", fine, ss, g, traj, 0.97 * old, CFG) == pytest.approx(0.97 * old)
    assert farming.is_farmable(fine, ss, g, traj, exact * 1.001, CFG)
    assert not farming.is_farmable(fine, ss, g, traj, exact * 0.999, CFG)


def test_other_methods_are_never_refused(robots):
    fine, ss, g, traj = _wall_task(robots)
    k = 0.99 * rewards.farming_bound(CFG.step_reward, traj)
    for method in ("first-visit", "progress", "potential", "dense"):
        assert farming.check_k(method, fine, ss, g, traj, k, CFG) == pytest.approx(k)


def test_old_bound_still_refused_and_auto_is_safe_on_the_wall_task(robots):
    fine, ss, g, traj = _wall_task(robots)
    old = rewards.farming_bound(CFG.step_reward, traj)
    with pytest.raises(InvalidParameterError):
        farming.check_k("mapping", fine, ss, g, traj, old, CFG)
    k = farming.check_k("pseudo", fine, ss, g, traj, "auto", CFG)
    assert 0 < k <= 0.5 * old
    assert not farming.is_farmable(fine, ss, g, traj, k, CFG)


def test_wind_is_part_of_the_check(robots):
    """The wind pushes +x, away from the wall at x = -3 that makes the wall task farmable:
    a robot at s_tn cannot stay there, so under wind the farming disappears (largest safe
    K = the old bound), while without wind it is below it."""
    fine, ss, g, traj = _wall_task(robots)
    windy = farming.largest_safe_k(fine, ss, g, traj, CFG, wind=0.3)
    calm = farming.largest_safe_k(fine, ss, g, traj, CFG)
    assert calm.k < 0.99 * calm.old_bound
    assert windy.k == pytest.approx(windy.old_bound, rel=1e-9)
    k = 0.99 * calm.old_bound
    assert farming.is_farmable(fine, ss, g, traj, k, CFG)
    assert not farming.is_farmable(fine, ss, g, traj, k, CFG, wind=0.3)


@pytest.mark.parametrize("direction", [("coarse", "fine"), ("fine", "coarse")])
@pytest.mark.parametrize("kind", ["optimal", "learned"])
def test_auto_k_is_accepted_on_every_table_i_task(robots, direction, kind):
    src, tgt = robots[direction[0]], robots[direction[1]]
    for number, task in TABLE_I.items():
        s, g = task.cells()
        traj = source_trajectory(kind, src, s, g, CFG, seed=number)
        ss = tgt.start_state(s)
        k = farming.check_k("pseudo", tgt, ss, g, traj, "auto", CFG)
        assert 0 < k <= 0.5 * rewards.farming_bound(CFG.step_reward, traj)
        assert not farming.is_farmable(tgt, ss, g, traj, k, CFG)
        # and check_k accepts the K it chose when given explicitly
        assert farming.check_k("mapping", tgt, ss, g, traj, k, CFG) == k


def _corridor(n: int = 5) -> DiscreteRobot:
    """States 0..n-1 in a row; actions: 0 right, 1 left, 2 stay. Walls at both ends."""
    nxt = np.array([[min(s + 1, n - 1), max(s - 1, 0), s] for s in range(n)], np.int32)
    return DiscreteRobot("corridor", nxt, np.arange(n, dtype=np.int32), np.arange(n, dtype=np.int32),
                         ("R", "L", "S"))


def _rollout_return(robot, policy, start, goal, bonus, gamma, step_reward, horizon=4000):
    """Discounted return of a deterministic policy from start, and whether it reaches goal."""
    s, ret, disc = start, 0.0, 1.0
    for _ in range(horizon):
        s = int(robot.next_state[s, policy[s]])
        ret += disc * (step_reward + bonus[s])
        if robot.label[s] == goal:
            return ret, True
        disc *= gamma
    return ret, False


@pytest.mark.parametrize("k", [0.05, 0.15, 0.24, 0.3])
def test_value_iteration_agrees_with_brute_force_over_all_policies(k):
    """On a 5-state corridor (start 0, goal 4, trajectory cells 1..3 paying i*K), the best
    of all 3^5 deterministic policies, by rollout, has VI's value at the start, and VI calls
    K farmable exactly when that best policy does not reach the goal."""
    robot = _corridor()
    gamma, step = 0.9, -1.0
    bonus = np.array([0.0, 1 * k, 2 * k, 3 * k, 0.0]) * 2.5
    Q, V, _ = farming.shaped_q(robot, 4, bonus, step, 0.0, gamma)
    best, best_reaches = -np.inf, None
    for policy in itertools.product(range(3), repeat=5):
        ret, reaches = _rollout_return(robot, policy, 0, 4, bonus, gamma, step)
        if ret > best + 1e-9:
            best, best_reaches = ret, reaches
    assert V[0] == pytest.approx(best, abs=1e-6)
    trap = farming.trap_states(robot, 0, 4, Q)
    assert (len(trap) > 0) == (not best_reaches)


def test_both_outcomes_occur_in_the_brute_force_cases():
    """The corridor cases above include a farmable and a safe K (else the test is vacuous)."""
    robot = _corridor()
    outcomes = set()
    for k in (0.05, 0.15, 0.24, 0.3):
        bonus = np.array([0.0, 1 * k, 2 * k, 3 * k, 0.0]) * 2.5
        Q, _, _ = farming.shaped_q(robot, 4, bonus, -1.0, 0.0, 0.9)
        outcomes.add(len(farming.trap_states(robot, 0, 4, Q)) > 0)
    assert outcomes == {True, False}
