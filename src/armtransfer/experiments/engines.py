"""Who learns a run on robot 2: the :class:`Engine` interface, its three implementations, and the
one place that chooses among them.

Three engines learn on robot 2: ``tabular``, the compiled SARSA(lambda) kernel on the target's
table of states (``learning.sarsa``); ``continuous``, the linear SARSA(lambda) learner over tile
coding on the arm's joint configuration (``learning.linear``); and ``outside``, a learner of the
registry from outside the package, on the target's Gymnasium environment through the harness
(``experiments.learner_trial``). ``armtransfer.transfer``, the benchmark's trial runs and sweep
runs (so the matrix) describe what to learn as a :class:`Work`, ask :func:`engine_for` for the
engine, and call its :meth:`Engine.trials`, which returns
the one result type, ``experiment.MethodResult``. A pairing no engine runs is refused by the
engine, in one line (:meth:`Engine.accepts`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence

from armtransfer.errors import ArmTransferError, InvalidParameterError
from armtransfer.experiments import experiment
from armtransfer.experiments.experiment import MethodResult
from armtransfer.experiments.run import STATES as STATES
from armtransfer.experiments.work import Work as Work
from armtransfer.learning.learner_names import SARSA
from armtransfer.learning.potentials import DENSE_BETA
from armtransfer.learning.trajectory import Trajectory
from armtransfer.tasks.robot import DiscreteRobot

TABULAR = "tabular"
CONTINUOUS = "continuous"
OUTSIDE = "outside"
ENGINES = (TABULAR, CONTINUOUS, OUTSIDE)



class Engine(ABC):
    """One way of learning on robot 2."""

    name: str

    def accepts(self, learner: str, state: str, subject: str = "the target is") -> None:
        """Refuse, in one line, a ``learner`` on a target whose state is ``state`` this engine
        does not run (``subject`` says what has that target); nothing when it runs it."""

    @abstractmethod
    def trials(self, work: Work, target: DiscreteRobot | None,
               trajectories: Sequence[Trajectory] | None) -> MethodResult:
        """``work``'s trials on ``target`` (its table robot: its world and cells; None only with a
        continuous arm in the work), paid for ``trajectories`` when the method reads them."""


class Tabular(Engine):
    """The compiled SARSA(lambda) kernel on the target's table of states: a method
    (``experiment.run_method``), a method paid for a control's stand-ins (``work.control``,
    ``experiment.run_control``) or method ``mapping`` with the macros of ``work.mapping``
    (``experiment.run_mapping``; the result carries the mapping it updated)."""

    name = TABULAR

    def trials(self, work: Work, target: DiscreteRobot | None,
               trajectories: Sequence[Trajectory] | None) -> MethodResult:
        assert target is not None
        start, goal = target.layout.cell(*work.start), target.layout.cell(*work.goal)
        given = None if trajectories is None else list(trajectories)
        beta = DENSE_BETA if work.beta is None else work.beta
        if work.control is not None:
            return experiment.run_control(work.method, work.control, work.source, target, start, goal, given or [],
                                          work.trials, work.seed, work.config, beta=beta, wind=work.wind, K=work.K,
                                          threads=work.threads, first_trial=work.first_trial, on_trial=work.on_trial)
        if work.mapping is not None:
            experiment.check_trajectories([work.method], given or [])
            assert given is not None
            return experiment.run_mapping(target, start, goal, given[0], work.mapping, work.trials, work.seed,
                                          work.config, wind=work.wind, K=work.K, on_trial=work.on_trial,
                                          max_span=work.max_span, shaping=work.shaping)[0]
        return experiment.run_method(work.method, target, start, goal, given, work.trials, work.seed, work.config,
                                     wind=work.wind, K=work.K, threads=work.threads, first_trial=work.first_trial,
                                     on_trial=work.on_trial, beta=beta, shaping=work.shaping)


class Continuous(Engine):
    """Linear SARSA(lambda) over tile coding on the target's continuous arm, made for the work
    (a few ms once its scene is cached, so trials on threads share no MuJoCo data) in the
    table robot's world with the work's actuation noise, placed over the start
    (``experiments.continuous``)."""

    name = CONTINUOUS

    def trials(self, work: Work, target: DiscreteRobot | None,
               trajectories: Sequence[Trajectory] | None) -> MethodResult:
        from armtransfer.experiments import continuous  # start-up: a table's runs load no continuous learner
        from armtransfer.tasks.continuous import continuous_arm  # start-up: only a continuous run builds one

        arm = work.arm
        if arm is None:
            assert target is not None
            arm = continuous_arm(work.target, layout=target.layout, noise=work.noise)
            arm.place(target.layout.cell(*work.start))
        goal = arm.layout.cell(*work.goal)
        return continuous.run_method(work.method, arm, goal, trajectories, work.trials, work.seed, work.config,
                                     K="auto" if work.K is None else work.K,
                                     approx=continuous.approximation_for(arm), first_trial=work.first_trial,
                                     on_trial=work.on_trial)


class Outside(Engine):
    """A learner of ``armtransfer.learning.learners`` from outside the package, through the
    benchmark's harness (``experiments.learner_transfer``); it learns on a discrete target only."""

    name = OUTSIDE

    def accepts(self, learner: str, state: str, subject: str = "the target is") -> None:
        if state == "continuous":
            raise InvalidParameterError(f"learner {learner!r} learns on a discrete target; {subject} a continuous "
                                        f"one; valid learners for it: {SARSA}")

    def trials(self, work: Work, target: DiscreteRobot | None,
               trajectories: Sequence[Trajectory] | None) -> MethodResult:
        from armtransfer.experiments import learner_transfer  # start-up: Gymnasium, for outside learners
        from armtransfer.learning.learners import get  # start-up: the registry loads Gymnasium

        assert target is not None
        return learner_transfer.run_method(get(work.learner), work.method, target, list(work.start),
                                           list(work.goal), trajectories, work.trials, work.seed, work.config,
                                           wind=work.wind, K=work.K, beta=work.beta, on_trial=work.on_trial,
                                           heartbeat=work.heartbeat, first_trial=work.first_trial)


_BY_NAME: dict[str, Engine] = {e.name: e for e in (Tabular(), Continuous(), Outside())}

BY_LEARNER: dict[str, Engine] = {}
"""An engine of its own for a learner name (the built-in learner's are chosen by state; a learner
of the outside registry not named here runs through the harness)."""


def engine_for(learner: str, state: str = "discrete", subject: str = "the target is") -> Engine:
    """The engine that runs ``learner`` on a target whose state is ``state`` (:data:`STATES`),
    having accepted them: the built-in learner runs on either (the kernel on a table, the linear
    learner on a continuous arm); an outside learner on a discrete target only, and on a
    continuous one is refused in one line (``subject`` says what has that target). A learner no
    engine runs is a one-line error listing the learners."""
    if state not in STATES:
        raise InvalidParameterError(f"unknown state {state!r}; valid states: {', '.join(STATES)}")
    if learner == SARSA:
        return _BY_NAME[CONTINUOUS if state == "continuous" else TABULAR]
    engine = BY_LEARNER.get(learner)
    if engine is None:
        from armtransfer.learning.learners import LEARNERS  # start-up: the registry loads Gymnasium

        if learner not in LEARNERS:  # a run of a learner this build does not have fails; it is no result
            valid = dict.fromkeys([SARSA, *BY_LEARNER, *LEARNERS])
            raise ArmTransferError(f"unknown learner {learner!r}; valid learners: {', '.join(valid)}")
        engine = _BY_NAME[OUTSIDE]
    engine.accepts(learner, state, subject)
    return engine
