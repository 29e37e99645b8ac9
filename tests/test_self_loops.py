"""No move that leaves the state unchanged can pay: the bounded potential of the potential-based
methods, and the farming check of every method against a learner's self-loops."""

import numpy as np
import pytest

from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.learning import farming, methods, potentials, sarsa
from armtransfer.learning import trajectory as trajectories
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.methods import Method
from armtransfer.learning.shaping import MODE_PSEUDO, Shaping
from armtransfer.tasks.catalog import TABLE_I
from test_first_exposure import small_task

CFG = LearnerConfig()


def arm_task():
    """planar3:joint -> planar4:cartesian, Table I task 4: unbounded ``dense`` loops there."""
    from armtransfer.tasks.specs import resolve

    src, tgt = resolve("planar3:joint"), resolve("planar4:cartesian")
    start, goal = TABLE_I[4].cells()
    return src, tgt, start, goal


def test_the_bound_keeps_the_order_and_caps_what_a_self_loop_earns():
    phi = np.array([-1e4, -300.0, -80.0, -1.0, 0.0, 5.0])
    b = potentials.bounded(phi, 0.99, -1.0)
    B = potentials.LOOP_MARGIN * 100.0
    assert np.all(np.diff(b) > 0)  # the order of the states is kept
    assert np.all(b[:4] > -B) and b[4] == 0.0 and b[5] == 5.0  # a non-negative potential is left alone
    assert abs(b[3] + 1.0) < 1e-3  # near 0 the slope is 1
    leak = (1 - 0.99) * -b[:4]  # what a self-loop earns: gamma*phi(s) - phi(s)
    assert np.all(-1.0 + leak <= -(1 - potentials.LOOP_MARGIN))
    assert np.array_equal(potentials.bounded(phi, 1.0, -1.0), phi)  # no discount, no leak
    assert np.array_equal(potentials.bounded(phi, 0.99, 0.0), np.maximum(phi, 0.0))  # steps cost nothing


def test_the_farming_check_catches_a_method_that_pays_on_self_loops(monkeypatch):
    fine, coarse, start, goal = small_task()
    traj = trajectories.shortest(coarse, start, goal)
    bad = Shaping.potential(np.full(fine.n_states, -1000.0))  # a deliberately unbounded potential
    with pytest.raises(InvalidParameterError, match="leaves its state unchanged"):
        farming.check_self_loops("bad", fine, goal, bad, CFG)
    # the same potential bounded passes, and so does every registered method
    farming.check_self_loops("bad", fine, goal, Shaping.potential(potentials.bounded(bad.phi, 0.99, -1.0)), CFG)
    for name, m in methods.METHODS.items():
        if m.shaped:
            sh = methods.build_shaping(name, fine, [traj], "auto", CFG.step_reward, gamma=CFG.gamma)
            farming.check_self_loops(name, fine, goal, sh, CFG, wind=0.2)
    # a method paying 2 on every cell: run_method refuses it in one line before any trial

    def build(robot, trajs, k, beta):
        n = robot.n_states
        return Shaping(MODE_PSEUDO, np.full(n, 2.0), np.full(n, -1, np.int64), np.zeros(n), k)

    monkeypatch.setitem(methods.METHODS, "bad", Method("bad", "pays for standing still", paper=False, build=build,
                                                       auto_k=1.0, baselines=("none",)))
    with pytest.raises(InvalidParameterError, match="method 'bad' pays a learner"):
        experiment.run_method("bad", fine, start, goal, [traj], 1, 0, CFG)


def test_dense_never_loops_on_a_blocked_move():
    """Fast: the first exposure, capped at 400,000 steps, with robot 1's shortest path. ``none``
    reaches the goal in every trial; so does ``dense``; with its potential unbounded (what it was)
    every trial runs to the cap, and the farming check refuses that potential."""
    src, tgt, start, goal = arm_task()
    traj = trajectories.shortest(src, start, goal)
    config = LearnerConfig(max_episodes=1, max_total_steps=400_000)
    s0 = tgt.start_state(start)

    def firsts(shaping):
        return [sarsa.learn(tgt, s0, goal, config, experiment.trial_rng(0, k), shaping=shaping).exploration_steps
                for k in range(3)]

    assert None not in firsts(None)
    dense = methods.build_shaping("dense", tgt, [traj], "auto", config.step_reward, gamma=config.gamma)
    assert None not in firsts(dense)
    unbounded = Shaping.potential(potentials.dense(tgt, traj), potentials.DENSE_K)
    assert firsts(unbounded) == [None, None, None]
    with pytest.raises(InvalidParameterError):
        farming.check_self_loops("dense", tgt, goal, unbounded, config)


@pytest.mark.slow
def test_dense_converges_where_none_does_with_robot_ones_learned_path():
    """The full trial (2,000,000-step cap) with robot 1's learned path, as the matrix runs it."""
    src, tgt, start, goal = arm_task()
    config = LearnerConfig(max_total_steps=2_000_000)
    traj = experiment.source_trajectory("learned", src, start, goal, LearnerConfig(), 0)
    none = experiment.run_method("none", tgt, start, goal, None, 3, 0, config)
    dense = experiment.run_method("dense", tgt, start, goal, [traj], 3, 0, config)
    assert all(none.column("converged"))
    assert all(dense.column("converged")) and None not in dense.column("exploration_steps")
