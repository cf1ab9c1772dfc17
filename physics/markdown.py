"""Markdown that the package writes: the tables of docstrings, summaries,
reports and benchmark records."""
from __future__ import annotations

__all__ = ["table_cell", "table_row"]


def table_cell(value) -> str:
    """``value`` as the text of one Markdown table cell: on one line, with
    its bars escaped, since a bar in the text (an absolute value, ``|x|``)
    would end the cell and shift the rest of the row."""
    return str(value).replace("|", "\\|").replace("\n", " ")


def table_row(cells) -> str:
    """One row of a Markdown table from its cells (see :func:`table_cell`)."""
    return "| " + " | ".join(table_cell(c) for c in cells) + " |"
