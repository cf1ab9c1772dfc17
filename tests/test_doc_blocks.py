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

import pytest

pytest.importorskip("markdown_it", reason="markdown-it-py comes with the docs extra")

from doc_blocks import OWN_MODULE_PAGES, block_tests, load_pages, parse_page

ALL_PAGES = load_pages()
#: the pages whose blocks this module runs (the others have modules of their
#: own, so that the test processes share the work)
page_runs, test_block_runs = block_tests(
    [p for p in ALL_PAGES if p.name not in OWN_MODULE_PAGES])


@pytest.mark.parametrize("page", ALL_PAGES, ids=[p.name for p in ALL_PAGES])
def test_page_structure(page):
    """Every fence is tagged and closed, every Python block compiles, every
    skip has a reason."""
    assert not page.problems, "\n".join(page.problems)


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
