"""What a fresh install resolves: constraints.txt pins every dependency the README's commands
install, at versions their requirements accept, and CI runs the suite on today's resolve with
no pip cache as well as on those pins."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]


def _pins() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        m = re.fullmatch(r"([A-Za-z0-9_.\-]+)==([^\s;]+)", line)
        assert m, f"constraints.txt: not a pin: {line!r}"
        pins[canonicalize_name(m.group(1))] = m.group(2)
    return pins


def _requirements() -> list[Requirement]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    return [Requirement(r) for r in (*project["dependencies"], *project["optional-dependencies"]["test"])]


def test_constraints_pin_every_dependency_at_an_accepted_version():
    pins = _pins()
    missing = [str(r) for r in _requirements() if canonicalize_name(r.name) not in pins]
    assert missing == [], f"constraints.txt does not pin {missing}"
    rejected = [f"{r} (pinned {pins[canonicalize_name(r.name)]})" for r in _requirements()
                if not r.specifier.contains(pins[canonicalize_name(r.name)], prereleases=True)]
    assert rejected == [], f"constraints.txt pins versions pyproject.toml refuses: {rejected}"


def test_the_pins_name_no_package_twice_and_not_armtransfer():
    names = [canonicalize_name(line.split("==")[0]) for line in (ROOT / "constraints.txt").read_text().splitlines()
             if line.strip() and not line.startswith("#")]
    assert len(names) == len(set(names))
    assert "armtransfer" not in names


def test_ci_resolves_without_a_cache_and_again_on_the_pins():
    script = (ROOT / ".ci" / "run").read_text()
    first_run = script.index('bash -c "$cmd"')
    assert script.index("export PIP_NO_CACHE_DIR=1") < first_run
    assert 'PIP_CONSTRAINT="$constraints" bash -c "$cmd"' in script
    assert "constraints.txt" in (ROOT / "docs" / "setup.md").read_text()
