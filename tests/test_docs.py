"""The documentation site builds without warnings, its generated pages are
there, and the README stays short with working links."""
from __future__ import annotations

import html
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks.harness import load_records

pytest.importorskip("sphinx")
pytest.importorskip("myst_parser")
pytest.importorskip("sphinx-mathjax-offline")

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README_LIMIT = 12 * 1024
# spelled in two parts so that this file does not name it
OUTSIDE_BRIEF = "PHYSICS" + ".md"
# never part of the project: version control, environments, build output
SKIP_DIRS = {".git", ".venv", "_build", "_generated", "__pycache__", ".pytest_cache",
             ".hypothesis", "runs", ".bench_cache", "build", "dist"}


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built from a copy of docs/ (so that the frames are rendered
    afresh and nothing is written into the work tree), warnings as errors."""
    work = tmp_path_factory.mktemp("docs")
    src = work / "docs"
    shutil.copytree(DOCS, src, ignore=shutil.ignore_patterns("_build", "_generated"))
    out = work / "html"
    env = dict(os.environ, SEAICE_QUIET="1", SEAICE_DOCS_OFFLINE="1")
    done = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         str(src), str(out)],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, f"the site does not build cleanly:\n{done.stderr[-6000:]}"
    return out


def test_every_environment_has_a_generated_page_with_a_frame(site):
    import iceenvs

    for env_id in iceenvs.ENV_IDS:
        name = env_id.split("/")[-1]
        page = site / "_generated" / "environments" / f"{name}.html"
        assert page.is_file(), f"no page for {env_id}"
        text = page.read_text(encoding="utf-8")
        assert env_id in text
        images = re.findall(r'<img[^>]*src="([^"]+)"', text)
        assert images, f"the page of {env_id} has no image"
        assert any((page.parent / src).is_file() and (page.parent / src).stat().st_size > 1000
                   for src in images), f"the frame of {env_id} is missing or empty"
        # the specification comes from the class docstring, not from a copy
        assert "Rewards" in text and "Task parameters" in text


def test_benchmarks_page_shows_the_tables_of_the_records(site):
    records = load_records(DOCS / "benchmarks")
    assert records, "no benchmark record in docs/benchmarks"
    page = (site / "benchmarks.html").read_text(encoding="utf-8")
    # the page's words without the markup (a title's `code` is set in tags),
    # Sphinx's smart quotes printing an apostrophe as a typographic one
    text = html.unescape(re.sub(r"<[^>]+>", "", page)).replace("’", "'")
    n_tables = 0
    for record in records:
        assert record["title"].replace("`", "") in text, record["title"]
        for table in record["tables"]:
            n_tables += 1
            assert table["title"].replace("`", "") in text, table["title"]
            for column in table["columns"]:
                assert str(column).strip("`") in text, column
    assert page.count("<table") >= n_tables


def test_docstring_labels_resolve_to_the_physics_page(site):
    text = (site / "physics.html").read_text(encoding="utf-8")
    for label in ("physics-fsd", "physics-drag", "physics-harddisk", "physics-contact",
                  "physics-observables", "physics-itd"):
        assert f'id="{label}"' in text, label


def test_math_loads_mathjax_from_the_site_itself(site):
    """Equations render offline: every page that loads MathJax loads it from
    a file of the built site, and no page loads a script from the network."""
    pages = sorted(site.rglob("*.html"))
    with_math = []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        sources = re.findall(r'<script[^>]*\bsrc="([^"]+)"', text)
        remote = [s for s in sources if re.match(r"(https?:)?//", s)]
        assert not remote, f"{page.relative_to(site)} loads scripts from the network: {remote}"
        mathjax = [s for s in sources if "mathjax" in s.lower()]
        if mathjax:
            with_math.append(page.name)
            for src in mathjax:
                script = (page.parent / src.split("?")[0]).resolve()
                assert script.is_file() and site.resolve() in script.parents, \
                    f"{page.relative_to(site)} loads MathJax from {src}, not a file of the site"
                assert "MathJax" in script.read_text(encoding="utf-8", errors="replace")
    # the physics page is mostly equations: it has math and so loads MathJax
    assert "\\(" in (site / "physics.html").read_text(encoding="utf-8")
    assert "physics.html" in with_math


def _project_files() -> list[Path]:
    try:
        listed = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"],
                                cwd=ROOT, capture_output=True, text=True, check=True).stdout
        files = [ROOT / line for line in listed.splitlines() if line]
    except (OSError, subprocess.CalledProcessError):
        files = [p for p in ROOT.rglob("*") if p.is_file()]
    return [p for p in files if p.is_file()
            and not SKIP_DIRS.intersection(p.relative_to(ROOT).parts)
            and not any(part.endswith(".egg-info") for part in p.relative_to(ROOT).parts)]


def test_no_file_refers_to_a_document_outside_the_project():
    needle = OUTSIDE_BRIEF.encode()
    offenders = [str(p.relative_to(ROOT)) for p in _project_files() if needle in p.read_bytes()]
    assert not offenders, f"{OUTSIDE_BRIEF} is named in {offenders}"


def test_readme_is_short():
    size = (ROOT / "README.md").stat().st_size
    assert size <= README_LIMIT, f"README.md is {size} bytes, more than {README_LIMIT}"


def test_the_navigation_page_stays_a_stable_page():
    """The task, its fields, the planners and how to score a policy of one's
    own, in at most 400 lines; the history of the PPO runs has its own page."""
    page = (DOCS / "navigation.md").read_text(encoding="utf-8")
    assert len(page.splitlines()) <= 400
    assert page.index("## Evaluate your own policy") < page.index("## The task")
    assert "{doc}`navigation-ppo`" in page


def test_readme_links_resolve():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)\s]+)\)", text) + re.findall(r'src="([^"]+)"', text)
    local = [t for t in targets if not re.match(r"[a-z]+:", t) and not t.startswith("#")]
    assert local, "the README links into the documentation"
    missing = [t for t in local if not (ROOT / t.split("#")[0]).exists()]
    assert not missing, f"README links to missing files: {missing}"


def test_readme_names_every_bundled_scenario_and_counts_them():
    from physics.scenarios.config import bundled_configs

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    found = re.search(r"`ice-scenarios list` names the (\w+) scenarios:(.*?)`ice-scenarios show",
                      text, re.S)
    assert found, "the README's Scenarios section no longer lists the scenarios"
    named = re.findall(r"`([\w-]+)`", found.group(2))
    assert sorted(named) == sorted(bundled_configs())
    words = "zero one two three four five six seven eight nine ten eleven twelve".split()
    assert found.group(1) == words[len(named)]
