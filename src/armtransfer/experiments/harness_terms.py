"""The terms of the harness that runs an outside learner's trial (``experiments.learner_trial``):
how often it is evaluated and when it counts as converged. The harness and the benchmark's
report (which states them) both read them here."""

CHUNKS = 200
"""Greedy evaluations per trial budget: a chunk is ``max_total_steps // CHUNKS`` training steps."""

EVALS = 3
"""Consecutive greedy episodes at (1 + TOLERANCE) x the shortest path that make a trial converged."""

TOLERANCE = 0.25
"""A greedy episode counts towards convergence when its steps are at most (1 + TOLERANCE) x the
target's shortest path."""

EVAL_CAP = 4
"""A greedy episode stops after EVAL_CAP x the target's shortest path steps (failed)."""
