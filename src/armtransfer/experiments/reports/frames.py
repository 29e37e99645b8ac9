"""The tidy frames of :mod:`armtransfer.experiments.frames`, by the name the store imports them."""

from armtransfer.experiments.frames import frame, pandas, trial_rows

__all__ = ["frame", "pandas", "trial_rows"]
