"""Godlovitch et al.: the ice thickness distribution as a coagulation
process, Figs 4–7, as scenarios.

* ``godlovitch-kernels`` (Fig. 4) — the generalised Thorndike model
  (:class:`physics.itd.ThorndikeModel`) with the four kernels of Table 1
  (constant, exponential, multiplicative, additive) from open water, daily
  steps; one case per kernel. Result: the e-folding thickness λ of the tail
  above 2 m and the R² of its log-linear fit at the last day.
* ``godlovitch-rafting`` (Fig. 5) — constant kernel r0 with rafting (K =
  factor · r0 where both floes are thinner than the cut-off h_R) for several
  cut-offs, and without rafting (case ``h_raft = 0``). Result: how fast the
  tail forms (the day λ first reaches a fixed target, the day the ice
  volume above 2 m and 5 m first reaches 90 % of its mean over the last
  year), the final λ and R².
* ``godlovitch-thermo`` (Fig. 6) — constant kernel K = r0/R_T for several
  relative strengths R_T of thermodynamics against stacking. Result: λ and
  R² at the end, and the seasonal cycle over the last year (amplitude of the
  mean thickness, range of λ).
* ``scm-analytic`` (Fig. 7) — pure Smoluchowski coagulation with K = 1 from
  u_1(0) = 1 against the exact u_k(t) = (1 + t/2)^(−2) (t/(2 + t))^(k−1).

The constants (kernel rates, rafting factor and cut-offs, relative
strengths, the Fig. 7 settings) are those of the :data:`physics.params.GODLOVITCH`
preset, and the configuration files' defaults equal them. The kernel rates
are tuned so that every kernel gives a tail with λ = 1.0 m after 2000 days
(:func:`tune_rate` repeats the tuning). The Thorndike-model runs record
time in days (day 0 is mid-winter) every ``output_every`` days: g(h) over the
``thickness`` coordinate (the ice classes; open water is ``open_water``),
mean thickness, ice volume above 2 m and 5 m, λ and R² of the tail fit.
Each run checkpoints its model and the daily diagnostics, so an interrupted
run continues exactly where it stopped.

Parameter choices
-----------------
The paper tunes the rate r of each kernel "so that the results are similar
in the extent and slope of the exponential tail". Here each r was found by
bisection in log r (:func:`tune_rate`) so that the tail above 2 m has an
e-folding thickness of 1.0 m after 2000 days; the kernels take thickness in
metres and time in days, so r is in 1/day for the constant kernel, 1/(m day)
for the additive and 1/(m² day) for the multiplicative kernel. With such
rates the 20 m class, which collects all stacking that would exceed it, holds
less than 1e-9 of the area. Faster rates spread the tail up to the
truncation, where ice accumulates and the tail is no longer exponential (for
the constant kernel R² = 0.89 at r = 0.008/day and 0.63 at 0.01/day). The
exponential kernel uses β = 0.2 per metre: with β = 0.5 thick ice hardly
stacks at all (K(10 m, 10 m) = e^(−10) r) and the tail bends strongly.

Figs 5 and 6 use the constant-kernel rate of Fig. 4 as their base,
r0 = 0.00341/day, so that the rafting runs are "K = 4 against K = 1" in
units of that rate and R_T = 1 is the run of Fig. 4. The paper's K = 1/R_T
is in its own units; what matters here is r0 against this model's
thermodynamics, in which 0.1 m ice grows by up to 0.07 m/day in mid-winter
and ice thicker than about 1.35 m thins by about 0.01 m/day all year.

The tail is not yet stationary after 2000 days for the constant kernel (λ
still creeps up by about 1 % per 200 days), so λ at the last day depends on
``days``; the rates above were tuned for 2000 days.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..itd import ThorndikeModel, constant_kernel, solve_smoluchowski, tail_fit
from ..params import GODLOVITCH
from . import plots
from .experiment import Experiment, register

#: the kernels of Table 1, in the order of the paper
KERNEL_NAMES = GODLOVITCH.KERNEL_NAMES
#: the kernels as formulas, and the units of their rates r
KERNEL_TEXT = {"constant": "K = r", "exponential": "K = r exp(−β(x+y))",
               "multiplicative": "K = r x y", "additive": "K = r (x+y)"}
R_UNITS = {"constant": "1/day", "exponential": "1/day", "multiplicative": "1/(m² day)",
           "additive": "1/(m day)"}
# brackets for the bisection in tune_rate (the tail e-folding grows with r)
_BRACKETS = {"constant": (0.001, 0.008), "exponential": (0.003, 0.05),
             "multiplicative": (1e-4, 1e-3), "additive": (1e-4, 1e-3)}
DPI = 120
GREEN, RED, BLUE = (0.0, 0.65, 0.0), (0.85, 0.0, 0.0), (0.0, 0.2, 0.9)


# ---------------------------------------------------------------------------
# Daily diagnostics and their statistics
# ---------------------------------------------------------------------------

def snapshot_every(days):
    """Days between the g(h) snapshots of a run of ``days`` days (ten per run)."""
    return max(1, int(round(days / 10)))


def ice_volume_above(model, h_min):
    """Ice volume per unit area in the classes thicker than ``h_min`` [m]."""
    use = model.h > h_min
    return float(np.dot(model.h[use], model.g[use]))


#: daily series kept by :func:`advance_day`: model time [days], mean thickness
#: [m], open water, ice volume above 2 m and above 5 m [m], tail e-folding λ [m]
SERIES = ("t", "mean", "open", "v2", "v5", "lam")


def new_series(days) -> dict:
    """Empty (NaN) daily series of :data:`SERIES` for a run of ``days`` days."""
    return {k: np.full(int(days), np.nan) for k in SERIES}


def advance_day(model, series: dict, d: int) -> None:
    """Step ``model`` by one day and store the diagnostics of day ``d``
    (0-based) in ``series`` (from :func:`new_series`), among them the tail
    e-folding thickness (NaN while the tail is too short to fit)."""
    model.step(1.0)
    series["t"][d] = model.time
    series["mean"][d] = model.mean_thickness
    series["open"][d] = model.open_water
    series["v2"][d] = ice_volume_above(model, 2.0)
    series["v5"][d] = ice_volume_above(model, 5.0)
    lam = model.tail_fit(GODLOVITCH.tail_min).efolding
    series["lam"][d] = lam if math.isfinite(lam) else np.nan


def first_day(t, series, level):
    """First time at which ``series`` >= ``level`` (NaN entries skipped)."""
    ok = np.isfinite(series) & (series >= level)
    return float(t[np.argmax(ok)]) if ok.any() else math.nan


def last_year(x):
    """The last 360 entries (one model year of daily values) of ``x``."""
    return x[-min(len(x), int(GODLOVITCH.year_days)):]


def tail_formation(s: dict) -> dict:
    """How fast the thick ice forms, from daily series ``s``: the day the ice
    volume above 2 m (and 5 m) first reaches 90 % of its mean over the last
    year, and those means [m]."""
    v2, v5 = last_year(s["v2"]).mean(), last_year(s["v5"]).mean()
    return dict(t90_volume_above_2m=first_day(s["t"], s["v2"], 0.9 * v2),
                t90_volume_above_5m=first_day(s["t"], s["v5"], 0.9 * v5),
                volume_above_2m=float(v2), volume_above_5m=float(v5))


def seasonal_cycle(s: dict) -> dict:
    """The seasonal cycle over the last year of daily series ``s``: mean
    thickness, its amplitude (half the range) absolute and relative, the
    range of the tail e-folding thickness λ and its range relative to its
    mean, and the range of the open-water fraction."""
    mean_y, lam_y = last_year(s["mean"]), last_year(s["lam"])
    lam_y = lam_y[np.isfinite(lam_y)]
    if lam_y.size == 0:
        lam_y = np.array([math.nan])
    open_y = last_year(s["open"])
    return dict(mean_thickness=float(mean_y.mean()),
                mean_thickness_amplitude=float((mean_y.max() - mean_y.min()) / 2),
                relative_amplitude=float((mean_y.max() - mean_y.min()) / 2 / mean_y.mean()),
                efolding_range=(float(lam_y.min()), float(lam_y.max())),
                efolding_relative_range=float((lam_y.max() - lam_y.min()) / lam_y.mean()),
                open_water_range=(float(open_y.min()), float(open_y.max())))


def scm_exact(k, t):
    """Exact solution of the coagulation equation with K = 1 from u_1(0) = 1:
    u_k(t) = (1 + t/2)^(−2) (t/(2 + t))^(k−1), broadcast over ``k`` and ``t``."""
    k = np.asarray(k, dtype=float)
    t = np.asarray(t, dtype=float)
    return (1.0 + t / 2.0) ** -2 * (t / (2.0 + t)) ** (k - 1)


def tune_rate(kind: str, target: float = GODLOVITCH.tail_target,
              days: int = GODLOVITCH.days, *, iterations: int = 12, bracket=None,
              **params) -> tuple[float, float]:
    """The rate r of kernel ``kind`` for which the tail above 2 m has an
    e-folding thickness ``target`` [m] after ``days`` days (bisection in
    log r; the e-folding grows with r). ``params`` are further kernel
    parameters (``beta`` of the exponential kernel). Returns (r, λ of the
    last trial).

    This is how the rates of :data:`physics.params.GODLOVITCH` were found
    (rounded to three significant digits), e.g. for the exponential kernel
    ``tune_rate("exponential", beta=GODLOVITCH.exponential_beta)`` (about 10 s).
    """
    lo, hi = bracket or _BRACKETS[kind]
    r = lam = math.nan
    for _ in range(iterations):
        r = math.sqrt(lo * hi)
        m = ThorndikeModel(kind, r=r, **params)
        m.run(days)
        lam = m.tail_fit(GODLOVITCH.tail_min).efolding
        if math.isfinite(lam) and lam >= target:
            hi = r
        else:
            lo = r
    return r, lam


# ---------------------------------------------------------------------------
# Panels
# ---------------------------------------------------------------------------

def colours(n, start, end):
    """n colours interpolated linearly from ``start`` to ``end`` (RGB)."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    return [tuple(a + (b - a) * (i / max(n - 1, 1))) for i in range(n)]


