"""armtransfer: transfer learning between robots that cannot imitate each other.

The library, in the one direction its imports follow (``tests/test_architecture.py``); each
file's path is its module's path:

  armtransfer.errors, .io, .cpus   every error a user can cause; atomic writes; cores
  armtransfer.models               MJCF arms, one folder each
  armtransfer.ik                   all MuJoCo code: scenes, mink labels and IK, compile,
                                   physics replay, offscreen rendering
  armtransfer.tasks                the rooms layout, discrete robots, tasks, environments
  armtransfer.learning             the learner: trajectories, methods, shaping, SARSA(lambda),
                                   the guide, mapping; never imports MuJoCo
  armtransfer.experiments          trials, results, sweeps, stores, matrices, statistics,
                                   reports and figures
  armtransfer                      the Python API, Gymnasium wrappers, dm_control
                                   environments (armtransfer.dmc), the command

The public names below are loaded on first use, so importing any part stays cheap:

    import armtransfer
    result = armtransfer.transfer(source="coarse", target="fine", task=1,
                                  methods=["none", "pseudo"], trials=3, seed=1)

A transfer method of one's own: ``armtransfer.potential_method`` (or ``bonus_method``), declared
by an installed package under the entry-point group ``armtransfer.methods`` or given to
``armtransfer.register_method`` (docs/extending.md). A learner of one's own (any Gymnasium
agent with ``learn`` and ``predict``): ``armtransfer.Learner``, declared under
``armtransfer.learners`` or given to ``armtransfer.register_learner``.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_LAZY = {
    "transfer": "armtransfer.api",
    "TransferResult": "armtransfer.experiments.results",
    "MethodResult": "armtransfer.experiments.experiment",
    "TrialResult": "armtransfer.learning.sarsa",
    "LearnerConfig": "armtransfer.learning.config",
    "METHODS": "armtransfer.learning.methods",
    "Method": "armtransfer.learning.methods",
    "register_method": "armtransfer.learning.methods",
    "Learner": "armtransfer.learning.learners",
    "LEARNERS": "armtransfer.learning.learners",
    "register_learner": "armtransfer.learning.learners",
    "potential_method": "armtransfer.learning.plugins",
    "bonus_method": "armtransfer.learning.plugins",
    "resolve_robot": "armtransfer.tasks.specs",
    "register_envs": "armtransfer.registration",
    "TransferReward": "armtransfer.wrappers",
    "ArmTransferError": "armtransfer.errors",
}

__all__ = sorted(_LAZY)


from armtransfer.registration import register_on_import as _register_on_import  # noqa: E402

_register_on_import()


def __getattr__(name: str):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'armtransfer' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), "resolve" if name == "resolve_robot" else name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
