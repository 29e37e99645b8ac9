"""The world robots move in: the grid of cells, its walls and doors, and its named tasks.

``worlds.resolve.world("rooms11")`` gives a world by name (``rooms``, the paper's, is the
default), ``generated:SEED[:SIDE]`` draws one, and a layout file (``worlds.files``) is one
written by hand.
"""
