"""The project's Gymnasium environments, registered when ``armtransfer`` is imported.

Registration names only an entry point string, so it loads nothing of the project's own:
``import armtransfer; gymnasium.make("armtransfer/ArmRooms-v0")`` works, as in Gymnasium's
ecosystem, in either order of the two imports. Where Gymnasium is not loaded yet, the
registration waits for it (:func:`register_on_import`), so ``import armtransfer`` stays cheap
for the command, which may never need Gymnasium.
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import sys
from typing import Any

ENVIRONMENTS = {
    "armtransfer/Rooms-v0": "armtransfer.tasks.envs:make_rooms_env",
    "armtransfer/ArmRooms-v0": "armtransfer.tasks.envs:make_arm_rooms_env",
    "armtransfer/ContinuousArmRooms-v0": "armtransfer.tasks.continuous_env:make_continuous_arm_rooms_env",
    "armtransfer/ContinuousArmRoomsBox-v0": "armtransfer.tasks.continuous_env:make_continuous_arm_rooms_box_env",
}
MAX_EPISODE_STEPS = 100_000


def register_envs() -> None:
    """Register this project's environments with Gymnasium (idempotent)."""
    import gymnasium as gym  # start-up: run once Gymnasium is imported (register_on_import)

    for env_id, entry_point in ENVIRONMENTS.items():
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry_point, max_episode_steps=MAX_EPISODE_STEPS)


def register_on_import() -> None:
    """Register now if Gymnasium is loaded, else right after it is first imported."""
    if "gymnasium" in sys.modules:
        register_envs()
    elif not any(isinstance(f, _AfterGymnasium) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterGymnasium())


class _AfterGymnasium(importlib.abc.MetaPathFinder):
    """Finds Gymnasium as the other finders do, and hands its loader a registration to run after."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        if fullname != "gymnasium":
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is not None and spec.loader is not None:
            spec.loader = _ThenRegister(spec.loader)
        return spec


class _ThenRegister(importlib.abc.Loader):
    def __init__(self, loader: Any) -> None:
        self._loader = loader

    def create_module(self, spec: Any) -> Any:
        return self._loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self._loader.exec_module(module)
        register_envs()

    def __getattr__(self, name: str) -> Any:  # resource readers and the rest: Gymnasium's own loader
        return getattr(self._loader, name)
