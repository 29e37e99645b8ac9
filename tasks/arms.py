"""Arms as discrete robots: ``arm_robot("planar2", "joint")`` or ``robot("ur5e_like:cartesian")``.

A robot name is ``ARM:ACTIONS``. The result is a ``tasks.robot.DiscreteRobot`` whose
labels are the shared rooms-world cells, so every learner runs on it unchanged. Its
``meta`` holds ``qpos`` [n_states, nq] (the joint configuration of every state, to replay
paths with the position actuators), ``tip`` [n_states, 3], ``reach`` (fraction of free
cells reached), ``cache`` ("hit", "miss", "stale", "corrupt") and the compile settings
(``xml_path``, ``tip_site``, ``mount``, ``yaw``, ``cell_size``, ``layout``: enough to rebuild
the exact MuJoCo scene, as ``armtransfer.ik.replay`` does).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from armtransfer.ik import cache as _cache
from armtransfer.ik.actions import ACTION_MODELS, action_model
from armtransfer.ik.description import ArmDescription
from armtransfer.errors import ArmModelError, UnknownArmError
from armtransfer.models import ARMS
from armtransfer.tasks.layout import ROOMS, Layout
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.ik.workspace import DEFAULT_CELL, WALL_HEIGHT

CUSTOM_JOINT_STEP = 0.05
SIDECAR_FORMAT = "armtransfer-generated-arm/1"
"""The JSON ``armtransfer arms generate`` writes beside an arm: its mount and tool."""


def parse_robot_spec(spec: str) -> tuple[str, str]:
    """'planar2:joint' -> ('planar2', 'joint'); the action model defaults to the arm's first."""
    arm, _, actions = spec.partition(":")
    if arm not in ARMS:
        raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
    actions = actions or ARMS[arm].actions[0]
    check_actions(arm, actions)
    return arm, actions


def check_actions(arm: str, actions: str) -> None:
    model = action_model(actions)
    allowed = _allowed_actions(ARMS[arm].kind)
    if model.name not in allowed:
        raise UnknownArmError(
            f"arm {arm!r} has no action model {actions!r}; valid action models: {', '.join(allowed)}")


def _allowed_actions(kind: str) -> tuple[str, ...]:
    if kind == "planar":
        return tuple(ACTION_MODELS)
    return tuple(a for a in ACTION_MODELS if ACTION_MODELS[a].kind == "cartesian")


def robot_specs() -> list[str]:
    """Every built-in robot name, ``ARM:ACTIONS``."""
    return [f"{arm}:{a}" for arm, info in ARMS.items() for a in _allowed_actions(info.kind)]


def robot(spec: str, **kwargs) -> DiscreteRobot:
    arm, actions = parse_robot_spec(spec)
    return arm_robot(arm, actions, **kwargs)


def _layout_data(layout: Layout) -> dict:
    return {"lo": layout.lo, "hi": layout.hi, "walls": layout.walls, "doors": layout.doors}


