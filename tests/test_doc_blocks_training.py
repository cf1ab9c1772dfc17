"""The blocks of docs/training.md and docs/training-agents.md, run as
``tests/test_doc_blocks.py`` runs those of the other pages: each
documented training in its small form (a few hundred steps, a few
episodes), in page order. A module of its own so that the test processes
share the pages' work."""
from __future__ import annotations

import pytest

pytest.importorskip("markdown_it", reason="markdown-it-py comes with the docs extra")

from doc_blocks import block_tests, load_pages

page_runs, test_block_runs = block_tests(
    [p for p in load_pages() if p.name in ("training.md", "training-agents.md")])
