"""Figures 4–7 of Godlovitch et al. (the ice thickness distribution as a
coagulation process) reproduced qualitatively with the generalised Thorndike
model of ``physics.itd``: ``python -m physics.itd_figures [--out DIR]
[--days 2000] [--tune]``.

Each figure is saved as a PNG and summarised by one printed line:

* ``itd_fig4_kernels.png`` — the four kernels of Table 1 (constant,
  exponential, multiplicative, additive), 2000 days in daily steps from open
  water, g(h) every 200 days (green → red with time). Printed: r, the
  e-folding thickness λ and R² of the log-linear fit of the tail above 2 m
  at the last day (``ThorndikeModel.tail_fit``).
* ``itd_fig5_rafting.png`` — constant kernel with rafting (K = 4r when both
  floes are thinner than the cut-off h_R, r otherwise, as in the caption of
  Fig. 5) for h_R = 0.2, 0.5, 1 and 2 m and without rafting. Printed per
  cut-off: the day the ice volume above 2 m (and above 5 m) first reaches
  90 % of its mean over the last year, the day λ first reaches 90 % of the
  final λ without rafting, and the final λ and R².
* ``itd_fig6_relative_strength.png`` — constant kernel K = r0/R_T for
  R_T = 0.5, 1, 2, 5, 10 (snapshots blue → red, as the caption of Fig. 6),
  and the mean thickness over the last three years. Printed per R_T: λ, R²,
  and the seasonal amplitude (half the range over the last year) of the
  mean thickness and of λ.
* ``itd_fig7_scm_constant.png`` — pure coagulation with K = 1 from a
  monodisperse start, u_k(t) for k = 1 … 50 against the exact solution
  u_k = (1 + t/2)^(−2) (t/(2 + t))^(k−1). Printed: the largest relative
  error for k ≤ 10.

Parameter choices
-----------------
The paper tunes the rate r of each kernel "so that the results are similar
in the extent and slope of the exponential tail". Here each r was found by
bisection in log r (``--tune`` repeats it) so that the tail above 2 m has an
e-folding thickness of 1.0 m after 2000 days; the kernels take thickness in
metres and time in days, so r is in 1/day for the constant kernel, 1/(m day)
for the additive and 1/(m² day) for the multiplicative kernel. With such
rates the 20 m class, which collects all stacking that would exceed it, holds
less than 1e-9 of the area. Faster rates spread the tail up to the
truncation, where ice accumulates and the tail is no longer exponential (for
the constant kernel R² = 0.89 at r = 0.008/day and 0.63 at 0.01/day). The
exponential kernel uses β = 0.2 per metre: with β = 0.5 thick ice hardly
stacks at all (K(10 m, 10 m) = e^(−10) r) and the tail bends strongly.

Fig. 5 and Fig. 6 use the constant-kernel rate of Fig. 4 as their base,
r0 = 0.00341/day, so that the rafting runs are "K = 4 against K = 1" in
units of that rate and R_T = 1 is the run of Fig. 4. The paper's K = 1/R_T
is in its own units; what matters here is r0 against this model's
thermodynamics, in which 0.1 m ice grows by up to 0.07 m/day in mid-winter
and ice thicker than about 1.35 m thins by about 0.01 m/day all year.

The tail is not yet stationary after 2000 days for the constant kernel (λ
still creeps up by about 1 % per 200 days), so λ at the last day depends on
``--days``; the rates above were tuned for 2000 days.

The constants and helpers here (daily diagnostics :func:`advance_day`,
:func:`tail_formation`, :func:`seasonal_cycle`, the panels :func:`plot_g` and
:func:`plot_scm`) are shared with the configurable, resumable scenarios of
:mod:`physics.scenarios.godlovitch` (``ice-scenarios run godlovitch-kernels``
and the others).
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from .itd import ThorndikeModel, constant_kernel, solve_smoluchowski

TAIL_MIN = 2.0          # m: the tail is fitted above this thickness
TAIL_TARGET = 1.0       # m: e-folding thickness the rates of Fig. 4 are tuned to
DPI = 120

# Table 1 kernels with the rates found by tune_rate(kind, TAIL_TARGET) for 2000 days.
KERNELS = {
    "constant": dict(r=0.00341),
    "exponential": dict(r=0.0141, beta=0.2),
    "multiplicative": dict(r=0.000498),
    "additive": dict(r=0.000477),
}
# brackets for the bisection in tune_rate (the tail e-folding grows with r)
_BRACKETS = {"constant": (0.001, 0.008), "exponential": (0.003, 0.05),
             "multiplicative": (1e-4, 1e-3), "additive": (1e-4, 1e-3)}
# the kernels as formulas, and the units of their rates r
KERNEL_TEXT = {"constant": "K = r", "exponential": "K = r exp(−β(x+y))",
               "multiplicative": "K = r x y", "additive": "K = r (x+y)"}
R_UNITS = {"constant": "1/day", "exponential": "1/day", "multiplicative": "1/(m² day)",
           "additive": "1/(m day)"}

R0 = KERNELS["constant"]["r"]            # base rate of Figs 5 and 6 [1/day]
RAFT_FACTOR = 4.0
RAFT_CUTOFFS = (None, 0.2, 0.5, 1.0, 2.0)   # m; None: no rafting
RELATIVE_STRENGTHS = (0.5, 1.0, 2.0, 5.0, 10.0)
SCM_TIMES = (0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0)
SCM_KMAX = 50
SCM_CLASSES = 400        # classes in the coagulation solve (masses beyond leave)


# -- helpers -----------------------------------------------------------------------------

def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def colours(n, start, end):
    """n colours interpolated linearly from ``start`` to ``end`` (RGB)."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    return [tuple(a + (b - a) * (i / max(n - 1, 1))) for i in range(n)]


