"""The records the documentation shows (``docs/records.yaml``): each exists,
is shown by its page, is written by commands of the project that its page
gives (or that the record names itself), and stays small; nothing generated
under docs/ is left out of the manifest."""
import importlib
import importlib.util
import json
import re
import shlex
import tomllib
from pathlib import Path

import pytest
import yaml

from benchmarks import SUITES

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
MANIFEST = yaml.safe_load((DOCS / "records.yaml").read_text(encoding="utf-8"))["records"]
#: the folders of generated files, every one of which a record covers
GENERATED = ("agents", "benchmarks", "crosscheck", "figures")
#: the largest a committed generated file may be [bytes]
FILE_LIMIT = 1_500_000
#: the largest the trained agents' records may be together [bytes], the
#: reference agents apart: 7 MiB (3.5 MiB until the waypoint learner's two
#: boards, 4 MiB until the costmap lattice's three, 4.5 MiB until the rollout
#: planner's two searches, 5 MiB until the residual learner's board, 5.5 MiB
#: until the settings searched a concentration at a time and their first two
#: boards, 6 MiB until their board of 160 fields, 6.5 MiB until the two boards
#: of the students those settings taught)
AGENTS_LIMIT = 7 * 2**20
#: the largest the files of one trained agents' record (a leaderboard, an
#: evaluation: the files of one folder under docs/agents) may be together
#: [bytes]. Regenerated, the record
#: adds new versions of these files to the history, each stored compressed,
#: so a rerun grows the repository's pack by less than this.
RUN_RECORD_LIMIT = 1_000_000
#: the reference agents (each under agents.reference.MAX_BYTES) and their limit together
REFERENCE = DOCS / "agents" / "reference"
#: the leaderboard's variant boards
VARIANTS = DOCS / "agents" / "leaderboard" / "variants"
REFERENCE_LIMIT = 6 * 2**20
SCRIPTS = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]


def not_kept(path: Path) -> bool:
    """Written by a record's command beside it but not kept (``.gitignore``):
    the episodes behind a board, and a variant board's figure, which no page
    shows (its tables are kept)."""
    return path.name == "episodes.json" or (
        path.name == "leaderboard.png" and path.parent.parent == VARIANTS)


def generated_files() -> list[Path]:
    return sorted(p for folder in GENERATED for p in (DOCS / folder).rglob("*")
                  if p.is_file() and not p.name.startswith(".") and not not_kept(p))


def test_no_page_shows_a_variant_boards_figure():
    """A variant board's figure is not kept, so no page may show one."""
    for page in DOCS.rglob("*.md"):
        if "_build" in page.parts or "_generated" in page.parts:
            continue
        shown = re.findall(r"variants/[^/\s)]+/leaderboard\.png", page.read_text(encoding="utf-8"))
        assert not shown, f"{page.relative_to(ROOT)} shows {shown}"


def page_text(page: str) -> str:
    """A page with its shell lines joined and its whitespace collapsed."""
    text = (ROOT / page).read_text(encoding="utf-8").replace("\\\n", " ")
    return " ".join(text.split())


def record_commands(path: Path) -> list[str]:
    """The commands a record names itself (:func:`agents.leaderboard.record_commands`
    of its JSON files; a table or figure names those of the JSON beside it)."""
    from agents.leaderboard import record_commands as of_record

    files = sorted(path.glob("*.json")) if path.is_dir() else [path.with_suffix(".json")]
    return [c for f in files for c in of_record(json.loads(f.read_text(encoding="utf-8")))]


def is_project_command(command: str) -> bool:
    """``python -m MODULE`` of a module with a ``main`` or a ``__main__``, a
    console script of the project (``seaice bench SUITE`` naming a suite)."""
    words = shlex.split(command)
    if words[:2] == ["python", "-m"] and len(words) > 2:
        module = words[2]
        try:
            spec = importlib.util.find_spec(module)
        except ModuleNotFoundError:
            return False
        if spec is None:
            return False
        if spec.submodule_search_locations and importlib.util.find_spec(f"{module}.__main__"):
            return True
        return hasattr(importlib.import_module(module), "main")
    if words and words[0] in SCRIPTS:
        return words[:2] != ["seaice", "bench"] or (len(words) > 2 and words[2] in SUITES)
    return False


