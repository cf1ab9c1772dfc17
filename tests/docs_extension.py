"""The documentation's Sphinx extension (``docs/_ext/seaice_docs.py``)
loaded as a module, for the tests that check what it generates from the
benchmark records: the one loader they share."""
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def docs_extension():
    """The extension module (the test is skipped without Sphinx and
    matplotlib, which it needs)."""
    pytest.importorskip("sphinx")
    pytest.importorskip("matplotlib")
    spec = importlib.util.spec_from_file_location("seaice_docs_under_test",
                                                  ROOT / "docs" / "_ext" / "seaice_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def benchmarks_page(records: Path, out: Path):
    """(the extension, the generated Benchmarks page's text) for the
    records in ``records``, generated under ``out``."""
    docs = docs_extension()
    docs.generate_benchmarks(out, records)
    return docs, (out / "include" / "benchmarks.md").read_text(encoding="utf-8")
