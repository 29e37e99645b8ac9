"""Arm kinematics: scenes, mink labelling and IK, action models, and compiling arms into
discrete robots. Arm robots are built by ``armtransfer.tasks.arms.arm_robot``, which drives
this layer.

Every module here that imports ``mujoco`` is below this package, so this is where the
offscreen backend is named (``MUJOCO_GL=egl`` unless the user chose one) before the first
``import mujoco``; ``ik.offscreen`` says whether it works."""

from armtransfer.ik import offscreen as _offscreen

_offscreen.set_default()