GREEN, RED, BLUE = (0.0, 0.65, 0.0), (0.85, 0.0, 0.0), (0.0, 0.2, 0.9)


def time_colourbar(fig, axes, plt, start, end, t_max, label="model time [days]"):
    """A colour bar from ``start`` (t = 0) to ``end`` (t = ``t_max``) beside ``axes``."""
    from matplotlib.colors import LinearSegmentedColormap, Normalize

    cmap = LinearSegmentedColormap.from_list("time", [start, end])
    sm = plt.cm.ScalarMappable(norm=Normalize(0, t_max), cmap=cmap)
    fig.colorbar(sm, ax=axes, label=label, shrink=0.8, pad=0.02)


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


def advance_day(model, series: dict, d: int, fit_every: int = 5) -> None:
    """Step ``model`` by one day and store the diagnostics of day ``d``
    (0-based) in ``series`` (from :func:`new_series`); the tail e-folding
    thickness is fitted every ``fit_every`` days and on the last day (NaN
    between, and while the tail is too short to fit)."""
    n = len(series["t"])
    model.step(1.0)
    series["t"][d] = model.time
    series["mean"][d] = model.mean_thickness
    series["open"][d] = model.open_water
    series["v2"][d] = ice_volume_above(model, 2.0)
    series["v5"][d] = ice_volume_above(model, 5.0)
    if (d + 1) % fit_every == 0 or d == n - 1:
        lam = model.tail_fit(TAIL_MIN).efolding
        series["lam"][d] = lam if math.isfinite(lam) else np.nan


def _run(model, days, *, fit_every=5):
    """Run ``model`` for ``days`` daily steps; returns snapshots (every days/10)
    and daily series of mean thickness, open water, ice volume above 2 m and
    5 m, and the tail e-folding thickness (every ``fit_every`` days, NaN
    between and while the tail is too short to fit)."""
    every = snapshot_every(days)
    snap_t, snaps = [], []
    n = int(days)
    s = new_series(n)
    for d in range(n):
        advance_day(model, s, d, fit_every)
        if (d + 1) % every == 0 or d == n - 1:
            snap_t.append(model.time)
            snaps.append(model.g.copy())
    return np.array(snap_t), np.array(snaps), s


def first_day(t, series, level):
    """First time at which ``series`` >= ``level`` (NaN entries skipped)."""
    ok = np.isfinite(series) & (series >= level)
    return float(t[np.argmax(ok)]) if ok.any() else math.nan


