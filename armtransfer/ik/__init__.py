"""Arm kinematics: scenes, mink labelling and IK, action models, and compiling arms into
discrete robots. Arm robots are built by ``armtransfer.tasks.arms.arm_robot``, which drives
this layer."""