def time_colourbar(fig, axes, plt, start, end, t_max, label="model time [days]"):
    """A colour bar from ``start`` (t = 0) to ``end`` (t = ``t_max``) beside ``axes``."""
    from matplotlib.colors import LinearSegmentedColormap, Normalize

    cmap = LinearSegmentedColormap.from_list("time", [start, end])
    sm = plt.cm.ScalarMappable(norm=Normalize(0, t_max), cmap=cmap)
    fig.colorbar(sm, ax=axes, label=label, shrink=0.8, pad=0.02)


def plot_g(ax, h, snaps, line_colours, fit=None, title=None):
    """g(h) of the ice classes on a log axis, one line per snapshot.

    Parameters
    ----------
    ax : matplotlib axes
    h : (n,) array — thicknesses of the ice classes [m] (open water left out)
    snaps : (k, n) array — area fractions of the ice classes, oldest first
    line_colours : k colours
    fit : TailFit, optional — drawn as a dashed line through the last snapshot
    title : str, optional
    """
    tail_min = GODLOVITCH.tail_min
    h = np.asarray(h, dtype=float)
    snaps = np.atleast_2d(np.asarray(snaps, dtype=float))
    for g, c in zip(snaps, line_colours):
        ax.semilogy(h, np.where(g > 0, g, np.nan), color=c, lw=1.1)
    if fit is not None and math.isfinite(fit.efolding):
        hh = np.linspace(tail_min, h[-2], 50)
        use = (h > tail_min) & (snaps[-1] > 1e-12)
        use[-1] = False
        icpt = np.mean(np.log(snaps[-1][use]) - fit.slope * h[use])
        ax.semilogy(hh, np.exp(icpt + fit.slope * hh), "k--", lw=1.0,
                    label=f"fit > {tail_min:g} m: λ = {fit.efolding:.2f} m, R² = {fit.r2:.3f}")
        ax.legend(loc="upper right", fontsize=7.5, frameon=False)
    ax.set_xlim(0, h[-1])
    ax.set_ylim(1e-12, 1.5)
    ax.set_xlabel("h [m]")
    ax.set_ylabel(f"g(h) per {h[1] - h[0]:.3g} m class")
    ax.grid(True, which="major", alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9.5)