def arm_robot(arm: str | None, actions: str, *, cell_size: float = DEFAULT_CELL,
              xml_path: str | Path | None = None, tip_site: str | None = None,
              base_pos: tuple[float, float, float] | None = None, base_yaw: float = 0.0,
              joint_step: float | None = None, tip_down: bool | None = None, layout: Layout = ROOMS,
              cache: bool = True, progress: bool = False) -> DiscreteRobot:
    """Compile (or load from the cache) the discrete robot of an arm and action model.

    Built-in arms are named by ``arm``; a bring-your-own arm is given by ``xml_path`` and
    ``tip_site`` (and optionally its base pose ``base_pos``/``base_yaw`` in the table frame:
    tabletop z = 0, cell (x, y) centred at (x * cell_size, y * cell_size)); ``tip_down``
    keeps a bring-your-own arm's tool pointing down in the ``cartesian`` models.
    """
    model = action_model(actions)
    if not (np.isfinite(cell_size) and cell_size > 0):
        raise ArmModelError(f"cell size must be a positive number of metres, got {cell_size}")
    if xml_path is not None:
        generated = read_sidecar(xml_path) if base_pos is None else None
        if generated is not None:  # mounted as it was generated, unless told otherwise
            base_pos, base_yaw = tuple(generated["mount_pos"]), float(generated["mount_yaw"])
            tip_down = generated["tip_down"] if tip_down is None else tip_down
            joint_step = joint_step or generated["joint_step"]
        path = Path(xml_path)
        try:
            xml_bytes = path.read_bytes()
        except OSError as err:
            raise ArmModelError(f"cannot read arm MJCF {str(path)!r}: {err.strerror or err}") from None
        name = arm or path.stem
        tip = tip_site or "tip"
        mount = tuple(float(v) for v in (base_pos or (0.0, 0.0, 0.0)))
        yaw, kind, tip_down = float(base_yaw), "custom", bool(tip_down)
        step = joint_step or CUSTOM_JOINT_STEP
    else:
        if arm not in ARMS:
            raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
        check_actions(arm, actions)
        info = ARMS[arm]
        path, name, tip = info.xml_path, arm, info.tip_site
        xml_bytes = path.read_bytes()
        mount = info.mount_pos
        if info.kind == "planar":  # hang over the same cell whatever the cell size
            mount = (mount[0] * cell_size / DEFAULT_CELL, mount[1] * cell_size / DEFAULT_CELL, mount[2])
        if base_pos is not None:
            mount = tuple(float(v) for v in base_pos)
        yaw = info.mount_yaw if base_pos is None else float(base_yaw)
        kind, tip_down = info.kind, info.tip_down
        step = joint_step or info.joint_step
    robot_name = f"{name}:{model.name}"
    parts = {
        "version": 1, "arm_xml": _sha(xml_bytes), "tip": tip, "mount": mount, "yaw": yaw,
        "actions": model.name, "cells": model.cells, "tip_down": tip_down,
        "joint_step": step if model.kind == "joint" else None, "cell": cell_size,
        "wall_height": WALL_HEIGHT, "layout": _layout_data(layout),
    }
    key = _cache.cache_key(parts)
    status = "off"
    start = time.perf_counter()
    arrays = None
    if cache:
        _check_cache_dir()
        arrays, status = _cache.load(robot_name, key)
    if arrays is None:
        if progress:
            print(f"compiling {robot_name} ...", file=sys.stderr, flush=True)
        arrays = _compile(path, tip, mount, yaw, model, tip_down, step, cell_size, layout, progress)
        if cache:
            _cache.save(robot_name, key, arrays)
    seconds = time.perf_counter() - start
    dof = int(arrays["qpos"].shape[1])
    label = arrays["label"]
    reach = float(len(np.unique(label)) / layout.free.sum())
    description = ArmDescription(
        name=name, actions=model.name, dof=dof, kind=kind, qpos=arrays["qpos"], tip=arrays["tip"],
        reach=reach, cache=status, key=key, seconds=seconds, cell_size=cell_size,
        mount=mount, yaw=yaw, xml_path=str(path), tip_site=tip,
        joint_step=step if model.kind == "joint" else None, layout=layout,
        lattice=arrays.get("lattice"),
    )
    return DiscreteRobot(
        name=robot_name,
        next_state=arrays["next_state"],
        wind_state=arrays["wind_state"],
        label=label,
        action_names=model.action_names(dof),
        cell_step=model.cells,
        canonical=arrays["canonical"],
        layout=layout,
        arm=description,
    )


def _check_cache_dir() -> None:
    """The arm cache must take files before any compiling starts (one line otherwise)."""
    from armtransfer.errors import OutputError
    from armtransfer.io import check_writable

    root = _cache.cache_dir()
    try:
        if root.exists() and not root.is_dir():
            raise OutputError(f"{str(root)!r} is not a directory")
        check_writable(root / "probe.npz")
    except OutputError as err:
        raise OutputError(f"the arm cache cannot be used ({err}); set ARMTRANSFER_CACHE to a writable "
                          "directory, or pass --no-cache") from None


def read_sidecar(xml_path: str | os.PathLike) -> dict | None:
    """The generator's JSON beside an arm file, or None when there is none."""
    from armtransfer.io import parse_json_bytes

    path = Path(xml_path).with_suffix(".json")
    try:
        data = parse_json_bytes(path.read_bytes())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("format") == SIDECAR_FORMAT else None


def _sha(data: bytes) -> str:
    import hashlib

    return hashlib.sha256(data).hexdigest()


def arm_scene(arm: str | None = None, *, cell_size: float = DEFAULT_CELL, xml_path=None,
              tip_site: str | None = None, base_pos=None, base_yaw: float = 0.0,
              layout: Layout = ROOMS):
    """The MuJoCo scene (``ik.scene.ArmScene``) a robot of this arm is compiled in."""
    from armtransfer.ik.scene import build_scene

    if xml_path is not None:
        return build_scene(Path(xml_path), tip_site or "tip", base_pos or (0.0, 0.0, 0.0),
                           base_yaw, cell_size, layout=layout)
    if arm not in ARMS:
        raise UnknownArmError(f"unknown arm {arm!r}; valid arms: {', '.join(ARMS)}")
    info = ARMS[arm]
    mount = info.mount_pos
    if info.kind == "planar":
        mount = (mount[0] * cell_size / DEFAULT_CELL, mount[1] * cell_size / DEFAULT_CELL, mount[2])
    return build_scene(info.xml_path, info.tip_site, mount, info.mount_yaw, cell_size, layout=layout)


def _compile(path, tip, mount, yaw, model, tip_down, step, cell, layout, progress) -> dict:
    from armtransfer.ik.compile import compile_cartesian, compile_joint
    from armtransfer.ik.scene import build_scene

    scene = build_scene(Path(path), tip, mount, yaw, cell, layout=layout)
    if model.kind == "joint":
        return compile_joint(scene, step, progress)
    return compile_cartesian(scene, tip_down, model.cells, progress)


__all__ = ["arm_robot", "arm_scene", "parse_robot_spec", "robot", "robot_specs"]
