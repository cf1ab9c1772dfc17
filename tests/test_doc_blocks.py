"""Every fenced code block of README.md and of the documentation pages runs,
in page order, as a reader would run it.

One test per block, named ``PAGE:L<line of the opening fence>``. The Python
blocks of a page share one namespace (one interpreter session); each page
works in a fresh directory of its own, so what its blocks write lands
there. Shell blocks run with ``bash -e`` in that directory, with this
interpreter's ``bin`` first on ``PATH`` and the checkout on ``PYTHONPATH``,
so ``ice-scenarios`` and ``seaice`` run the code of this checkout. Files of
the checkout that a block names by their path from its root (such as
``docs/agents/.../evaluation.json``) are copied into the directory first,
so that such a block reads them and writes nothing into the checkout.

Blocks marked ``<!-- doc-test: skip (reason) -->`` (``tests/doc_blocks.py``)
are reported as skipped with their reason; a block after one that failed
is skipped with a pointer to the failure.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("markdown_it", reason="markdown-it-py comes with the docs extra")

from doc_blocks import ROOT, Block, Page, load_pages, parse_page

PAGES = load_pages()
BLOCKS = [b for page in PAGES for b in page.blocks if b.kind in ("python", "shell")]
#: the longest a single block may take [s]; the budget of all of them is
#: about 90 s on two cores, so this only catches a block that hangs
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


@pytest.fixture(scope="module")
def page_runs(tmp_path_factory):
    runs = {page.name: PageRun(page, tmp_path_factory.mktemp(
        re.sub(r"\W", "_", page.name))) for page in PAGES}
    yield runs


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_page_structure(page):
    """Every fence is tagged and closed, every Python block compiles, every
    skip has a reason."""
    assert not page.problems, "\n".join(page.problems)


@pytest.mark.parametrize("block", BLOCKS, ids=[b.id for b in BLOCKS])
def test_block_runs(block, page_runs, monkeypatch):
    if block.skip:
        pytest.skip(f"marked in the page: {block.skip}")
    page_runs[block.page].run_through(block, monkeypatch)


# -- the checker itself ------------------------------------------------------------------

#: the "A first environment" section of docs/getting-started.md as it once
#: was: its opening fence and imports were lost, so the closing fence opened
#: an untagged block and every later fence of the page was read inside out
BROKEN_FIRST_ENVIRONMENT = '''\
## A first environment


env = gym.make("iceenvs/WindDrift-v0", render_mode="rgb_array", heading=0.5)
obs, info = env.reset(seed=42)
done = False
while not done:
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    done = terminated or truncated
print(info["physics"], info["task"])   # the observables in SI units, the episode's task
plt.imsave("wind_drift.png", env.render())
env.close()
```

Every environment's class docstring is its specification (Description,
Task analysis, Action Space, Observation Space table, Rewards, Starting
State, Task parameters, Episode End, Arguments, Version History):
`help(gym.make("iceenvs/WindDrift-v0").unwrapped)`.


{doc}`environments` has one page per environment: its task, spaces, rewards
and a rendered frame.

## A first scenario

```bash
ice-scenarios list                                   # the scenarios
ice-scenarios run herman2013-convergence --quick     # the reduced form: seconds
```
'''


def test_checker_finds_the_lost_opening_fence():
    problems = parse_page(BROKEN_FIRST_ENVIRONMENT, "old.md").problems
    assert problems == ["old.md:L13: a fence without a language tag (if this is meant to close "
                        "a block, the opening fence above it is missing)"]


def test_checker_accepts_the_same_section_repaired():
    fixed = BROKEN_FIRST_ENVIRONMENT.replace(
        "\n\nenv = gym.make", "\n\n```python\nimport gymnasium as gym\nenv = gym.make", 1)
    page = parse_page(fixed, "new.md")
    assert not page.problems, page.problems
    assert [(b.line, b.tag) for b in page.blocks] == [(4, "python"), (28, "bash")]


def test_checker_finds_skips_without_reason_and_code_that_does_not_compile():
    text = ("<!-- doc-test: skip -->\n```bash\nmake demo\n```\n\n"
            "<!-- doc-test: skip (needs a cluster) -->\n```bash\nsrun x\n```\n\n"
            "```python\nsim.advance(\n```\n\n```pyhton\nx = 1\n```\n")
    page = parse_page(text, "p.md")
    assert page.blocks[1].skip == "needs a cluster" and page.blocks[0].skip is None
    assert any("p.md:L1: a skip marker needs a reason" in p for p in page.problems)
    assert any("p.md:L11: the Python block does not compile" in p for p in page.problems)
    assert any("language 'pyhton'" in p for p in page.problems)
    assert len(page.problems) == 3, page.problems


def test_checker_finds_a_fence_left_open():
    problems = parse_page("text\n\n```bash\nls\n\nmore text\n", "p.md").problems
    assert problems == ["p.md:L3: the fence opened here is never closed"]
