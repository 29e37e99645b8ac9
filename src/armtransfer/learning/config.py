"""Learning parameters of SARSA(lambda) (Algorithm 1) and the limits of one trial.

Every field says once what it is (``help``) and the range it must lie in (``lo``/``hi``); the
command's flags (``--alpha`` ...), the API's keyword options and the sweep files' keys are
all made from these fields, so a new parameter is one field here.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields

import armtransfer.checks as checks
from armtransfer.errors import InvalidParameterError


MAX_REWARD = 1e6
"""The largest magnitude of a reward: far past any useful one, and far from where Q values of
sums over millions of steps overflow (a goal reward of 1e308 ran and converged nowhere)."""


def _param(default, help: str, lo: float, hi: float = math.inf, *, lo_open: bool = False, cli: bool = True):
    return field(default=default, metadata={"help": help, "lo": lo, "hi": hi, "lo_open": lo_open, "cli": cli})


@dataclass(frozen=True)
class LearnerConfig:
    """Parameters of Algorithm 1. The paper does not state its values; these are ours.

    Q starts at 0 everywhere, so with a negative step reward every untried action looks
    better than a tried one: the agent explores systematically, as in the paper.
    """

    alpha: float = _param(0.1, "learning rate", 0.0, 1.0, lo_open=True)
    gamma: float = _param(0.99, "discount", 0.0, 1.0)
    lam: float = _param(0.9, "trace decay lambda", 0.0, 1.0)
    epsilon: float = _param(0.1, "exploration rate of epsilon-greedy", 0.0, 1.0)
    step_reward: float = _param(-1.0, "reward per step", -MAX_REWARD, MAX_REWARD)
    goal_reward: float = _param(0.0, "reward on reaching the goal", -MAX_REWARD, MAX_REWARD)
    trace_cutoff: float = _param(1e-3, "eligibility traces below this are dropped", 0.0, 1.0, cli=False)
    """With gamma*lambda = 0.891 a trace of 1 falls below 1e-3 after 60 steps. 0 keeps every
    trace until it underflows, which is exactly the dense Algorithm 1."""
    max_episodes: int = _param(2000, "episodes per trial at most", 1, 1_000_000)
    max_total_steps: int = _param(20_000_000, "steps per trial at most (a trial that has not reached the goal by "
                                  "then counts as unreached)", 1, checks.MAX_COUNT)
    max_episode_steps: int = _param(200_000, "steps per episode at most, after the first", 1, checks.MAX_COUNT)
    """Cap on every episode but the first (the first runs until the goal or the total cap)."""
    patience: int = _param(20, "episodes the greedy path must stay the same to count as converged", 1,
                            1_000_000)
    """The greedy path has converged when it reaches the goal and stays the same for this
    many consecutive episodes."""
    quality: float = _param(1.05, "a target's trial ends only on a settled greedy path at most ceil(quality x "
                            "shortest) steps long (else at a cap); good_path_steps counts the steps until the "
                            "greedy path is that good and stays so", 1.0, 1000.0)
    """The harness's threshold of a good path (``learning.clock``); the learner never reads it.
    Robot 1's learning, handed no shortest path, stops on any settled path."""
    run_on: float = _param(1.0, "a trial that settles on a path that is not good runs on at most this many times the "
                           "steps it took to settle (then its good path, if none yet, is censored)", 0.0, 1000.0)
    """The budget of the good-path clock's run-on: a trial that first settled after S steps on a path
    longer than the good length stops at (1 + run_on) x S steps at most (or at its caps). It bounds
    what the clock costs (docs/benchmark.md: the standard suite in 90 minutes on 2 cores); a trial
    not good by then counts at the step cap in the benchmark's statistics, so a smaller budget never
    favours a method that settles on a worse path."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            lo, hi, lo_open = f.metadata["lo"], f.metadata["hi"], f.metadata["lo_open"]
            if f.type in (int, "int"):  # a count is an integer, as on the command line and in sweep files: 1e3 is not
                value = checks.whole(value, f.name, int(lo), int(hi))
            else:
                value = checks.real(value, f.name, lo, hi, lo_open=lo_open)
                if f.name == "trace_cutoff" and value >= 1:
                    raise InvalidParameterError(f"trace_cutoff must be in [0, 1), got {value!r}")
            object.__setattr__(self, f.name, value)  # numpy scalars are numbers; the config holds Python ones

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def options(cls) -> tuple[str, ...]:
        """The fields a user may set (flags, API keywords, sweep keys)."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def from_options(cls, options: dict) -> "LearnerConfig":
        """A config from keyword options; an unknown one is a one-line error listing the valid."""
        unknown = sorted(set(options) - set(cls.options()))
        if unknown:
            raise InvalidParameterError(
                f"unknown learner option {unknown[0]!r}; valid options: {', '.join(cls.options())}")
        return cls(**options)
