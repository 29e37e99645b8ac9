"""Arm kinematics: scenes, mink labelling and IK, action models, and compiling arms into
discrete robots. The public entry point is ``ik.robots.arm_robot``."""
