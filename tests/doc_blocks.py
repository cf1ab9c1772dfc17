"""The fenced code blocks of the README and the documentation pages, as a
reader meets them, and what it takes to run them.

A block is run according to its language tag: Python blocks (``python``)
in one namespace per page, shell blocks (``bash``, ``sh``, ``shell``,
``console``) with ``bash -e``. Blocks that show text, data or output, and
MyST directives (``{toctree}``, ``{include}``, ...), are not run. A block
that must not run is marked on the line right above its opening fence with
an HTML comment, which neither GitHub nor the site shows::

    <!-- doc-test: skip (takes 45 min; `make bench` runs it) -->

The reason in parentheses is required.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: language tags of blocks that run, and how
PYTHON_TAGS = {"python", "py"}
SHELL_TAGS = {"bash", "sh", "shell", "console"}
#: language tags of blocks that only show something (output, data, a layout)
SHOWN_TAGS = {"text", "yaml", "json", "toml", "ini", "output", "none", "markdown", "md"}

_MARKER = re.compile(r"^\s*<!--\s*doc-test:\s*(?P<body>.*?)\s*-->\s*$")
_SKIP = re.compile(r"^skip\s*(?:\((?P<reason>.*)\))?$")


@dataclass
class Block:
    """One fenced block: ``line`` is the 1-based line of its opening fence."""
    page: str
    line: int
    tag: str
    code: str
    skip: str | None = None          # the reason, if marked to be skipped

    @property
    def id(self) -> str:
        return f"{self.page}:L{self.line}"

    @property
    def kind(self) -> str:
        """"python", "shell", "shown" (not run) or "unknown"."""
        if self.tag in PYTHON_TAGS:
            return "python"
        if self.tag in SHELL_TAGS:
            return "shell"
        if self.tag in SHOWN_TAGS or self.tag.startswith("{"):
            return "shown"
        return "unknown"


@dataclass
class Page:
    name: str
    blocks: list[Block] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def parse_page(text: str, name: str) -> Page:
    """The fenced blocks of a Markdown text, and what is wrong with them: a
    fence with no language tag, a fence that is never closed, a Python
    block that does not compile, a ``doc-test`` marker that is malformed,
    has no reason or stands above no fence, a language nobody decided on."""
    from markdown_it import MarkdownIt

    lines = text.splitlines()
    page = Page(name)
    fences = {}
    for tok in MarkdownIt("commonmark").parse(text):
        if tok.type != "fence":
            continue
        start, end = tok.map
        where = f"{name}:L{start + 1}"
        tag = tok.info.split()[0] if tok.info.strip() else ""
        closing = lines[end - 1].strip() if end - 1 > start else ""
        if not (closing.startswith(tok.markup) and set(closing) == {tok.markup[0]}):
            page.problems.append(f"{where}: the fence opened here is never closed")
        if not tag:
            page.problems.append(
                f"{where}: a fence without a language tag (if this is meant to close a "
                f"block, the opening fence above it is missing)")
        block = Block(name, start + 1, tag, tok.content)
        if tag and block.kind == "unknown":
            page.problems.append(f"{where}: language {tag!r} is neither run nor known "
                                 f"as shown-only (tests/doc_blocks.py)")
        if block.kind == "python":
            try:
                compile(block.code, where, "exec")
            except SyntaxError as exc:
                page.problems.append(f"{where}: the Python block does not compile: {exc}")
        fences[start] = block
        page.blocks.append(block)
    for k, line in enumerate(lines):
        m = _MARKER.match(line)
        if not m:
            continue
        where = f"{name}:L{k + 1}"
        skip = _SKIP.match(m.group("body"))
        block = fences.get(k + 1)
        if skip is None:
            page.problems.append(f"{where}: unknown doc-test marker {m.group('body')!r} "
                                 f"(the one marker is `doc-test: skip (reason)`)")
        elif not (skip.group("reason") or "").strip():
            page.problems.append(f"{where}: a skip marker needs a reason in parentheses")
        elif block is None:
            page.problems.append(f"{where}: a skip marker must stand on the line right "
                                 f"above an opening fence")
        else:
            block.skip = skip.group("reason").strip()
    return page


def documentation_pages() -> list[Path]:
    """README.md and the Markdown pages of docs/ (not the generated ones)."""
    docs = ROOT / "docs"
    pages = [ROOT / "README.md"] + sorted(docs.glob("*.md")) + sorted(docs.glob("results/*.md"))
    return [p for p in pages if p.is_file()]


def page_name(path: Path) -> str:
    return path.name if path.parent in (ROOT, ROOT / "docs") else str(
        path.relative_to(ROOT / "docs"))


def load_pages() -> list[Page]:
    return [parse_page(p.read_text(encoding="utf-8"), page_name(p))
            for p in documentation_pages()]
