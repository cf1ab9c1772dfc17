"""``python -m benchmarks.bench_compare``: the old revision's worktree is made
and always removed, and a quick comparison runs each workload on both
trees, the packages of each imported from its own tree."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest

from benchmarks import bench_compare, harness

REPO = Path(bench_compare.__file__).resolve().parents[1]


def _worktrees() -> str:
    return subprocess.run(["git", "worktree", "list"], cwd=REPO, capture_output=True,
                          text=True, check=True).stdout


def _has_history(rev: str) -> bool:
    return subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"],
                          cwd=REPO, capture_output=True).returncode == 0


pytestmark = pytest.mark.skipif(not (REPO / ".git").exists() or not _has_history("HEAD"),
                                reason="needs the project's git history")


def test_worktree_is_removed_after_an_error():
    tree = bench_compare.Worktree("HEAD")
    with pytest.raises(KeyboardInterrupt):
        with tree as path:
            assert (path / "physics" / "__init__.py").is_file()
            assert str(path) in _worktrees()
            stamp = float(subprocess.run(["git", "show", "-s", "--format=%ct", tree.sha],
                                         cwd=REPO, capture_output=True, text=True).stdout)
            assert (path / "physics" / "hertz.py").stat().st_mtime == stamp
            child = harness.Child(harness.module_file, ("physics",), source=path)
            assert Path(child.result()).resolve() == (path / "physics" / "__init__.py").resolve()
            raise KeyboardInterrupt
    assert not path.exists() and str(path) not in _worktrees()


def test_bad_revision_and_suites_are_refused(tmp_path):
    with pytest.raises(SystemExit):
        bench_compare.main(["--against", "no-such-revision-xyz", "--no-json"])
    with pytest.raises(SystemExit):
        bench_compare.main(["--against", "HEAD", "--suites", "hertz,nope", "--no-json"])
    with pytest.raises(SystemExit):
        bench_compare.main(["--against", "HEAD", "--rounds", "0", "--no-json"])


@pytest.mark.slow
def test_quick_comparison_against_head(tmp_path):
    """Hard discs and one environment, two rounds, against HEAD (a minute
    or more: the old tree's kernels compile on first use)."""
    path = tmp_path / "compare.json"
    assert bench_compare.main(["--against", "HEAD", "--quick", "--quiet", "--rounds", "2",
                         "--suites", "harddisk,environments", "--ids", "ThicknessDistribution-v0",
                         "--json", str(path)]) == 0
    record = json.loads(path.read_text())
    harness.validate_record(record)
    assert record["title"] == "This commit against HEAD"
    (t,) = record["tables"]
    assert len(t["rows"]) == 3 and all(len(r) == len(t["columns"]) for r in t["rows"])
    for res in record["data"]["results"]:
        assert len(res["old"]) == len(res["new"]) == len(res["ratios"]) == 2
        assert res["ratio_min"] <= res["ratio_median"] <= res["ratio_max"]
    sha = record["data"]["old_commit"][:7]
    assert record["data"]["imported_from"] == {
        "old": {"physics": f"{sha}:physics/__init__.py", "iceenvs": f"{sha}:iceenvs/__init__.py"},
        "new": {"physics": "this tree:physics/__init__.py",
                "iceenvs": "this tree:iceenvs/__init__.py"}}
    assert "seaice-compare" not in _worktrees()
