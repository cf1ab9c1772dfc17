"""The pins that ``make setup`` installs with cover every requirement of the
project, so that a fresh clone installs the versions the suite was run with
(``make lock`` regenerates them)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")

ROOT = Path(__file__).resolve().parents[1]


def _name(requirement: str) -> str:
    """The normalised distribution name of a requirement string (PEP 503)."""
    name = re.match(r"\s*([A-Za-z0-9][A-Za-z0-9._-]*)", requirement).group(1)
    return re.sub(r"[-_.]+", "-", name).lower()


def _pins() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "constraints.txt").read_text(encoding="utf-8").splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        name, sep, version = line.partition("==")
        assert sep and version, f"constraints.txt: {line!r} is not a 'name==version' pin"
        pins[_name(name)] = version
    return pins


def test_every_requirement_of_every_extra_is_pinned():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    own = _name(project["name"])
    wanted = {_name(r) for r in project["dependencies"]}
    for extra in project["optional-dependencies"].values():
        wanted |= {_name(r) for r in extra if _name(r) != own}
    missing = sorted(wanted - set(_pins()))
    assert not missing, f"not pinned in constraints.txt (run `make lock`): {missing}"


def test_torch_pin_of_the_makefile_matches_the_constraints():
    """``make setup`` installs torch before the rest; a constraint that
    disagreed would make pip refuse the install."""
    pin = re.search(r"^TORCH_PIN\s*:=\s*torch==(\S+)", (ROOT / "Makefile").read_text(),
                    re.MULTILINE).group(1)
    assert _pins()["torch"] == pin
