"""Jammed floe packings: FIRE energy minimisation and the jamming concentration.

A dense state made by compressing ice with the dynamic engine carries the
kinetic energy the compression injects; a *jammed packing* is instead a
mechanical equilibrium: every floe's contact forces balance. It is found
the way jammed packings of soft discs are found in granular physics
(O'Hern et al. 2003, Phys. Rev. E 68, 011306):

* :func:`relax_floes` minimises the elastic energy of the normal Hertz
  overlaps, U = Σ_contacts (2/5) k √R* δ^{5/2} (the potential of the normal
  force k √R* δ^{3/2} of Herman 2013 eq 2; damping, friction and drag do
  not change where the minima are), with FIRE (Bitzek et al. 2006, Phys.
  Rev. Lett. 97, 170201; the semi-implicit form of Guénolé et al. 2020,
  Comput. Mater. Sci. 175, 109584). Below jamming the minimum has U = 0 (no
  overlaps); above it the floes must overlap and the minimum is a
  force-balanced, jammed state.
* :func:`compress_floes` shrinks a periodic box affinely to a target
  concentration in small increments, relaxing after each: a jammed packing
  at that concentration (or an unjammed one below the jamming point).
* :func:`jamming_concentration` finds the concentration A_J where a zero
  energy state stops existing: compress while relaxations end at U = 0,
  and halve the increment whenever one does not (O'Hern's protocol).

The minimiser works in units of the mean radius, with unit modulus and
masses proportional to the radius (neither changes where the minima are;
masses ∝ r make the stiffest modes of large floes, which touch many small
ones, about as fast as those of small floes, so the FIRE time step is not
held down by a few giants). Its
tolerances are dimensionless: ``energy_tol`` is the energy per floe below
which a state counts as unjammed (overlaps of about 1e-6 mean radii), and
``force_tol`` the largest net force on a floe, relative to the mean
contact force, at which a jammed state counts as balanced.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field as dc_field

import numpy as np
from numba import njit

from .input_checks import check_range
from .domain import PeriodicBox, minimum_image, wrap_coordinate
from .floes import FloeField, max_overlap
from .neighbors import build_pair_list_serial, choose_cell_size, radius_rank

__all__ = ["RelaxResult", "relax_floes", "compress_floes", "jamming_concentration",
           "JammingResult"]

# status of the FIRE kernel
FIRE_UNJAMMED, FIRE_BALANCED, FIRE_MAX_ITER = 0, 1, 2
_STATUS_NAMES = {FIRE_UNJAMMED: "unjammed", FIRE_BALANCED: "balanced",
                 FIRE_MAX_ITER: "not converged"}

# FIRE parameters (Bitzek et al. 2006; Guénolé et al. 2020)
_N_DELAY = 5
_F_INC = 1.1
_F_DEC = 0.5
_ALPHA_START = 0.1
_F_ALPHA = 0.99
_SKIN = 0.3          # Verlet skin in mean radii


@njit(cache=True, error_model="numpy")
def overlap_forces(pos, radius, lx, ly, start, nbr, force, stiffness):
    """Normal Hertz forces √R* δ^{3/2} of every overlapping pair of the
    Verlet list (periodic box, unit modulus) into ``force`` (N, 2), and the
    sum of the pair stiffnesses dF/dδ = 1.5 √R* √δ of each floe into
    ``stiffness`` (N,).

    Returns (energy Σ (2/5) √R* δ^{5/2}, number of contacts, sum of the
    contact force magnitudes, largest stiffness/radius of a floe).
    """
    force[:] = 0.0
    stiffness[:] = 0.0
    energy = 0.0
    n_contacts = 0
    f_sum = 0.0
    for i in range(radius.shape[0]):
        xi = pos[i, 0]
        yi = pos[i, 1]
        ri = radius[i]
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            dx = minimum_image(pos[j, 0] - xi, lx, True)
            dy = minimum_image(pos[j, 1] - yi, ly, True)
            rsum = ri + radius[j]
            d2 = dx * dx + dy * dy
            if d2 >= rsum * rsum:
                continue
            d = math.sqrt(d2)
            delta = rsum - d
            sr = math.sqrt(ri * radius[j] / rsum)
            sd = math.sqrt(delta)
            f = sr * delta * sd
            energy += 0.4 * f * delta
            n_contacts += 1
            f_sum += f
            k = 1.5 * sr * sd
            stiffness[i] += k
            stiffness[j] += k
            fx = f * dx / d
            fy = f * dy / d
            force[i, 0] -= fx
            force[i, 1] -= fy
            force[j, 0] += fx
            force[j, 1] += fy
    k_max = 0.0
    for i in range(radius.shape[0]):
        k_max = max(k_max, stiffness[i] / radius[i])
    return energy, n_contacts, f_sum, k_max


@njit(cache=True, error_model="numpy")
def fire_relax(pos, radius, rank, lx, ly, cell_size, max_iter, energy_tol, force_tol, dt_cap):
    """FIRE minimisation of the overlap energy, positions updated in place.

    Returns (status, iterations, energy per floe, contacts, largest net
    force over mean contact force, number of list rebuilds).
    """
    n = radius.shape[0]
    vel = np.zeros((n, 2))
    force = np.zeros((n, 2))
    stiffness = np.zeros(n)
    start, nbr = build_pair_list_serial(pos, radius, rank, lx, ly, True, True, _SKIN, cell_size)
    ref = pos.copy()
    n_rebuilds = 0
    energy, n_contacts, f_sum, k_max = overlap_forces(pos, radius, lx, ly, start, nbr, force,
                                                          stiffness)
    dt_max = dt_cap if k_max == 0.0 else min(dt_cap, 1.0 / math.sqrt(2.0 * k_max))
    dt = 0.1 * dt_max
    alpha = _ALPHA_START
    n_pos = 0
    status = FIRE_MAX_ITER
    residual = 0.0
    it = 0
    while True:
        # convergence
        f_max2 = 0.0
        for i in range(n):
            f_max2 = max(f_max2, force[i, 0] ** 2 + force[i, 1] ** 2)
        if energy < energy_tol * n:
            status = FIRE_UNJAMMED
            residual = 0.0 if n_contacts == 0 else math.sqrt(f_max2) / (f_sum / n_contacts)
            break
        residual = math.sqrt(f_max2) / (f_sum / n_contacts)
        if residual < force_tol:
            status = FIRE_BALANCED
            break
        if it >= max_iter:
            break
        it += 1
        # FIRE velocity control
        power = 0.0
        for i in range(n):
            power += force[i, 0] * vel[i, 0] + force[i, 1] * vel[i, 1]
        dt_max = dt_cap if k_max == 0.0 else min(dt_cap, 1.0 / math.sqrt(2.0 * k_max))
        if power > 0.0:
            n_pos += 1
            if n_pos > _N_DELAY:
                dt = min(dt * _F_INC, dt_max)
                alpha *= _F_ALPHA
        else:
            n_pos = 0
            dt *= _F_DEC
            alpha = _ALPHA_START
            for i in range(n):
                pos[i, 0] -= 0.5 * dt * vel[i, 0]
                pos[i, 1] -= 0.5 * dt * vel[i, 1]
                vel[i, 0] = 0.0
                vel[i, 1] = 0.0
        dt = min(dt, dt_max)
        # semi-implicit Euler step with FIRE mixing
        v2 = 0.0
        f2 = 0.0
        for i in range(n):
            vel[i, 0] += dt * force[i, 0] / radius[i]
            vel[i, 1] += dt * force[i, 1] / radius[i]
            v2 += vel[i, 0] ** 2 + vel[i, 1] ** 2
            f2 += force[i, 0] ** 2 + force[i, 1] ** 2
        mix = alpha * math.sqrt(v2 / f2) if f2 > 0.0 else 0.0
        worst = 0.0
        for i in range(n):
            vel[i, 0] = (1.0 - alpha) * vel[i, 0] + mix * force[i, 0]
            vel[i, 1] = (1.0 - alpha) * vel[i, 1] + mix * force[i, 1]
            pos[i, 0] += dt * vel[i, 0]
            pos[i, 1] += dt * vel[i, 1]
            dx = minimum_image(pos[i, 0] - ref[i, 0], lx, True)
            dy = minimum_image(pos[i, 1] - ref[i, 1], ly, True)
            worst = max(worst, dx * dx + dy * dy)
        if 2.0 * math.sqrt(worst) >= _SKIN:
            for i in range(n):
                pos[i, 0] = wrap_coordinate(pos[i, 0], lx, True)
                pos[i, 1] = wrap_coordinate(pos[i, 1], ly, True)
            start, nbr = build_pair_list_serial(pos, radius, rank, lx, ly, True, True, _SKIN,
                                                cell_size)
            ref[:] = pos
            n_rebuilds += 1
        energy, n_contacts, f_sum, k_max = overlap_forces(pos, radius, lx, ly, start, nbr, force,
                                                          stiffness)
    for i in range(n):
        pos[i, 0] = wrap_coordinate(pos[i, 0], lx, True)
        pos[i, 1] = wrap_coordinate(pos[i, 1], ly, True)
    return status, it, energy / n, n_contacts, residual, n_rebuilds


@dataclass(frozen=True)
class RelaxResult:
    """Outcome of :func:`relax_floes`.

    Attributes
    ----------
    positions : (N, 2) relaxed positions [m]
    status : "unjammed" (U = 0 to tolerance), "balanced" (jammed, forces in
        balance to tolerance) or "not converged"
    iterations : FIRE iterations done
    energy_per_floe : overlap energy per floe in the minimiser's units
        (unit modulus, lengths in mean radii; see the module docstring)
    contacts_per_floe : 2 × contacts / N (the mean coordination number Z)
    residual_force : largest net force on a floe over the mean contact force
    max_overlap : largest overlap over the smaller radius of its pair
    """
    positions: np.ndarray = dc_field(repr=False)
    status: str
    iterations: int
    energy_per_floe: float
    contacts_per_floe: float
    residual_force: float
    max_overlap: float

    @property
    def jammed(self) -> bool:
        """True when the minimum has overlaps (U > 0): the floes are jammed."""
        return self.status != "unjammed"


def _check_periodic(box) -> None:
    if not isinstance(box, PeriodicBox):
        raise ValueError(f"jammed packings are made in a doubly periodic box (PeriodicBox), "
                         f"got {type(box).__name__}")


def _at_rest(field: FloeField, positions) -> FloeField:
    """The floes of ``field`` at ``positions``, at rest."""
    return FloeField(positions, field.radii, field.thickness, np.zeros_like(positions),
                     np.zeros(field.n), field.density)


def _check_input(positions, radii, box):
    _check_periodic(box)
    pos = np.array(positions, dtype=float)
    r = np.asarray(radii, dtype=float)
    if r.ndim != 1 or r.size < 2:
        raise ValueError("radii must be a 1-D array of at least two floes")
    if pos.shape != (r.size, 2):
        raise ValueError(f"positions must have shape ({r.size}, 2), got {pos.shape}")
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(r))):
        raise ValueError("positions and radii must be finite")
    if np.any(r <= 0):
        raise ValueError(f"radii must be positive; the smallest is {r.min():g} m")
    cut = 2.0 * r.max() + _SKIN * r.mean()
    if cut >= 0.5 * min(box.lx, box.ly):
        raise ValueError(f"the box ({box.lx:.4g} × {box.ly:.4g} m) is too small for the largest "
                         f"floe (radius {r.max():.4g} m): both sides must exceed {2 * cut:.4g} m")
    return pos, r


def relax_floes(positions, radii, box: PeriodicBox, *, max_iter: int = 200000,
                energy_tol: float = 1e-16, force_tol: float = 1e-4) -> RelaxResult:
    """Minimise the Hertz overlap energy of floes in a periodic box (FIRE).

    Parameters
    ----------
    positions : (N, 2) floe centres [m]; not modified
    radii : (N,) floe radii [m]
    box : PeriodicBox
    max_iter : FIRE iterations at most
    energy_tol : energy per floe (dimensionless, see the module docstring)
        below which the state is unjammed
    force_tol : largest net force on a floe, relative to the mean contact
        force, below which a jammed state is balanced

    Notes
    -----
    Returns a :class:`RelaxResult`; ``status`` says which criterion ended it.
    """
    pos, r = _check_input(positions, radii, box)
    check_range("max_iter", max_iter, 0, None)
    check_range("energy_tol", energy_tol, 0.0, None, low_open=True)
    check_range("force_tol", force_tol, 0.0, None, low_open=True)
    scale = float(r.mean())
    p = box.wrap(pos) / scale
    rs = r / scale
    lx, ly = box.lx / scale, box.ly / scale
    cell = choose_cell_size(rs, lx, ly, _SKIN)
    status, it, e, nc, res, _ = fire_relax(p, rs, radius_rank(rs), lx, ly, cell, int(max_iter),
                                           float(energy_tol), float(force_tol), 1.0)
    out = p * scale
    return RelaxResult(positions=out, status=_STATUS_NAMES[int(status)], iterations=int(it),
                       energy_per_floe=float(e), contacts_per_floe=2.0 * nc / r.size,
                       residual_force=float(res), max_overlap=max_overlap(out, r, box))


def _scaled(field: FloeField, box: PeriodicBox, positions, concentration: float):
    """Positions and box scaled affinely to ``concentration``."""
    s = math.sqrt(field.total_area / box.area / concentration)
    return positions * s, PeriodicBox(box.lx * s, box.ly * s)


def _check_field(field: FloeField, box):
    if not isinstance(field, FloeField):
        raise TypeError(f"field must be a FloeField, got {type(field).__name__}")
    if np.any(field.frozen):
        raise ValueError("jammed packings are made of mobile floes; this field has "
                         f"{int(field.frozen.sum())} frozen floes")
    _check_periodic(box)


def compress_floes(field: FloeField, box: PeriodicBox, concentration: float, *,
                   increment: float = 0.005, progress: bool = False, **relax_options):
    """Compress a floe field affinely to ``concentration``, relaxing (FIRE)
    after every ``increment`` of concentration.

    Returns (field, box, result): a new :class:`FloeField` at rest with the
    relaxed positions, the new :class:`PeriodicBox`, and the
    :class:`RelaxResult` of the last relaxation (``result.jammed`` tells
    whether the target is above the jamming point; a jammed state has
    overlaps and is in force balance). ``relax_options`` go to
    :func:`relax_floes`.
    """
    _check_field(field, box)
    check_range("concentration", concentration, 0.0, 1.0, low_open=True, high_open=True)
    check_range("increment", increment, 0.0, None, low_open=True)
    a0 = field.total_area / box.area
    n_steps = max(1, int(math.ceil(abs(concentration - a0) / increment)))
    targets = a0 + (concentration - a0) * np.arange(1, n_steps + 1) / n_steps
    if progress:
        from tqdm.auto import tqdm
        targets = tqdm(targets, desc=f"compressing to A = {concentration:g}", unit="step")
    pos = field.positions
    result = None
    for a in targets:
        pos, box = _scaled(field, box, pos, float(a))
        result = relax_floes(pos, field.radii, box, **relax_options)
        pos = result.positions
        if progress:
            targets.set_postfix(Z=f"{result.contacts_per_floe:.2f}", status=result.status)
    return _at_rest(field, pos), box, result


@dataclass(frozen=True)
class JammingResult:
    """Outcome of :func:`jamming_concentration`.

    Attributes
    ----------
    concentration : A_J, midway between the last unjammed and the first
        jammed concentration tried
    uncertainty : half their distance
    unjammed_field, unjammed_box : the densest zero-energy packing found
    jammed_field, jammed_box : the packing just above A_J (a jammed,
        force-balanced state with small overlaps)
    jammed_result : its :class:`RelaxResult`
    relaxations : number of FIRE relaxations done
    """
    concentration: float
    uncertainty: float
    unjammed_field: FloeField = dc_field(repr=False)
    unjammed_box: PeriodicBox
    jammed_field: FloeField = dc_field(repr=False)
    jammed_box: PeriodicBox
    jammed_result: RelaxResult
    relaxations: int


def jamming_concentration(field: FloeField, box: PeriodicBox, *, increment: float = 0.01,
                          tolerance: float = 2e-4, max_concentration: float = 0.99,
                          progress: bool = False, **relax_options) -> JammingResult:
    """Jamming concentration A_J of these floes (O'Hern et al. 2003).

    From the field's (unjammed) concentration, compress affinely by
    ``increment`` and relax; a relaxation that ends with zero energy is
    accepted and compression goes on from it, one that ends jammed is
    discarded and the increment halved, until it is below ``tolerance``.
    The result depends on the packing history (the protocol, the start
    configuration); for a wide power-law FSD the spread between seeds is
    small because the largest floes are many.

    Raises ``ValueError`` if the field is already jammed at its start
    concentration or the floes are still unjammed at ``max_concentration``.
    """
    _check_field(field, box)
    check_range("increment", increment, 0.0, None, low_open=True)
    check_range("tolerance", tolerance, 0.0, increment, low_open=True)
    a = field.total_area / box.area
    first = relax_floes(field.positions, field.radii, box, **relax_options)
    if first.jammed:
        raise ValueError(f"the field is already jammed at its concentration {a:.4f}; start "
                         f"from a lower concentration")
    pos, cur_box = first.positions, box
    jam_pos = jam_box = jam_res = None
    count = 1
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(desc="jamming", unit="relaxation")
    step = increment
    while step >= tolerance:
        trial_a = a + step
        if trial_a >= max_concentration:
            if jam_pos is None and step == increment:
                raise ValueError(f"no jamming below max_concentration={max_concentration}")
            step *= 0.5
            continue
        trial_pos, trial_box = _scaled(field, cur_box, pos, trial_a)
        res = relax_floes(trial_pos, field.radii, trial_box, **relax_options)
        count += 1
        if bar is not None:
            bar.update(1)
            bar.set_postfix(A=f"{trial_a:.4f}", status=res.status)
        if res.jammed:
            jam_pos, jam_box, jam_res = res.positions, trial_box, res
            step *= 0.5
        else:
            pos, cur_box, a = res.positions, trial_box, trial_a
    if bar is not None:
        bar.close()
    if jam_pos is None:
        raise ValueError(f"no jamming below max_concentration={max_concentration}")
    jam_a = field.total_area / jam_box.area

    return JammingResult(concentration=0.5 * (a + jam_a), uncertainty=0.5 * (jam_a - a),
                         unjammed_field=_at_rest(field, pos), unjammed_box=cur_box,
                         jammed_field=_at_rest(field, jam_pos), jammed_box=jam_box,
                         jammed_result=jam_res, relaxations=count)
