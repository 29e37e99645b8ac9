"""What the docs count and list of the code follows the code: the Gymnasium environments
``import armtransfer`` registers (docs/api.md counts them and names each, the README names each),
and the built-in worlds (docs/worlds.md's table, extending.md's "Your world")."""

from __future__ import annotations

import re
from pathlib import Path

from armtransfer.registration import ENVIRONMENTS
from armtransfer.worlds.generate import PREFIX
from armtransfer.worlds.resolve import WORLDS

ROOT = Path(__file__).resolve().parents[1]
WORDS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight"}


def test_the_docs_count_and_name_every_registered_environment():
    api = (ROOT / "docs" / "api.md").read_text()
    counted = re.findall(r"`import armtransfer` registers (\w+) environments", api)
    assert counted == [WORDS[len(ENVIRONMENTS)]], counted
    readme = (ROOT / "README.md").read_text()
    for env_id in ENVIRONMENTS:
        assert f"`{env_id}`" in api and f"`{env_id}`" in readme, env_id
    named = set(re.findall(r"`(armtransfer/[A-Za-z]+-v\d+)`", api + readme))
    assert named <= set(ENVIRONMENTS), named - set(ENVIRONMENTS)


def test_the_docs_list_the_built_in_worlds():
    worlds = (ROOT / "docs" / "worlds.md").read_text()
    table = worlds[worlds.index("| world |"):].split("\n\n")[0]  # the table of worlds
    rows = re.findall(r"^\| `([^`]+)` \|", table, flags=re.M)
    built_in = [r for r in rows if not r.startswith((PREFIX, "PATH"))]
    assert built_in == list(WORLDS), built_in
    extending = (ROOT / "docs" / "extending.md").read_text()
    own = extending[extending.index("## Your world"):]
    assert "one world" not in own
    for name in WORLDS:
        assert f"`{name}`" in own, name
