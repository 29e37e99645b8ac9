"""Robot specs as users type them: grid robots by name, arms as ``ARM[:ACTIONS]``, an arm file
as ``PATH.xml[:ACTIONS]``, and ``custom[:ACTIONS]`` or ``NAME[:ACTIONS]`` (the file's name, as
``armtransfer arms list`` prints it) for the arm file given separately."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from armtransfer.errors import InvalidWorldError, UnknownArmError, UnknownRobotError
from armtransfer.models import ARMS
from armtransfer.tasks.arms import arm_robot, file_arm_name, parse_robot_spec
from armtransfer.tasks.generated import resolve_generated
from armtransfer.tasks.grid_robots import GRID_ROBOTS, grid_robot
from armtransfer.tasks.robot import DiscreteRobot
from armtransfer.worlds.layout import ROOMS, Layout

CUSTOM = "custom"
"""The spec of a bring-your-own arm: ``custom`` or ``custom:ACTIONS`` with its file given."""


def resolve(spec: str | DiscreteRobot, *, xml_path=None, progress: bool = False, arms: dict | None = None,
            layout: Layout = ROOMS, **arm_options) -> DiscreteRobot:
    """A robot from its spec: ``fine``/``coarse`` (grid robots), ``planar2:joint`` (a built-in
    arm and action model; the arm's first model when omitted), ``PATH.xml[:ACTIONS]`` (an arm
    file), or ``custom[:ACTIONS]`` (the arm in ``xml_path``); ``arm_options`` such as
    ``tip_site`` and ``base_pos`` go to arm files; ``arms`` names bring-your-own arms (a sweep
    file's ``[arms.NAME]`` tables: ``NAME[:ACTIONS]``). The robot moves in the world ``layout``
    (the paper's rooms by default). A robot passes through unchanged when it is in that world."""
    if isinstance(spec, DiscreteRobot):
        if spec.layout is not layout and spec.layout != layout:
            raise InvalidWorldError(f"robot {spec.name} moves in the world {spec.layout.name or 'unnamed'}, not in "
                                    f"{layout.name or 'unnamed'}: build it with the world's layout")
        return spec
    if not isinstance(spec, str):
        raise UnknownRobotError(f"a robot is a spec string or a DiscreteRobot, got {type(spec).__name__}")
    if spec in GRID_ROBOTS:
        return grid_robot(spec, layout)
    if arms and spec.partition(":")[0] in arms:
        name, _, actions = spec.partition(":")
        arm = arms[name]
        options: dict[str, Any] = {k: (tuple(v) if isinstance(v, list) else v) for k, v in arm.items() if k != "xml"}
        return arm_robot(None, actions or "cartesian", xml_path=arm["xml"], arm_name=name, progress=progress,
                         layout=layout, **options)
    if ".xml" in spec:  # an arm file: PATH.xml or PATH.xml:ACTIONS
        path, _, actions = spec.rpartition(":") if not spec.endswith(".xml") else (spec, "", "")
        return arm_robot(None, actions or "cartesian", xml_path=path, progress=progress, layout=layout,
                         **arm_options)
    if spec.startswith("gen:"):
        return resolve_generated(spec, progress=progress, layout=layout)
    name, _, actions = spec.partition(":")
    given = xml_arm_name(xml_path, arm_options.get("arm_name")) if xml_path is not None else None
    if name == CUSTOM or (name == given and name not in ARMS):
        if xml_path is None:
            raise UnknownRobotError(f"robot '{CUSTOM}' needs --arm-xml PATH (arm_xml= in the API)")
        return arm_robot(None, actions or "cartesian", xml_path=xml_path, progress=progress, layout=layout,
                         **arm_options)
    if name in ARMS:
        arm, actions = parse_robot_spec(spec)
        sized = {k: arm_options[k] for k in ("cell_size", "cache") if arm_options.get(k) is not None}
        return arm_robot(arm, actions, progress=progress, layout=layout, **sized)
    file_arm = f"{CUSTOM} or {given} (the arm of --arm-xml)" if given else f"or {CUSTOM} with --arm-xml"
    if actions:
        raise UnknownArmError(f"unknown arm {name!r}; valid arms: {', '.join(ARMS)}, {file_arm}")
    file_robot = (f"{CUSTOM}[:ACTIONS] or {given}[:ACTIONS] (the arm of --arm-xml)" if given
                  else f"or {CUSTOM}[:ACTIONS] with --arm-xml")
    raise UnknownRobotError(
        f"unknown robot {spec!r}; valid: {', '.join(sorted(GRID_ROBOTS))}, ARM[:ACTIONS] with ARM one of "
        f"{', '.join(ARMS)} (see `armtransfer arms list`), PATH.xml[:ACTIONS], gen:FAMILY:DOF:SEED[:ACTIONS], "
        f"{file_robot}"
    )


def xml_arm_name(xml_path, arm_name: str | None = None) -> str:
    """The name an arm file's robots go by (``NAME:ACTIONS``, as ``armtransfer arms list``
    prints them): ``arm_name`` when given, else the file's MJCF ``model`` attribute, else its
    stem. A spec may name the file's arm by it instead of ``custom``; a built-in arm of the
    same name keeps it."""
    return arm_name or file_arm_name(Path(xml_path))
