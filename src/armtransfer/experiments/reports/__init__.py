"""What a person reads: figures, store summaries and the reports of ``reproduce`` and
``benchmark``. Below them and the results, ``experiments.tables`` (text tables) and
``experiments.frames`` (tidy frames) import nothing of the experiments."""
