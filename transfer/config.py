"""Learning parameters of SARSA(lambda) (Algorithm 1) and the limits of one trial."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from armtransfer.errors import InvalidParameterError


@dataclass(frozen=True)
class LearnerConfig:
    """Parameters of Algorithm 1. The paper does not state its values; these are ours.

    Q starts at 0 everywhere, so with a negative step reward every untried action looks
    better than a tried one: the agent explores systematically, as in the paper.
    """

    alpha: float = 0.1
    gamma: float = 0.99
    lam: float = 0.9
    epsilon: float = 0.1
    step_reward: float = -1.0
    goal_reward: float = 0.0
    trace_cutoff: float = 1e-3
    """Eligibility traces below this are dropped (set to 0). With gamma*lambda = 0.891 a
    trace of 1 falls below 1e-3 after 60 steps. 0 keeps every trace until it underflows,
    which is exactly the dense Algorithm 1."""
    max_episodes: int = 2000
    max_total_steps: int = 20_000_000
    max_episode_steps: int = 200_000
    """Cap on every episode but the first (the first runs until the goal or the total cap)."""
    patience: int = 20
    """The greedy path has converged when it reaches the goal and stays the same for this
    many consecutive episodes."""

    def __post_init__(self) -> None:
        checks = {
            "alpha": 0.0 < self.alpha <= 1.0,
            "gamma": 0.0 <= self.gamma <= 1.0,
            "lam": 0.0 <= self.lam <= 1.0,
            "epsilon": 0.0 <= self.epsilon <= 1.0,
            "trace_cutoff": 0.0 <= self.trace_cutoff < 1.0,
            "max_episodes": self.max_episodes >= 1,
            "max_total_steps": self.max_total_steps >= 1,
            "max_episode_steps": self.max_episode_steps >= 1,
            "patience": self.patience >= 1,
        }
        ranges = {
            "alpha": "(0, 1]",
            "gamma": "[0, 1]",
            "lam": "[0, 1]",
            "epsilon": "[0, 1]",
            "trace_cutoff": "[0, 1)",
        }
        for name, ok in checks.items():
            if not ok:
                want = ranges.get(name, ">= 1")
                raise InvalidParameterError(
                    f"{name} must be in {want}, got {getattr(self, name)}"
                )

    def to_dict(self) -> dict:
        return asdict(self)
