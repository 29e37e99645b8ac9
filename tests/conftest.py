import os

# Offscreen rendering needs the GL backend chosen before mujoco is first imported.
os.environ.setdefault("MUJOCO_GL", "egl")
