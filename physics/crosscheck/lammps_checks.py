"""The Hertz engine against LAMMPS on identical discs.

Every comparison builds one :class:`~physics.FloeField`, runs it in
:class:`~physics.HertzSimulation` and in the LAMMPS engine the scenarios run
on, :class:`~physics.lammps_engine.LammpsHertzSimulation` (here without
forcing and walls), and returns :class:`~physics.crosscheck.results.Check`
rows:

* :func:`zero_step_forces` — forces and torques of the set-up evaluation
  (LAMMPS ``run 0``), on a compressed field full of contacts;
* :func:`trajectories` — positions, velocities and spins after 500 steps of a
  dense, colliding field with friction;
* :func:`convergence` — the pressure–concentration curve of a convergence
  run through a deforming box;
* :func:`speed` — floe-steps per second of both engines on the same system.

Where the engines are allowed to differ
---------------------------------------
* With tangential damping (x_γt > 0), a *new* contact whose viscous
  tangential force alone exceeds the Coulomb cap gets the capped force in our
  engine and none in LAMMPS (``mindlin_rescale/force`` returns zero when the
  spring is still empty). The zero-step check with tangential damping uses
  slow floes, so no contact reaches the cap; our default (and Herman's) is
  x_γt = 0, where the laws are identical.
* A deforming box is remapped after the drift in our engine and at the end of
  the step in LAMMPS (``fix deform``); the pressure check starts from a
  jammed packing, where this changes nothing measurable, and the figure also
  shows a run through the jamming point, where the two runs (like any two
  runs differing by rounding) part ways and only agree statistically.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..domain import DeformingPeriodicBox, PeriodicBox
from ..floes import FloeField
from ..hertz import HertzSimulation
from ..lammps_engine import LammpsHertzSimulation
from ..params import HERMAN2013, ContactParams
from .results import Check, save_figure

__all__ = ["zero_step_forces", "trajectories", "convergence", "speed", "run",
           "compressed_field", "jammed_field"]


def _periodic_error(a: np.ndarray, b: np.ndarray, lengths) -> np.ndarray:
    d = a - b
    L = np.asarray(lengths, dtype=float)
    return d - np.round(d / L) * L


def compressed_field(n: int, seed: int, squeeze: float = 0.997, speed: float = 0.0,
                     spin: float = 0.0):
    """A field at Ā = 0.85 squeezed by the factor ``squeeze`` (so that many
    floes overlap by ~1e-4 m), thickness 1–2 m, Gaussian velocities of
    standard deviation ``speed`` [m/s] and contact-point spin speeds r ω of
    standard deviation ``spin`` [m/s]. Returns (field, box)."""
    rng = np.random.default_rng(seed)
    field, box = HERMAN2013.floe_field(n, 0.85, seed=seed)
    vel = rng.normal(0.0, speed, (n, 2)) if speed > 0 else np.zeros((n, 2))
    omega = rng.normal(0.0, spin, n) / field.radii if spin > 0 else np.zeros(n)
    f = FloeField(field.positions * squeeze, field.radii, 1.0 + rng.random(n), vel, omega)
    return f, PeriodicBox(box.lx * squeeze, box.ly * squeeze)


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    scale = float(np.abs(a).max())
    if scale == 0.0:
        return float(np.abs(b).max())
    return float(np.abs(a - b).max() / scale)


def zero_step_forces(n: int = 2000, seed: int = 0) -> list[Check]:
    """Forces and torques at the set-up evaluation, no step taken.

    Two contact laws on a squeezed field: (1) Herman's (μ = 0.7, x_γt = 0),
    floes moving at 0.05 m/s; torques are zero in both engines there (no
    spring history yet). (2) x_γt = 0.5 and μ = 10, floes moving at 1e-5 m/s,
    so that the tangential damping gives every contact a torque without
    reaching the Coulomb cap. Error: max over floes of |ΔF| / max |F|.
    """
    rows = []
    cases = [("herman", ContactParams(restitution=0.5, friction=0.7), 0.05, 0.0),
             ("tangential-damping", ContactParams(restitution=0.5, friction=10.0,
                                                  tangential_damping=0.5), 1e-5, 1e-5)]
    for label, contact, speed, spin in cases:
        field, box = compressed_field(n, seed, speed=speed, spin=spin)
        ours = HertzSimulation(field, box, contact, dt=1e-3, allow_overlap=True)
        f_o, t_o = ours.contact_forces()
        n_contacts = len(ours.contacts().i)
        with LammpsHertzSimulation(field, PeriodicBox(box.lx, box.ly), contact, dt=1e-3,
                                   allow_overlap=True) as lmp:
            f_l, t_l = lmp.force, lmp.torque
        torque_note = ("torques zero in both" if not np.any(t_o) and not np.any(t_l)
                       else f"max |τ| {np.abs(t_o).max():.3g} N m")
        rows.append(Check(
            f"lammps/zero-step/{label}/forces",
            f"contact forces before any step, {n} floes, {n_contacts} contacts "
            f"(x_γt = {contact.tangential_damping:g}, μ = {contact.friction:g})",
            _relative(f_o, f_l), 1e-10, detail=f"max |F| {np.abs(f_o).max():.3g} N"))
        rows.append(Check(
            f"lammps/zero-step/{label}/torques",
            "contact torques before any step", _relative(t_o, t_l), 1e-10,
            detail=torque_note))
    return rows


def trajectories(n: int = 2000, steps: int = 500, seed: int = 0,
                 out_dir: Path | None = None, progress: bool = False) -> list[Check]:
    """Positions, velocities and spins after ``steps`` steps.

    A field at Ā = 0.85 with velocities of 0.1 m/s and spins, thickness
    1–2 m, Herman's contact law (e = 0.5, μ = 0.7), Δt = 1 ms: hundreds of
    impacts, with friction, start and end during the run. Errors are sampled
    every 10 steps; the position error is relative to the mean radius.
    """
    field, box = compressed_field(n, seed, squeeze=1.0, speed=0.1, spin=0.01)
    contact = ContactParams(restitution=0.5, friction=0.7)
    dt = 1e-3
    ours = HertzSimulation(field, box, contact, dt=dt)
    lmp = LammpsHertzSimulation(field, PeriodicBox(box.lx, box.ly), contact, dt=dt)
    r_mean = float(field.radii.mean())
    hist = []
    contacts = []
    chunk = 10
    it = range(0, steps, chunk)
    if progress:
        from tqdm.auto import tqdm

        it = tqdm(it, desc="Hertz vs LAMMPS trajectories", unit="x10 steps", leave=False)
    try:
        for _ in it:
            ours.step(chunk)
            lmp.step(chunk)
            dx = _periodic_error(ours.positions, lmp.positions, (box.lx, box.ly))
            hist.append((ours.n_steps, np.abs(dx).max() / r_mean,
                         _relative(ours.velocities, lmp.velocities),
                         _relative(ours.angular_velocities, lmp.angular_velocities)))
            contacts.append(len(ours.contacts().i))
    finally:
        lmp.close()
    h = np.array(hist)
    figures = []
    if out_dir is not None:
        figures.append(_plot_trajectories(h, out_dir))
    detail = (f"after {steps} steps: |Δu|/max|u| {h[-1, 2]:.2g}, |Δω|/max|ω| {h[-1, 3]:.2g}; "
              f"{min(contacts)}–{max(contacts)} contacts")
    return [Check("lammps/trajectories/positions",
                  f"{n} discs, {steps} steps of {dt:g} s with impacts and friction: largest "
                  f"position difference / mean radius", float(h[:, 1].max()), 1e-6,
                  detail=detail, figures=figures)]


def _plot_trajectories(h, out_dir: Path) -> str:
    from ..scenarios.plots import pyplot

    plt = pyplot()

    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    floor = 1e-18
    ax.semilogy(h[:, 0], np.maximum(h[:, 1], floor), label="position / mean radius")
    ax.semilogy(h[:, 0], np.maximum(h[:, 2], floor), label="velocity / max |u|")
    ax.semilogy(h[:, 0], np.maximum(h[:, 3], floor), label="spin / max |ω|")
    ax.axhline(1e-6, color="k", lw=0.8, ls="--", label="tolerance (positions)")
    ax.set_xlabel("step")
    ax.set_ylabel("largest difference, ours − LAMMPS")
    ax.set_title("Hertz engine vs LAMMPS: same discs, same steps")
    ax.legend(fontsize=8)
    return save_figure(fig, out_dir, "lammps_trajectories.png")


def jammed_field(n: int, seed: int, concentration: float, rate_per_hour: float = 10.0):
    """A packing at ``concentration`` made by our engine: convergence with
    water drag from Ā = 0.80, one minute at rest, velocities set to zero.
    Returns (field, box)."""
    field, box = HERMAN2013.floe_field(n, 0.80, seed=seed)
    forcing = HERMAN2013.make_forcing(wind=(0.0, 0.0), current=(0.0, 0.0))
    pre = HertzSimulation(field, DeformingPeriodicBox(box.lx, box.ly,
                                                      concentration_rate=rate_per_hour / 3600),
                          ContactParams(), forcing, dt=1e-3)
    while pre.concentration < concentration:
        pre.step(100)
    pre.box.set_rate(0.0)
    pre.advance(60.0)
    st = pre.state()
    st.velocities[:] = 0.0
    st.angular_velocities[:] = 0.0
    return st, PeriodicBox(pre.box.lx, pre.box.ly)


def _compress(field, box, rate, dt, a_end, d_a, progress, label):
    """Both engines from the same state; samples (A, p_ours, p_lammps)."""
    ours = HertzSimulation(field, DeformingPeriodicBox(box.lx, box.ly, concentration_rate=rate),
                           ContactParams(), dt=dt, allow_overlap=True)
    lmp = LammpsHertzSimulation(field, DeformingPeriodicBox(box.lx, box.ly,
                                                            concentration_rate=rate),
                                ContactParams(), dt=dt, allow_overlap=True)
    per = max(1, int(round(d_a / rate / dt)))
    rows = []
    total = int(np.ceil((a_end - ours.concentration) / (rate * per * dt)))
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=total, desc=label, unit="sample", leave=False)
    try:
        while ours.concentration < a_end:
            ours.step(per)
            lmp.step(per)
            rows.append((ours.concentration, lmp.concentration,
                         ours.contact_stress(per_floe=False).pressure, lmp.virial_pressure()))
            if bar is not None:
                bar.update(1)
    finally:
        lmp.close()
        if bar is not None:
            bar.close()
    return np.array(rows)


def convergence(n: int = 1000, seed: int = 3, out_dir: Path | None = None,
                progress: bool = False, quick: bool = False) -> list[Check]:
    """Pressure against concentration under convergence (no drag, 3.6/h).

    Check: a jammed packing (Ā = 0.90, prepared by our engine) compressed to
    0.93 in both engines; the largest relative pressure difference over the
    samples. Report: the same floes compressed from Ā = 0.85 through the
    jamming point; there the two runs part ways (chaos amplifies rounding and
    the different remap order) and agree only as two realisations do.
    """
    rate = 3.6 / 3600
    dt = 5e-4
    a_jam, a_end = 0.90, (0.915 if quick else 0.93)
    field, box = jammed_field(n, seed, a_jam)
    jam = _compress(field, box, rate, dt, a_end, 0.0005, progress, "LAMMPS convergence (jammed)")
    rel = np.abs(jam[:, 3] / jam[:, 2] - 1.0)
    rows = [Check("lammps/convergence/jammed",
                  f"p(A) of {n} floes compressed from a jammed packing at Ā = {jam[0, 0]:.3f} "
                  f"to {jam[-1, 0]:.3f} at 3.6/h: largest |p_LAMMPS / p_ours − 1|",
                  float(rel.max()), 0.02,
                  detail=f"{len(jam)} samples; p {jam[0, 2]:.3g}–{jam[-1, 2]:.3g} N/m; "
                         f"mean |Δp|/p {rel.mean():.2g}; box sides equal to "
                         f"{np.abs(jam[:, 1] / jam[:, 0] - 1).max():.1g}")]
    through = None
    if not quick:
        field2, box2 = jammed_field(n, seed, 0.85)
        through = _compress(field2, box2, rate, dt, a_end, 0.0005, progress,
                            "LAMMPS convergence (through jamming)")
        p_max = max(through[:, 2].max(), through[:, 3].max())
        hi = through[:, 2] > 0.1 * p_max
        rel2 = np.abs(through[hi, 3] / through[hi, 2] - 1.0)
        rows.append(Check(
            "lammps/convergence/through-jamming",
            "the same floes compressed from Ā = 0.85 through jamming: largest |Δp|/p where "
            "p > 10 % of its final value (two realisations, not one trajectory)",
            float(rel2.max()), None,
            detail=f"A at which p first exceeds 1e6 N/m: ours "
                   f"{_first_above(through[:, 0], through[:, 2], 1e6):.4f}, LAMMPS "
                   f"{_first_above(through[:, 0], through[:, 3], 1e6):.4f}"))
    figures = []
    if out_dir is not None:
        figures.append(_plot_convergence(jam, through, out_dir))
        rows[0].figures = figures
    return rows


def _first_above(a, p, level):
    k = np.flatnonzero(p > level)
    return float(a[k[0]]) if k.size else float("nan")


def _plot_convergence(jam, through, out_dir: Path) -> str:
    from ..scenarios.plots import pyplot

    plt = pyplot()

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    ax = axes[0]
    if through is not None:
        ax.semilogy(through[:, 0], np.maximum(through[:, 2], 1e-3), color="C0", lw=1,
                    label="ours, from Ā = 0.85")
        ax.semilogy(through[:, 1], np.maximum(through[:, 3], 1e-3), color="C1", lw=1, ls="--",
                    label="LAMMPS, from Ā = 0.85")
    ax.semilogy(jam[:, 0], jam[:, 2], color="C0", lw=2.5, alpha=0.5, label="ours, jammed start")
    ax.semilogy(jam[:, 1], jam[:, 3], color="C3", lw=1, ls=":", label="LAMMPS, jammed start")
    ax.set_xlabel("concentration A")
    ax.set_ylabel("pressure p [N/m]")
    ax.set_title("Convergence at 3.6/h, no drag")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.plot(jam[:, 0], 100 * (jam[:, 3] / jam[:, 2] - 1.0), color="C3", label="jammed start")
    if through is not None:
        hi = through[:, 2] > 0.1 * through[:, 2].max()
        ax.plot(through[hi, 0], 100 * (through[hi, 3] / through[hi, 2] - 1.0), color="C1",
                label="through jamming (p > 10 % of final)")
    ax.axhspan(-2, 2, color="0.9", label="± 2 %")
    ax.set_xlabel("concentration A")
    ax.set_ylabel("p_LAMMPS / p_ours − 1 [%]")
    ax.legend(fontsize=8)
    return save_figure(fig, out_dir, "lammps_convergence.png")


def speed(n: int = 20000, steps: int = 1000, seed: int = 1,
          progress: bool = False) -> list[Check]:
    """Floe-steps per second on one system: Ā = 0.7, velocities of 0.03 m/s,
    Herman's contact law, Δt of Herman (2013), no forcing (the contacts
    alone). Ours on one thread (serial kernels) and on all threads (parallel
    kernels); LAMMPS on one process. Compile time and LAMMPS set-up are
    excluded (both engines run 20 steps first)."""
    import numba

    field, box = HERMAN2013.floe_field(n, 0.7, seed=seed, velocity_std=0.03)
    dt = HERMAN2013.time_step
    contact = HERMAN2013.contact
    threads = numba.get_num_threads()
    rates = {}
    for label, parallel in (("ours, 1 thread", False), (f"ours, {threads} threads", True)):
        sim = HertzSimulation(field, PeriodicBox(box.lx, box.ly), contact, dt=dt,
                              parallel=parallel)
        sim.step(20)
        t0 = time.perf_counter()
        sim.step(steps)
        rates[label] = n * steps / (time.perf_counter() - t0)
    with LammpsHertzSimulation(field, PeriodicBox(box.lx, box.ly), contact, dt=dt) as lmp:
        lmp.step(20)
        w0 = lmp.wall_time
        lmp.step(steps)
        rates["LAMMPS, 1 process"] = n * steps / (lmp.wall_time - w0)
    base = rates["LAMMPS, 1 process"]
    rows = [Check(f"speed/hertz/{k.replace(', ', '-').replace(' ', '-')}",
                  f"floe-steps per second, N = {n}, Ā = 0.7, {steps} steps", v, None,
                  unit="floe-steps/s", detail=f"{v / base:.2f}× LAMMPS")
            for k, v in rates.items()]
    return rows


def run(out_dir: Path | None = None, quick: bool = False, seed: int = 0,
        progress: bool = True) -> list[Check]:
    """Every LAMMPS comparison. ``quick`` uses smaller systems (same tolerances)."""
    rows = []
    rows += zero_step_forces(500 if quick else 2000, seed)
    rows += trajectories(500 if quick else 2000, 500, seed, out_dir, progress)
    rows += convergence(400 if quick else 1000, seed + 3, out_dir, progress, quick)
    rows += speed(5000 if quick else 20000, 200 if quick else 1000, seed + 1, progress)
    return rows