@pytest.mark.parametrize("entry", MANIFEST, ids=[e["path"] for e in MANIFEST])
def test_each_record_exists_is_shown_and_has_its_commands(entry):
    path = ROOT / entry["path"]
    assert path.exists(), entry["path"]
    text = page_text(entry["page"])
    rel = path.relative_to(DOCS).as_posix()
    shown = (rel, Path(rel).parent.as_posix() if path.is_file() else rel, path.name)
    assert any(s in text for s in shown), f"{entry['page']} does not show {rel}"
    if entry["commands"] == "record":
        commands = record_commands(path)
        assert commands, f"{rel} names no command"
    else:
        commands = entry["commands"]
        for command in commands:
            assert " ".join(command.split()) in text, f"{entry['page']} lacks `{command}`"
    for command in commands:
        assert is_project_command(command), f"{rel}: `{command}` is not a command of the project"


def _entry_of(path: Path) -> str | None:
    for entry in MANIFEST:
        root = ROOT / entry["path"]
        if path == root or root in path.parents:
            return entry["path"]
    return None


def test_every_generated_file_is_in_a_record_and_small():
    files = generated_files()
    assert len(files) > 50
    left_out = [f.relative_to(ROOT).as_posix() for f in files if _entry_of(f) is None]
    assert not left_out, f"not in docs/records.yaml: {left_out}"
    large = {f.relative_to(ROOT).as_posix(): f.stat().st_size for f in files
             if f.stat().st_size > FILE_LIMIT}
    assert not large, f"larger than {FILE_LIMIT} bytes: {large}"
    agents = sum(f.stat().st_size for f in files if (DOCS / "agents") in f.parents
                 and REFERENCE not in f.parents)
    assert agents <= AGENTS_LIMIT, f"docs/agents holds {agents} bytes"


def test_each_reference_agent_is_under_its_limit():
    """A reference agent's directory stays under agents.reference.MAX_BYTES
    (2 MiB), and all of them under REFERENCE_LIMIT."""
    from agents.reference import MAX_BYTES

    sizes = {d.name: sum(f.stat().st_size for f in d.rglob("*") if f.is_file())
             for d in REFERENCE.iterdir() if d.is_dir()}
    assert sizes, "no reference agent"
    large = {name: n for name, n in sizes.items() if n > MAX_BYTES}
    assert not large, f"reference agents over {MAX_BYTES} bytes: {large}"
    assert sum(sizes.values()) <= REFERENCE_LIMIT


def test_a_regenerated_record_adds_less_than_a_megabyte():
    folders: dict[Path, int] = {}
    for f in generated_files():
        if (DOCS / "agents") not in f.parents:
            continue
        folders[f.parent] = folders.get(f.parent, 0) + f.stat().st_size
    assert (DOCS / "agents" / "leaderboard") in folders
    large = {d.relative_to(ROOT).as_posix(): n for d, n in folders.items()
             if n > RUN_RECORD_LIMIT}
    assert not large, f"records of more than {RUN_RECORD_LIMIT} bytes: {large}"


#: what marks a record of agents on a ship environment: its path names one,
#: or it is a leaderboard, its frames or the task table (or its commands run
#: a ship environment)
SHIP_RECORD = ("Ship", "leaderboard", "frames", "docs/agents/tasks")


def test_each_ship_record_names_its_engine_step():
    """The ship environments' default step changed from the exact to the
    fast one: every record of agents on them says which it ran, and no
    other record does."""
    for entry in MANIFEST:
        commands = entry["commands"] if isinstance(entry["commands"], list) else []
        ship = entry["path"].startswith("docs/agents") and (
            any(mark in entry["path"] for mark in SHIP_RECORD)
            or any("iceenvs/Ship" in c for c in commands))
        if ship:
            assert entry.get("step") in ("exact", "fast"), entry["path"]
        else:
            assert "step" not in entry, entry["path"]


def test_the_check_of_commands_can_fail():
    assert is_project_command("python -m agents.leaderboard --out runs/x")
    assert is_project_command("python -m physics.crosscheck all")
    assert is_project_command("seaice bench itd --docs")
    assert is_project_command("ice-scenarios run herman2013-miz")
    assert not is_project_command("python -m agents.no_such_module")
    assert not is_project_command("seaice bench no_such_suite")
    assert not is_project_command("cp a b")
