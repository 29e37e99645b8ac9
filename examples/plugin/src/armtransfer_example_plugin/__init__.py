"""An example plugin for armtransfer: one transfer method, ``breadcrumbs`` (``method.py``), and one
learner, ``tabular-q`` (``learner.py``)."""
