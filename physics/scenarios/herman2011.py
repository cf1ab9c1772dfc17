"""Herman (2011): clustering of hard-disc floes under a steady wind.

Scenario ``herman2011-clustering`` (file ``configs/herman2011-clustering.yaml``)
runs the "Small Floe Collider" set-up of Herman (2011, Phys. Rev. E 84,
056104), section IV: N hard-disc floes with the rank-ordered power-law
floe-size sample of appendix A (α_r = 1.5, d̄ = 2 m, h = 1.5 m) in a square
periodic box, driven by a 10 m/s wind along x and a 0.1 m/s current through
drag in Stokes form (each floe relaxes towards its own free-drift velocity
u_eq(d) with time constant τ(d), no Coriolis), colliding inelastically
(ε = 0.85, TC model with Δt_c = 0.1 s). One run per mean concentration Ā.

Every ``output_interval`` the run records the cluster statistics of
section IV C (clusters: floes closer than d_m edge to edge): the
largest-cluster fraction F_c,1/F_tot, the number of clusters, the
maximum-likelihood exponent α of the effective cluster radii r_e (with all
clusters, and without the largest one, which deviates from the power law at
high Ā), the pair distributions g_rdf and g_ffd (Fig 7), the mean speed,
the mass-weighted drift velocity, the slip |u − u_eq| and the collision
rate. The rank-ordered r_e of the final state (Fig 8) are recorded in the
last sample over the dimension ``rank``. The largest-cluster fraction is
also recorded for every d_m of ``gap_sweep`` (dimension ``gap``), since
the paper states that d_m of 0.1–1.0 m gave very similar results.
Snapshots (positions, radii, velocities) are taken at ``snapshots`` evenly spaced times, the first at
t = 0 and the last at the end (with one snapshot, only the end).

Summaries and figures average the statistics over the last
``average_last`` fraction of the run (the quasi-stationary state) and over
the ensemble members.

Time scales. τ runs from about 300 s (the smallest floes) to about 1000 s
(the largest), and u_eq from about 0.16 to 0.26 m/s, so floes of different
sizes drift one box length apart in ``sweep_time`` = L / (u_eq,max −
u_eq,min) (a per-run result: about 2900 s for 3000 floes at Ā = 0.6 and
2400 s at Ā = 0.9; it grows as √N).
Runs much longer than that keep bringing the same floes together across
the periodic boundary.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from .experiment import Experiment, register

#: fewer clusters than this give no exponent α (the fit would rest on a
#: handful of values)
MIN_CLUSTERS_FOR_ALPHA = 10

#: the paper's thresholds (section IV C, Fig 10)
LOW_REGIME_MAX = 0.7          # Ā below: largest cluster comparable with the largest floe
HIGH_REGIME_MIN = 0.75        # Ā from: one mega-cluster with > 85 % of F_tot
MEGA_FRACTION = 0.85


def _preset():
    from .. import HERMAN2011
    return HERMAN2011


def _forcing(p: dict):
    """The Herman (2011) forcing with the scenario's wind and current
    (both along +x), without Coriolis."""
    return _preset().make_forcing(wind_speed=float(p["wind_speed"]), wind_direction=0.0,
                                  current_speed=float(p["current_speed"]), current_angle=0.0,
                                  coriolis=0.0)


def _equilibrium(p: dict, diameters):
    """τ(d) [s] and the along-wind u_eq(d) [m/s] of floes of diameters ``d``."""
    pre = _preset()
    r = 0.5 * np.asarray(diameters, dtype=float)
    h = np.full_like(r, pre.thickness)
    m = pre.forcing.ice_density * h * np.pi * r * r
    f = _forcing(p)
    return f.time_constant(r, h, m), f.equilibrium_velocity(r, h, m)[:, 0]


def _grid(x_max: float, bins: int) -> tuple[np.ndarray, float]:
    """Bin centres of [0, x_max) in ``bins`` bins, and the bin width."""
    dx = float(x_max) / int(bins)
    return (np.arange(int(bins)) + 0.5) * dx, dx


def _pair_distribution(kind: str, pos, radii, box, x_max: float, bins: int) -> np.ndarray:
    """g_rdf or g_ffd on the grid of :func:`_grid`, truncated (NaN) where
    the pair range would exceed half the periodic box."""
    from ..clusters import g_ffd, g_rdf

    _, dx = _grid(x_max, bins)
    half = 0.5 * min(box.lx, box.ly)
    limit = half if kind == "rdf" else half - 2.0 * float(np.max(radii))
    nb = min(int(bins), int(math.floor(limit / dx * (1.0 - 1e-9))))
    out = np.full(int(bins), np.nan)
    if nb < 1:
        return out
    if kind == "rdf":
        _, g = g_rdf(pos, box, nb * dx, bins=nb)
    else:
        _, g = g_ffd(pos, radii, box, nb * dx, bins=nb)
    out[:nb] = g
    return out


def _widest_gap(p: dict) -> float:
    """The largest d_m the run uses (``cluster_gap`` and ``gap_sweep``)."""
    return max([float(p["cluster_gap"])] + [float(g) for g in p["gap_sweep"]])


def _rank_sample_fits(p: dict, a: float) -> None:
    """``ValueError`` if the largest floe of the rank-ordered sample is too
    large for the box at concentration ``a`` (cluster search and the
    engine's cell list need 2 r_max + d_m below half the box side)."""
    from .. import domain_size, rank_order_diameters

    pre = _preset()
    d = rank_order_diameters(int(p["floes"]), float(p["fsd_exponent"]), pre.mean_diameter)
    lx, _ = domain_size(np.repeat(d, int(p["repeat"])), a)
    reach = float(d[0]) + _widest_gap(p)
    if reach >= 0.5 * lx:
        raise ValueError(
            f"with {p['floes']} floes at concentration {a:g} the largest floe (diameter "
            f"{d[0]:.3g} m) spans {d[0] / lx:.0%} of the box ({lx:.4g} m); clusters can only be "
            f"found if its diameter plus cluster_gap (and every gap_sweep value) stays below half "
            f"the box: use more floes or lower concentrations")


def _window_mask(ds, p: dict) -> np.ndarray:
    """(case, member, sample) mask of the averaging window: the last
    ``average_last`` of each run."""
    t = np.asarray(ds["time"], dtype=float)
    t_end = np.nanmax(t, axis=-1, keepdims=True)
    return np.isfinite(t) & (t >= t_end * (1.0 - float(p["average_last"])) - 1e-9)


def _window_stats(ds, p: dict) -> dict:
    """Per-case statistics over the averaging window and the members:
    concentration, F_c,1/F_tot mean/min/max, α mean/std (both fits), and
    more; arrays sorted by concentration."""
    mask = _window_mask(ds, p)
    conc = np.asarray(ds["concentration"], dtype=float)
    out = {"concentration": conc}

    def pick(name):
        v = np.asarray(ds[name], dtype=float)
        return np.where(mask, v, np.nan).reshape(v.shape[0], -1)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)      # all-NaN rows give NaN
        fc = pick("largest_fraction")
        out["fc_mean"] = np.nanmean(fc, axis=1)
        out["fc_min"] = np.nanmin(fc, axis=1)
        out["fc_max"] = np.nanmax(fc, axis=1)
        for name in ("alpha", "alpha_without_largest", "n_clusters", "drift_velocity",
                     "mean_speed", "collision_rate", "slip_rms"):
            v = pick(name)
            out[name] = np.nanmean(v, axis=1)
            out[name + "_std"] = np.nanstd(v, axis=1)
            out[name + "_valid"] = np.sum(np.isfinite(v), axis=1)
        if _gaps(ds).size:
            v = np.asarray(ds["largest_fraction_by_gap"].transpose("case", "member", "sample",
                                                                   "gap"), dtype=float)
            v = np.where(mask[..., None], v, np.nan).reshape(v.shape[0], -1, v.shape[-1])
            out["fc_by_gap"] = np.nanmean(v, axis=1)           # (case, gap)
    out["largest_floe"] = np.asarray(ds["largest_floe_fraction"], dtype=float).reshape(
        len(conc), -1).mean(axis=1)
    order = np.argsort(conc, kind="stable")
    return {k: np.asarray(v)[order] for k, v in out.items()}


