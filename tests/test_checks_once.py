"""The command line checks the world and the task once, on the way to the kernel, and hands
them down typed: the API takes the command's ``Task`` and ``Layout`` as they are."""

import pytest

import armtransfer
from armtransfer import api
from armtransfer.cli import main
from armtransfer.commands import common
from armtransfer.errors import InvalidTaskError
from armtransfer.tasks.catalog import custom_task, world_task
from armtransfer.worlds.resolve import world


def _counted(monkeypatch, module, name, calls):
    real = getattr(module, name)

    def counted(*args, **kwargs):
        calls.append(name)
        return real(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)


@pytest.mark.parametrize("where", [["--task", "2", "--world", "rooms"], ["--start", "0,0", "--goal", "-8,12"]])
def test_rooms_resolves_its_world_and_task_once(monkeypatch, capsys, where):
    calls: list[str] = []
    for module, name in ((common, "world"), (common, "world_task"), (common, "custom_task"),
                         (api, "resolve_world"), (api, "world_task"), (api, "custom_task"), (api, "table_task")):
        _counted(monkeypatch, module, name, calls)
    assert main(["rooms", *where, "--trials", "1", "--method", "none", "--no-controls"]) == 0
    task = "world_task" if "--task" in where else "custom_task"
    # the world is named once (the API is handed the Layout itself) and the task looked up once
    assert sorted(calls) == sorted(["world", task, "resolve_world"]), calls
    assert "exploration steps" in capsys.readouterr().out


def test_the_api_takes_a_task_in_its_world_and_refuses_one_of_another():
    rooms11 = world("rooms11")
    task = world_task(rooms11, None)
    result = armtransfer.transfer("coarse", "fine", task=task, trials=1, methods=["none"], controls=False)
    assert result.task is task and result.target.layout is rooms11  # its world came with it
    with pytest.raises(InvalidTaskError, match="of another world"):
        armtransfer.transfer("coarse", "fine", task=task, world="rooms", trials=1, methods=["none"], controls=False)
    with pytest.raises(InvalidTaskError, match="either a task or start/goal"):
        armtransfer.transfer("coarse", "fine", task=custom_task((0, 0), (-8, 12)), start=(0, 0), goal=(-8, 12))
