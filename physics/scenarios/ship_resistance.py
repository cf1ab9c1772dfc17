"""The ``ship-resistance`` scenario: the ship's ice resistance in floating,
unbroken floes, swept over concentration, speed (a Froude number on the ice
thickness), floe-size law and hull, beside the field's laws
(:mod:`physics.ice_resistance`).

Each run is a prescribed, windless transit of the ``ship-transit``
scenario (:class:`~physics.scenarios.ship_transit.ShipTransit` records it
and measures its resistance window); this module chooses the cases, seeds
the fields so that field k is the same draw at every point, and sums the
points up against Zuev's law and Huang et al.'s fit.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..ice_resistance import (HUANG_COEFFICIENT, ZUEV_COEFFICIENTS, huang_coefficient,
                              huang_resistance, power_law_exponent, power_law_fit,
                              zuev_coefficient, zuev_resistance, zuev_terms)
from ..ice_fields import AUTO_ICENAV_SIZES
from ..params import GRAVITY, HERMAN2013
from . import plots
from .config import bundled_configs, load_config
from .experiment import register
from .ship_transit import SHIPS, ShipTransit

#: the hulls and floe-size laws of the ``hulls`` and ``size_laws`` choices
HULLS = {"both": ("psv", "research"), "psv": ("psv",), "research": ("research",)}
SIZE_LAWS = {"both": ("auto_icenav", "brash"), "auto_icenav": ("auto_icenav",),
             "brash": ("brash",)}
#: σ of ln d of the brash floes
BRASH_SIGMA = 0.4
#: the ShipNavigation tasks' Froude numbers on the ice thickness (2 m/s on
#: 1.2-1.5 m of ice: 0.52-0.58) and drawn concentrations (v0: 0.2-0.6, v1:
#: 0.2-0.5): the summary's row for the points inside both ranges
TASK_FROUDE = (0.4, 0.7)
TASK_CONCENTRATIONS = (0.2, 0.6)


def ice_thickness() -> float:
    """The floes' thickness [m] (the Herman 2013 material)."""
    return float(HERMAN2013.thickness)


def froude_speed(froude: float) -> float:
    """The ship speed [m/s] of a Froude number on the ice thickness."""
    return float(froude) * math.sqrt(GRAVITY * ice_thickness())


def field_seed(seed: int, field: int) -> int:
    """The seed of field ``field`` of a run seeded ``seed``: the same at every
    concentration, speed, hull and size law."""
    return int(np.random.SeedSequence([int(seed), int(field)]).generate_state(1)[0])


def transit_parameters(p: dict, case: dict) -> dict:
    """The ``ship-transit`` parameters of one case: that scenario's defaults,
    then this one's parameters, its hull, its floe-size law and no wind."""
    hull = HULLS["both"][int(case["hull"])]
    law = SIZE_LAWS["both"][int(case["size_law"])]
    transit = load_config(bundled_configs()["ship-transit"]).defaults()
    q = dict(transit, **p, hull=hull, wind_speed=0.0)
    if law == "brash":
        q.update(sizes="lognormal", lognormal_median=p["brash_median"],
                 lognormal_sigma=BRASH_SIGMA)
    else:
        q.update(sizes=law)
    return q