def plot_scm(ax, ax2, k, times, u, exact, n_classes, rtol):
    """Fig. 7 panels: numerical u_k (dots) against the exact solution (lines)
    on ``ax`` and their relative error on ``ax2``, one colour per time
    (blue → red); ``u`` and ``exact`` have shape (len(times), len(k))."""
    u, exact = np.asarray(u, float), np.asarray(exact, float)
    shown = exact > 1e-12
    rel = np.abs(u - exact) / np.where(shown, exact, 1.0)
    for q, (tq, c) in enumerate(zip(times, colours(len(times), BLUE, RED))):
        ax.semilogy(k, exact[q], color=c, lw=1.0)
        ax.semilogy(k, u[q], "o", color=c, ms=3, label=f"t = {tq:g}")
        ok = shown[q]
        ax2.semilogy(k[ok], np.maximum(rel[q][ok], 1e-16), color=c, lw=1.0)
    ax.set_ylim(1e-12, 1.5)
    ax.set_xlabel("mass k")
    ax.set_ylabel("number density u_k")
    ax.set_title(r"$u_k(t)$: numerical (dots), exact $(1 + t/2)^{-2}\,(t/(2 + t))^{k-1}$ "
                 "(lines)", fontsize=9.5)
    ax.legend(fontsize=7.5, frameon=False, ncol=2)
    ax.grid(True, alpha=0.3)
    ax2.set_xlabel("mass k")
    ax2.set_ylabel("|u_k − exact| / exact (where exact u_k > 1e-12)")
    ax2.set_title(f"relative error ({n_classes} classes, DOP853, rtol {rtol:g})", fontsize=9.5)
    ax2.grid(True, alpha=0.3)


# ---------------------------------------------------------------------------
# The scenarios
# ---------------------------------------------------------------------------

_ITD_VARIABLES = {
    "time": ("d", "model time of the output (day 0 is mid-winter, 360-day years)"),
    "g": ("1", "area fraction of the ice-thickness class (open water apart)"),
    "open_water": ("1", "open-water fraction g_0"),
    "mean_thickness": ("m", "mean ice thickness over the whole area (open water as 0)"),
    "volume_above_2m": ("m", "ice volume per unit area in the classes thicker than 2 m"),
    "volume_above_5m": ("m", "ice volume per unit area in the classes thicker than 5 m"),
    "tail_lambda": ("m", "e-folding thickness λ of the tail above 2 m (log-linear fit)"),
    "tail_r2": ("1", "R² of the log-linear fit of the tail above 2 m"),
    "top_class": ("1", "area fraction of the top class, which collects truncated stacking"),
    "lambda_final": ("m", "e-folding thickness λ of the tail above 2 m at the last day"),
    "r2_final": ("1", "R² of the log-linear tail fit above 2 m at the last day"),
    "open_water_final": ("1", "open-water fraction at the last day"),
    "mean_thickness_final": ("m", "mean ice thickness at the last day"),
    "top_class_final": ("1", "area fraction of the top class at the last day"),
}
_ITD_REQUIRED = ("time", "g", "open_water", "mean_thickness", "tail_lambda", "tail_r2",
                 "lambda_final", "r2_final")


def _fmt(x, fmt=".2f", nan="n/a") -> str:
    """``x`` formatted, or ``nan`` for NaN and infinities."""
    return nan if x is None or not math.isfinite(float(x)) else format(float(x), fmt)


def _member0(ds, c: int):
    """Case ``c``, first ensemble member (the model is deterministic, so all
    members are the same run)."""
    return ds.isel(case=c, member=0)


def _series(run, name: str):
    """(time, values) of a recorded series, without the padding of an outer join."""
    t = np.asarray(run["time"].values, dtype=float)
    y = np.asarray(run[name].values, dtype=float)
    ok = np.isfinite(t)
    return t[ok], y[ok]