def last_year(x):
    """The last 360 entries (one model year of daily values) of ``x``."""
    return x[-min(len(x), int(360)):]


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
    h = np.asarray(h, dtype=float)
    snaps = np.atleast_2d(np.asarray(snaps, dtype=float))
    for g, c in zip(snaps, line_colours):
        ax.semilogy(h, np.where(g > 0, g, np.nan), color=c, lw=1.1)
    if fit is not None and math.isfinite(fit.efolding):
        hh = np.linspace(TAIL_MIN, h[-2], 50)
        use = (h > TAIL_MIN) & (snaps[-1] > 1e-12)
        use[-1] = False
        icpt = np.mean(np.log(snaps[-1][use]) - fit.slope * h[use])
        ax.semilogy(hh, np.exp(icpt + fit.slope * hh), "k--", lw=1.0,
                    label=f"fit > {TAIL_MIN:g} m: λ = {fit.efolding:.2f} m, R² = {fit.r2:.3f}")
        ax.legend(loc="upper right", fontsize=7.5, frameon=False)
    ax.set_xlim(0, h[-1])
    ax.set_ylim(1e-12, 1.5)
    ax.set_xlabel("h [m]")
    ax.set_ylabel(f"g(h) per {h[1] - h[0]:.3g} m class")
    ax.grid(True, which="major", alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9.5)


def scm_exact(k, t):
    """Exact solution of the coagulation equation with K = 1 from u_1(0) = 1:
    u_k(t) = (1 + t/2)^(−2) (t/(2 + t))^(k−1), broadcast over ``k`` and ``t``."""
    k = np.asarray(k, dtype=float)
    t = np.asarray(t, dtype=float)
    return (1.0 + t / 2.0) ** -2 * (t / (2.0 + t)) ** (k - 1)


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


# -- tuning --------------------------------------------------------------------------------

def tune_rate(kind: str, target: float = TAIL_TARGET, days: int = 2000, *,
              iterations: int = 12, bracket=None, **params) -> tuple[float, float]:
    """The rate r of kernel ``kind`` for which the tail above 2 m has an
    e-folding thickness ``target`` [m] after ``days`` days (bisection in
    log r; the e-folding grows with r). Returns (r, λ of the last trial)."""
    lo, hi = bracket or _BRACKETS[kind]
    r = lam = math.nan
    for _ in range(iterations):
        r = math.sqrt(lo * hi)
        m = ThorndikeModel(kind, r=r, **params)
        m.run(days)
        lam = m.tail_fit(TAIL_MIN).efolding
        if math.isfinite(lam) and lam >= target:
            hi = r
        else:
            lo = r
    return r, lam


# -- the figures ---------------------------------------------------------------------------

def figure4(out_dir: Path, days: int = 2000, kernels=None) -> dict:
    """Table 1 kernels, g(h) every days/10 days."""
    plt = _plt()
    kernels = kernels or KERNELS
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.6), sharex=True, sharey=True,
                             layout="constrained")
    res = {}
    for ax, (kind, params) in zip(axes.flat, kernels.items()):
        m = ThorndikeModel(kind, **params)
        t, snaps, _ = _run(m, days, fit_every=days + 1)
        fit = m.tail_fit(TAIL_MIN)
        res[kind] = dict(params, efolding=fit.efolding, r2=fit.r2, open_water=m.open_water,
                         mean_thickness=m.mean_thickness, top_class=float(m.g[-1]))
        extra = f", β = {params['beta']:g}/m" if "beta" in params else ""
        plot_g(ax, m.h[1:], snaps[:, 1:], colours(len(t), GREEN, RED), fit,
               f"{kind}: {KERNEL_TEXT[kind]}, r = {params['r']:.3g} {R_UNITS[kind]}{extra}")
    for ax in axes[0]:
        ax.set_xlabel("")
    for ax in axes[:, 1]:
        ax.set_ylabel("")
    fig.suptitle(f"Godlovitch et al. Fig. 4: Table 1 kernels, g(h) every "
                 f"{snapshot_every(days)} days for {days} days (green → red)", fontsize=11)
    time_colourbar(fig, axes, plt, GREEN, RED, days)
    _save(fig, out_dir / "itd_fig4_kernels.png", plt)
    return res


