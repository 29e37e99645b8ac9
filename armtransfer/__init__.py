"""armtransfer: transfer learning between robots that cannot imitate each other.

The packages, in the one direction data flows:
  models/    MJCF arms, one folder each
  ik/        mink kinematics: labels, IK, action models, compiling arms into robots
  tasks/     the rooms layout, the workspace, discrete robots and start/goal tasks
  transfer/  trajectories, pseudo rewards, SARSA(lambda), mapping, metrics, experiments
  armtransfer/  the ``armtransfer`` command
"""

__version__ = "0.1.0"
