"""The experiment layer: trials, results, sweeps, stores, matrices, summaries, reports and figures, built on the learner."""
