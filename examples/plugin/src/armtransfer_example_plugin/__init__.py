"""An example plugin for armtransfer: one transfer method, ``breadcrumbs`` (``method.py``)."""