def _snapshot_rows(t, days: int) -> list[int]:
    """Rows of the outputs nearest to every ``days``/10 days (the paper's
    snapshot times), oldest first, without repeats."""
    every = snapshot_every(days)
    targets = np.arange(every, int(days) + 1, every, dtype=float)
    if len(t) == 0:
        return []
    rows = [int(np.argmin(np.abs(t - x))) for x in targets]
    return sorted(set(rows))


def _fit_of(run, row: int):
    """The tail fit at output ``row``, leaving out the top class as
    :meth:`ThorndikeModel.tail_fit` does (for the dashed line of the panels)."""
    h = np.asarray(run["thickness"].values, dtype=float)
    g = np.asarray(run["g"].values[row], dtype=float)
    return tail_fit(h[:-1], g[:-1], GODLOVITCH.tail_min)


def _g_panel(ax, run, days: int, start, end, title: str) -> None:
    """Snapshots of g(h) of one run (every days/10 days, ``start`` → ``end``
    colours) with the tail fit of the last one."""
    t = np.asarray(run["time"].values, dtype=float)
    rows = _snapshot_rows(np.where(np.isfinite(t), t, -np.inf), days)
    snaps = np.asarray(run["g"].values, dtype=float)[rows]
    plot_g(ax, run["thickness"].values, snaps, colours(len(rows), start, end),
                _fit_of(run, rows[-1]) if rows else None, title)


def _save(fig, out_dir, name: str) -> Path:
    """Save a figure with a constrained layout (no tight_layout) and close it."""
    plt = plots.pyplot()
    path = Path(out_dir) / name
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


class _ThorndikeExperiment(Experiment):
    """The daily loop of a generalised Thorndike-model run, with outputs and
    checkpoints; subclasses build the model of a case and its results."""

    variables = _ITD_VARIABLES
    required = _ITD_REQUIRED

    def model(self, p: dict, case: dict) -> ThorndikeModel:
        raise NotImplementedError

    def results(self, model: ThorndikeModel, series: dict, p: dict, case: dict) -> dict:
        """Per-run results beyond the final tail fit (default: none)."""
        return {}

    def workload(self, p: dict, case: dict) -> float:
        return float(p["days"])

    def simulate(self, p, case, seed, rec):
        """Run the case's model from open water for ``days`` daily steps
        (deterministic: ``seed`` is not used), recording every
        ``output_every`` days and checkpointing the model, the day and the
        daily diagnostics after each output."""
        days, every = int(p["days"]), int(p["output_every"])
        if days < 1 or every < 1:
            raise ValueError(f"days and output_every must be positive, got {days} and {every}")
        st = rec.restore()
        if st is None:
            m = self.model(p, case)
            rec.coord("thickness", m.h[1:], "m", "ice thickness of the class")
            st = {"model": m, "day": 0, "series": new_series(days)}
        m, s = st["model"], st["series"]
        for d in range(st["day"], days):
            advance_day(m, s, d)
            st["day"] = d + 1
            if (d + 1) % every == 0 or d + 1 == days:
                fit = m.tail_fit(GODLOVITCH.tail_min)
                rec.record(m.time, g=("thickness", m.g[1:]), open_water=m.open_water,
                           mean_thickness=m.mean_thickness,
                           volume_above_2m=s["v2"][d], volume_above_5m=s["v5"][d],
                           tail_lambda=fit.efolding, tail_r2=fit.r2, top_class=m.g[-1])
                rec.progress((d + 1) / days)
                rec.checkpoint(st)
        fit = m.tail_fit(GODLOVITCH.tail_min)
        rec.result(lambda_final=fit.efolding, r2_final=fit.r2, open_water_final=m.open_water,
                   mean_thickness_final=m.mean_thickness, top_class_final=m.g[-1],
                   **self.results(m, s, p, case))


# ---------------------------------------------------------------------------
# Fig. 4: the kernels of Table 1
# ---------------------------------------------------------------------------

