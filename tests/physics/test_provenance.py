"""physics.provenance: the commit a record names."""
import shutil
import subprocess

import pytest

from physics.provenance import MODIFIED, source_commit

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="needs git")


def _git(root, *args):
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "-C", str(root), *args],
                   check=True, capture_output=True)


def test_the_commit_of_a_checkout_and_its_changes(tmp_path):
    assert source_commit(tmp_path) is None                    # not a checkout
    _git(tmp_path, "init", "-q")
    (tmp_path / "a.txt").write_text("one\n")
    _git(tmp_path, "add", "a.txt")
    _git(tmp_path, "commit", "-q", "-m", "first")
    head = subprocess.run(["git", "-C", str(tmp_path), "rev-parse", "HEAD"],
                          capture_output=True, text=True, check=True).stdout.strip()
    assert source_commit(tmp_path) == head[:12]
    (tmp_path / "a.txt").write_text("two\n")                  # a tracked file changed
    assert source_commit(tmp_path) == head[:12] + MODIFIED
    (tmp_path / "b.txt").write_text("new\n")                  # an untracked one does not count
    (tmp_path / "a.txt").write_text("one\n")
    assert source_commit(tmp_path) == head[:12]
