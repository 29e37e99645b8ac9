"""The world robots move in: the grid of cells, its walls and doors, and its tasks."""