@register("godlovitch-kernels")
class Kernels(_ThorndikeExperiment):
    """Fig. 4: the four kernels of Table 1 from open water."""

    case_label = "kernel"

    def cases(self, p):
        choice = p["kernel"]
        return [{"kernel": k} for k in KERNEL_NAMES if choice in ("all", k)]

    def model(self, p, case):
        kind = case["kernel"]
        extra = {"beta": p["beta"]} if kind == "exponential" else {}
        return ThorndikeModel(kind, r=p[f"r_{kind}"], **extra)

    def summarise(self, ds, p):
        rows = []
        for c, kind in enumerate(np.asarray(ds["kernel"].values).astype(str)):
            run = _member0(ds, c)
            rows.append((f"R² of the tail fit above 2 m, {kind} kernel",
                         _fmt(run["r2_final"], ".4f"),
                         "exponential (semilog-linear) tail for every kernel, R² ≥ 0.95"))
            rows.append((f"e-folding thickness λ of the tail at day {p['days']}, {kind} kernel "
                         f"(r = {p[f'r_{kind}']:.3g} {R_UNITS[kind]})",
                         f"{_fmt(run['lambda_final'])} m",
                         "r adjusted per kernel for a similar tail "
                         "(tuned here: λ = 1.0 m at day 2000)"))
        r2 = np.asarray(ds["r2_final"].isel(member=0).values, dtype=float)
        rows.append((f"smallest tail R² over the kernels at day {p['days']}",
                     _fmt(np.nanmin(r2), ".4f"),
                     "≥ 0.95: the kernel has little qualitative effect"))
        lows = []
        for c, kind in enumerate(np.asarray(ds["kernel"].values).astype(str)):
            t, y = _series(_member0(ds, c), "tail_r2")
            last = (t > t[-1] - 360.0) & np.isfinite(y) if len(t) else t.astype(bool)
            if last.any():
                lows.append(f"{kind} {np.min(y[last]):.3f}")
        if lows:
            rows.append(("smallest tail R² over the last year (seasonal dips)", ", ".join(lows),
                         "quasi-exponential tail through the seasons"))
        top = np.asarray(ds["top_class_final"].isel(member=0).values, dtype=float)
        rows.append(("largest area fraction in the 20 m top class", f"{np.nanmax(top):.1e}",
                     "truncation negligible (tail well below 20 m)"))
        return rows

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        days = int(p["days"])
        kinds = list(np.asarray(ds["kernel"].values).astype(str))
        ncol = 2 if len(kinds) > 1 else 1
        nrow = math.ceil(len(kinds) / ncol)
        fig, axes = plt.subplots(nrow, ncol, figsize=(5.6 * ncol, 3.9 * nrow), squeeze=False,
                                 layout="constrained")
        for c, (ax, kind) in enumerate(zip(axes.flat, kinds)):
            extra = f", β = {p['beta']:g}/m" if kind == "exponential" else ""
            _g_panel(ax, _member0(ds, c), days, GREEN, RED,
                     f"{kind}: {KERNEL_TEXT[kind]}, r = {p[f'r_{kind}']:.3g} "
                     f"{R_UNITS[kind]}{extra}")
        for ax in axes.flat[len(kinds):]:
            ax.set_visible(False)
        fig.suptitle(f"Godlovitch et al. Fig. 4: Table 1 kernels, g(h) every "
                     f"{snapshot_every(days)} days for {days} days (green → red)",
                     fontsize=11)
        time_colourbar(fig, axes, plt, GREEN, RED, days)
        out = [_save(fig, out_dir, "godlovitch_fig4_kernels.png")]

        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
        for c, kind in enumerate(kinds):
            run = _member0(ds, c)
            t, lam = _series(run, "tail_lambda")
            ok = np.isfinite(lam)
            ax1.plot(t[ok], lam[ok], lw=1.2, label=kind)
            t, r2 = _series(run, "tail_r2")
            ok = np.isfinite(r2)
            ax2.plot(t[ok], r2[ok], lw=1.2, label=kind)
        ax1.set_ylabel(f"tail e-folding thickness λ (h > {GODLOVITCH.tail_min:g} m) [m]")
        ax2.set_ylabel("R² of the log-linear tail fit")
        ax2.axhline(0.95, color="k", ls=":", lw=0.8)
        for ax in (ax1, ax2):
            ax.set_xlabel("t [days]")
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8, frameon=False)
        fig.suptitle("Growth of the exponential tail for the Table 1 kernels", fontsize=11)
        out.append(plots.savefig(fig, Path(out_dir) / "godlovitch_fig4_tail.png"))
        return out


# ---------------------------------------------------------------------------
# Fig. 5: rafting
# ---------------------------------------------------------------------------

def _raft_label(h: float) -> str:
    return "no rafting" if h <= 0 else f"rafting below h_R = {h:g} m"