def _gaps(ds) -> np.ndarray:
    """The d_m values of ``largest_fraction_by_gap`` (empty without it)."""
    if "largest_fraction_by_gap" not in ds or "gap" not in ds.dims:
        return np.zeros(0)
    return np.asarray(ds["gap"], dtype=float)


def _crossings(x, y, level: float) -> list[float]:
    """Concentrations where the piecewise-linear y(x) crosses ``level``
    (NaN points skipped), with the direction: [(x, +1 up / −1 down), ...]."""
    ok = np.isfinite(y)
    x, y = np.asarray(x)[ok], np.asarray(y)[ok]
    found = []
    for i in range(len(x) - 1):
        a, b = y[i] - level, y[i + 1] - level
        if a == 0.0:
            found.append((float(x[i]), 0))
        elif a * b < 0:
            found.append((float(x[i] + (x[i + 1] - x[i]) * a / (a - b)), 1 if b > 0 else -1))
    if len(y) and y[-1] == level:
        found.append((float(x[-1]), 0))
    return found


def _last_valid_sample(values: np.ndarray) -> np.ndarray | None:
    """The last row of a (sample, n) array with any finite entry."""
    rows = np.flatnonzero(np.isfinite(values).any(axis=1))
    return values[rows[-1]] if rows.size else None


