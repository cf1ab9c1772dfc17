"""The serial Hertz step that lets free floes drift in closed form
(``HertzSimulation(free_drift=True)``).

Between two contacts a floe feels only its forcing (Herman 2013, eqs 6–7):
wind, water drag, Coriolis and rotational drag, all constant or linear in its
velocity. Under the engine's leapfrog that motion is a linear recurrence,

    u_{n+1} = μ u_n + c,        x_{n+1} = x_n + Δt u_{n+1},
    μ = 1 − Δt (b + i m f)/m,   c = Δt (a |u_a| u_a + b u_w)/m,

in complex notation (u = u_x + i u_y), and ω_{n+1} = (1 − Δt c_r/I) ω_n. Its
sum over K steps has a closed form (:func:`drift_sums`: μ^K and two geometric
sums, by doubling, O(log K) operations and no cancellation). A floe that can
touch nothing for a while can therefore be left where it is and moved to
where the recurrence puts it when it is next needed, at no cost per step.

**Windows.** A run is cut into windows of at most ``window`` steps. At the
start of each (:func:`classify`), with every floe up to date, each floe gets
a straight line, x_i(0) + t u_i (u_i its velocity after the window's first
kick), and a bound on how far it leaves it in the window:

* a floe under its forcing alone changes its velocity by at most
  δ_i = |μ − 1| s_i + |c| a step (s_i = |u_i| + (K − 1)|c| bounds its speed,
  as |μ| ≤ 1), so it leaves its line by at most ρ_i = Δt δ_i K²/2;
* any other floe gets a budget E_j (a tenth of its speed, or 1.25 times
  the hull's near the hull, plus 2 cm/s, times the window's length W);
* the hull moves at most H (1.25 times the speed of its fastest point, plus
  2 cm/s, times W).

A floe is *free* for the window when the least distance between its line and
each listed partner's, less both radii, exceeds ρ_i + ρ_j (the partner free)
or ρ_i + E_j (engaged); its gap to the hull exceeds s_i W + H, and to each
rigid wall s_i W. A floe that fails one test is engaged, and its partners are
tested again against its budget. A pair of engaged floes is looked at only
when their lines come within their two budgets. Pairs outside the Verlet
list cannot touch while the list holds, and the list's expiry test covers
the free floes through a bound (D_0 + S t)² on their distance from the
list's centre, which is held fixed through the window. The engaged floes
take the step of
:class:`physics.hertz_step.AwakeFloes`: the same arithmetic, over them
and their pairs alone.

**Guards.** E_j and H are assumptions, checked at every step: each engaged
floe's distance from its line, and the hull's travel.

* When an engaged floe has left its line by more than E_j (a floe struck by
  the hull or by another floe turns), the window goes on
  (:func:`repair`): the floe gets a new line from where it is, x_j(now) +
  (t − now) u_j, and a new budget, and each of its listed partners is
  tested against the new line over the rest of the window as above. A free
  partner that could come within ρ_i + E_j is brought up to date and
  engaged from this step on (its own partners are then tested in turn); an
  engaged partner whose line comes within the two budgets makes the pair
  live. Until this step the floe kept to its old line, so no free floe
  could have touched it earlier.
* When the hull's travel exceeds H, or the list expires, or the window's
  steps are done, the window ends at that step: the free floes are brought
  up to date (:func:`sync_free`) and the next window begins; after the
  hull's guard failed, the step's pairs are all looked at and the hull sees
  all its floes (a free floe may touch an engaged floe or the hull at that
  step, and at no earlier one).

So every contact the full step would find is found at the same step, and
the free floes follow the same recurrence: the result is that of the full
step but for rounding (the closed form is summed in another order, and the
list's expiry test can fall a step apart), which the contacts then amplify
as they amplify any rounding. The check mode (``iterate``) steps the free
floes one step at a time with the full step's arithmetic, and then the
result is the full step's bit for bit (the tests hold it so).

The cost of a step is that of the engaged floes and their pairs; each window
adds a pass over all floes and the list (:func:`classify`) and the closed
form of the free floes (:func:`sync_free`). A window ends at a guard only
when the hull's travel or the list's expiry ends it, so the windows are
nearly all :data:`DEFAULT_WINDOW` steps long.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from .domain import minimum_image
from .hertz_kernels import (KICK_FASTMATH, Kick, drift_bound, floe_drag, kick_drift_floe,
                            kick_drift_pass, max_keep_nan, min_image_step, path_slack,
                            rigid_drift_bound, wall_overlap, wide_floe_test)
from .hertz_resting import pair_index
from .hull import disc_hull_contact
from .hull_contact import (S_X, S_Y, hull_point_speed,
                           set_world_hull)

__all__ = ["DEFAULT_WINDOW", "TALLY", "drift_sums", "classify", "sync_free", "repair"]

#: what :func:`physics.hertz_step.run_windows` counts: the windows, those that the hull's
#: guard ended, the engaged floe-steps, the steps, the engaged floes given a
#: new line within a window and the free floes engaged within one
#: (:func:`repair`)
TALLY = ("windows", "ended by the hull's guard", "engaged floe-steps", "steps", "lines renewed",
         "floes engaged within a window")

#: steps in a window (the most between two passes over all floes): longer
#: windows pass over all floes less often but keep more floes engaged
#: (measured on ShipNavigation-v1 at A = 0.5, 48 steps ran 3–5 % faster than
#: 64 and 10 % faster than 96 with the default ice, and as fast as 32 with
#: soft ice)
DEFAULT_WINDOW = 48

#: the margin on the speeds of the hull and of the engaged floes, and the
#: speed added to it [m/s], for the bounds E and H of a window
SPEED_MARGIN = 1.25
SPEED_FLOOR = 0.02
#: an engaged floe's budget for leaving its straight line in a window, as a
#: fraction of its speed (or of the hull's, near the hull) times the window:
#: smaller budgets engage fewer floes and end more windows early (measured
#: on a late ShipNavigation-v1 state, 0.1 with a floor of 2 cm/s cost 0.8 of
#: 0.5 with 5 cm/s)
DEVIATION = 0.1


class WindowPairs(NamedTuple):
    """The pairs of a Verlet list as the windows see them (the fields that
    :func:`physics.hertz_resting.live_pair_forces` reads, and the
    classification's own)."""

    #: (M,) owner of each listed pair
    owner: np.ndarray
    #: (N + 1,) slice bounds of each floe's pairs as a partner in ``as_partner``
    partner_start: np.ndarray
    #: (M,) the pairs of each floe as a partner, in CSR form
    as_partner: np.ndarray
    #: (M,) the live pairs in ``live[:count[2]]`` of the :class:`~physics.hertz_resting.Awake`
    live: np.ndarray
    #: (M,) a pair found apart is not looked at again while the sum of its
    #: floes' paths stays below this (:func:`~physics.hertz_kernels.apart_until`)
    due: np.ndarray
    #: (M,) the gap of each pair when the window began [m]
    gap: np.ndarray
    #: (N,) scratch for the classification
    stack: np.ndarray
    #: (N + 1,) the engaged floes with a wide skin, by their index in
    #: ``verlet.wide``, in ``wide[1:wide[0] + 1]``
    wide: np.ndarray


@njit(cache=True, inline="always", error_model="numpy")
def drift_sums(mu, m):
    """(μ^m, T(m), Q(m)) with T(m) = Σ_{j<m} μ^j and Q(m) = Σ_{k=1..m} T(k),
    by doubling: T(a + b) = T(a) + μ^a T(b), Q(a + b) = Q(a) + b T(a) + μ^a Q(b)."""
    p = 1.0 + 0.0j
    t = 0.0 + 0.0j
    q = 0.0 + 0.0j
    size = 0
    bp = mu                                 # block of length b: μ^b, T(b), Q(b)
    bt = 1.0 + 0.0j
    bq = 1.0 + 0.0j
    b = 1
    while m > 0:
        if m & 1:
            q = q + b * t + p * bq
            t = t + p * bt
            p = p * bp
            size += b
        bq = bq + b * bt + bp * bq
        bt = bt + bp * bt
        bp = bp * bp
        b *= 2
        m >>= 1
    return p, t, q


@njit(cache=True, inline="always", error_model="numpy")
def drift_coefficients(i, floes, drive, dt):
    """(μ, c, ν) of floe i's free recurrence (module docstring): u ← μ u + c,
    ω ← ν ω."""
    on = 1.0 if drive.active else 0.0
    k = drive.coefficients
    a, b, cr, g = on * k[i, 0], on * k[i, 1], on * k[i, 2], on * k[i, 3]
    im = floes.inv_mass[i]
    cx = a * drive.wind_speed * drive.wind_x + b * drive.current_x
    cy = a * drive.wind_speed * drive.wind_y + b * drive.current_y
    mu = complex(1.0 - dt * im * b, -dt * im * g)
    c = complex(dt * im * cx, dt * im * cy)
    return mu, c, 1.0 - dt * floes.inv_inertia[i] * cr


@njit(cache=True, error_model="numpy")
def drift_table(floes, drive, dt):
    """(μ, c, ν, and per floe |μ|, |c|, |μ − 1| in the columns of an (N, 3)
    array) of every floe (:func:`drift_coefficients`), once per run."""
    n = floes.pos.shape[0]
    mu = np.empty(n, dtype=np.complex128)
    c = np.empty(n, dtype=np.complex128)
    nu = np.empty(n)
    size = np.empty((n, 3))
    for i in range(n):
        mu[i], c[i], nu[i] = drift_coefficients(i, floes, drive, dt)
        size[i, 0] = abs(mu[i])
        size[i, 1] = abs(c[i])
        size[i, 2] = abs(mu[i] - 1.0)
    return mu, c, nu, size


@njit(cache=True, inline="always", error_model="numpy")
def first_kick(i, floes, fbuf, tbuf, dt_kick):
    """Floe i's velocity and angular velocity after the first kick of a
    window (with the forces in the buffer), as in
    :func:`~physics.hertz_kernels.kick_drift_floe`."""
    im = floes.inv_mass[i]
    vx = floes.vel[i, 0] + dt_kick * fbuf[i, 0] * im
    vy = floes.vel[i, 1] + dt_kick * fbuf[i, 1] * im
    w = floes.omega[i] + dt_kick * tbuf[i] * floes.inv_inertia[i]
    return vx, vy, w


@njit(cache=True, inline="always", error_model="numpy")
def closest_approach(dx, dy, wx, wy, span):
    """The least distance over 0 ≤ t ≤ ``span`` of (dx, dy) + t (wx, wy)."""
    w2 = wx * wx + wy * wy
    t = 0.0
    if w2 > 0.0:
        t = min(max(-(dx * wx + dy * wy) / w2, 0.0), span)
    ex = dx + t * wx
    ey = dy + t * wy
    return math.sqrt(ex * ex + ey * ey)


@njit(cache=True, error_model="numpy")
def classify(floes, fbuf, tbuf, table, box, verlet, ship, dt, dt_kick, n_window, awake, pairs,
             mark, lines, bounds):
    """The free and engaged floes of a window of ``n_window`` steps that
    begins now (module docstring), written to ``awake`` (flag 1: engaged, 0:
    free; ``order[:count[0]]`` the engaged floes, ``pending[:count[1]]`` the
    free ones) and ``pairs`` (the live pairs: both floes engaged, their lines
    within their two budgets of each other). Sets the
    list's centre to the floes' mean displacement. ``table``: the floes'
    recurrences (:func:`drift_table`).

    Each floe's motion in the window is held to a straight line,
    x_i(t) = x_i(0) + t u_i with u_i its velocity after the window's first
    kick, and a deviation: for a free floe at most ρ_i (its recurrence moves
    u by at most δ_i = |μ − 1| s_i + |c| a step, so ρ_i = Δt δ_i K²/2), for
    an engaged one a budget E_j that each step checks. ``lines`` (N, 6)
    gets per floe (x_i(0), u_i, E_j or ρ_i, the speed bound s_i); ``mark``
    (N,) 1 for a floe near the hull, plus 2 for one with a wide skin.

    Two free floes stay apart when the least distance of their straight
    lines exceeds r_i + r_j + ρ_i + ρ_j; a free and an engaged one when it
    exceeds r_i + r_j + ρ_i + E_j; a free floe stays clear of the hull when
    its gap exceeds s_i W + H, and of a wall when its gap exceeds s_i W. A
    floe that fails one of these is engaged, and its partners are seen
    again with its budget (a depth-first pass).

    Writes to ``bounds`` (H, the largest speed bound of a free floe, D_0
    and S of the bound (D_0 + S t)² on the free floes' term in the list's
    expiry test, the hull's speed bound, the margin of the tests), lengths
    in m and speeds in m/s. With no free floe every pair is live (the
    steps then take no guard)."""
    pos, radius, inv_mass = floes.pos, floes.radius, floes.inv_mass
    n = pos.shape[0]
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    span = n_window * dt
    ref = verlet.ref
    flag = awake.flag
    # the centre, the straight lines and the speed bounds
    sx = 0.0
    sy = 0.0
    for i in range(n):
        sx += min_image_step(pos[i, 0] - ref[i, 0], lx, px)
        sy += min_image_step(pos[i, 1] - ref[i, 1], ly, py)
        abs_mu, abs_c, abs_mu1 = table[3][i, 0], table[3][i, 1], table[3][i, 2]
        vx, vy, _ = first_kick(i, floes, fbuf, tbuf, dt_kick)
        u = math.sqrt(vx * vx + vy * vy)
        lines[i, 0] = pos[i, 0]
        lines[i, 1] = pos[i, 1]
        lines[i, 2] = vx
        lines[i, 3] = vy
        flag[i] = 0
        mark[i] = 0
        if abs_mu > 1.0:
            lines[i, 5] = math.inf          # no bound: the floe is engaged
            lines[i, 4] = 0.0
            flag[i] = 1
        else:
            s_i = u + (n_window - 1) * abs_c
            lines[i, 5] = s_i
            lines[i, 4] = 0.5 * dt * (abs_mu1 * s_i + abs_c) * n_window * n_window
    cx = sx / n if n > 0 else 0.0
    cy = sy / n if n > 0 else 0.0
    verlet.centre[0] = cx
    verlet.centre[1] = cy
    hull_speed = 0.0
    if ship.active:
        s = ship.state
        hull_speed = hull_point_speed(ship)
    big_h = (SPEED_MARGIN * hull_speed + SPEED_FLOOR) * span
    margin = 1e-9 + 1e-12 * (lx + ly) + path_slack(lx, ly) * n_window
    # the walls and the hull
    for i in range(n):
        if flag[i]:
            continue
        reach_i = lines[i, 5] * span + margin
        if 2.0 * lines[i, 5] * dt >= verlet.skin:
            flag[i] = 1
            continue
        for side in range(4):
            if (side < 2 and px) or (side >= 2 and py) or inv_mass[i] == 0.0:
                continue
            if -wall_overlap(side, pos[i, 0], pos[i, 1], radius[i], lx, ly)[0] <= reach_i:
                flag[i] = 1
    if ship.active:
        set_world_hull(ship)
        s = ship.state
        for i in range(n):
            reach_i = lines[i, 5] * span + margin + big_h
            if not math.isfinite(reach_i):
                continue
            dx = minimum_image(pos[i, 0] - s[S_X], lx, px)
            dy = minimum_image(pos[i, 1] - s[S_Y], ly, py)
            far = ship.reach + radius[i] + reach_i
            if dx * dx + dy * dy >= far * far:
                continue
            if -disc_hull_contact(dx, dy, radius[i], ship.world_x, ship.world_y)[0] <= reach_i:
                flag[i] = 1
                mark[i] = 1
    # the listed pairs: the least distance of their straight lines, and two
    # free floes that could meet
    start, nbr, gap = verlet.start, verlet.nbr, pairs.gap
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            dx = minimum_image(pos[j, 0] - pos[i, 0], lx, px)
            dy = minimum_image(pos[j, 1] - pos[i, 1], ly, py)
            g = closest_approach(dx, dy, lines[j, 2] - lines[i, 2], lines[j, 3] - lines[i, 3],
                                 span) - radius[i] - radius[j]
            gap[p] = g
            if g <= lines[i, 4] + lines[j, 4] + margin:
                flag[i] = 1
                flag[j] = 1
    # each engaged floe's budget, and the free floes it could reach engaged
    # in turn (a stack of the floes whose partners are still to be seen)
    stack = pairs.stack
    top = 0
    for i in range(n):
        if flag[i]:
            stack[top] = i
            top += 1
    while top > 0:
        top -= 1
        j = stack[top]
        u_j = math.sqrt(lines[j, 2] ** 2 + lines[j, 3] ** 2)
        e_j = (DEVIATION * max(u_j, mark[j] * hull_speed) + SPEED_FLOOR) * span
        lines[j, 4] = e_j
        for p in range(start[j], start[j + 1]):
            i = nbr[p]
            if flag[i] == 0 and gap[p] <= lines[i, 4] + e_j + margin:
                flag[i] = 1
                stack[top] = i
                top += 1
        for k in range(pairs.partner_start[j], pairs.partner_start[j + 1]):
            p = pairs.as_partner[k]
            i = pairs.owner[p]
            if flag[i] == 0 and gap[p] <= lines[i, 4] + e_j + margin:
                flag[i] = 1
                stack[top] = i
                top += 1
    # the lists, and the bound on the free floes' term of the expiry test:
    # (D_0 + S t)², from their distances from the centre and their speeds,
    # each weighted (s/s_i)² for a floe with a wide skin (measured from its
    # own reference, wide_floes_pass)
    wide = verlet.wide
    for k in range(wide.shape[0]):
        mark[wide[k]] += 2
    n_eng = 0
    n_free = 0
    s_free = 0.0
    s_test = 0.0
    d0 = 0.0
    n_wide = 0
    for k in range(wide.shape[0]):
        i = wide[k]
        if flag[i]:
            n_wide += 1
            pairs.wide[n_wide] = k
        else:
            root = math.sqrt(verlet.wide_weight[k])
            ex = min_image_step(pos[i, 0] - verlet.wide_ref[k, 0], lx, px) - cx
            ey = min_image_step(pos[i, 1] - verlet.wide_ref[k, 1], ly, py) - cy
            d0 = max(d0, root * math.sqrt(ex * ex + ey * ey))
            s_test = max(s_test, root * lines[i, 5])
    for i in range(n):
        if flag[i]:
            awake.order[n_eng] = i
            n_eng += 1
        else:
            awake.pending[n_free] = i
            n_free += 1
            s_free = max(s_free, lines[i, 5])
            if mark[i] < 2:
                ex = min_image_step(pos[i, 0] - ref[i, 0], lx, px) - cx
                ey = min_image_step(pos[i, 1] - ref[i, 1], ly, py) - cy
                d0 = max(d0, math.sqrt(ex * ex + ey * ey))
                s_test = max(s_test, lines[i, 5])
    pairs.wide[0] = n_wide
    awake.count[0] = n_eng
    awake.count[1] = n_free
    # the live pairs: two engaged floes whose lines come within their budgets
    # (farther apart, they cannot touch while both keep to them)
    bounds[0] = big_h
    bounds[1] = s_free
    bounds[2] = d0
    bounds[3] = s_test
    bounds[4] = hull_speed
    bounds[5] = margin
    if n_free == 0:
        all_pairs_live(verlet, awake, pairs)
        return
    n_live = 0
    for i in range(n):
        if not flag[i]:
            continue
        for p in range(start[i], start[i + 1]):
            j = nbr[p]
            if flag[j] and gap[p] <= lines[i, 4] + lines[j, 4] + margin:
                pairs.live[n_live] = p
                n_live += 1
    awake.count[2] = n_live


@njit(cache=True, error_model="numpy")
def all_pairs_live(verlet, awake, pairs):
    """Every listed pair live (the last step of a window)."""
    m = verlet.nbr.shape[0]
    for p in range(m):
        pairs.live[p] = p
    awake.count[2] = m


@njit(cache=True, error_model="numpy", _nrt=False)
def sync_free(floes, fbuf, tbuf, drive, table, box, awake, lines, path, dt, dt_kick, n_done,
              iterate, ref):
    """The free floes (``awake.pending[:count[1]]`` less those engaged since
    the window began, which are up to date) brought up to date:
    ``n_done`` steps of their recurrence in closed form from the state they
    had when the window began (still in the arrays; the first kick by
    ``dt_kick`` with the forces then in the buffers), their drag force
    written to the buffers as the kick–drift pass writes it, and their
    paths grown by s_i Δt per step (s_i in ``lines[:, 5]``, :func:`classify`).

    With ``iterate``, the steps are taken one by one instead, with the
    arithmetic of the full step (:func:`~physics.hertz_kernels.kick_drift_floe`
    and its path): no faster than the full step, but its result bit for bit,
    so that a test can tell the windows' logic from the closed form's
    rounding. Returns False when a new state is not finite."""
    ok = sync_floes(floes, fbuf, tbuf, drive, table, box, awake.pending, 0, awake.count[1],
                    awake.flag, lines, path, dt, dt_kick, n_done, iterate, ref)
    awake.count[1] = 0
    return ok


@njit(cache=True, error_model="numpy", _nrt=False)
def sync_floes(floes, fbuf, tbuf, drive, table, box, which, first, stop, flag, lines, path, dt,
               dt_kick, n_done, iterate, ref):
    """:func:`sync_free` of the floes ``which[first:stop]`` with ``flag``
    0 (the others are passed over)."""
    if iterate:
        return iterate_floes(floes, fbuf, tbuf, drive, box, which, first, stop, flag, path, dt,
                             dt_kick, n_done, ref)
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    step_length, slack = rigid_drift_bound(dt, lx, ly)
    pos, vel, omega = floes.pos, floes.vel, floes.omega
    on = 1.0 if drive.active else 0.0
    k = drive.coefficients
    ok = True
    # floes of one thickness share μ and ν: their sums are taken once
    last_mu = complex(math.nan, 0.0)
    last_nu = math.nan
    pw = t = qs = 0.0j
    nu_k = 0.0
    for q in range(first, stop):
        i = which[q]
        if floes.inv_mass[i] == 0.0 or flag[i]:
            continue                        # frozen, or engaged in the window and up to date
        mu, c, nu = table[0][i], table[1][i], table[2][i]
        if (vel[i, 0] == 0.0 and vel[i, 1] == 0.0 and omega[i] == 0.0 and fbuf[i, 0] == 0.0
                and fbuf[i, 1] == 0.0 and tbuf[i] == 0.0 and c == 0.0):
            path[i] += n_done * slack       # at rest, and nothing moves it: it stays
            continue
        vx1, vy1, w1 = first_kick(i, floes, fbuf, tbuf, dt_kick)
        u1 = complex(vx1, vy1)
        if mu != last_mu:
            pw, t, qs = drift_sums(mu, n_done - 1)
            last_mu = mu
        if nu != last_nu:
            nu_k = nu ** (n_done - 1)
            last_nu = nu
        u = pw * u1 + c * t
        shift = dt * u1 + dt * (u1 * mu * t + c * qs)
        x = pos[i, 0] + shift.real
        y = pos[i, 1] + shift.imag
        if px:
            x -= lx * math.floor(x / lx)
        if py:
            y -= ly * math.floor(y / ly)
        w = w1 * nu_k
        pos[i, 0] = x
        pos[i, 1] = y
        vel[i, 0] = u.real
        vel[i, 1] = u.imag
        omega[i] = w
        fx, fy, tq = floe_drag(u.real, u.imag, w, on * k[i, 0], on * k[i, 1], on * k[i, 2],
                               on * k[i, 3], drive.wind_x, drive.wind_y, drive.current_x,
                               drive.current_y, drive.wind_speed)
        fbuf[i, 0] = fx
        fbuf[i, 1] = fy
        tbuf[i] = tq
        path[i] += n_done * (lines[i, 5] * step_length + slack)
        ok = ok and math.isfinite(x + y + u.real + u.imag + w)
    return ok


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy", _nrt=False)
def iterate_floes(floes, fbuf, tbuf, drive, box, which, first, stop, flag, path, dt, dt_kick,
                  n_done, ref):
    """:func:`sync_floes` step by step (its ``iterate``), compiled with the
    kick–drift pass's flags, as the engaged floes' pass is."""
    lx, ly = box.lengths[0], box.lengths[1]
    first_kick_ = Kick(dt_kick, dt, lx, ly, box.periodic_x, box.periodic_y, 1.0, 1.0, 0.0, 0.0)
    later = Kick(dt, dt, lx, ly, box.periodic_x, box.periodic_y, 1.0, 1.0, 0.0, 0.0)
    p = floes.pos.reshape(-1)
    v = floes.vel.reshape(-1)
    f = fbuf.reshape(-1)
    r = ref.reshape(-1)
    kc = drive.coefficients.reshape(-1)
    step_length, slack = drift_bound(later)
    ok = True
    for q in range(first, stop):
        i = which[q]
        if flag[i]:
            continue
        for m in range(n_done):
            v2, _, _, _ = kick_drift_floe(i, p, v, f, floes.omega, tbuf, floes.inv_mass,
                                          floes.inv_inertia, r, kc, drive,
                                          first_kick_ if m == 0 else later)
            path[i] += math.sqrt(v2) * step_length + slack
        ok = ok and math.isfinite(p[2 * i] + p[2 * i + 1] + v[2 * i] + v[2 * i + 1])
    return ok


@njit(cache=True, fastmath=KICK_FASTMATH, error_model="numpy", _nrt=False)
def engaged_pass(floes, ref, drive, kick, awake, path, lines, elapsed, broken):
    """The kick–drift of the engaged floes
    (:func:`~physics.hertz_kernels.kick_drift_pass`, the same arithmetic),
    as :func:`physics.hertz_resting.first_half_awake` does it. The engaged
    floes that left their straight lines (``lines`` of :func:`classify`, at
    time ``elapsed`` into the window) by more than their budgets are written
    to ``broken``; returns (worst, Σ dx, Σ dy, largest squared speed, their
    number)."""
    return kick_drift_pass(floes, ref, drive, kick, path, awake.order, awake.count[0], lines,
                           elapsed, broken)


@njit(cache=True, error_model="numpy", _nrt=False)
def engaged_wide_pass(pos, verlet, lx, ly, px, py, cx, cy, worst, live_wide):
    """:func:`~physics.hertz_kernels.wide_floes_pass` over the engaged
    floes with a wide skin (``live_wide`` of :class:`WindowPairs`; the
    centre held through the window; the free ones are in the
    classification's bound)."""
    for q in range(1, live_wide[0] + 1):
        worst = max_keep_nan(worst, wide_floe_test(live_wide[q], pos, verlet, lx, ly, px, py,
                                                   cx, cy, cx, cy))
    return worst


@njit(cache=True, error_model="numpy", _nrt=False)
def make_live(p, pairs, awake):
    """Pair p made live, if it is not already: inserted into
    ``pairs.live[:count[2]]``, which stays in increasing order (the order of
    the full pair loop)."""
    live = pairs.live
    n_live = awake.count[2]
    lo = 0
    hi = n_live
    while lo < hi:
        mid = (lo + hi) // 2
        if live[mid] < p:
            lo = mid + 1
        else:
            hi = mid
    if lo < n_live and live[lo] == p:
        return
    for q in range(n_live, lo, -1):
        live[q] = live[q - 1]
    live[lo] = p
    awake.count[2] = n_live + 1


@njit(cache=True, error_model="numpy", _nrt=False)
def engage(i, floes, fbuf, tbuf, drive, table, box, verlet, awake, pairs, lines, mark, path,
           dt, dt_kick0, n_done, iterate):
    """Free floe i engaged in the middle of a window: brought up to date
    (:func:`sync_floes`), flagged,
    added to the engaged floes (and to those with a wide skin that the
    steps test, ``pairs.wide``). Returns False when its state is not
    finite."""
    slot = awake.count[0]
    awake.order[slot] = i
    ok = sync_floes(floes, fbuf, tbuf, drive, table, box, awake.order, slot, slot + 1,
                    awake.flag, lines, path, dt, dt_kick0, n_done, iterate, verlet.ref)
    awake.flag[i] = 1
    awake.count[0] = slot + 1
    if mark[i] & 2:
        wide = verlet.wide
        for k in range(wide.shape[0]):
            if wide[k] == i:
                pairs.wide[0] += 1
                pairs.wide[pairs.wide[0]] = k
                break
    return ok


@njit(cache=True, error_model="numpy", _nrt=False)
def repair(n_broken, floes, fbuf, tbuf, drive, table, box, verlet, awake, pairs, lines, mark,
           path, dt, dt_kick0, n_done, span, hull_speed, margin, iterate):
    """The window carried on past its guard (module docstring): each engaged
    floe in ``pairs.stack[:n_broken]``, which has left its straight line by
    more than its budget, gets a new line from where it is now (n_done
    steps into the window, all floes but the free ones up to date) and a
    new budget; each of its listed partners is tested against it over the
    rest of the window, as :func:`classify` tests them. A free partner that
    could come within its deviation ρ plus the new budget is engaged
    (:func:`engage`) and its own partners are tested in turn; an engaged
    partner whose line comes within the two budgets makes the pair live.

    Returns (whether every state is finite, floes engaged, lines renewed,
    the largest distance a newly engaged floe drifted in the window unseen
    by a hull list: its speed bound times the time into the window)."""
    pos, vel, radius = floes.pos, floes.vel, floes.radius
    lx, ly = box.lengths[0], box.lengths[1]
    px, py = box.periodic_x, box.periodic_y
    flag, stack = awake.flag, pairs.stack
    start, nbr, owner = verlet.start, verlet.nbr, pairs.owner
    elapsed = n_done * dt
    left = max(span - elapsed, 0.0)
    top = n_broken
    n_new = 0
    n_lines = 0
    unseen = 0.0
    ok = True
    while top > 0:
        top -= 1
        j = stack[top]
        # the new line: x_j(t) = x_j(now) + (t − now) u_j, kept as its value at t = 0
        ux = vel[j, 0]
        uy = vel[j, 1]
        lines[j, 0] = pos[j, 0] - elapsed * ux
        lines[j, 1] = pos[j, 1] - elapsed * uy
        lines[j, 2] = ux
        lines[j, 3] = uy
        near = hull_speed if mark[j] & 1 else 0.0
        e_j = (DEVIATION * max(math.sqrt(ux * ux + uy * uy), near) + SPEED_FLOOR) * span
        lines[j, 4] = e_j
        n_lines += 1
        # its pairs as the owner, then as the partner
        for side in range(2):
            lo = start[j] if side == 0 else pairs.partner_start[j]
            hi = start[j + 1] if side == 0 else pairs.partner_start[j + 1]
            for q in range(lo, hi):
                p = q if side == 0 else pairs.as_partner[q]
                i = nbr[p] if side == 0 else owner[p]
                dx = minimum_image(lines[i, 0] + elapsed * lines[i, 2] - pos[j, 0], lx, px)
                dy = minimum_image(lines[i, 1] + elapsed * lines[i, 3] - pos[j, 1], ly, py)
                g = closest_approach(dx, dy, lines[i, 2] - ux, lines[i, 3] - uy, left) \
                    - radius[i] - radius[j]
                if g > lines[i, 4] + e_j + margin:
                    continue
                if flag[i]:
                    make_live(p, pairs, awake)
                    continue
                unseen = max(unseen, lines[i, 5] * elapsed)
                ok = engage(i, floes, fbuf, tbuf, drive, table, box, verlet, awake, pairs,
                            lines, mark, path, dt, dt_kick0, n_done, iterate) and ok
                n_new += 1
                make_live(p, pairs, awake)
                stack[top] = i
                top += 1
    return ok, n_new, n_lines, unseen


@njit(cache=True, error_model="numpy")
def new_pairs(verlet):
    """The :class:`WindowPairs` of the list ``verlet``."""
    n = verlet.start.shape[0] - 1
    m = verlet.nbr.shape[0]
    owner, partner_start, as_partner = pair_index(verlet)
    return WindowPairs(owner, partner_start, as_partner, np.empty(m, dtype=np.int64),
                       np.full(m, -np.inf), np.empty(m), np.empty(n, dtype=np.int64),
                       np.zeros(n + 1, dtype=np.int64))


@njit(cache=True, error_model="numpy")
def awake_all(awake, n):
    """Every floe engaged (the step that ends with a list rebuild)."""
    for i in range(n):
        awake.flag[i] = 1
        awake.order[i] = i
    awake.count[0] = n
    awake.count[1] = 0