@register("godlovitch-rafting")
class Rafting(_ThorndikeExperiment):
    """Fig. 5: constant kernel with and without rafting of thin ice."""

    variables = dict(
        _ITD_VARIABLES,
        t_lambda_target=("d", "first day the tail e-folding thickness λ reaches lambda_target"),
        t90_volume_above_2m=("d", "first day the ice volume above 2 m reaches 90 % of its "
                                  "mean over the last year"),
        t90_volume_above_5m=("d", "first day the ice volume above 5 m reaches 90 % of its "
                                  "mean over the last year"),
        volume_above_2m_last_year=("m", "mean ice volume above 2 m over the last year"),
        volume_above_5m_last_year=("m", "mean ice volume above 5 m over the last year"))
    required = _ITD_REQUIRED + ("volume_above_2m", "t_lambda_target", "t90_volume_above_2m")
    case_label = "h_raft"

    def cases(self, p):
        cutoffs = sorted({float(h) for h in p["raft_cutoffs"]})
        return [{"h_raft": 0.0}] + [{"h_raft": h} for h in cutoffs]

    def model(self, p, case):
        h = float(case["h_raft"])
        if h <= 0:
            return ThorndikeModel("constant", r=p["r0"])
        return ThorndikeModel("rafting", r=p["r0"], h_raft=h, factor=p["raft_factor"])

    def results(self, model, series, p, case):
        tf = tail_formation(series)
        return dict(t_lambda_target=first_day(series["t"], series["lam"],
                                                   p["lambda_target"]),
                    t90_volume_above_2m=tf["t90_volume_above_2m"],
                    t90_volume_above_5m=tf["t90_volume_above_5m"],
                    volume_above_2m_last_year=tf["volume_above_2m"],
                    volume_above_5m_last_year=tf["volume_above_5m"])

    def summarise(self, ds, p):
        target, days = p["lambda_target"], p["days"]
        hs = np.asarray(ds["h_raft"].values, dtype=float)
        rows = []
        for c, h in enumerate(hs):
            run, label = _member0(ds, c), _raft_label(h)
            t = float(run["t_lambda_target"])
            rows.append((f"day λ first reaches {target:g} m, {label}",
                         f"{t:.0f} d" if math.isfinite(t) else f"not within {days} d",
                         "reference" if h <= 0 else
                         "rafting speeds up tail formation, more for larger h_R; small "
                         "h_R has a smaller effect"))
            rows.append((f"day the ice volume above 2 m / 5 m reaches 90 % of its last-year "
                         f"mean, {label}",
                         f"{_fmt(run['t90_volume_above_2m'], '.0f')} / "
                         f"{_fmt(run['t90_volume_above_5m'], '.0f')} d", ""))
            rows.append((f"tail λ and R² above 2 m at day {days}, {label}",
                         f"λ = {_fmt(run['lambda_final'])} m, R² = "
                         f"{_fmt(run['r2_final'], '.4f')}",
                         "quasi-exponential form not affected by rafting (R² ≥ 0.95)"))
        if len(hs) > 1:
            t_none = float(_member0(ds, 0)["t_lambda_target"])
            c = int(np.argmax(hs))
            t_raft = float(_member0(ds, c)["t_lambda_target"])
            ratio = t_none / t_raft if math.isfinite(t_none) and math.isfinite(t_raft) \
                and t_raft > 0 else math.nan
            rows.append((f"tail formation, day λ reaches {target:g} m: no rafting / "
                         f"h_R = {hs[c]:g} m",
                         f"{_fmt(t_none, '.0f')} / {_fmt(t_raft, '.0f')} d "
                         f"({_fmt(ratio, '.2f')}× faster)",
                         "rafting speeds tail formation; small h_R has little effect "
                         "(thin ice grows out thermodynamically)"))
        return rows

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        days = int(p["days"])
        hs = np.asarray(ds["h_raft"].values, dtype=float)
        ncol = 3
        nrow = math.ceil((len(hs) + 2) / ncol)
        fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.8 * nrow), squeeze=False)
        flat = list(axes.flat)
        for c, h in enumerate(hs):
            title = "no rafting (K = r0 everywhere)" if h <= 0 else \
                f"h_R = {h:g} m: K = {p['raft_factor']:g} r0 below, r0 above"
            _g_panel(flat[c], _member0(ds, c), days, GREEN, RED, title)
        ax_lam, ax_vol = flat[len(hs)], flat[len(hs) + 1]
        line_colours = ["k"] + list(plt.cm.viridis(np.linspace(0.0, 0.9, max(len(hs) - 1, 1))))
        for c in list(range(1, len(hs))) + [0]:         # no rafting drawn on top
            h, run, colour = hs[c], _member0(ds, c), line_colours[c]
            t, lam = _series(run, "tail_lambda")
            ok = np.isfinite(lam)
            ax_lam.plot(t[ok], lam[ok], color=colour, lw=1.1, ls="--" if h <= 0 else "-",
                        label=_raft_label(h).replace("rafting below ", ""))
            t, v2 = _series(run, "volume_above_2m")
            _, v5 = _series(run, "volume_above_5m")
            ax_vol.semilogy(t, np.where(v2 > 0, v2, np.nan), color=colour, lw=1.1)
            ax_vol.semilogy(t, np.where(v5 > 0, v5, np.nan), color=colour, lw=1.1, ls="--")
        ax_lam.axhline(p["lambda_target"], color="0.5", ls=":", lw=0.8)
        ax_lam.set_ylabel(f"tail e-folding thickness λ (h > {GODLOVITCH.tail_min:g} m) [m]")
        ax_lam.set_title("tail e-folding thickness (dotted: lambda_target)", fontsize=9.5)
        ax_lam.legend(fontsize=7.5, frameon=False)
        ax_vol.set_ylabel("ice volume per unit area [m]")
        ax_vol.set_title("ice volume above 2 m (solid) and 5 m (dashed)", fontsize=9.5)
        ax_vol.set_ylim(1e-5, 1.5)
        for ax in (ax_lam, ax_vol):
            ax.set_xlabel("t [days]")
            ax.grid(True, alpha=0.3)
        for ax in flat[len(hs) + 2:]:
            ax.set_visible(False)
        fig.suptitle(f"Godlovitch et al. Fig. 5: constant kernel r0 = {p['r0']:g}/day with "
                     f"rafting (K = {p['raft_factor']:g} r0 where both floes are thinner than "
                     f"h_R), g(h) every {snapshot_every(days)} days (green → red)",
                     fontsize=10.5)
        return [plots.savefig(fig, Path(out_dir) / "godlovitch_fig5_rafting.png")]


# ---------------------------------------------------------------------------
# Fig. 6: relative strength of thermodynamics and stacking
# ---------------------------------------------------------------------------

