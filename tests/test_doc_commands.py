"""What the documentation's code blocks cover: most of them run in the
tests, and the commands of those that do not (full runs of minutes to
hours, given beside the small form that runs) still parse and name
scenarios, parameters and options that exist.

A block that runs for minutes or hours shows its small form as the
commands that run, and its full form as comment lines, each one command as
a reader would type it once the ``# `` is taken away::

    # the run reported below (45 min on 2 cores):
    # ice-scenarios run herman2013-convergence --set start_concentration=0.85
    ice-scenarios run herman2013-convergence --quick --set start_concentration=0.85
"""
from __future__ import annotations

import argparse
import contextlib
import importlib
import io
import re
import shlex

import pytest

pytest.importorskip("markdown_it", reason="markdown-it-py comes with the docs extra")

from doc_blocks import Block, load_pages, parse_page

#: the least share of the code blocks (Python and shell) that run in the tests
RUN_SHARE = 0.60
#: modules run as ``python -m MODULE`` whose ``build_parser()`` reads a command line
PARSED_MODULES = ("agents.train", "agents.evaluate", "agents.leaderboard", "agents.frames",
                  "agents.constant")
#: words that end a command on a shell line (a redirection, a pipe, a list)
SHELL_OPERATORS = {">", ">>", "|", "&&", "||", ";", "2>"}
PROJECT_PACKAGES = ("agents", "iceenvs", "physics", "benchmarks", "seaice_gym")
_COMMAND = re.compile(r"^(?:\.venv/bin/)?(ice-scenarios|python -m [\w.]+)\b")


def code_blocks(pages) -> list[Block]:
    return [b for page in pages for b in page.blocks if b.kind in ("python", "shell")]


def share_that_runs(pages) -> tuple[int, int]:
    blocks = code_blocks(pages)
    return sum(not b.skip for b in blocks), len(blocks)


def test_most_code_blocks_run():
    pages = load_pages()
    ran, total = share_that_runs(pages)
    per_page = "\n".join(f"  {p.name}: {share_that_runs([p])[0]} of {share_that_runs([p])[1]}"
                         for p in pages if code_blocks([p]))
    assert ran / total >= RUN_SHARE, (
        f"{ran} of {total} code blocks run in the tests ({ran / total:.0%}), fewer than "
        f"{RUN_SHARE:.0%}; give a long block its small form (see this module's docstring):\n"
        f"{per_page}")


def block_commands(block: Block) -> list[str]:
    """The commands of a shell block that name a command of the project, in
    its small and its full form (comment lines that hold a command): lines
    continued with a backslash joined, trailing comments dropped. Lines
    built by the shell (``$(...)``) are left out; a ``$variable`` stands
    for a word."""
    uncommented = "\n".join(line.strip().lstrip("#").strip() if line.strip().startswith("#")
                            else line for line in block.code.splitlines())
    out = []
    for line in uncommented.replace("\\\n", " ").splitlines():
        line = re.sub(r"\s+", " ", line.strip())
        if not _COMMAND.match(line) or "$(" in line:
            continue
        words = shlex.split(re.sub(r"\$\w+", "WORD", line), comments=True)
        cut = [k for k, w in enumerate(words) if w in SHELL_OPERATORS]
        words = words[:cut[0]] if cut else words           # the command, not what follows it
        if words[0].startswith(".venv/bin/"):
            words[0] = words[0].removeprefix(".venv/bin/")
        out.append(shlex.join(words))
    return out


def command_problem(command: str) -> str | None:
    """Why ``command`` would be refused before it ran, or None: a bad option
    or value (its parser), or, for ``ice-scenarios run``, a scenario, a
    ``--set`` parameter or a value out of its range."""
    words = shlex.split(command)
    if words[0] == "ice-scenarios":
        from physics.scenarios.cli import build_parser

        parser, args_of = build_parser(), words[1:]
    elif words[:2] == ["python", "-m"] and words[2] in PARSED_MODULES:
        parser, args_of = importlib.import_module(words[2]).build_parser(), words[3:]
    else:
        return None
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err):
            args = parser.parse_args(args_of)
    except SystemExit:
        message = err.getvalue().strip().splitlines()[-1]
        own = re.search(r"cannot import '(\w+)'", message)
        # a reader's own module (``--env calm:mytasks/Calm-v0``) is theirs to give
        return None if own and own.group(1) not in PROJECT_PACKAGES else message
    if words[0] == "ice-scenarios" and args.command == "run" and args.name:
        return scenario_problem(args)
    return None


def scenario_problem(args: argparse.Namespace) -> str | None:
    from physics.scenarios import find_config, get_experiment
    from physics.scenarios.config import parse_set

    try:
        cfg = find_config(args.name)
    except (FileNotFoundError, ValueError) as exc:
        return None if args.name.endswith(".yaml") else str(exc)   # a reader's own file
    try:
        overrides = parse_set(args.set)
        if args.floes is not None:
            overrides["floes"] = args.floes
        params = cfg.resolve(overrides, quick=args.quick)
        if not get_experiment(cfg.name).cases(params):
            return "nothing to run"
    except (ValueError, KeyError) as exc:
        return str(exc)
    return None


def test_every_documented_command_parses():
    """Each command in a shell block, run or not, small form or full,
    would start."""
    commands = [(b.id, c) for b in code_blocks(load_pages()) if b.kind == "shell"
                for c in block_commands(b)]
    assert len(commands) > 100
    problems = [f"{where}: {c}\n    {why}" for where, c in commands
                if (why := command_problem(c)) is not None]
    assert not problems, "\n".join(problems)


def test_the_command_check_can_fail():
    page = parse_page(
        "```bash\n"
        "# the full run (an hour):\n"
        "# ice-scenarios run herman2013-miz --floes 2000 \\\n"
        "#     --set durration=10800\n"
        "ice-scenarios run herman2013-miz --quick\n"
        "python -m agents.train --env iceenvs/Convergence-v0 --algo ppo \\\n"
        "    --timesteps ten   # a comment\n"
        "ice-scenarios run herman2013-wind --set concentrations=[1.5]\n"
        "```\n", "p.md")
    commands = block_commands(page.blocks[0])
    assert commands[1] == "ice-scenarios run herman2013-miz --quick"
    assert commands[2].endswith("--timesteps ten")
    problems = [command_problem(c) for c in commands]
    assert "durration" in problems[0]
    assert problems[1] is None
    assert "--timesteps" in problems[2]
    assert problems[3] is not None


def test_the_share_is_counted_by_block():
    page = parse_page("```bash\nls\n```\n\n<!-- doc-test: skip (an hour) -->\n```bash\nx\n```\n"
                      "\n```text\nshown\n```\n", "p.md")
    assert share_that_runs([page]) == (1, 2)