@register("ship-resistance")
class ShipResistance(ShipTransit):
    """Resistance sweeps; see the module docstring."""

    case_label = "concentration"

    def cases(self, p: dict) -> list[dict]:
        widest = 4.0 * AUTO_ICENAV_SIZES.max_radius
        if "auto_icenav" in SIZE_LAWS[p["size_laws"]] and p["channel_width"] <= widest:
            raise ValueError(f"channel_width = {p['channel_width']:g} m cannot hold AUTO-IceNav's "
                             f"largest floes (radius {AUTO_ICENAV_SIZES.max_radius:g} m) across "
                             f"a periodic channel: give more than {widest:g} m, or "
                             f"size_laws = brash")
        hulls = [HULLS["both"].index(h) for h in HULLS[p["hulls"]]]
        laws = [SIZE_LAWS["both"].index(s) for s in SIZE_LAWS[p["size_laws"]]]
        return [{"hull": h, "size_law": s, "concentration": float(c),
                 "froude": float(f), "speed": froude_speed(f), "field": k,
                 "dynamic": 0, "wind": 0.0, "walls": 0}
                for h in hulls for s in laws for c in dict.fromkeys(p["concentrations"])
                for f in dict.fromkeys(p["froude_numbers"]) for k in range(int(p["fields"]))]

    def workload(self, p: dict, case: dict) -> float:
        small = SIZE_LAWS["both"][int(case["size_law"])] == "brash"
        return super().workload(p, case) * (20.0 if small else 1.0)

    def simulate(self, p: dict, case: dict, seed: int, rec) -> None:
        super().simulate(transit_parameters(p, case), case, field_seed(seed, case["field"]), rec)

    # -- summary ------------------------------------------------------------
    def summarise(self, ds, p: dict) -> list[tuple[str, str, str]]:
        rows = []
        for g in resistance_points(ds):
            label = f"{g['hull']}, {g['law']}"
            s, v, r = g["concentration"], g["speed"], g["mean"]
            b_s = [power_law_exponent(s, r[:, j]) for j in range(v.size)]
            b_v = [power_law_exponent(v, r[i, :]) for i in range(s.size)]
            zuev, huang = law_values(g, s, v)
            zs = [power_law_fit(s, zuev[:, j])[1] for j in range(v.size)]
            zv = [power_law_fit(v, zuev[i, :])[1] for i in range(s.size)]
            rows.append((f"{label}: exponent b of R = a S^b (± its standard error), at Fr_h = "
                         + ", ".join(f"{f:g}" for f in g["froude"]),
                         _exponents(b_s),
                         f"Zuev {_numbers(zs)}; Huang 1.5"))
            rows.append((f"{label}: exponent b of R = a v^b (± its standard error), at S = "
                         + ", ".join(f"{x:g}" for x in s),
                         _exponents(b_v), f"Zuev {_numbers(zv)}; Huang 1; momentum flux 2"))
            with np.errstate(divide="ignore", invalid="ignore"):
                rz, rh = r / zuev, r / huang
            rows.append((f"{label}: R / Zuev's R over the sweep (median, range)",
                         _ratio(rz), "1"))
            rows.append((f"{label}: R / Huang et al.'s R over the sweep (median, range)",
                         _ratio(rh), "1"))
            inertial = law_values(g, s, v, terms=("quadratic",))[0]
            with np.errstate(divide="ignore", invalid="ignore"):
                rq = r / inertial
            rows.append((f"{label}: R / the inertial term of Zuev's law alone, "
                         f"ρ g B h² 0.5 Fr_h² (2 − S) S² (median, range)", _ratio(rq),
                         "1 if the model's resistance is the inertial part of Zuev's"))
            task = ((g["concentration"] >= TASK_CONCENTRATIONS[0])
                    & (g["concentration"] <= TASK_CONCENTRATIONS[1]))[:, None] & (
                (g["froude"] >= TASK_FROUDE[0]) & (g["froude"] <= TASK_FROUDE[1]))[None, :]
            rows.append((f"{label}: at the ShipNavigation tasks' speeds and concentrations "
                         f"(Fr_h {TASK_FROUDE[0]:g}–{TASK_FROUDE[1]:g}, "
                         f"S {TASK_CONCENTRATIONS[0]:g}–{TASK_CONCENTRATIONS[1]:g}): "
                         f"R / Zuev's R; R / its inertial term; R / Huang et al.'s R",
                         "; ".join(_ratio(x[task]) for x in (rz, rq, rh)), "1; 1; 1"))
            rel = g["err"] / g["mean"]
            rows.append((f"{label}: standard error of a point's mean over its fields "
                         f"({g['fields']}), as a share of the mean (median, largest)",
                         _ratio(rel, percent=True), "—"))
        return rows

    # -- figures ------------------------------------------------------------
    def plot(self, ds, p: dict, out_dir: Path) -> list[Path]:
        groups = resistance_points(ds)
        if not groups:
            return []
        return [law_figure(groups, law, Path(out_dir)) for law in FIGURES]


#: the figures of a run: law → (file name, title of the law's curves)
FIGURES = {"zuev": ("resistance_zuev.png", "Zuev's law dashed, its inertial term dotted"),
           "huang": ("resistance_huang.png", "Huang et al.'s law dashed")}


def law_figure(groups: list[dict], law: str, out_dir: Path) -> Path:
    """One law's figure (:data:`FIGURES`): a row per hull × size law, the
    points against the law's resistance (left) and in its nondimensional
    form (right)."""
    plt = plots.pyplot()
    name, curves = FIGURES[law]
    fig, axes = plt.subplots(len(groups), 2, figsize=(11, 4.0 * len(groups)), squeeze=False)
    for (left, right), g in zip(axes, groups):
        s, v = g["concentration"], g["speed"]
        zuev, huang = law_values(g, s, v)
        lines = ([(zuev, "--"), (law_values(g, s, v, terms=("quadratic",))[0], ":")]
                 if law == "zuev" else [(huang, "--")])
        for j, f in enumerate(g["froude"]):
            bars = left.errorbar(s, g["mean"][:, j] / 1e3, yerr=g["err"][:, j] / 1e3, fmt="o",
                                 ms=4, capsize=2, label=f"Fr_h = {f:g} ({v[j]:.2g} m/s)")
            for values, style in lines:
                left.plot(s, values[:, j] / 1e3, style, color=bars[0].get_color(), lw=1)
        left.set(xscale="log", yscale="log", xlabel="concentration S",
                 ylabel="ice resistance [kN]",
                 title=f"{g['hull']}, {g['law']} floes\npoints ± s.e.; {curves}")
        left.legend(fontsize=7)
        (_zuev_form if law == "zuev" else _huang_form)(right, g)
    fig.tight_layout()
    return plots.savefig(fig, out_dir / name, palette=True)