@register("godlovitch-thermo")
class Thermo(_ThorndikeExperiment):
    """Fig. 6: constant kernel K = r0/R_T for several relative strengths R_T."""

    variables = dict(
        _ITD_VARIABLES,
        mean_thickness_last_year=("m", "mean of the mean thickness over the last year"),
        mean_thickness_amplitude=("m", "seasonal amplitude (half the range over the last "
                                       "year) of the mean thickness"),
        mean_thickness_relative_amplitude=("1", "seasonal amplitude of the mean thickness "
                                                "over its mean"),
        lambda_min_last_year=("m", "smallest tail e-folding thickness λ over the last year"),
        lambda_max_last_year=("m", "largest tail e-folding thickness λ over the last year"),
        lambda_relative_range=("1", "range of λ over the last year over its mean"),
        open_water_min_last_year=("1", "smallest open-water fraction over the last year"),
        open_water_max_last_year=("1", "largest open-water fraction over the last year"))
    required = _ITD_REQUIRED + ("mean_thickness_amplitude", "lambda_relative_range")
    case_label = "relative_strength"

    def cases(self, p):
        seen = list(dict.fromkeys(float(r) for r in p["relative_strengths"]))
        return [{"relative_strength": r} for r in seen]

    def model(self, p, case):
        return ThorndikeModel("constant", r=p["r0"], scale=1.0 / case["relative_strength"])

    def results(self, model, series, p, case):
        sc = seasonal_cycle(series)
        return dict(mean_thickness_last_year=sc["mean_thickness"],
                    mean_thickness_amplitude=sc["mean_thickness_amplitude"],
                    mean_thickness_relative_amplitude=sc["relative_amplitude"],
                    lambda_min_last_year=sc["efolding_range"][0],
                    lambda_max_last_year=sc["efolding_range"][1],
                    lambda_relative_range=sc["efolding_relative_range"],
                    open_water_min_last_year=sc["open_water_range"][0],
                    open_water_max_last_year=sc["open_water_range"][1])

    def summarise(self, ds, p):
        rts = np.asarray(ds["relative_strength"].values, dtype=float)
        rows = []
        for c, rt in enumerate(rts):
            run = _member0(ds, c)
            paper = ("R_T < 1: stacking dominates, the tail becomes nearly flat (large λ)"
                     if rt < 1 else "reference run (K = r0)" if rt == 1 else
                     "R_T > 1: the slope of the tail decreases (steeper, smaller λ)")
            rows.append((f"tail λ and R² above 2 m at day {p['days']}, R_T = {rt:g}",
                         f"λ = {_fmt(run['lambda_final'])} m, R² = "
                         f"{_fmt(run['r2_final'], '.4f')}", paper))
            rows.append((f"seasonal cycle over the last year, R_T = {rt:g}: mean thickness "
                         f"± amplitude; λ range",
                         f"{_fmt(run['mean_thickness_last_year'])} ± "
                         f"{_fmt(run['mean_thickness_amplitude'])} m "
                         f"({_fmt(100 * float(run['mean_thickness_relative_amplitude']), '.0f')}"
                         f" %); λ {_fmt(run['lambda_min_last_year'])}–"
                         f"{_fmt(run['lambda_max_last_year'])} m "
                         f"({_fmt(100 * float(run['lambda_relative_range']), '.0f')} %)",
                         "R_T > 5: thermodynamics dominate, strongly cyclic" if rt > 5 else ""))
        if len(rts) > 1:
            order = np.argsort(rts)
            lam = np.asarray(ds["lambda_final"].isel(member=0).values, dtype=float)[order]
            falling = bool(np.all(np.diff(lam) < 0))
            rows.append(("λ falls as R_T grows",
                         f"{'yes' if falling else 'no'}: {_fmt(lam[0])} m at R_T = "
                         f"{rts[order[0]]:g} → {_fmt(lam[-1])} m at R_T = {rts[order[-1]]:g}",
                         "R_T sets the slope of the tail"))
        return rows

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        days = int(p["days"])
        rts = np.asarray(ds["relative_strength"].values, dtype=float)
        ncol = 4
        nrow = math.ceil((len(rts) + 3) / ncol)
        fig, axes = plt.subplots(nrow, ncol, figsize=(4.3 * ncol, 3.8 * nrow), squeeze=False)
        flat = list(axes.flat)
        for c, rt in enumerate(rts):
            _g_panel(flat[c], _member0(ds, c), days, BLUE, RED,
                     f"R_T = {rt:g}: K = r0/R_T = {p['r0'] / rt:.3g}/day")
        strength_colours = colours(len(rts), BLUE, RED)
        panels = [("mean_thickness", "mean thickness (open water as 0) [m]", "mean thickness"),
                  ("tail_lambda", "λ / its mean over the last year",
                   f"tail e-folding thickness λ (h > {GODLOVITCH.tail_min:g} m), relative"),
                  ("open_water", "open-water fraction g_0", "open water")]
        years = min(3.0, days / 360.0)                  # the last (up to) three years
        for ax, (key, ylabel, title) in zip(flat[len(rts):], panels):
            for c, (rt, colour) in enumerate(zip(rts, strength_colours)):
                t, y = _series(_member0(ds, c), key)
                if not len(t):
                    continue
                last = t > t[-1] - 360.0 * years
                t, y = t[last], y[last]
                if key == "tail_lambda":
                    y = y / np.nanmean(y[t > t[-1] - 360.0])
                ok = np.isfinite(y)
                ax.plot(t[ok], y[ok], color=colour, lw=1.2, label=f"R_T = {rt:g}")
            ax.set_xlabel("t [days] (mid-winter at multiples of 360)")
            ax.set_ylabel(ylabel)
            ax.set_title(f"{title}, last {years:.3g} years", fontsize=9.5)
            ax.grid(True, alpha=0.3)
        flat[len(rts)].legend(fontsize=7.5, frameon=False, ncol=3, loc="upper center")
        lo, hi = flat[len(rts)].get_ylim()
        flat[len(rts)].set_ylim(lo, hi + 0.3 * (hi - lo))
        for ax in flat[len(rts) + 3:]:
            ax.set_visible(False)
        fig.suptitle(f"Godlovitch et al. Fig. 6: relative strength R_T of thermodynamics and "
                     f"stacking, K = r0/R_T with r0 = {p['r0']:g}/day, g(h) every "
                     f"{snapshot_every(days)} days (blue → red)", fontsize=11)
        return [plots.savefig(fig, Path(out_dir) / "godlovitch_fig6_relative_strength.png")]