@register("herman2011-clustering")
class Herman2011Clustering(Experiment):
    """Cluster formation against the mean concentration Ā (Herman 2011,
    Figs 5–10); see the module docstring."""

    variables = {
        "largest_fraction": ("1", "largest-cluster fraction F_c,1/F_tot"),
        "largest_fraction_by_gap": ("1", "largest-cluster fraction F_c,1/F_tot with clusters "
                                         "of gap d_m (one per gap_sweep value)"),
        "n_clusters": ("1", "number of clusters N_c"),
        "alpha": ("1", f"ML exponent alpha of P(r_e) ~ r_e^(-1-alpha) from all clusters "
                       f"(NaN with fewer than {MIN_CLUSTERS_FOR_ALPHA} clusters)"),
        "alpha_error": ("1", "standard error of alpha"),
        "alpha_without_largest": ("1", "ML exponent alpha without the largest cluster "
                                       "(ranks 2..N_c)"),
        "mean_speed": ("m/s", "mean floe speed |u_i|"),
        "drift_velocity": ("m/s", "mass-weighted mean along-wind velocity"),
        "slip_rms": ("m/s", "rms of |u_i - u_eq,i| over the floes"),
        "collision_rate": ("1/s", "floe-floe collisions per floe and second since the "
                                  "previous output"),
        "collisions": ("1", "floe-floe collisions since the start"),
        "g_rdf": ("1", "radial distribution function of floe centres (ideal gas = 1)"),
        "g_ffd": ("1", "floe-floe (edge-to-edge) distance distribution (random = 1)"),
        "cluster_radius": ("m", "rank-ordered effective cluster radii r_e of the final state "
                                "(NaN-padded)"),
        "largest_floe_fraction": ("1", "area of the largest floe over F_tot"),
        "box_length": ("m", "side L of the periodic box"),
        "tau_min": ("s", "smallest drag time constant tau (smallest floe)"),
        "tau_max": ("s", "largest drag time constant tau (largest floe)"),
        "ueq_min": ("m/s", "smallest free-drift speed u_eq (smallest floe)"),
        "ueq_max": ("m/s", "largest free-drift speed u_eq (largest floe)"),
        "sweep_time": ("s", "L / (u_eq,max - u_eq,min): time for floes of different sizes to "
                            "drift one box length apart"),
        "fsd_alpha": ("1", "ML exponent of the floe diameters of the sample (alpha_r)"),
    }
    required = ("largest_fraction", "n_clusters", "alpha", "alpha_without_largest",
                "mean_speed", "drift_velocity", "collision_rate", "g_rdf", "g_ffd",
                "cluster_radius", "largest_floe_fraction", "box_length", "sweep_time",
                "floe_x", "floe_u", "floe_radius")
    case_label = "concentration"

    # -- runs ------------------------------------------------------------------
    def cases(self, p: dict) -> list[dict]:
        if p.get("fsd", "rank") == "rank":
            for a in p["concentrations"]:
                _rank_sample_fits(p, float(a))
        return [{"concentration": float(a)} for a in p["concentrations"]]

    def workload(self, p: dict, case: dict) -> float:
        a = float(case["concentration"])
        # collisions (and their cost) grow steeply as the ice closes up
        return (float(p["floes"]) * int(p["repeat"]) * float(p["duration"])
                * (1.0 + a / (1.0 - a) / 9.0))

    def simulate(self, p: dict, case: dict, seed: int, rec) -> None:
        from .. import HardDiskSimulation

        pre = _preset()
        n_out = max(1, int(round(float(p["duration"]) / float(p["output_interval"]))))
        interval = float(p["duration"]) / n_out
        n_floes = int(p["floes"]) * int(p["repeat"])
        rdf_x, _ = _grid(p["rdf_range"], p["rdf_bins"])
        ffd_x, _ = _grid(p["ffd_range"], p["ffd_bins"])
        rec.coord("x_rdf", rdf_x, "m", "centre-to-centre distance (bin centres)")
        rec.coord("x_ffd", ffd_x, "m", "edge-to-edge distance (bin centres)")
        rec.coord("rank", np.arange(1, n_floes + 1), "1", "rank of the cluster by size")
        if p["gap_sweep"]:
            rec.coord("gap", np.asarray(p["gap_sweep"], dtype=float), "m",
                      "cluster gap d_m of largest_fraction_by_gap")
        k_snap = int(p["snapshots"])
        snap_times = [n_out] if k_snap == 1 else np.linspace(0, n_out, k_snap)
        snap_steps = sorted({int(round(x)) for x in snap_times})

        st = rec.restore()
        if st is None:
            a = float(case["concentration"])
            field, box = pre.floe_field(
                int(p["floes"]), a, seed=int(seed), repeat=int(p["repeat"]),
                alpha=float(p["fsd_exponent"]), fsd=str(p["fsd"]),
                velocity_std=float(p["initial_velocity_std"]))
            reach = 2.0 * float(field.radii.max()) + _widest_gap(p)
            if reach >= 0.5 * box.lx:
                raise ValueError(
                    f"the largest floe (diameter {2 * field.radii.max():.3g} m) is too large for "
                    f"the box ({box.lx:.4g} m) at concentration {a:g}: its diameter plus "
                    f"cluster_gap (and every gap_sweep value) must stay below half the box; use "
                    f"more floes")
            sim = HardDiskSimulation(field, box, restitution=float(p["restitution"]),
                                     forcing=_forcing(p),
                                     max_velocity_step=float(p["max_velocity_step"]),
                                     collision_duration=float(p["collision_duration"]))
            st = dict(sim=sim, step=0, count=0)
            self._constants(p, sim, rec)
            self._output(p, st, rec, interval, n_out, snap_steps)
            rec.progress(0.0)
            rec.checkpoint(st)
        sim = st["sim"]
        while st["step"] < n_out:
            sim.advance(interval)
            st["step"] += 1
            self._output(p, st, rec, interval, n_out, snap_steps)
            rec.progress(st["step"] / n_out)
            rec.checkpoint(st)

    @staticmethod
    def _constants(p: dict, sim, rec) -> None:
        """Per-run constants: box, largest floe, τ and u_eq ranges."""
        from ..clusters import fsd_exponent

        d = 2.0 * sim.radii
        tau, ueq = _equilibrium(p, d)
        areas = np.pi * sim.radii ** 2
        du = float(ueq.max() - ueq.min())
        rec.result(largest_floe_fraction=float(areas.max() / areas.sum()), box_length=sim.L,
                   tau_min=float(tau.min()), tau_max=float(tau.max()),
                   ueq_min=float(ueq.min()), ueq_max=float(ueq.max()),
                   sweep_time=sim.L / du if du > 0 else math.inf,
                   fsd_alpha=fsd_exponent(d).alpha)

    @staticmethod
    def _output(p: dict, st: dict, rec, interval: float, n_out: int, snap_steps) -> None:
        """Measure and record the state at the current output step."""
        from ..clusters import cluster_statistics, find_clusters, power_law_exponent

        sim = st["sim"]
        pos, vel, r = sim.positions, sim.velocities, sim.radii
        labels = find_clusters(pos, r, sim.box, float(p["cluster_gap"]))
        cs = cluster_statistics(labels, r)
        alpha = err = alpha2 = math.nan
        if cs.n_clusters >= MIN_CLUSTERS_FOR_ALPHA:
            alpha, err = cs.alpha, cs.alpha_error
            re = cs.effective_radius
            if re[1] > re[-1]:
                alpha2 = power_law_exponent(re, k=2).alpha
        _, ueq = _equilibrium(p, 2.0 * r)
        speed = np.hypot(vel[:, 0], vel[:, 1])
        mass = sim.masses
        slip = np.hypot(vel[:, 0] - ueq, vel[:, 1])
        count = sim.collision_count
        rate = (count - st["count"]) / (sim.n_floes * interval) if st["step"] > 0 else math.nan
        st["count"] = count
        values = dict(
            largest_fraction=cs.largest_fraction, n_clusters=cs.n_clusters, alpha=alpha,
            alpha_error=err, alpha_without_largest=alpha2, mean_speed=float(speed.mean()),
            drift_velocity=float(np.sum(mass * vel[:, 0]) / np.sum(mass)),
            slip_rms=float(np.sqrt(np.mean(slip ** 2))), collision_rate=rate, collisions=count,
            g_rdf=("x_rdf", _pair_distribution("rdf", pos, r, sim.box, p["rdf_range"],
                                               p["rdf_bins"])),
            g_ffd=("x_ffd", _pair_distribution("ffd", pos, r, sim.box, p["ffd_range"],
                                               p["ffd_bins"])))
        if p["gap_sweep"]:
            # the main gap's clusters are found above already
            values["largest_fraction_by_gap"] = ("gap", np.array([
                cs.largest_fraction if float(g) == float(p["cluster_gap"]) else
                cluster_statistics(find_clusters(pos, r, sim.box, float(g)), r).largest_fraction
                for g in p["gap_sweep"]]))
        if st["step"] == n_out:
            ranked = np.full(sim.n_floes, np.nan)
            ranked[:cs.n_clusters] = cs.effective_radius
            values["cluster_radius"] = ("rank", ranked)
        rec.record(sim.time, **values)
        if st["step"] in snap_steps:
            rec.snapshot(sim.time, pos, r, vel, box=(sim.L, sim.L))

    # -- summary -------------------------------------------------------------
    def summarise(self, ds, p: dict) -> list[tuple[str, str, str]]:
        s = _window_stats(ds, p)
        alpha_r = float(p["fsd_exponent"])
        frac = float(p["average_last"])
        rows = [("largest floe / F_tot", f"{np.nanmean(s['largest_floe']):.3f}",
                 "almost 0.10 (N = 3000)"),
                ("averaging window", f"last {frac:.0%} of {p['duration']:g} s, "
                                     f"{ds.sizes.get('member', 1)} member(s)",
                 "quasi-stationary state")]
        for i, a in enumerate(s["concentration"]):
            if a < LOW_REGIME_MAX:
                paper = "comparable with the largest floe"
            elif a < HIGH_REGIME_MIN:
                paper = "transition: erratic break-ups and re-consolidation"
            else:
                paper = f"> {MEGA_FRACTION:.2f} (one mega-cluster)"
            rows.append((f"F_c,1/F_tot at Ā = {a:.3g} (mean [min, max])",
                         f"{s['fc_mean'][i]:.3f} [{s['fc_min'][i]:.3f}, {s['fc_max'][i]:.3f}] "
                         f"= {s['fc_mean'][i] / s['largest_floe'][i]:.1f} × largest floe",
                         paper))
        gaps = _gaps(ds)
        for i, a in enumerate(s["concentration"] if gaps.size else []):
            rows.append((f"F_c,1/F_tot at Ā = {a:.3g} against the cluster gap d_m",
                         ", ".join(f"{g:g} m: {f:.2f}" for g, f in zip(gaps, s["fc_by_gap"][i])),
                         "very similar for d_m = 0.1–1.0 m"))
        for i, a in enumerate(s["concentration"]):
            if a < LOW_REGIME_MAX:
                paper = f"< α_r = {alpha_r:g}"
            elif a < HIGH_REGIME_MIN:
                paper = f"≈ α_r = {alpha_r:g}"
            else:
                paper = f"> α_r = {alpha_r:g}, growing with Ā"
            rows.append((f"α at Ā = {a:.3g} (all clusters / without the largest)",
                         f"{_fmt(s['alpha'][i])} ± {_fmt(s['alpha_std'][i])} / "
                         f"{_fmt(s['alpha_without_largest'][i])} ± "
                         f"{_fmt(s['alpha_without_largest_std'][i])} "
                         f"(N_c ≈ {s['n_clusters'][i]:.0f})", paper))
        for key, label in (("alpha", "all clusters"), ("alpha_without_largest",
                                                         "without the largest")):
            cross = _crossings(s["concentration"], s[key], alpha_r)
            text = ", ".join(f"{x:.3g} ({'up' if d > 0 else 'down' if d < 0 else 'touch'})"
                             for x, d in cross) or "none"
            rows.append((f"Ā where α ({label}) crosses α_r", text,
                         "rises through α_r at the transition (Ā ≈ 0.7–0.75)"))
        mega = s["concentration"][s["fc_mean"] > MEGA_FRACTION]
        rows.append(("lowest Ā with F_c,1/F_tot > 0.85",
                     f"{mega.min():.3g}" if mega.size else "none", "≈ 0.75"))
        v = ", ".join(f"{x:.3f}" for x in s["drift_velocity"])
        rows.append(("mass-weighted drift velocity per Ā [m/s]", v, "≈ 0.23 m/s"))
        small = _small_floe_velocity(ds, p)
        if small is not None:
            excess, spread = small
            rows.append(("smallest 10 % of floes at the end: u/u_eq − 1 per Ā",
                         ", ".join(f"{x:+.0%}" for x in excess), "up to +30 %"))
            rows.append(("smallest 10 % of floes: cross-wind velocity std per Ā [m/s]",
                         ", ".join(f"{x:.3f}" for x in spread), "random component 0.01–0.03 m/s"))
        sweep = np.asarray(ds["sweep_time"], dtype=float)
        rows.append(("sweep time L/Δu_eq [s]", f"{np.nanmin(sweep):.0f}–{np.nanmax(sweep):.0f}",
                     "(periodic-box time scale; not in the paper)"))
        return rows

    # -- figures ---------------------------------------------------------------
    def plot(self, ds, p: dict, out_dir: Path) -> list[Path]:
        out_dir = Path(out_dir)
        paths = [self._plot_snapshots(ds, p, out_dir), self._plot_velocities(ds, p, out_dir),
                 self._plot_pairs(ds, p, out_dir), self._plot_rank(ds, p, out_dir),
                 self._plot_alpha(ds, p, out_dir), self._plot_largest(ds, p, out_dir),
                 self._plot_series(ds, p, out_dir)]
        return [q for q in paths if q is not None]

    @staticmethod
    def _chosen_cases(ds, k: int = 3) -> list[int]:
        """Up to k case indices spread over the concentrations (lowest,
        middle, highest)."""
        conc = np.asarray(ds["concentration"], dtype=float)
        order = np.argsort(conc, kind="stable")
        picks = np.unique(np.round(np.linspace(0, len(order) - 1, min(k, len(order)))).astype(int))
        return [int(order[i]) for i in picks]

    def _plot_snapshots(self, ds, p, out_dir):
        from .plots import snapshot_panels

        if ds.sizes.get("snapshot", 0) == 0:
            return None
        cases = self._chosen_cases(ds, 3)
        last = ds.sizes["snapshot"] - 1
        labels = [f"Ā = {float(ds['concentration'][c]):.3g}, "
                  f"t = {float(ds['snapshot_time'].isel(case=c, member=0, snapshot=last)):.0f} s"
                  for c in cases]
        return snapshot_panels(ds, out_dir / "fig5_snapshots.png",
                               title="Floes in the final state, coloured by speed "
                                     "(Herman 2011, Fig 5)", labels=labels, forces=False,
                               select=[{"case": c, "member": 0, "snapshot": last} for c in cases])

    def _plot_velocities(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        if ds.sizes.get("snapshot", 0) == 0:
            return None
        plt = pyplot()
        conc = np.asarray(ds["concentration"], dtype=float)
        cases = [int(np.argmin(conc)), int(np.argmax(conc))]
        if cases[0] == cases[1]:
            cases = cases[:1]
        fig, axes = plt.subplots(len(cases), 2, figsize=(10, 3.6 * len(cases)), squeeze=False)
        last = ds.sizes["snapshot"] - 1
        for row, c in zip(axes, cases):
            snap = ds.isel(case=c, snapshot=last)
            r = np.asarray(snap["floe_radius"], dtype=float).ravel()
            u = np.asarray(snap["floe_u"], dtype=float).ravel()
            v = np.asarray(snap["floe_v"], dtype=float).ravel()
            ok = np.isfinite(r)
            d = 2.0 * r[ok]
            row[0].scatter(d, u[ok], s=3, alpha=0.5, lw=0, label="floes")
            grid = np.geomspace(d.min(), d.max(), 200)
            _, ueq = _equilibrium(p, grid)
            row[0].plot(grid, ueq, "k-", lw=1.5, label="u_eq(d)")
            row[1].scatter(d, v[ok], s=3, alpha=0.5, lw=0)
            row[1].axhline(0.0, color="k", lw=0.8)
            for ax, comp in zip(row, ("along-wind u", "cross-wind v")):
                ax.set_xscale("log")
                ax.set_xlabel("floe diameter d [m]")
                ax.set_ylabel(f"{comp} [m/s]")
                ax.set_title(f"Ā = {conc[c]:.3g}", fontsize=9)
            row[0].legend(fontsize=8, loc="lower right")
        fig.suptitle("Floe velocity against size in the final state (Herman 2011, Fig 6)",
                     fontsize=10)
        return savefig(fig, out_dir / "fig6_velocity_size.png")

    def _plot_pairs(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        plt = pyplot()
        conc = np.asarray(ds["concentration"], dtype=float)
        cases = [int(np.argmin(conc)), int(np.argmax(conc))]
        if cases[0] == cases[1]:
            cases = cases[:1]
        mask = _window_mask(ds, p)
        fig, axes = plt.subplots(2, len(cases), figsize=(5.2 * len(cases), 7), squeeze=False)
        for col, c in enumerate(cases):
            for row, (name, dim, label) in enumerate((("g_rdf", "x_rdf", "g_rdf"),
                                                      ("g_ffd", "x_ffd", "g_ffd"))):
                ax = axes[row, col]
                x = np.asarray(ds[dim], dtype=float)
                g = np.asarray(ds[name].isel(case=c), dtype=float)      # member, sample, x
                sel = np.where(mask[c][:, :, None], g, np.nan)
                init, final = _nanmean(g[:, 0, :], axis=0), _nanmean(sel, axis=(0, 1))
                ax.plot(x, init, color="0.5", lw=1, label="initial (random)")
                ax.plot(x, final, color="C3", lw=1.2, label="final (window mean)")
                ax.axhline(1.0, color="k", lw=0.6, ls=":")
                ax.set_xlabel(("centre-to-centre" if dim == "x_rdf" else "edge-to-edge")
                              + " distance x [m]")
                ax.set_ylabel(label)
                ax.set_title(f"Ā = {conc[c]:.3g}", fontsize=9)
                if name == "g_ffd":
                    ax.set_yscale("log")
                if name == "g_rdf" and "floe_radius" in ds:
                    radii = np.sort(np.asarray(ds["floe_radius"].isel(case=c, member=0,
                                                                      snapshot=0)))[::-1]
                    radii = radii[np.isfinite(radii)][:8]
                    top = ax.get_ylim()[1]
                    ax.plot(radii[radii < x[-1]], np.full(np.sum(radii < x[-1]), top), "kv",
                            ms=4, clip_on=False, label="radii of the 8 largest floes")
                ax.legend(fontsize=7)
        fig.suptitle("Pair distributions (Herman 2011, Fig 7)", fontsize=10)
        return savefig(fig, out_dir / "fig7_pair_distributions.png")

    def _plot_rank(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        plt = pyplot()
        conc = np.asarray(ds["concentration"], dtype=float)
        fig, ax = plt.subplots(figsize=(6, 4.8))
        for c in np.argsort(conc, kind="stable"):
            vals = _last_valid_sample(np.asarray(ds["cluster_radius"].isel(case=c, member=0),
                                                 dtype=float))
            if vals is None:
                continue
            re = vals[np.isfinite(vals)]
            ax.loglog(re, np.arange(1, re.size + 1), ".", ms=3, label=f"Ā = {conc[c]:.3g}")
        if "floe_radius" in ds:
            r = np.asarray(ds["floe_radius"].isel(case=0, member=0, snapshot=0), dtype=float)
            r = np.sort(r[np.isfinite(r)])[::-1]
            ax.loglog(r, np.arange(1, r.size + 1), "k-", lw=1, label="floe radii")
        ax.set_xlabel("effective cluster radius r_e [m]")
        ax.set_ylabel("rank")
        ax.set_title("Rank-ordered cluster sizes, final state (Herman 2011, Fig 8)", fontsize=10)
        ax.legend(fontsize=8)
        return savefig(fig, out_dir / "fig8_cluster_rank_order.png")

    def _plot_alpha(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        plt = pyplot()
        s = _window_stats(ds, p)
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.errorbar(s["concentration"], s["alpha"], yerr=s["alpha_std"], fmt="o-", capsize=3,
                    label="all clusters")
        ax.errorbar(s["concentration"], s["alpha_without_largest"],
                    yerr=s["alpha_without_largest_std"], fmt="s--", mfc="none", capsize=3,
                    label="without the largest cluster")
        ax.axhline(float(p["fsd_exponent"]), color="k", ls="--", lw=1,
                   label=f"α_r = {float(p['fsd_exponent']):g}")
        ax.set_xlabel("mean concentration Ā")
        ax.set_ylabel("α of P(r_e) ~ r_e^(−1−α)")
        ax.set_title("Cluster-size exponent, window mean ± std (Herman 2011, Fig 9)",
                     fontsize=10)
        ax.legend(fontsize=8)
        return savefig(fig, out_dir / "fig9_alpha.png")

    def _plot_largest(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        plt = pyplot()
        s = _window_stats(ds, p)
        fig, ax = plt.subplots(figsize=(6, 4.5))
        x = s["concentration"]
        ax.errorbar(x, s["fc_mean"], yerr=[s["fc_mean"] - s["fc_min"], s["fc_max"] - s["fc_mean"]],
                    fmt="o-", capsize=3,
                    label=f"F_c,1/F_tot, d_m = {float(p['cluster_gap']):g} m (mean, min–max)")
        for k, g in enumerate(_gaps(ds)):
            if g == float(p["cluster_gap"]):
                continue                        # the same as the main curve
            ax.plot(x, s["fc_by_gap"][:, k], "-", lw=0.8, alpha=0.7, marker=".",
                    label=f"d_m = {g:g} m (window mean)")
        ax.plot(x, s["largest_floe"], "k:", label="largest floe / F_tot")
        ax.axhline(MEGA_FRACTION, color="0.5", ls="--", lw=1, label="0.85")
        ax.set_ylim(0, 1.05)
        ax.set_xlabel("mean concentration Ā")
        ax.set_ylabel("F_c,1 / F_tot")
        ax.set_title("Largest cluster in the quasi-stationary state (Herman 2011, Fig 10)",
                     fontsize=10)
        ax.legend(fontsize=8)
        return savefig(fig, out_dir / "fig10_largest_cluster.png")

    def _plot_series(self, ds, p, out_dir):
        from .plots import pyplot, savefig

        plt = pyplot()
        conc = np.asarray(ds["concentration"], dtype=float)
        fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
        t_start = None
        for c in np.argsort(conc, kind="stable"):
            t = np.asarray(ds["time"].isel(case=c, member=0), dtype=float)
            for ax, name in zip(axes.ravel(), ("largest_fraction", "alpha", "collision_rate",
                                               "drift_velocity")):
                ax.plot(t, np.asarray(ds[name].isel(case=c, member=0), dtype=float), lw=1,
                        label=f"Ā = {conc[c]:.3g}")
            t_start = np.nanmax(t) * (1.0 - float(p["average_last"]))
        for ax, label in zip(axes.ravel(), ("F_c,1 / F_tot", "α (all clusters)",
                                            "collisions per floe and second [1/s]",
                                            "mass-weighted along-wind velocity [m/s]")):
            ax.set_ylabel(label)
            if t_start is not None:
                ax.axvline(t_start, color="0.5", ls=":", lw=1)
        axes[0, 1].axhline(float(p["fsd_exponent"]), color="k", ls="--", lw=0.8)
        axes[1, 0].set_yscale("log")
        for ax in axes[1]:
            ax.set_xlabel("time [s]")
        axes[0, 0].legend(fontsize=7)
        fig.suptitle("Time series, member 0 (dotted: start of the averaging window)",
                     fontsize=10)
        return savefig(fig, out_dir / "time_series.png")


def _nanmean(a, axis):
    """``np.nanmean`` giving NaN for all-NaN slices without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(a, axis=axis)


def _fmt(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:.2f}"


def _small_floe_velocity(ds, p: dict):
    """For the smallest 10 % of floes in the final snapshot of each case
    (member 0), sorted by Ā: the mean along-wind u/u_eq − 1 and the std of
    the cross-wind velocity. ``None`` without snapshots."""
    if ds.sizes.get("snapshot", 0) == 0:
        return None
    conc = np.asarray(ds["concentration"], dtype=float)
    last = ds.sizes["snapshot"] - 1
    excess, spread = [], []
    for c in np.argsort(conc, kind="stable"):
        snap = ds.isel(case=c, member=0, snapshot=last)
        r = np.asarray(snap["floe_radius"], dtype=float)
        ok = np.isfinite(r)
        r = r[ok]
        u = np.asarray(snap["floe_u"], dtype=float)[ok]
        v = np.asarray(snap["floe_v"], dtype=float)[ok]
        small = r <= np.quantile(r, 0.1)
        _, ueq = _equilibrium(p, 2.0 * r[small])
        excess.append(float(np.mean(u[small] / ueq) - 1.0))
        spread.append(float(np.std(v[small])))
    return np.array(excess), np.array(spread)