def _zuev_form(ax, g: dict) -> None:
    """The points of ``g`` as Zuev's coefficient against Fr_h, with the law."""
    h, beam = ice_thickness(), g["beam"]
    k1, k2, k3 = ZUEV_COEFFICIENTS
    fr = np.linspace(0.0, max(g["froude"]) * 1.1, 50)
    ax.plot(fr, k1 * beam / h + k2 * fr + k3 * fr ** 2, "k--", lw=1,
            label=f"Zuev: {k1:g} B/h + {k2:g} Fr_h + {k3:g} Fr_h²")
    ax.plot(fr[1:], k3 * fr[1:] ** 2, "k:", lw=1, label=f"its inertial term, {k3:g} Fr_h²")
    for i, c in enumerate(g["concentration"]):
        cz = zuev_coefficient(g["mean"][i], c, beam, h, density=g["density"])
        ax.plot(g["froude"], cz, "o-", ms=4, lw=1, label=f"S = {c:g}")
    ax.set(yscale="log", xlabel="Fr_h = v / √(g h)", ylabel="R / (ρ g B h² (2 − S) S²)",
           title="the same points in the form of Zuev's law")
    ax.legend(fontsize=7)


def _huang_form(ax, g: dict) -> None:
    """The points of ``g`` as Huang et al.'s coefficient against the
    ship's Froude number on its length, with the law's C_R."""
    h, beam, length = ice_thickness(), g["beam"], g["length"]
    fn = g["speed"] / math.sqrt(GRAVITY * length)
    ax.axhline(HUANG_COEFFICIENT, color="k", ls="--", lw=1,
               label=f"Huang et al.: C_R = {HUANG_COEFFICIENT:g}")
    for i, c in enumerate(g["concentration"]):
        cr = huang_coefficient(g["mean"][i], g["speed"], c, beam, h, length,
                               density=g["density"])
        ax.plot(fn, cr, "o-", ms=4, lw=1, label=f"S = {c:g}")
    ax.set(yscale="log", xlabel="Fn = v / √(g L)", ylabel="R Fn / (ρ B h v² S^1.5)",
           title="the same points in the form of Huang et al.'s law")
    ax.legend(fontsize=7)


def resistance_points(ds) -> list[dict]:
    """One dict per hull × size law present: its concentrations and speeds
    (ascending), the mean resistance over the fields (concentration ×
    speed), its standard error, and the hull's beam and length."""
    coords = ds.coords
    hull, law = coords["hull"].values.astype(int), coords["size_law"].values.astype(int)
    conc, fr = coords["concentration"].values, coords["froude"].values
    r = np.nanmean(ds["resistance"].values, axis=1)          # one member per run
    out = []
    for h in sorted(set(hull)):
        for s_ in sorted(set(law)):
            sel = (hull == h) & (law == s_)
            cs, fs = np.unique(conc[sel]), np.unique(fr[sel])
            mean = np.full((cs.size, fs.size), np.nan)
            err = np.full_like(mean, np.nan)
            fields = 0
            for i, c in enumerate(cs):
                for j, f in enumerate(fs):
                    vals = r[sel & (conc == c) & (fr == f)]
                    vals = vals[np.isfinite(vals)]
                    fields = max(fields, vals.size)
                    if vals.size:
                        mean[i, j] = vals.mean()
                    if vals.size > 1:
                        err[i, j] = vals.std(ddof=1) / math.sqrt(vals.size)
            ship = SHIPS[HULLS["both"][h]]()
            out.append(dict(hull=ship.hull.name, law=SIZE_LAWS["both"][s_].replace("_", "-"),
                            concentration=cs, froude=fs, speed=np.array([froude_speed(f)
                                                                        for f in fs]),
                            mean=mean, err=err, fields=fields, beam=ship.hull.beam,
                            length=ship.hull.length,
                            density=float(HERMAN2013.forcing.ice_density)))
    return out


def law_values(g: dict, s, v, terms=None) -> tuple[np.ndarray, np.ndarray]:
    """Zuev's and Huang et al.'s resistance [N] at the points of group ``g``
    (concentration × speed), with its hull and the floes' thickness and
    density; ``terms``: only these of Zuev's terms (:func:`zuev_terms`)."""
    S, V = np.meshgrid(s, v, indexing="ij")
    h = ice_thickness()
    zuev = (zuev_resistance(V, S, g["beam"], h, density=g["density"]) if terms is None else
            sum(zuev_terms(V, S, g["beam"], h, density=g["density"])[k] for k in terms))
    return zuev, huang_resistance(V, S, g["beam"], h, g["length"], density=g["density"])


def _numbers(values) -> str:
    return ", ".join("—" if not np.isfinite(x) else f"{x:.2f}" for x in values)


def _exponents(fits) -> str:
    """Exponents ± their standard errors (:func:`power_law_exponent`)."""
    return ", ".join("—" if not np.isfinite(b) else f"{b:.2f}" if not np.isfinite(se)
                     else f"{b:.2f} ± {se:.2f}" for b, se in fits)


def _ratio(values, percent: bool = False) -> str:
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if not x.size:
        return "—"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if percent:
            return f"{100 * np.median(x):.1f} %, {100 * x.max():.1f} %"
        return f"{np.median(x):.3g} ({x.min():.3g}–{x.max():.3g})"