# ---------------------------------------------------------------------------
# Fig. 7: Smoluchowski coagulation against its exact solution
# ---------------------------------------------------------------------------

@register("scm-analytic")
class ScmAnalytic(Experiment):
    """Fig. 7: K = 1 coagulation from a monodisperse start against the exact
    u_k(t). The integration runs from output time to output time (adaptive
    DOP853), so that a run checkpoints and resumes between them."""

    variables = {
        "time": ("1", "dimensionless time t (in units of 1/(K u_1(0)))"),
        "u": ("1", "number density u_k of particles of mass k, numerical"),
        "u_exact": ("1", "exact u_k = (1 + t/2)^(-2) (t/(2 + t))^(k-1)"),
        "rel_error": ("1", "relative error |u_k - exact| / exact"),
        "max_rel_error_k10": ("1", "largest relative error of u_k for k <= 10 at this time"),
        "number": ("1", "number of particles, sum of u_k"),
        "number_exact": ("1", "exact number of particles 1/(1 + t/2)"),
        "total_mass": ("1", "total mass, sum of k u_k (1 at t = 0; mass beyond the last "
                            "class leaves)"),
        "error_k10_max": ("1", "largest relative error of u_k for k <= 10 over all times"),
        "error_kmax_max": ("1", "largest relative error of u_k for k <= kmax where the exact "
                                "u_k > 1e-12, over all times"),
        "mass_error_max": ("1", "largest |total mass - 1| over all times"),
    }
    required = ("time", "u", "u_exact", "rel_error", "max_rel_error_k10", "error_k10_max",
                "error_kmax_max", "mass_error_max")

    def simulate(self, p, case, seed, rec):
        """Integrate from one output time to the next, recording u_k, the
        exact u_k and their relative error at each, and checkpointing u, the
        time and the running error maxima."""
        times = sorted({float(t) for t in p["times"]})
        n, kmax = int(p["classes"]), int(p["kmax"])
        if kmax > n:
            raise ValueError(f"kmax ({kmax}) must not exceed the number of classes ({n})")
        if times[0] <= 0:
            raise ValueError(f"output times must be > 0, got {times[0]:g}")
        k = np.arange(1, n + 1, dtype=float)
        st = rec.restore()
        if st is None:
            rec.coord("k", k[:kmax], "1", "particle mass k in units of the smallest particle")
            u0 = np.zeros(n)
            u0[0] = 1.0
            st = {"u": u0, "t": 0.0, "next": 0, "err10": 0.0, "errk": 0.0, "mass_err": 0.0}
        kernel = constant_kernel(n, 1.0)
        while st["next"] < len(times):
            tq = times[st["next"]]
            u = solve_smoluchowski(kernel, st["u"], [0.0, tq - st["t"]], rtol=p["rtol"])[-1]
            exact = scm_exact(k, tq)
            rel = np.abs(u - exact) / np.where(exact > 0, exact, 1.0)
            shown = exact[:kmax] > 1e-12
            err10 = float(rel[:10].max())
            errk = float(rel[:kmax][shown].max()) if shown.any() else 0.0
            mass = float(np.dot(k, u))
            st.update(u=u, t=tq, next=st["next"] + 1, err10=max(st["err10"], err10),
                      errk=max(st["errk"], errk),
                      mass_err=max(st["mass_err"], abs(mass - 1.0)))
            rec.record(tq, u=("k", u[:kmax]), u_exact=("k", exact[:kmax]),
                       rel_error=("k", rel[:kmax]), max_rel_error_k10=err10,
                       number=u.sum(), number_exact=1.0 / (1.0 + tq / 2.0), total_mass=mass)
            rec.progress(st["next"] / len(times))
            rec.checkpoint(st)
        rec.result(error_k10_max=st["err10"], error_kmax_max=st["errk"],
                   mass_error_max=st["mass_err"])

    def summarise(self, ds, p):
        run = _member0(ds, 0)
        t, num = _series(run, "number")
        _, num_exact = _series(run, "number_exact")
        return [
            (f"largest relative error of u_k, k ≤ 10, t = {t[0]:g} … {t[-1]:g}",
             f"{float(run['error_k10_max']):.2e}", "numerical u_k on the exact curves (Fig. 7)"),
            (f"largest relative error of u_k, k ≤ {p['kmax']} (where exact u_k > 1e-12)",
             f"{float(run['error_kmax_max']):.2e}", "exact solution reproduced"),
            ("largest deviation of the total mass Σ k u_k from 1",
             f"{float(run['mass_error_max']):.1e}",
             "mass conserved (only mass beyond the last class is lost)"),
            (f"number of particles Σ u_k at t = {t[-1]:g} (exact 1/(1 + t/2))",
             f"{num[-1]:.6g} (exact {num_exact[-1]:.6g})", "N(t) = 1/(1 + t/2)"),
        ]

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        run = _member0(ds, 0)
        t = np.asarray(run["time"].values, dtype=float)
        ok = np.isfinite(t)
        fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11.5, 4.8))
        plot_scm(ax, ax2, np.asarray(run["k"].values), t[ok],
                      np.asarray(run["u"].values)[ok], np.asarray(run["u_exact"].values)[ok],
                      int(p["classes"]), float(p["rtol"]))
        fig.suptitle("Godlovitch et al. Fig. 7: Smoluchowski coagulation with K(j, k) = 1, "
                     "u_1(0) = 1", fontsize=11)
        return [plots.savefig(fig, Path(out_dir) / "godlovitch_fig7_scm.png")]
