"""Two finished runs of one scenario side by side, e.g. the same ensemble on
our engine and on LAMMPS: ``ice-scenarios compare REFERENCE OTHER``.

For every case and every per-member quantity it gives each run's ensemble
mean, standard deviation and range, and whether the other run's mean lies
within the ensemble spread of the reference::

    |mean_other − mean_ref| ≤ k σ,   σ = √(s_ref² + s_other²)

with s the standard deviation of the members (``ddof=1``; a run of one
member contributes none) and k = 2 by default. Two runs of one member each
have no spread, so no verdict.

The quantities are the scenario's per-member results (variables with the
dimensions (case, member), such as A_J) or, for a scenario that has none,
the means over the second half of each member's time series (such as p, τ
and Z_c under a steady wind, where the first half is the spin-up), and the
ratio p/τ of the means.

The two runs must be of the same scenario, with the same cases; parameters
that differ (floes, seeds, engine) are listed above the table.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .runner import load_run

#: time series that are coordinates of the others, not quantities
_AXES = ("time", "concentration")
#: ratios of two time means compared as quantities of their own (p/τ, the
#: stress ratio of Herman 2013)
_RATIOS = (("p", "tau"),)


@dataclass
class Row:
    """One quantity of one case in both runs."""
    case: str
    quantity: str
    reference: np.ndarray           # per-member values (finite ones)
    other: np.ndarray

    @property
    def spread(self) -> float:
        parts = [np.std(v, ddof=1) ** 2 for v in (self.reference, self.other) if v.size > 1]
        return math.sqrt(sum(parts)) if parts else math.nan

    @property
    def difference(self) -> float:
        if not (self.reference.size and self.other.size):
            return math.nan
        return float(np.mean(self.other) - np.mean(self.reference))

    def within(self, k: float) -> bool | None:
        """Whether the means differ by at most k σ (None without a spread)."""
        s, d = self.spread, self.difference
        if not (math.isfinite(s) and math.isfinite(d)):
            return None
        return abs(d) <= k * s


@dataclass
class Comparison:
    """The rows of :func:`compare_runs`, the runs' labels and what else
    differs between them."""
    reference: str
    other: str
    basis: str
    k: float
    rows: list[Row]
    differences: list[str] = field(default_factory=list)

    @property
    def outside(self) -> list[Row]:
        return [r for r in self.rows if r.within(self.k) is False]

    def markdown(self) -> str:
        lines = [f"reference: {self.reference}", f"other: {self.other}",
                 f"quantities: {self.basis}"]
        if self.differences:
            lines.append("parameters that differ: " + "; ".join(self.differences))
        lines += ["", f"| case | quantity | reference | other | difference / σ | "
                      f"within {self.k:g} σ |", "|---|---|---|---|---|---|"]
        for r in self.rows:
            s, d, ok = r.spread, r.difference, r.within(self.k)
            ratio = f"{d / s:+.2f}" if math.isfinite(s) and s > 0 and math.isfinite(d) else "–"
            verdict = "–" if ok is None else ("yes" if ok else "**no**")
            lines.append(f"| {r.case} | {r.quantity} | {_stats(r.reference)} | "
                         f"{_stats(r.other)} | {ratio} | {verdict} |")
        n_out, n = len(self.outside), sum(r.within(self.k) is not None for r in self.rows)
        lines += ["", f"{n - n_out} of {n} quantities within {self.k:g} σ"
                      + (f"; outside: {', '.join(f'{r.case} {r.quantity}' for r in self.outside)}"
                         if n_out else "") + "."]
        return "\n".join(lines)


def _stats(v: np.ndarray) -> str:
    if v.size == 0:
        return "–"
    if v.size == 1:
        return f"{v[0]:.4g} (1 member)"
    return (f"{np.mean(v):.4g} ± {np.std(v, ddof=1):.2g} ({v.size} members, "
            f"{v.min():.4g}–{v.max():.4g})")


def _label(directory, info: dict) -> str:
    engine = info.get("engine", "numba")
    ranks = info.get("mpi_ranks")
    where = f"LAMMPS on {ranks or 1} MPI rank(s)" if engine == "lammps" else "our engine"
    return f"{directory} ({where}, {info.get('ensemble', 1)} member(s))"


def _case_labels(ds) -> list[str]:
    n = ds.sizes.get("case", 1)
    coords = [name for name, c in ds.coords.items() if c.dims == ("case",) and name != "case"]
    if not coords:
        return [str(c) for c in range(n)]
    return [", ".join(f"{name} = {ds[name].values[c]:.4g}"
                      if np.issubdtype(ds[name].dtype, np.number)
                      else f"{name} = {ds[name].values[c]}" for name in coords)
            for c in range(n)]


def _per_member(ds) -> tuple[str, dict[str, np.ndarray]]:
    """(basis, {quantity: (case, member) array})."""
    scalars = {name: v.values for name, v in ds.data_vars.items()
               if v.dims == ("case", "member") and np.issubdtype(v.dtype, np.floating)}
    if scalars:
        return "the per-member results of the scenario", scalars
    if "time" not in ds:
        raise ValueError("the runs hold neither per-member results nor time series")
    t = ds["time"].values                                   # (case, member, sample)
    end = np.nanmax(t, axis=-1, keepdims=True)
    second_half = np.isfinite(t) & (t >= 0.5 * end)
    means = {}
    for name, v in ds.data_vars.items():
        if v.dims != ("case", "member", "sample") or name in _AXES \
                or not np.issubdtype(v.dtype, np.floating):
            continue
        x = np.where(second_half, v.values, np.nan)
        with np.errstate(invalid="ignore"):
            means[name] = np.nanmean(x, axis=-1)
    for num, den in _RATIOS:
        if num in means and den in means:
            with np.errstate(divide="ignore", invalid="ignore"):
                means[f"{num}/{den}"] = means[num] / means[den]
    return "time means over the second half of each member's run", means


def compare_runs(reference, other, *, k: float = 2.0,
                 quantities: list[str] | None = None) -> Comparison:
    """Compare two finished run directories (see the module docstring)."""
    if not (isinstance(k, (int, float)) and k > 0):
        raise ValueError(f"k must be a positive number of standard deviations, got {k!r}")
    ref_dir, ref_info, _, ref = load_run(reference)
    oth_dir, oth_info, _, oth = load_run(other)
    if ref_info["scenario"] != oth_info["scenario"]:
        raise ValueError(f"the runs are of different scenarios: {ref_info['scenario']} "
                         f"({ref_dir}) and {oth_info['scenario']} ({oth_dir})")
    labels = _case_labels(ref)
    if labels != _case_labels(oth):
        raise ValueError(f"the runs have different cases: {labels} and {_case_labels(oth)}")
    basis, a = _per_member(ref)
    _, b = _per_member(oth)
    names = [q for q in a if q in b]
    if quantities:
        unknown = [q for q in quantities if q not in names]
        if unknown:
            raise ValueError(f"unknown quantit{'y' if len(unknown) == 1 else 'ies'} "
                             f"{', '.join(unknown)}; valid: {', '.join(names)}")
        names = list(quantities)
    rows = []
    for c, case in enumerate(labels):
        for q in names:
            x, y = np.asarray(a[q][c], float), np.asarray(b[q][c], float)
            rows.append(Row(case, q, x[np.isfinite(x)], y[np.isfinite(y)]))
    differences = []
    p, q = ref_info.get("parameters", {}), oth_info.get("parameters", {})
    for key in sorted(set(p) | set(q)):
        if p.get(key) != q.get(key):
            differences.append(f"{key}: {p.get(key)!r} / {q.get(key)!r}")
    for key in ("engine", "mpi_ranks", "ensemble", "seed"):
        if ref_info.get(key) != oth_info.get(key):
            differences.append(f"{key}: {ref_info.get(key)!r} / {oth_info.get(key)!r}")
    return Comparison(_label(Path(reference), ref_info), _label(Path(other), oth_info), basis,
                      float(k), rows, differences)
