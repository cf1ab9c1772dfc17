"""The benchmarks come with a source checkout and are not installed: the
package discovery of ``pyproject.toml`` leaves ``benchmarks`` out of the
distribution, and the suites find the checkout's files from their own
location, whatever the working directory."""
from __future__ import annotations

from pathlib import Path

import pytest

from benchmarks import harness, headline

ROOT = Path(__file__).resolve().parents[2]
#: the import packages the distribution installs
INSTALLED = {"physics", "iceenvs", "agents", "seaice_gym"}


def _toml():
    """``tomllib`` (Python 3.11+), else ``tomli``, else the test is skipped."""
    try:
        import tomllib
    except ModuleNotFoundError:
        tomllib = pytest.importorskip(
            "tomli", reason="reading pyproject.toml needs Python 3.11+ or tomli")
    return tomllib


def test_the_distribution_leaves_the_benchmarks_out():
    setuptools = pytest.importorskip("setuptools")
    config = _toml().loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    find = config["tool"]["setuptools"]["packages"]["find"]
    # the defaults setuptools applies to [tool.setuptools.packages.find]
    discover = (setuptools.find_namespace_packages if find.get("namespaces", True)
                else setuptools.find_packages)
    packages = [p for where in find.get("where", ["."])
                for p in discover(where=str(ROOT / where), include=find.get("include", ["*"]),
                                  exclude=find.get("exclude", []))]
    assert {p.split(".")[0] for p in packages} == INSTALLED
    assert "physics.scenarios" in packages and "agents.hyperparams" in packages


def test_records_cache_and_readme_default_to_the_checkout_from_anywhere(tmp_path, monkeypatch,
                                                                       capsys):
    monkeypatch.chdir(tmp_path)
    assert harness.ROOT.resolve() == ROOT
    args = harness.suite_parser("itd", "").parse_args([])
    assert args.json.resolve() == ROOT / "runs" / "benchmarks" / "itd.json"
    documented = harness.suite_parser("itd", "").parse_args(["--docs"])
    assert documented.json.resolve() == ROOT / "docs" / "benchmarks" / "itd.json"
    assert harness.CACHE_DIR.resolve() == ROOT / ".bench_cache"
    help_text = " ".join(harness.suite_parser("itd", "").format_help().split())
    assert "runs/benchmarks/itd.json of the checkout" in help_text
    assert "docs/benchmarks/itd.json of the checkout" in help_text
    assert str(tmp_path) not in help_text and str(ROOT) not in help_text
    with pytest.raises(SystemExit):
        headline.main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "(default README.md of the checkout)" in out
    assert "(default docs/benchmarks of the checkout)" in out