def figure5(out_dir: Path, days: int = 2000) -> dict:
    """Constant kernel with rafting for several cut-offs."""
    plt = _plt()
    runs = {}
    for hr in RAFT_CUTOFFS:
        if hr is None:
            m = ThorndikeModel("constant", r=R0)
        else:
            m = ThorndikeModel("rafting", r=R0, h_raft=hr, factor=RAFT_FACTOR)
        t, snaps, s = _run(m, days)
        runs[hr] = (m, t, snaps, s)
    lam_ref = runs[None][0].tail_fit(TAIL_MIN).efolding
    res = {}
    for hr, (m, t, snaps, s) in runs.items():
        fit = m.tail_fit(TAIL_MIN)
        res["none" if hr is None else hr] = dict(
            tail_formation(s),
            t_efolding_90pc_of_no_rafting=first_day(s["t"], s["lam"], 0.9 * lam_ref),
            efolding=fit.efolding, r2=fit.r2)

    fig, axes = plt.subplots(2, 3, figsize=(13.5, 7.6))
    shown = [None, 0.5, 1.0, 2.0]
    for ax, hr in zip(axes.flat[:4], shown):
        m, t, snaps, _ = runs[hr]
        name = "no rafting (K = r0 everywhere)" if hr is None else \
            f"rafting below h_R = {hr:g} m (K = 4 r0), K = r0 above"
        if hr is None:
            name += "; h_R = 0.2 m is the same"
        plot_g(ax, m.h[1:], snaps[:, 1:], colours(len(t), GREEN, RED),
               m.tail_fit(TAIL_MIN), name)
    styles = dict(zip(RAFT_CUTOFFS, ["k", "tab:cyan", "tab:blue", "tab:orange", "tab:red"]))
    order = list(RAFT_CUTOFFS[1:]) + [None]         # no rafting on top
    ax = axes.flat[4]
    for hr in order:
        s = runs[hr][3]
        ok = np.isfinite(s["lam"])
        ax.plot(s["t"][ok], s["lam"][ok], color=styles[hr], lw=1.0,
                ls="--" if hr is None else (":" if hr == 0.2 else "-"),
                label="no rafting" if hr is None else f"h_R = {hr:g} m")
    ax.set_xlabel("t [days]")
    ax.set_ylabel(f"tail e-folding thickness λ (h > {TAIL_MIN:g} m) [m]")
    ax.set_title("tail e-folding thickness (h_R = 0.2 and 0.5 m: as no rafting)", fontsize=9.5)
    ax.legend(fontsize=7.5, frameon=False)
    ax.grid(True, alpha=0.3)
    ax = axes.flat[5]
    for hr in order:
        s = runs[hr][3]
        ax.semilogy(s["t"], s["v2"], color=styles[hr], lw=1.0, ls="-")
        ax.semilogy(s["t"], s["v5"], color=styles[hr], lw=1.0, ls="--")
    ax.set_xlabel("t [days]")
    ax.set_ylabel("ice volume per unit area [m]")
    ax.set_title("ice volume above 2 m (solid) and above 5 m (dashed)", fontsize=9.5)
    ax.set_ylim(1e-5, 1.5)
    ax.grid(True, alpha=0.3)
    fig.suptitle(f"Godlovitch et al. Fig. 5: constant kernel r0 = {R0:g}/day with rafting "
                 f"(K = {RAFT_FACTOR:g} r0 below the cut-off h_R), g(h) every "
                 f"{snapshot_every(days)} days (green → red)", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    _save(fig, out_dir / "itd_fig5_rafting.png", plt)
    return res


def figure6(out_dir: Path, days: int = 2000) -> dict:
    """Constant kernel K = r0/R_T for several relative strengths R_T."""
    plt = _plt()
    fig, axes = plt.subplots(2, 4, figsize=(17, 7.6))
    res, series = {}, {}
    for ax, rt in zip(axes.flat, RELATIVE_STRENGTHS):
        m = ThorndikeModel("constant", r=R0, scale=1.0 / rt)
        t, snaps, s = _run(m, days)
        fit = m.tail_fit(TAIL_MIN)
        res[rt] = dict(efolding=fit.efolding, r2=fit.r2, **seasonal_cycle(s))
        series[rt] = s
        plot_g(ax, m.h[1:], snaps[:, 1:], colours(len(t), BLUE, RED), fit,
               f"R_T = {rt:g}: K = r0/R_T = {R0 / rt:.3g}/day")
    strength_colours = colours(len(RELATIVE_STRENGTHS), BLUE, RED)
    panels = [("mean", "mean thickness (open water as 0) [m]", "mean thickness"),
              ("lam", "λ / its mean over the last year",
               f"tail e-folding thickness λ (h > {TAIL_MIN:g} m), relative"),
              ("open", "open-water fraction g_0", "open water")]
    for ax, (key, ylabel, title) in zip(axes.flat[5:], panels):
        for rt, c in zip(RELATIVE_STRENGTHS, strength_colours):
            s = series[rt]
            last = slice(-min(len(s["t"]), 1080), None)
            y, tt = s[key][last], s["t"][last]
            ok = np.isfinite(y)
            if key == "lam":
                y = y / np.nanmean(last_year(s["lam"]))
            ax.plot(tt[ok], y[ok], color=c, lw=1.2, label=f"R_T = {rt:g}")
        ax.set_xlabel("t [days] (mid-winter at multiples of 360)")
        ax.set_ylabel(ylabel)
        ax.set_title(f"{title}, last three years", fontsize=9.5)
        ax.grid(True, alpha=0.3)
    axes.flat[5].legend(fontsize=7.5, frameon=False, ncol=3, loc="upper center")
    lo, hi = axes.flat[5].get_ylim()
    axes.flat[5].set_ylim(lo, hi + 0.3 * (hi - lo))
    fig.suptitle(f"Godlovitch et al. Fig. 6: relative strength R_T of thermodynamics and "
                 f"stacking, K = r0/R_T with r0 = {R0:g}/day, g(h) every "
                 f"{snapshot_every(days)} days (blue → red)", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    _save(fig, out_dir / "itd_fig6_relative_strength.png", plt)
    return res


def figure7(out_dir: Path) -> dict:
    """Pure coagulation, K = 1, monodisperse start, against the exact solution."""
    plt = _plt()
    n = SCM_CLASSES
    t = np.concatenate([[0.0], SCM_TIMES])
    u0 = np.zeros(n)
    u0[0] = 1.0
    u = solve_smoluchowski(constant_kernel(n, 1.0), u0, t)[1:]
    k = np.arange(1, n + 1)
    exact = scm_exact(k[None, :], np.asarray(SCM_TIMES)[:, None])
    rel = np.abs(u - exact) / exact
    shown = exact[:, :SCM_KMAX] > 1e-12
    res = dict(max_rel_error_k_le_10=float(rel[:, :10].max()),
               max_rel_error_k_le_50=float(rel[:, :SCM_KMAX][shown].max()),
               mass_error=float(np.abs((u * k).sum(1) - 1.0).max()))

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11.5, 4.8))
    plot_scm(ax, ax2, k[:SCM_KMAX], SCM_TIMES, u[:, :SCM_KMAX], exact[:, :SCM_KMAX], n, 1e-10)
    fig.suptitle("Godlovitch et al. Fig. 7: Smoluchowski coagulation with K(j, k) = 1, "
                 "u_1(0) = 1", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    _save(fig, out_dir / "itd_fig7_scm_constant.png", plt)
    return res


def _save(fig, path: Path, plt) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def make_figures(out_dir, days: int = 2000, kernels=None) -> dict:
    """Draw Figs 4–7 into ``out_dir`` (created if needed) from runs of
    ``days`` days; ``kernels`` overrides :data:`KERNELS` for Fig. 4. Returns
    {"fig4": {kernel: …}, "fig5": {cut-off or "none": …},
    "fig6": {R_T: …}, "fig7": {…}} with the numbers :func:`summary` prints."""
    days = int(days)
    if days < 10:
        raise ValueError(f"days must be at least 10, got {days}")
    out = Path(out_dir)
    return {"fig4": figure4(out, days, kernels), "fig5": figure5(out, days),
            "fig6": figure6(out, days), "fig7": figure7(out)}


def summary(res: dict) -> list[str]:
    """One line per figure from the result of :func:`make_figures`."""
    def f(x, fmt=".2f"):
        return "nan" if x is None or not math.isfinite(x) else format(x, fmt)

    lines = ["Fig 4 (kernels; λ, R² of the tail above 2 m at the end): " + "; ".join(
        f"{k} r={v['r']:.3g}" + (f" β={v['beta']:g}" if "beta" in v else "")
        + f" λ={f(v['efolding'])} m R²={f(v['r2'], '.4f')} top={v['top_class']:.1e}"
        for k, v in res["fig4"].items())]
    lines.append("Fig 5 (rafting, K=4r0 below h_R; day of 90 % of final volume above 2 m / "
                 "5 m, day λ reaches 90 % of λ without rafting, final λ, R²): " + "; ".join(
                     f"{'none' if k == 'none' else f'h_R={k:g} m'}: "
                     f"{f(v['t90_volume_above_2m'], '.0f')}/{f(v['t90_volume_above_5m'], '.0f')} d, "
                     f"{f(v['t_efolding_90pc_of_no_rafting'], '.0f')} d, λ={f(v['efolding'])} m, "
                     f"R²={f(v['r2'], '.4f')}" for k, v in res["fig5"].items()))
    lines.append("Fig 6 (K=r0/R_T; λ, R², mean thickness ± seasonal amplitude over the last "
                 "year, λ range over the last year): " + "; ".join(
                     f"R_T={k:g}: λ={f(v['efolding'])} m R²={f(v['r2'], '.4f')} "
                     f"H={v['mean_thickness']:.2f}±{v['mean_thickness_amplitude']:.2f} m "
                     f"({100 * v['relative_amplitude']:.0f} %) "
                     f"λ {v['efolding_range'][0]:.2f}–{v['efolding_range'][1]:.2f} m "
                     f"({100 * v['efolding_relative_range']:.0f} %)"
                     for k, v in res["fig6"].items()))
    v = res["fig7"]
    lines.append(f"Fig 7 (SCM K=1 vs exact): max relative error k ≤ 10: "
                 f"{v['max_rel_error_k_le_10']:.2e}; k ≤ {SCM_KMAX} (u_k > 1e-12): "
                 f"{v['max_rel_error_k_le_50']:.2e}; mass error {v['mass_error']:.1e}")
    return lines


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m physics.itd_figures", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=Path, default=Path("docs/figures"),
                   help="directory for the PNGs (default: docs/figures)")
    p.add_argument("--days", type=int, default=2000,
                   help="model days of the Thorndike-model runs (default 2000)")
    p.add_argument("--tune", action="store_true",
                   help=f"first re-tune r of each Fig. 4 kernel to a tail e-folding of "
                        f"{TAIL_TARGET:g} m after --days days (adds about 10 s)")
    args = p.parse_args(argv)
    if args.days < 10:
        p.error("--days must be at least 10")
    t0 = time.perf_counter()
    kernels = None
    if args.tune:
        kernels = {}
        for kind, params in KERNELS.items():
            extra = {k: v for k, v in params.items() if k != "r"}
            r, lam = tune_rate(kind, TAIL_TARGET, args.days, **extra)
            kernels[kind] = dict(params, r=float(f"{r:.3g}"))
            print(f"tuned {kind}: r = {r:.3g} {R_UNITS[kind]} (λ = {lam:.3f} m)")
    res = make_figures(args.out, args.days, kernels)
    for line in summary(res):
        print(line)
    print(f"figures in {args.out}: itd_fig4_kernels.png, itd_fig5_rafting.png, "
          f"itd_fig6_relative_strength.png, itd_fig7_scm_constant.png "
          f"({time.perf_counter() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
