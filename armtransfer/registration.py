"""The project's Gymnasium environments, registered when ``armtransfer`` is imported.

Registration names only an entry point string, so it imports nothing of the project's own:
``import armtransfer; gymnasium.make("armtransfer/ArmRooms-v0")`` works, as in Gymnasium's
ecosystem, and importing ``armtransfer`` stays cheap.
"""

from __future__ import annotations

ENVIRONMENTS = {
    "armtransfer/Rooms-v0": "armtransfer.tasks.envs:make_rooms_env",
    "armtransfer/ArmRooms-v0": "armtransfer.tasks.envs:make_arm_rooms_env",
}
MAX_EPISODE_STEPS = 100_000


def register_envs() -> None:
    """Register this project's environments with Gymnasium (idempotent)."""
    import gymnasium as gym

    for env_id, entry_point in ENVIRONMENTS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry_point, max_episode_steps=MAX_EPISODE_STEPS)
