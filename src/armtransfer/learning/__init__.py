"""The learner: trajectories, methods, shaping, SARSA(lambda) and its dense reference, the guide, action sequence mapping. Never imports MuJoCo."""
