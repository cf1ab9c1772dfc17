"""Herman (2013) experiments on the Hertz engine (:ref:`physics-contact`).

* ``herman2013-convergence`` — pure convergence without wind: p(A), Z_c(A),
  f_nr(A), the jamming concentration A_J from the pressure curve (Figs 1a,
  3) and force-network snapshots (Fig 2).
* ``herman2013-wind`` — constant wind at fixed A, swept over A: p, τ, Z_c,
  Z_a against A (Fig 5) and snapshots with force chains (Fig 4).
* ``herman2013-miz`` — a frozen fast-ice edge and wind at several angles:
  u_x(y) profiles (Fig 6), p and τ time series and p/τ (Fig 7), Z_c and Z_a.

Contact numbers. ``z_c`` is eq 10 of the paper as :func:`physics.observables.fabric`
computes it: the trace of the fabric tensor over the non-rattlers (floes
with at least two contacts), so it is 0 when there are none and at least 2
otherwise. The paper also calls "mean contact number Z_c ≈ 1" the state of
binary collisions below jamming; that is ``z_touch``, the mean number of
contacts of the floes that touch anything (1 when every contact is a binary
collision). Both are recorded.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np

from ..domain import ChannelBox, DeformingPeriodicBox, PeriodicBox
from ..engine import FloeEngine
from ..floes import FloeField
from ..forcing import Forcing, steady_drift
from ..hertz import hertz_time_step, scaled_contact
from ..hertz_kernels import floe_drag
from ..ice_fields import place_then_compress
from ..observables import fabric, stress
from ..params import HERMAN2013
from . import plots
from .engines import hertz_simulation
from .experiment import Experiment, register

NETWORK_VARIABLES = {
    "concentration": ("1", "ice concentration A"),
    "p": ("N/m", "pressure (σ1 + σ2)/2 of the Love-Weber contact stress, compression > 0"),
    "tau": ("N/m", "shear stress (σ1 − σ2)/2"),
    "z_c": ("1", "Z_c of eq 10: contacts per non-rattler (0 without non-rattlers)"),
    "z_a": ("1", "anisotropy Z_a = (λ1 − λ2)/Z_c of the fabric tensor"),
    "f_nr": ("1", "fraction of non-rattlers (floes with at least two contacts)"),
    "z_touch": ("1", "mean contacts of the floes that touch anything (1: binary collisions)"),
    "contacts_per_floe": ("1", "2 × contacts / N"),
    "mean_u": ("m/s", "mean x velocity of the mobile floes"),
    "mean_v": ("m/s", "mean y velocity of the mobile floes"),
}

IMPACT_SPEED = 1.0   # m/s: the time-step check admits impacts up to this relative speed


# ---------------------------------------------------------------------------
# shared set-up and measurements
# ---------------------------------------------------------------------------

def contact_law(p: dict):
    """The Herman (2013) contact law with the scenario parameters
    ``friction``, ``restitution``, ``tangential_damping``,
    ``tangential_stiffness``, ``friction_moves_floes`` and
    ``stiffness_scale`` of ``p`` (also that of ship-transit)."""
    c = dataclasses.replace(HERMAN2013.contact, friction=p["friction"],
                            restitution=p["restitution"],
                            tangential_damping=p["tangential_damping"],
                            tangential_stiffness=p["tangential_stiffness"],
                            tangential_translation=p["friction_moves_floes"])
    return scaled_contact(c, p["stiffness_scale"])


def _simulation(field: FloeField, box, p: dict, forcing: Forcing | None,
                engine: str) -> FloeEngine:
    contact = contact_law(p)
    dt = hertz_time_step(field, box, contact, IMPACT_SPEED, HERMAN2013.time_step,
                         p["stiffness_scale"])
    return hertz_simulation(engine, field, box, contact, forcing, dt=dt,
                            impact_speed=IMPACT_SPEED, allow_overlap=True)


def _field(n: int, concentration: float, seed: int, *, aspect: float = 1.0, box_type=PeriodicBox):
    """Herman (2013) floe field (α = 1.8, mean radius 4 m, h = 1.5 m) at
    ``concentration``. In a periodic box, above the random-placement limit
    (0.85) it is placed at 0.85 and compressed affinely with FIRE relaxation
    (below the jamming point the floes then do not overlap; above it they
    form a jammed packing in force balance). A box with walls cannot be
    compressed that way: the floes are placed at the concentration itself,
    which works up to about 0.88 (beyond, placement fails with a
    :class:`physics.floes.PlacementError` saying so)."""
    def place(c: float):
        return HERMAN2013.floe_field(n, c, seed=seed, aspect=aspect, box_type=box_type)

    if box_type is not PeriodicBox or concentration <= 0.85:
        return place(concentration)
    # above the field's jamming point the result is a jammed packing in force
    # balance (small overlaps), which the engine accepts as a start
    field, box, _ = place_then_compress(place, concentration, 0.85)
    return field, box


def network(sim: FloeEngine) -> tuple[dict, object]:
    """The contact-network and stress measures of NETWORK_VARIABLES, and the
    contact table."""
    c = sim.contacts()
    n = sim.n_floes
    fab = fabric(c, n)
    st = stress(c, sim.box.area, n_floes=n, per_floe=False)
    coord = fab.coordination
    touching = coord > 0
    mobile = ~sim.frozen
    vel = sim.velocities[mobile]
    return dict(concentration=sim.concentration, p=st.pressure, tau=st.shear, z_c=fab.z_c,
                z_a=fab.z_a, f_nr=fab.f_nr,
                z_touch=float(coord[touching].mean()) if touching.any() else 0.0,
                contacts_per_floe=2.0 * len(c) / n, mean_u=float(vel[:, 0].mean()),
                mean_v=float(vel[:, 1].mean())), c


def _snapshot(rec, sim: FloeEngine, contacts) -> None:
    rec.snapshot(sim.time, sim.positions, sim.radii, sim.velocities,
                 box=(sim.box.lx, sim.box.ly), contacts=(contacts.i, contacts.j,
                                                         contacts.normal_force),
                 frozen=sim.frozen)


def advance(sim: FloeEngine, duration: float) -> str | None:
    """Advance ``sim`` by ``duration`` (at least one step); a physics failure
    is returned as a message (the run ends there, with everything recorded
    so far), else None."""
    try:
        sim.advance(max(duration, sim.dt))     # at least one step: the loops always progress
    except (FloatingPointError, RuntimeError) as exc:
        return str(exc)
    return None


def _finish(rec, sim: FloeEngine, st: dict) -> None:
    """End of a run: a last snapshot if the state changed since the last
    one, and a note if the run ended early."""
    if not rec.snapshots or rec.snapshots[-1]["time"] < sim.time:
        _snapshot(rec, sim, network(sim)[1])
    if st["error"] is not None:
        rec.note(f"ended at t = {sim.time:.1f} s: {st['error']}")


def _run_for_duration(p: dict, st: dict, rec, measure) -> None:
    """The time loop of the fixed-forcing runs: advance ``st["sim"]`` to
    ``p["duration"]`` in steps of ``p["output_interval"]``, record
    ``measure(sim)`` → (values, contacts) after each, take snapshots at
    ``p["snapshot_times"]`` and at the end, report progress and checkpoint
    ``st`` (which carries ``sim``, ``error`` and ``next_snap``)."""
    sim = st["sim"]
    snaps = sorted(p["snapshot_times"]) + [p["duration"]]
    while st["error"] is None and sim.time < p["duration"] - 0.5 * sim.dt:
        st["error"] = advance(sim, min(p["output_interval"], p["duration"] - sim.time))
        values, c = measure(sim)
        rec.record(sim.time, **values)
        while st["next_snap"] < len(snaps) and sim.time >= snaps[st["next_snap"]] - 1e-9:
            st["next_snap"] += 1
            _snapshot(rec, sim, c)
        rec.progress(sim.time / p["duration"])
        rec.checkpoint(st)
    _finish(rec, sim, st)


def _fmt(values, fmt=".3g") -> str:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return "n/a"
    if v.size == 1:
        return format(v[0], fmt)
    return f"{format(v.mean(), fmt)} ± {format(v.std(ddof=1), fmt)}"


def _late(ds, name: str, fraction: float = 0.5) -> np.ndarray:
    """Time mean of ``name`` over the last ``fraction`` of each run:
    (case, member)."""
    t = ds["time"].values
    x = ds[name].values
    out = np.full(x.shape[:2], np.nan)
    for c in range(x.shape[0]):
        for m in range(x.shape[1]):
            ok = np.isfinite(t[c, m]) & np.isfinite(x[c, m])
            if ok.sum() < 2:
                continue
            tt = t[c, m][ok]
            sel = tt >= tt[0] + (1.0 - fraction) * (tt[-1] - tt[0])
            out[c, m] = x[c, m][ok][sel].mean()
    return out


def _member_lines(ax, x, y, **kw):
    for m in range(y.shape[0]):
        ok = np.isfinite(x[m]) & np.isfinite(y[m])
        ax.plot(x[m][ok], y[m][ok], **(kw if m == 0 else {**kw, "label": None}))


# ---------------------------------------------------------------------------
# pure convergence
# ---------------------------------------------------------------------------

def jamming_from_pressure(concentration, pressure, *, min_points: int = 4):
    """A_J as the knee of ln p(A): the breakpoint of the best continuous
    two-piece linear fit ln p = a + b A + c max(0, A − A_J) (exponential
    growth below A_J, much faster growth above). Outputs with p ≤ 0 are
    skipped. Returns (A_J, slope below, slope above) or NaNs when there are
    too few points."""
    a = np.asarray(concentration, dtype=float)
    p = np.asarray(pressure, dtype=float)
    ok = np.isfinite(a) & np.isfinite(p) & (p > 0)
    a, y = a[ok], np.log(p[ok])
    if a.size < 2 * min_points + 1:
        return math.nan, math.nan, math.nan
    best = (math.inf, math.nan, math.nan, math.nan)
    for k in range(min_points, a.size - min_points):
        knee = a[k]
        X = np.column_stack([np.ones_like(a), a, np.maximum(0.0, a - knee)])
        coef, *_ = np.linalg.lstsq(X, y, rcond=None)
        sse = float(np.sum((X @ coef - y) ** 2))
        if sse < best[0] and coef[2] > 0:
            best = (sse, knee, coef[1], coef[1] + coef[2])
    return best[1], best[2], best[3]


def first_crossing(concentration, values, level: float) -> float:
    """The first A from which ``values`` stays above ``level`` (NaN if never)."""
    a = np.asarray(concentration, dtype=float)
    v = np.asarray(values, dtype=float)
    ok = np.isfinite(a) & np.isfinite(v)
    a, v = a[ok], v[ok]
    above = v > level
    if not above.any() or not above[-1]:
        return math.nan
    below = np.nonzero(~above)[0]
    k = below[-1] + 1 if below.size else 0
    return float(a[k])


@register("herman2013-convergence")
class Convergence(Experiment):
    """Pure convergence of a periodic box at dA/dt, floes initially at rest."""

    engines = ("numba", "lammps")

    variables = {**NETWORK_VARIABLES,
                 "a_j": ("1", "A_J: knee of ln p(A) (two-piece fit)"),
                 "a_j_network": ("1", "first A from which Z_c stays above 3"),
                 "slope_below": ("1", "d ln p / dA below A_J"),
                 "slope_above": ("1", "d ln p / dA above A_J"),
                 "completed": ("1", "1 if the run reached end_concentration or max_pressure")}
    required = ("time", "concentration", "p", "tau", "z_c", "z_a", "f_nr", "z_touch", "a_j",
                "floe_x", "contact_force")

    def workload(self, p, case):
        return p["floes"] * (p["end_concentration"] - p["start_concentration"]) / p["rate"]

    def simulate(self, p, case, seed, rec):
        st = rec.restore()
        rate = p["rate"] / 3600.0
        if st is None:
            field, box = _field(p["floes"], p["start_concentration"], seed)
            box = DeformingPeriodicBox(box.lx, box.ly, concentration_rate=rate,
                                       max_concentration=min(0.999, p["end_concentration"] + 0.02))
            # no wind and no current, but water drag and Coriolis act on moving floes
            forcing = HERMAN2013.make_forcing(wind=(0.0, 0.0), current=(0.0, 0.0))
            sim = _simulation(field, box, p, forcing, self.engine)
            st = dict(sim=sim, next_snap=p["start_concentration"] + p["snapshot_step"],
                      error=None)
            net, c = network(sim)
            rec.record(sim.time, **net)
            _snapshot(rec, sim, c)
        sim = st["sim"]
        a0, a1 = p["start_concentration"], p["end_concentration"]
        dt_out = p["output_step"] / rate
        while st["error"] is None and sim.concentration < a1 - 0.5 * rate * sim.dt:
            step = min(dt_out, (a1 - sim.concentration) / rate)
            st["error"] = advance(sim, step)
            net, c = network(sim)
            rec.record(sim.time, **net)
            if net["concentration"] >= st["next_snap"] - 1e-9:
                while st["next_snap"] <= net["concentration"] + 1e-9:
                    st["next_snap"] += p["snapshot_step"]
                _snapshot(rec, sim, c)
            rec.progress((sim.concentration - a0) / (a1 - a0))
            if net["p"] > p["max_pressure"]:
                st["error"] = f"pressure {net['p']:.3g} N/m above max_pressure"
                st["pressure_limit"] = True
            rec.checkpoint(st)
        _finish(rec, sim, st)
        a = np.array([row["concentration"] for _, row in rec.rows])
        pr = np.array([row["p"] for _, row in rec.rows])
        zc = np.array([row["z_c"] for _, row in rec.rows])
        a_j, lo, hi = jamming_from_pressure(a, pr)
        rec.result(a_j=a_j, a_j_network=first_crossing(a, zc, 3.0), slope_below=lo,
                   slope_above=hi,
                   completed=float(sim.concentration >= a1 - 1e-6
                                   or st.get("pressure_limit", False)))

    def summarise(self, ds, p):
        a = ds["concentration"].values[0]            # (member, sample)
        aj = ds["a_j"].values.ravel()
        rows = [("A_J, knee of ln p(A)", _fmt(aj, ".4f"), "0.918–0.921"),
                ("A_J, Z_c stays above 3", _fmt(ds["a_j_network"].values.ravel(), ".4f"),
                 "Z_c exceeds 3 at A_J")]
        below, above = [], []
        for m, ref in enumerate(aj):
            if np.isfinite(ref):
                below.append((a[m] > ref - 0.03) & (a[m] < ref - 0.01))
                above.append(a[m] > ref + 0.005)
        if below:
            below, above = np.array(below), np.array(above)
            for name, label in (("z_touch", "contacts per touching floe (binary collisions: 1)"),
                                ("f_nr", "f_nr")):
                v = ds[name].values[0][np.isfinite(aj)]
                rows.append((f"{label}, A_J − 0.03 < A < A_J − 0.01", _fmt(v[below], ".3f"),
                             "Z_c ≈ 1, f_nr ≈ 0 well below A_J"))
                rows.append((f"{label}, A > A_J + 0.005", _fmt(v[above], ".3f"),
                             "grows above A_J"))
            zc = ds["z_c"].values[0][np.isfinite(aj)]
            rows.append(("Z_c (eq 10), A > A_J + 0.005", _fmt(zc[above], ".2f"), "> 3 above A_J"))
        pr = ds["p"].values[0]
        last = [(pr[m][np.isfinite(pr[m])][-1], a[m][np.isfinite(pr[m])][-1])
                for m in range(pr.shape[0]) if np.isfinite(pr[m]).any()]
        if last:
            rows.append(("p at the last output", ", ".join(f"{v:.3g} N/m at A = {x:.4f}"
                                                           for v, x in last),
                         "hyper-exponential above A_J"))
        rows.append(("slopes d ln p/dA below / above A_J",
                     f"{_fmt(ds['slope_below'].values.ravel(), '.0f')} / "
                     f"{_fmt(ds['slope_above'].values.ravel(), '.0f')}", "exponential, then faster"))
        return rows

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        out = []
        a = ds["concentration"].values[0]
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        ax = axes[0]
        _member_lines(ax, a, ds["p"].values[0], color="k", lw=1, label="p")
        _member_lines(ax, a, ds["tau"].values[0], color="0.6", lw=0.8, label="τ")
        ax.set_yscale("log")
        ax.set_xlabel("A")
        ax.set_ylabel("stress [N/m]")
        for aj in ds["a_j"].values.ravel():
            if np.isfinite(aj):
                ax.axvline(aj, color="crimson", ls="--", lw=0.8)
        ax.axvspan(0.918, 0.921, color="orange", alpha=0.3, label="paper A_J")
        ax.legend(fontsize=8)
        ax.set_title("pressure under pure convergence (Fig 1a)", fontsize=9)
        ax = axes[1]
        _member_lines(ax, a, ds["z_c"].values[0], color="k", label="Z_c (eq 10)")
        _member_lines(ax, a, ds["z_touch"].values[0], color="tab:blue",
                      label="contacts per touching floe")
        ax.set_xlabel("A")
        ax.set_ylabel("contacts")
        ax2 = ax.twinx()
        _member_lines(ax2, a, ds["f_nr"].values[0], color="tab:green", label="f_nr")
        ax2.set_ylabel("f_nr", color="tab:green")
        ax2.set_ylim(0, 1)
        ax.axhline(3, color="0.5", lw=0.5, ls=":")
        ax.legend(fontsize=8, loc="upper left")
        ax.set_title("contact numbers (Fig 3)", fontsize=9)
        out.append(plots.savefig(fig, Path(out_dir) / "convergence_pressure_contacts.png"))
        # three snapshots of member 0 around its A_J: below, near and at/after it (Fig 2)
        times = ds["snapshot_time"].values[0, 0]
        times = times[np.isfinite(times)]
        conc_snap = np.interp(times, ds["time"].values[0, 0][np.isfinite(a[0])],
                              a[0][np.isfinite(a[0])])
        aj = float(ds["a_j"].values[0, 0])
        ref = aj if np.isfinite(aj) else float(conc_snap[-1])
        picks = sorted({int(np.argmin(np.abs(conc_snap - t)))
                        for t in (ref - 0.01, ref - 0.004, ref + 0.004)})
        conc_at = [conc_snap[s] for s in picks]
        out.append(plots.snapshot_panels(
            ds, Path(out_dir) / "convergence_force_networks.png",
            title="force networks under convergence (Fig 2); line width ∝ √F_n",
            labels=[f"A = {c:.3f}" for c in conc_at],
            select=[{"case": 0, "member": 0, "snapshot": s} for s in picks]))
        return out


# ---------------------------------------------------------------------------
# constant wind at fixed concentration
# ---------------------------------------------------------------------------

@register("herman2013-wind")
class Wind(Experiment):
    """Constant wind along x in a periodic box, one run per concentration."""

    engines = ("numba", "lammps")

    variables = {**NETWORK_VARIABLES}
    required = ("time", "p", "tau", "z_c", "z_a", "f_nr", "z_touch", "floe_x", "contact_force")
    case_label = "concentration"

    def cases(self, p):
        return [{"concentration": a} for a in p["concentrations"]]

    def workload(self, p, case):
        return case["concentration"] ** 4

    def simulate(self, p, case, seed, rec):
        st = rec.restore()
        if st is None:
            field, box = _field(p["floes"], case["concentration"], seed)
            forcing = HERMAN2013.make_forcing(wind=(p["wind_speed"], 0.0))
            # every floe starts at its own free drift: the spin-up of the whole sheet
            # (water-drag time of ~20 min) is skipped
            drift = steady_drift(forcing, field.radii, field.thickness, field.masses)
            field = FloeField(field.positions, field.radii, field.thickness, drift,
                              density=field.density)
            sim = _simulation(field, box, p, forcing, self.engine)
            st = dict(sim=sim, error=None, next_snap=0)

        def measure(sim):
            net, c = network(sim)
            net.pop("concentration")          # fixed: it is the case coordinate
            return net, c
        _run_for_duration(p, st, rec, measure)

    def summarise(self, ds, p):
        conc = ds.coords["concentration"].values
        rows = []
        late = {k: _late(ds, k) for k in ("p", "tau", "z_c", "z_a", "z_touch", "f_nr")}
        for c, a in enumerate(conc):
            rows.append((f"A = {a:.3f}: p, τ [N/m]",
                         f"{_fmt(late['p'][c])}, {_fmt(late['tau'][c])}",
                         "p as in the transitional regime below A_J"))
            rows.append((f"A = {a:.3f}: Z_c, Z_a, contacts per touching floe, f_nr",
                         f"{_fmt(late['z_c'][c], '.2f')}, {_fmt(late['z_a'][c], '.3f')}, "
                         f"{_fmt(late['z_touch'][c], '.2f')}, {_fmt(late['f_nr'][c], '.2f')}",
                         "τ and Z_a grow as A decreases"))
        za = np.nanmean(late["z_a"], axis=1)
        tau = np.nanmean(late["tau"], axis=1)
        if len(conc) > 2:
            rows.append(("rank correlation of Z_a with A", f"{_spearman(conc, za):+.2f}",
                         "negative"))
            rows.append(("rank correlation of τ/p with A",
                         f"{_spearman(conc, tau / np.nanmean(late['p'], axis=1)):+.2f}",
                         "negative"))
        return rows

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        conc = ds.coords["concentration"].values
        late = {k: _late(ds, k) for k in ("p", "tau", "z_c", "z_a", "z_touch")}
        fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
        for key, colour, label in (("p", "k", "p"), ("tau", "0.5", "τ")):
            axes[0].errorbar(conc, np.nanmean(late[key], 1), yerr=_sd(late[key]), color=colour,
                             marker="o", label=label, capsize=2)
        axes[0].set_yscale("log")
        axes[0].set_ylabel("stress [N/m]")
        axes[0].legend(fontsize=8)
        axes[1].errorbar(conc, np.nanmean(late["z_c"], 1), yerr=_sd(late["z_c"]), marker="o",
                         color="k", label="Z_c (eq 10)", capsize=2)
        axes[1].errorbar(conc, np.nanmean(late["z_touch"], 1), yerr=_sd(late["z_touch"]),
                         marker="s", color="tab:blue", label="contacts per touching floe",
                         capsize=2)
        axes[1].set_ylabel("contacts")
        axes[1].legend(fontsize=8)
        axes[2].errorbar(conc, np.nanmean(late["z_a"], 1), yerr=_sd(late["z_a"]), marker="o",
                         color="k", capsize=2)
        axes[2].set_ylabel("Z_a")
        for ax, t in zip(axes, ("(a) p and τ", "(b) contact number", "(c) anisotropy")):
            ax.set_xlabel("A")
            ax.set_title(t + f", wind {p['wind_speed']:g} m/s (Fig 5)", fontsize=9)
        out = [plots.savefig(fig, Path(out_dir) / "wind_stress_fabric.png")]
        last = [int(np.isfinite(ds["snapshot_time"].values[c, 0]).sum()) - 1
                for c in range(len(conc))]
        pick = sorted({0, len(conc) - 1}) if len(conc) > 1 else [0]
        out.append(plots.snapshot_panels(
            ds, Path(out_dir) / "wind_force_networks.png",
            title=f"force networks under a {p['wind_speed']:g} m/s wind along x (Fig 4)",
            labels=[f"A = {conc[c]:.3f}, t = {ds['snapshot_time'].values[c, 0, last[c]]:.0f} s"
                    for c in pick],
            select=[{"case": c, "member": 0, "snapshot": last[c]} for c in pick]))
        return out


def _sd(x):
    n = np.sum(np.isfinite(x), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 1, np.nanstd(x, axis=1, ddof=1) if x.shape[1] > 1 else 0.0, 0.0)


def _spearman(x, y) -> float:
    x, y = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3:
        return math.nan
    rx = np.argsort(np.argsort(x[ok]))
    ry = np.argsort(np.argsort(y[ok]))
    return float(np.corrcoef(rx, ry)[0, 1])


# ---------------------------------------------------------------------------
# marginal ice zone
# ---------------------------------------------------------------------------

@register("herman2013-miz")
class MarginalIceZone(Experiment):
    """Frozen floes along y = 0, periodic in x, a wall at the top; constant
    wind of fixed speed at an angle to the edge, one run per angle."""

    engines = ("numba", "lammps")

    variables = {**NETWORK_VARIABLES,
                 "u_x_profile": ("m/s", "mean u_x of the mobile floes in bins of y")}
    required = ("time", "p", "tau", "z_c", "z_a", "z_touch", "u_x_profile", "floe_x")
    case_label = "wind_y"

    def cases(self, p):
        return [{"wind_y": v} for v in p["wind_y"]]

    def simulate(self, p, case, seed, rec):
        st = rec.restore()
        speed = p["wind_speed"]
        uy = case["wind_y"]
        if abs(uy) > speed:
            raise ValueError(f"wind_y = {uy} exceeds wind_speed = {speed}")
        if st is None:
            field, box = _field(p["floes"], p["concentration"], seed, aspect=p["aspect"],
                                box_type=ChannelBox)
            if p["open_water"] > 0.0:
                # open water above the ice: the wall at the top moves away
                box = ChannelBox(box.lx, box.ly * (1.0 + p["open_water"]))
            frozen = field.positions[:, 1] < p["edge_width"]
            if frozen.all() or not frozen.any():
                raise ValueError(f"edge_width = {p['edge_width']} m freezes {int(frozen.sum())} "
                                 f"of {field.n} floes; choose it so that some but not all are")
            field = FloeField(field.positions, field.radii, field.thickness, field.velocities,
                              density=field.density, frozen=frozen)
            forcing = HERMAN2013.make_forcing(wind=(math.sqrt(speed ** 2 - uy ** 2), uy))
            sim = _simulation(field, box, p, forcing, self.engine)
            st = dict(sim=sim, error=None, next_snap=0)
        sim = st["sim"]
        edges = np.linspace(0.0, sim.box.ly, p["profile_bins"] + 1)
        rec.coord("y", 0.5 * (edges[1:] + edges[:-1]), "m", "distance from the fast-ice side")
        mobile = ~sim.frozen

        def measure(sim):
            net, c = network(sim)
            y = sim.positions[mobile, 1]
            k = np.clip(np.searchsorted(edges, y) - 1, 0, p["profile_bins"] - 1)
            counts = np.bincount(k, minlength=p["profile_bins"])
            sums = np.bincount(k, sim.velocities[mobile, 0], minlength=p["profile_bins"])
            with np.errstate(invalid="ignore", divide="ignore"):
                prof = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
            return dict(u_x_profile=("y", prof), **net), c
        _run_for_duration(p, st, rec, measure)

    def summarise(self, ds, p):
        rows = []
        wy = ds.coords["wind_y"].values
        for c, v in enumerate(wy):
            t = ds["time"].values[c]
            late = t >= 0.5 * np.nanmax(t)
            pr = ds["p"].values[c][late]
            ta = ds["tau"].values[c][late]
            ok = np.isfinite(pr) & np.isfinite(ta)
            corr = float(np.corrcoef(pr[ok], ta[ok])[0, 1]) if ok.sum() > 2 else math.nan
            with np.errstate(invalid="ignore", divide="ignore"):
                ratio = pr[ok] / ta[ok]
            ratio = ratio[np.isfinite(ratio)]
            width, outer = shear_zone(ds["y"].values,
                                      late_profile(ds["u_x_profile"].values[c][late]),
                                      p["edge_width"])
            rows += [
                (f"u_a,y = {v:g}: shear-zone width (10–90 % of the outer u_x)",
                 f"{_fmt(width, '.1f')} m; outer u_x {_fmt(outer, '.3f')} m/s",
                 "narrow shear zone by the edge"),
                (f"u_a,y = {v:g}: σ_xy, σ_yy on the fast ice (end of run), ratio",
                 self._edge_row(ds, p, c, v), "not given"),
                (f"u_a,y = {v:g}: corr(p, τ)", f"{_fmt(corr, '.2f')}", "0.68"),
                (f"u_a,y = {v:g}: p/τ, 5th–95th percentile",
                 (f"{np.percentile(ratio, 5):.1f}–{np.percentile(ratio, 95):.1f}"
                  if ratio.size else "n/a"), "≈ 1 to ≈ 12"),
                (f"u_a,y = {v:g}: Z_c (eq 10), contacts per touching floe, Z_a",
                 f"{_fmt(np.nanmean(ds['z_c'].values[c][late]), '.2f')}, "
                 f"{_fmt(np.nanmean(ds['z_touch'].values[c][late]), '.2f')}, "
                 f"{_fmt(np.nanmean(ds['z_a'].values[c][late]), '.3f')}",
                 "Z_c ≈ 1.6, Z_a in 0.04–0.08"),
            ]
        return rows

    @staticmethod
    def _edge_row(ds, p, c, wind_y):
        """Mean over the members of the edge stress of the last snapshot."""
        k = int(np.isfinite(ds["snapshot_time"].values[c, 0]).sum()) - 1
        if k < 0:
            return "n/a"
        wind = (math.sqrt(p["wind_speed"] ** 2 - wind_y ** 2), wind_y)
        res = np.array([edge_stress(ds.isel(case=c, member=m, snapshot=k), wind)
                        for m in range(ds.sizes["member"])])
        sxy, syy = res.mean(axis=0)
        ratio = sxy / syy if syy > 0 else math.nan
        return f"{sxy:.1f}, {syy:.1f} N/m; {_fmt(ratio, '.2f')}"

    def plot(self, ds, p, out_dir):
        plt = plots.pyplot()
        out = []
        wy = ds.coords["wind_y"].values
        y = ds["y"].values
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for c, v in enumerate(wy):
            t = ds["time"].values[c, 0]
            late = t >= 0.5 * np.nanmax(t)
            k = int(np.isfinite(ds["snapshot_time"].values[c, 0]).sum()) - 1
            snap = ds.isel(case=c, member=0, snapshot=k)
            mob = (snap["floe_frozen"].values == 0) & np.isfinite(snap["floe_x"].values)
            line, = ax.plot(late_profile(ds["u_x_profile"].values[c, 0][late]), y,
                            lw=2, label=f"u_a,y = {v:g} m/s")
            ax.scatter(snap["floe_u"].values[mob], snap["floe_y"].values[mob], s=2,
                       color=line.get_color(), alpha=0.4)
        ax.axhline(p["edge_width"], color="0.5", ls=":", lw=0.8)
        ax.set_xlabel("u_x [m/s]")
        ax.set_ylabel("y [m] (fast ice at y = 0)")
        ax.legend(fontsize=8)
        ax.set_title("along-edge velocity: floes (dots) and late-time mean (Fig 6)", fontsize=9)
        out.append(plots.savefig(fig, Path(out_dir) / "miz_velocity_profiles.png"))
        c = int(np.argmin(wy))
        t = ds["time"].values[c, 0]
        fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
        axes[0].plot(t / 60, ds["p"].values[c, 0], color="k", lw=0.8, label="p")
        axes[0].plot(t / 60, ds["tau"].values[c, 0], color="0.5", lw=0.8, label="τ")
        axes[0].set_ylabel("stress [N/m]")
        axes[0].legend(fontsize=8)
        axes[0].set_title(f"u_a,y = {wy[c]:g} m/s (Fig 7)", fontsize=9)
        with np.errstate(invalid="ignore", divide="ignore"):
            axes[1].plot(t / 60, ds["p"].values[c, 0] / ds["tau"].values[c, 0], color="k", lw=0.8)
        axes[1].set_ylabel("p/τ")
        axes[1].set_yscale("log")
        axes[1].set_xlabel("t [min]")
        out.append(plots.savefig(fig, Path(out_dir) / "miz_stress_series.png"))
        last = [int(np.isfinite(ds["snapshot_time"].values[c, 0]).sum()) - 1
                for c in range(len(wy))]
        out.append(plots.snapshot_panels(
            ds, Path(out_dir) / "miz_force_networks.png",
            title="marginal ice zone at the end of the runs (grey: fast ice)",
            labels=[f"u_a,y = {v:g} m/s" for v in wy],
            select=[{"case": c, "member": 0, "snapshot": last[c]} for c in range(len(wy))]))
        return out


def edge_stress(snap, wind, thickness: float = HERMAN2013.thickness,
                forcing_params=HERMAN2013.forcing):
    """Stress (σ_xy, σ_yy) [N/m] that the mobile ice exerts on the fast ice,
    from the momentum balance of the mobile floes in one snapshot.

    In a steady state (on average) the frozen floes take up the sum of the
    external forces on the mobile ones: wind, water drag and Coriolis (eq 6,
    the engine's own :func:`physics.hertz_kernels.floe_drag`) at the
    snapshot's velocities. Divided by the length of the edge, that
    is the shear and normal stress across the edge, and σ_xy/σ_yy is the
    friction the ice mobilises there. Floes at rest under a wind (u_a,x,
    u_a,y) give σ_xy/σ_yy = u_a,x/u_a,y whatever their sizes.
    """
    r = np.asarray(snap["floe_radius"], float)
    ok = np.isfinite(r) & (np.asarray(snap["floe_frozen"]) == 0)
    r = r[ok]
    u = np.asarray(snap["floe_u"], float)[ok]
    v = np.asarray(snap["floe_v"], float)[ok]
    forcing = Forcing(forcing_params, wind=wind)
    k = forcing.coefficients(r, np.full_like(r, thickness),
                             forcing_params.ice_density * thickness * math.pi * r ** 2)
    uax, uay, uwx, uwy = forcing.kernel_vector()
    fx, fy, _ = floe_drag(u, v, np.zeros_like(u), k.wind, k.water, k.rotation,
                          k.coriolis_mass, uax, uay, uwx, uwy, math.hypot(uax, uay))
    lx = float(snap["snapshot_lx"])
    return float(fx.sum()) / lx, float(-fy.sum()) / lx


def late_profile(profiles: np.ndarray) -> np.ndarray:
    """Mean of u_x(y) profiles (samples × bins), NaN in bins that stayed
    empty (open water behind the drifting ice) without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(profiles, axis=0)


def shear_zone(y, profile, edge_width: float):
    """Width of the shear zone of a u_x(y) profile: the distance between the
    first bins above the fast ice where u_x reaches 10 % and 90 % of the
    outer speed (the mean over the outer half of the mobile ice). Returns
    (width [m], outer speed [m/s])."""
    y = np.asarray(y, float)
    u = np.asarray(profile, float)
    ok = np.isfinite(u) & (y > edge_width)
    y, u = y[ok], u[ok]
    if y.size < 4:
        return math.nan, math.nan
    outer = float(np.mean(u[y >= 0.5 * (y[0] + y[-1])]))
    if abs(outer) < 1e-6:
        return math.nan, outer
    frac = u / outer
    lo = np.nonzero(frac >= 0.1)[0]
    hi = np.nonzero(frac >= 0.9)[0]
    if not lo.size or not hi.size:
        return math.nan, outer
    return float(y[hi[0]] - y[lo[0]]), outer
