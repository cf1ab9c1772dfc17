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

import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: pages whose blocks run in a test module of their own
#: (``tests/test_doc_blocks_<stem>.py``), so that the test processes share them
OWN_MODULE_PAGES = ("reproduction.md", "training.md", "training-agents.md")

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


# -- running them ------------------------------------------------------------------------

#: the longest a single block may take [s]; the budget of all of them is
#: a few minutes on two cores, so this only catches a block that hangs
BLOCK_TIMEOUT = 600
QUIET_ENV = {"MPLBACKEND": "Agg", "SEAICE_QUIET": "1", "TQDM_MININTERVAL": "5"}
_CHECKOUT_PATH = re.compile(
    r"(?<![\w./-])((?:docs|physics|iceenvs|agents|benchmarks|seaice_gym)/[\w./-]*\w)")


class PageRun:
    """The state a reader builds up on one page: the working directory, the
    Python namespace, the blocks run so far and the first that failed."""

    def __init__(self, page: Page, directory: Path):
        self.page = page
        self.dir = directory
        self.namespace: dict = {"__name__": "__main__"}
        self.done: set[int] = set()
        self.failed: Block | None = None

    def run_through(self, block: Block, monkeypatch) -> None:
        """Run the page's blocks up to ``block`` that have not run yet (so a
        block selected alone still sees what the page defined before it),
        then ``block``; a failure is remembered and raised."""
        for b in self.page.blocks:
            if b.line in self.done or b.skip or b.kind not in ("python", "shell"):
                if b is block:
                    break
                continue
            if self.failed is not None:
                pytest.skip(f"an earlier block of the page failed: {self.failed.id}")
            self.done.add(b.line)
            try:
                self._run(b, monkeypatch)
            except BaseException:
                self.failed = b
                raise
            if b is block:
                break

    def _run(self, block: Block, monkeypatch) -> None:
        for rel in _CHECKOUT_PATH.findall(block.code):
            src, dst = ROOT / rel, self.dir / rel
            if src.exists() and not dst.exists():
                dst.parent.mkdir(parents=True, exist_ok=True)
                (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
        start = time.perf_counter()
        if block.kind == "python":
            run_python(block, self.namespace, self.dir, monkeypatch)
        else:
            run_shell(block, self.dir)
        print(f"{block.id}: {time.perf_counter() - start:.1f} s")


def run_python(block: Block, namespace: dict, directory: Path, monkeypatch) -> None:
    """``exec`` the block, compiled so that tracebacks name the page and its
    own line numbers, in ``directory``."""
    monkeypatch.chdir(directory)
    for key, value in QUIET_ENV.items():
        monkeypatch.setenv(key, value)
    if "matplotlib" in sys.modules:
        import matplotlib

        matplotlib.use("Agg")
    source = "\n" * block.line + block.code
    path = ROOT / "docs" / block.page if block.page != "README.md" else ROOT / "README.md"
    exec(compile(source, str(path), "exec"), namespace)


def shell_script(block: Block) -> str:
    """The commands of a shell block (a ``console`` block: the lines after
    its ``$`` prompts)."""
    if block.tag != "console":
        return block.code
    return "\n".join(line[2:] for line in block.code.splitlines() if line.startswith("$ "))


def run_shell(block: Block, directory: Path) -> None:
    env = dict(os.environ, **QUIET_ENV)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env["PYTHONPATH"] = str(ROOT)
    done = subprocess.run(["bash", "-e", "-c", shell_script(block)], cwd=directory, env=env,
                          capture_output=True, text=True, timeout=BLOCK_TIMEOUT)
    print(done.stdout[-3000:])
    if done.returncode != 0:
        pytest.fail(f"{block.id}: exit status {done.returncode}\n"
                    f"--- stdout (end)\n{done.stdout[-3000:]}\n"
                    f"--- stderr (end)\n{done.stderr[-3000:]}", pytrace=False)


def page_runs_of(pages: list[Page], tmp_path_factory) -> dict[str, PageRun]:
    """A fresh working directory and namespace for each page."""
    return {page.name: PageRun(page, tmp_path_factory.mktemp(re.sub(r"\W", "_", page.name)))
            for page in pages}


def run_block(block: Block, page_runs: dict[str, PageRun], monkeypatch) -> None:
    """The test of one block: skipped with its page's reason, or run after
    the blocks above it."""
    if block.skip:
        pytest.skip(f"marked in the page: {block.skip}")
    page_runs[block.page].run_through(block, monkeypatch)


def block_tests(pages: list[Page]):
    """The module-scoped ``page_runs`` fixture and the ``test_block_runs``
    test of ``pages``' blocks, for a test module to bind at its top level::

        page_runs, test_block_runs = block_tests(pages)
    """
    blocks = [b for page in pages for b in page.blocks if b.kind in ("python", "shell")]

    @pytest.fixture(scope="module")
    def page_runs(tmp_path_factory):
        return page_runs_of(pages, tmp_path_factory)

    @pytest.mark.parametrize("block", blocks, ids=[b.id for b in blocks])
    def test_block_runs(block, page_runs, monkeypatch):
        run_block(block, page_runs, monkeypatch)

    return page_runs, test_block_runs
