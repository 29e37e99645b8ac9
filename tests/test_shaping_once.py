"""One K check and one shaping build per method and trajectory: ``transfer`` makes each method's
shaping before any learning (so a bad K is refused first) and its run learns with that one,
instead of checking K (a value-iteration solve) and building the shaping again."""

from collections import Counter

import pytest

import armtransfer
from armtransfer.errors import InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.learning import farming
from armtransfer.learning import methods as registry
from armtransfer.learning.config import LearnerConfig
from armtransfer.learning.trajectory import shortest
from armtransfer.tasks.catalog import table_task
from armtransfer.tasks.specs import resolve

SHAPED = ["pseudo", "dense", "mapping"]
"""Two farmable methods (pseudo, mapping: K checked by value iteration) and one that is not."""


@pytest.fixture
def counted(monkeypatch):
    """Counts of K checks and shaping builds per method, and of value-iteration solves."""
    counts: Counter = Counter()

    def wrap(module, name, key):
        real = getattr(module, name)

        def counting(*args, **kwargs):
            counts[key(args)] += 1
            return real(*args, **kwargs)

        monkeypatch.setattr(module, name, counting)

    wrap(farming, "check_k", lambda args: ("check_k", args[0]))
    wrap(registry, "build_shaping", lambda args: ("build", args[0]))
    wrap(farming, "analyse", lambda args: ("solve",))  # every value-iteration solve of the farming check
    return counts


@pytest.mark.parametrize("controls", [False, True])
def test_each_method_and_trial_checks_k_and_builds_its_shaping_once(counted, controls):
    trials = 3
    result = armtransfer.transfer(methods=["none", *SHAPED], trajectory="optimal", trials=trials, controls=controls,
                                  max_episodes=3)
    with_controls = [m for m in SHAPED if any(m in by for by in result.controls.values())]
    assert (with_controls != []) == controls  # pseudo and dense have controls, mapping has none
    per_method = {m: 1 + trials * len(result.controls) * (m in with_controls) for m in SHAPED}
    farmable = [m for m in SHAPED if registry.get(m).farmable]
    assert farmable == ["pseudo", "mapping"]
    assert {m: counted["build", m] for m in SHAPED} == per_method
    assert {m: counted["check_k", m] for m in farmable} == {m: per_method[m] for m in farmable}
    assert counted["check_k", "dense"] == counted["check_k", "none"] == counted["build", "none"] == 0
    # 'auto' for the real trajectory is one solve when half the old bound is safe; each control
    # trial checks the K it is given, one solve each
    assert counted["solve",] == sum(per_method[m] for m in farmable)
    assert result.methods["pseudo"].extra["K"] > 0


def test_a_run_learns_with_the_shaping_made_before_it(monkeypatch):
    """The shaping that ``transfer`` made is the one the run learns with (not a second, equal one)."""
    made, used = {}, {}
    real_shaping, real_learn = experiment.method_shaping, experiment.sarsa.learn

    def shaping(method, *args, **kwargs):
        made[method] = sh = real_shaping(method, *args, **kwargs)
        return sh

    def learn(*args, shaping=None, **kwargs):
        if shaping is not None:
            used.setdefault(id(shaping), shaping)
        return real_learn(*args, shaping=shaping, **kwargs)

    monkeypatch.setattr(experiment, "method_shaping", shaping)
    monkeypatch.setattr(experiment.sarsa, "learn", learn)
    armtransfer.transfer(methods=["none", "pseudo", "dense"], trajectory="optimal", trials=2, controls=False,
                         max_episodes=3)
    assert set(made) == {"none", "pseudo", "dense"} and made["none"] is None
    assert {id(made["pseudo"]), id(made["dense"])} == set(used)


def test_a_shaping_made_in_advance_needs_one_trajectory_for_every_trial():
    fine = resolve("fine")
    start, goal = table_task(1).cells()
    config = LearnerConfig(max_episodes=2)
    traj = shortest(fine, start, goal)
    sh = experiment.method_shaping("pseudo", fine, fine.start_state(start), goal, [traj], "auto", config)
    with pytest.raises(InvalidParameterError, match="per trial"):
        experiment.run_method("pseudo", fine, start, goal, lambda trial: [traj], 1, 0, config, shaping=sh)
    with pytest.raises(InvalidParameterError, match="'none'"):
        experiment.run_method("none", fine, start, goal, None, 1, 0, config, shaping=sh)
