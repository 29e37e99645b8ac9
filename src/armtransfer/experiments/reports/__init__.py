"""What a person reads: text tables, figures, tidy frames, store summaries and the reports of
``reproduce`` and ``benchmark``."""
