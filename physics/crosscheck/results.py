"""One row of a cross-check report, the table they make, and its figures."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..markdown import table_row

__all__ = ["Check", "format_table", "save_figure"]


@dataclass
class Check:
    """The outcome of one comparison.

    Attributes
    ----------
    name : short identifier, e.g. ``"binary/frictionless/harddisk-vs-law"``
    description : one sentence saying what was compared
    measured : the number compared with ``tolerance`` (an error, usually
        relative), or a speed for rows with ``tolerance=None``
    tolerance : the acceptance bound on ``measured`` (``measured <= tolerance``
        passes); ``None`` for rows that only report (speeds, ratios)
    unit : unit of ``measured`` ("" for relative numbers)
    detail : anything else worth printing (counts, sizes, explanations)
    figures : file names of the figures made for this row
    """

    name: str
    description: str
    measured: float
    tolerance: float | None = None
    unit: str = ""
    detail: str = ""
    figures: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool | None:
        if self.tolerance is None:
            return None
        return bool(math.isfinite(self.measured) and self.measured <= self.tolerance)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["passed"] = self.passed
        return d


def _num(x: float) -> str:
    if x is None:
        return "–"
    if x == 0 or (1e-3 <= abs(x) < 1e5):
        return f"{x:.4g}"
    return f"{x:.3e}"


def format_table(checks: list[Check]) -> str:
    """A Markdown table of the checks: name, measured, tolerance, verdict."""
    lines = ["| check | measured | tolerance | result | detail |",
             "| --- | --- | --- | --- | --- |"]
    for c in checks:
        verdict = {True: "pass", False: "**FAIL**", None: "report"}[c.passed]
        unit = f" {c.unit}" if c.unit else ""
        tol = "–" if c.tolerance is None else f"≤ {_num(c.tolerance)}{unit}"
        lines.append(table_row([c.name, f"{_num(c.measured)}{unit}", tol, verdict, c.detail]))
    return "\n".join(lines)


def save_figure(fig, out_dir: Path, name: str) -> str:
    """Save ``fig`` as ``out_dir/name`` (tight layout, 120 dpi, the
    scenarios' :func:`~physics.scenarios.plots.savefig`), creating the
    directory; returns ``name`` for :attr:`Check.figures`."""
    from ..scenarios.plots import savefig

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    savefig(fig, out_dir / name)
    return name
