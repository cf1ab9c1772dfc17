"""Ice thickness distribution: Smoluchowski coagulation, the generalised
Thorndike model and pure fragmentation (Godlovitch et al., after Thorndike
2000; :ref:`physics-itd`).

Coagulation (ridging and rafting as "stacking")
    :func:`solve_smoluchowski` integrates the discrete coagulation equation
    du_k/dt = ½ Σ_{j<k} K(k−j, j) u_j u_{k−j} − u_k Σ_j K(k, j) u_j for masses
    1 … n with an adaptive high-order integrator.

Kernels
    :func:`constant_kernel`, :func:`exponential_kernel`,
    :func:`multiplicative_kernel`, :func:`additive_kernel` (Table 1 of the
    paper), :func:`rafting_kernel` (eq 18) and :func:`kernel_from_function`
    for any callable K(x, y); each returns the symmetric n × n matrix
    K(x_a, x_b) on the class values x_a (masses 1 … n, or thicknesses
    Δh … nΔh).

Generalised Thorndike model
    :class:`ThorndikeModel` steps the area fractions g_0 (open water) and
    g_1 … g_n (ice of thickness kΔh, 200 classes of 0.1 m by default):

        dg_k/dt = ½ Σ_{j+l=k} K_jl g_j g_l − g_k Σ_j K_kj g_j − [upwind thermodynamics]_k
        dg_0/dt = C(K, t) − [freezing of open water]
        C(K, t) = ½ Σ_j Σ_l K_jl g_j g_l   (one open-water cell per stacking event)

    with forward Euler (as the paper) over time steps in days, subdivided so
    that no class loses more than it holds. Choices, documented here:

    * **Open water** is class 0 (thickness 0). Stacking with open water would
      be a null event (ice of h plus water is ice of h), so only ice classes
      stack; every stacking event of two ice cells frees one cell, hence the
      ½ in C, which keeps Σ g = 1 (the paper's printed C lacks it).
    * **Truncation**: stacking that would exceed the top class (20 m) puts
      the ice in the top class, so no area is lost.
    * **Seasons**: t in days, a 360-day year starting in mid-winter. The
      growth rate of class k is G_k = S(t) W1(kΔh) − (1 − S(t)) W2(kΔh)
      [m/day]: W1 is winter growth (thin ice grows fast, ice above
      ln(10)/1.7 = 1.35 m thins slightly), W2 summer melt, S = 1 at t = 0
      (winter) falling to 0 at day 180 (summer) and back. A fraction
      |G_k| Δt/Δh of class k moves up (G > 0) or down (G < 0) one class;
      open water freezes into class 1 in winter, and melting class 1 opens
      water in summer; nothing grows out of the top class.
    * **Strength**: the kernel matrix is multiplied by ``kernel_scale``
      (settable between steps, e.g. by an environment); for the constant
      kernel K = 1/R_T this sets Godlovitch's relative strength R_T.
      :meth:`ThorndikeModel.set_rafting` changes the rafting factor and
      cut-off between steps, for any kernel.

Fragmentation
    :func:`solve_fragmentation` — Lensu's pure-fragmentation model: every
    floe breaks at rate a (1/time) into two pieces, the fraction of the
    first uniform in (0, 1); the number of floes grows as e^{at} and the
    distribution of ln(size) tends to a normal (log-normal sizes).

Example
-------
>>> m = ThorndikeModel(kernel="constant", scale=1.0)
>>> m.run(2000)                      # days, daily steps
>>> m.g, m.open_water, m.mean_thickness, m.tail_efolding()
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from collections.abc import Callable

import numpy as np
from numba import njit

from .input_checks import check_range
from .params import GODLOVITCH

__all__ = ["constant_kernel", "exponential_kernel", "multiplicative_kernel", "additive_kernel",
           "rafting_kernel", "kernel_from_function", "make_kernel", "check_kernel",
           "solve_smoluchowski", "smoluchowski_rhs", "ThorndikeModel", "growth_rates",
           "season", "tail_fit", "TailFit", "solve_fragmentation", "YEAR_DAYS"]

#: length of the model year [days] (:data:`physics.params.GODLOVITCH`)
YEAR_DAYS = GODLOVITCH.year_days


# -- kernels ---------------------------------------------------------------------

def _class_values(n, dx):
    if isinstance(n, bool) or int(n) != n or n < 2:
        raise ValueError(f"the number of classes n must be an integer >= 2, got {n!r}")
    check_range("class width dx", dx, 0.0, None, low_open=True)
    return float(dx) * np.arange(1, int(n) + 1)


def _check_rate(name, value) -> float:
    """A rate or factor: finite and >= 0, as a float."""
    check_range(name, value, 0.0, None)
    return float(value)


def _check_times(t_eval) -> np.ndarray:
    t = np.asarray(t_eval, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or t[0] < 0 \
            or np.any(np.diff(t) < 0):
        raise ValueError("t_eval must be a non-empty, non-decreasing array of finite times >= 0")
    return t


def check_kernel(K, n: int | None = None) -> np.ndarray:
    """A kernel matrix as a float array: square, finite, non-negative and
    symmetric (to 1e-12 relative); ``ValueError`` otherwise."""
    k = np.asarray(K, dtype=float)
    if k.ndim != 2 or k.shape[0] != k.shape[1]:
        raise ValueError(f"a kernel must be a square matrix, got shape {k.shape}")
    if n is not None and k.shape[0] != n:
        raise ValueError(f"the kernel has {k.shape[0]} classes, expected {n}")
    if k.shape[0] < 2:
        raise ValueError(f"a kernel needs at least 2 classes, got {k.shape[0]}")
    if not np.all(np.isfinite(k)):
        raise ValueError("the kernel contains NaN or infinite values")
    if np.any(k < 0):
        raise ValueError(f"kernel values must be >= 0 (a rate), the smallest is {k.min():g}")
    if not np.allclose(k, k.T, rtol=1e-12, atol=0.0):
        raise ValueError("the kernel must be symmetric, K(x, y) = K(y, x)")
    return np.ascontiguousarray(k)


def constant_kernel(n: int, r: float = 1.0) -> np.ndarray:
    """K(x, y) = r (Table 1, run 1; Thorndike's model)."""
    _class_values(n, 1.0)
    return np.full((int(n), int(n)), _check_rate("r", r))


def exponential_kernel(n: int, r: float = 1.0, beta: float = 1.0, dx: float = 1.0) -> np.ndarray:
    """K(x, y) = r exp(−β (x + y)) on x = dx, 2dx, … (Table 1, run 2)."""
    x = _class_values(n, dx)
    return _check_rate("r", r) * np.exp(-_check_rate("beta", beta) * (x[:, None] + x[None, :]))


def multiplicative_kernel(n: int, r: float = 1.0, dx: float = 1.0) -> np.ndarray:
    """K(x, y) = r x y (Table 1, run 3)."""
    x = _class_values(n, dx)
    return _check_rate("r", r) * x[:, None] * x[None, :]


def additive_kernel(n: int, r: float = 1.0, dx: float = 1.0) -> np.ndarray:
    """K(x, y) = r (x + y) (Table 1, run 4)."""
    x = _class_values(n, dx)
    return _check_rate("r", r) * (x[:, None] + x[None, :])


def rafting_kernel(n: int, r: float = 1.0, h_raft: float = 0.5, dx: float = 1.0,
                   factor: float = 2.0) -> np.ndarray:
    """Constant kernel with rafting (eq 18): K = factor · r when both floes
    are thinner than ``h_raft`` (thin ice over-rides thin ice), r otherwise.
    The paper's eq 18 has factor 2; its Fig. 5 uses K = 4 against 1."""
    x = _class_values(n, dx)
    thin = x < float(h_raft)
    k = np.full((x.size, x.size), _check_rate("r", r))
    k[np.ix_(thin, thin)] *= _check_rate("factor", factor)
    return k


def kernel_from_function(fn: Callable, n: int, dx: float = 1.0) -> np.ndarray:
    """K(x_a, x_b) for any callable ``fn(x, y)`` (broadcast over arrays, or
    called pairwise if it does not broadcast), checked by :func:`check_kernel`."""
    x = _class_values(n, dx)
    try:
        k = np.asarray(fn(x[:, None], x[None, :]), dtype=float)
        if k.shape != (x.size, x.size):
            k = np.broadcast_to(k, (x.size, x.size)).copy()
    except (TypeError, ValueError):
        k = np.array([[float(fn(a, b)) for b in x] for a in x])
    return check_kernel(k)


def make_kernel(kind, n: int, dx: float = 1.0, **params) -> np.ndarray:
    """A kernel by name ("constant", "exponential", "multiplicative",
    "additive", "rafting"), a callable K(x, y), or a matrix."""
    if callable(kind):
        return kernel_from_function(kind, n, dx)
    if not isinstance(kind, str):
        return check_kernel(kind, n)
    makers = {"constant": lambda: constant_kernel(n, **params),
              "exponential": lambda: exponential_kernel(n, dx=dx, **params),
              "multiplicative": lambda: multiplicative_kernel(n, dx=dx, **params),
              "additive": lambda: additive_kernel(n, dx=dx, **params),
              "rafting": lambda: rafting_kernel(n, dx=dx, **params)}
    if kind not in makers:
        raise ValueError(f"unknown kernel {kind!r}; choose one of {sorted(makers)} or pass a "
                         f"callable K(x, y) or a matrix")
    return check_kernel(makers[kind]())


# -- Smoluchowski coagulation ---------------------------------------------------------

def _check_numbers(u0) -> np.ndarray:
    u0 = np.asarray(u0, dtype=float)
    if u0.ndim != 1 or u0.size < 2:
        raise ValueError(f"u0 must be 1-D with n >= 2 classes, got shape {u0.shape}")
    if not np.all(np.isfinite(u0)) or np.any(u0 < 0):
        raise ValueError("u0 must be finite and >= 0")
    return u0


@njit(cache=True, error_model="numpy")
def smoluchowski_rhs(u, K, out):
    """du/dt of the discrete coagulation equation for masses 1 … n (index
    a holds mass a + 1): gain ½ Σ_{a+b=k−2} K_ab u_a u_b, loss u_k Σ_b K_kb u_b.
    Particles heavier than n leave the system."""
    n = u.shape[0]
    for k in range(n):
        gain = 0.0
        # masses (a+1) + (b+1) = k+1  ->  a + b = k - 1
        for a in range(k):
            gain += K[a, k - 1 - a] * u[a] * u[k - 1 - a]
        loss = 0.0
        for b in range(n):
            loss += K[k, b] * u[b]
        out[k] = 0.5 * gain - u[k] * loss
    return out


@njit(cache=True, error_model="numpy")
def _smoluchowski_jac(u, K):
    n = u.shape[0]
    jac = np.zeros((n, n))
    for k in range(n):
        loss = 0.0
        for b in range(n):
            loss += K[k, b] * u[b]
            jac[k, b] -= u[k] * K[k, b]
        jac[k, k] -= loss
        for a in range(k):
            jac[k, a] += K[a, k - 1 - a] * u[k - 1 - a]
    return jac


def solve_smoluchowski(K, u0, t_eval, *, method: str = "DOP853", rtol: float = 1e-10,
                       atol: float = 1e-16) -> np.ndarray:
    """Number densities u_k(t) of masses 1 … n at the times ``t_eval``
    (increasing, from 0), for the kernel matrix ``K`` (n × n, symmetric,
    K[a, b] = K(a + 1, b + 1)) and initial numbers ``u0``. Returns an array
    of shape (len(t_eval), n).

    Adaptive explicit integration (DOP853, 8th order) by default; for
    stiff cases (fast-growing kernels with large n) pass ``method="Radau"``
    or ``"BDF"``, which use the analytic Jacobian. Particles that would be
    heavier than n leave the system, so mass is conserved only while the
    largest classes are empty.
    """
    from scipy.integrate import solve_ivp

    u0 = _check_numbers(u0)
    k = check_kernel(K, u0.size)
    t = _check_times(t_eval)
    out = np.empty_like(u0)
    if t[-1] == 0:
        return np.repeat(u0[None, :], t.size, axis=0)
    options = {}
    if method in ("Radau", "BDF", "LSODA"):
        options["jac"] = lambda _t, u: _smoluchowski_jac(u, k)
    sol = solve_ivp(lambda _t, u: smoluchowski_rhs(u, k, out).copy(), (0.0, t[-1]), u0,
                    method=method, t_eval=t, rtol=rtol, atol=atol, **options)
    if not sol.success:
        raise RuntimeError(f"the coagulation integration failed: {sol.message}")
    return sol.y.T.copy()


# -- generalised Thorndike model -----------------------------------------------------

def season(t_days) -> np.ndarray:
    """S(t): 1 at mid-winter (t = 0), falling linearly to 0 at day 180
    (mid-summer) and back to 1 at day 360; t in days, period 360."""
    t = np.mod(np.asarray(t_days, dtype=float), YEAR_DAYS)
    return np.where(t < 180.0, 1.0 - t / 180.0, t / 180.0 - 1.0)


def growth_rates(h, t_days) -> np.ndarray:
    """Thermodynamic growth rate G(h, t) = S W1(h) − (1 − S) W2(h) [m/day]:
    W1 = 0.1 exp(−1.7 h) − 0.01 (winter growth), W2 = 0.01 exp(−0.01 h)
    (summer melt), h in m."""
    s = season(t_days)
    h = np.asarray(h, dtype=float)
    w1 = 0.1 * np.exp(-1.7 * h) - 0.01
    w2 = 0.01 * np.exp(-0.01 * h)
    return s * w1 - (1.0 - s) * w2


@njit(cache=True, error_model="numpy")
def _thorndike_step(g, K, scale, speed, dt, work):
    """One forward-Euler step of the generalised Thorndike model. g[0] is
    open water, g[1:] ice classes; K is the kernel on the ice classes;
    speed[k] = G_k / Δh (1/day) for classes 0 … n. Products beyond the top
    class go to the top class; open water takes the balance so Σ g is
    conserved to rounding."""
    n = g.shape[0] - 1
    for k in range(n + 1):
        work[k] = 0.0
    events = 0.0
    for a in range(n):                      # ice class a+1
        ga = g[a + 1]
        if ga == 0.0:
            continue
        loss = 0.0
        for b in range(n):
            gb = g[b + 1]
            if gb == 0.0:
                continue
            rate = scale * K[a, b] * ga * gb
            loss += rate
            if b >= a:
                pair = rate if b > a else 0.5 * rate
                events += pair
                top = a + b + 2                  # thickness class of the product
                if top > n:
                    top = n
                work[top] += pair
        work[a + 1] -= loss
    work[0] += events
    # upwind thermodynamics: class k moves |G_k| dt/Δh of itself one class
    for k in range(n + 1):
        v = speed[k]
        if v > 0.0 and k < n:
            f = v * g[k]
            work[k] -= f
            work[k + 1] += f
        elif v < 0.0 and k > 0:
            f = -v * g[k]
            work[k] -= f
            work[k - 1] += f
    total = 0.0
    for k in range(1, n + 1):
        g[k] = g[k] + dt * work[k]
        if g[k] < 0.0:
            g[k] = 0.0                           # rounding only: steps are limited
        total += g[k]
    g[0] = max(1.0 - total, 0.0)                 # Σ g = 1 to rounding


@njit(cache=True, error_model="numpy")
def _max_outflow(g, K, scale, speed):
    """Largest fractional loss rate of any class (1/day)."""
    n = g.shape[0] - 1
    worst = 0.0
    for k in range(n + 1):
        out = abs(speed[k])
        if k > 0:
            s = 0.0
            for b in range(n):
                s += K[k - 1, b] * g[b + 1]
            out += scale * s
        if out > worst:
            worst = out
    return worst


@dataclass
class TailFit:
    """Log-linear fit ln g = a − h/λ of the thickness distribution above
    ``h_min``: e-folding thickness λ [m], slope −1/λ [1/m], R² of the fit."""
    efolding: float
    slope: float
    r2: float
    n_points: int


def tail_fit(h, g, h_min: float = 2.0, floor: float = 1e-12) -> TailFit:
    """Fit ln g against h for h > ``h_min`` where g > ``floor``."""
    h = np.asarray(h, dtype=float)
    g = np.asarray(g, dtype=float)
    use = (h > h_min) & (g > floor)
    if use.sum() < 3:
        return TailFit(math.nan, math.nan, math.nan, int(use.sum()))
    x, y = h[use], np.log(g[use])
    slope, icpt = np.polyfit(x, y, 1)
    resid = y - (slope * x + icpt)
    ss = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(resid ** 2)) / ss if ss > 0 else math.nan
    return TailFit(-1.0 / slope if slope < 0 else math.inf, float(slope), r2, int(use.sum()))


class ThorndikeModel:
    """The generalised Thorndike model (Godlovitch et al., eqs 13–17), to be
    stepped in days.

    Parameters
    ----------
    kernel : str, callable or (n, n) matrix — "constant", "exponential",
        "multiplicative", "additive", "rafting", a callable K(x, y) of the
        thicknesses [m], or a matrix on the ice classes
    n_classes : int — ice classes (default ``GODLOVITCH.n_classes``, 200)
    dh : float — class width [m] (default ``GODLOVITCH.class_width``, 0.1)
    g0 : (n_classes + 1,) array, optional — initial fractions (open water
        first); default all open water
    thermodynamics : bool — the seasonal growth and melt (default on)
    thermo_strength : float — multiplies G(h, t) (default 1)
    scale : float — kernel scale, settable between steps (``kernel_scale``)
    start_day : float — model time at the start [days]
    **kernel_params — r, beta, h_raft, factor for the named kernels

    Attributes
    ----------
    time : float [days]; g : (n + 1,) fractions; h : (n + 1,) class
    thicknesses [m] (h[0] = 0, open water)
    """

    def __init__(self, kernel="constant", *, n_classes: int = GODLOVITCH.n_classes,
                 dh: float = GODLOVITCH.class_width,
                 g0=None, thermodynamics: bool = True, thermo_strength: float = 1.0,
                 scale: float = 1.0, start_day: float = 0.0, **kernel_params):
        self.h = _class_values(n_classes, dh)
        self.n = self.h.size
        self.dh = float(dh)
        self.h = np.concatenate([[0.0], self.h])
        self.rafting_factor, self.h_raft = 1.0, 0.0
        if isinstance(kernel, str) and kernel == "rafting":
            # the stacking and rafting parts kept apart, so that either can change
            self._K_base = make_kernel("constant", self.n, self.dh, r=kernel_params.pop("r", 1.0))
            self.K = self._K_base
            self.set_rafting(kernel_params.pop("factor", 2.0), kernel_params.pop("h_raft", 0.5))
            if kernel_params:
                raise TypeError(f"unexpected rafting kernel parameters {sorted(kernel_params)}")
        else:
            self.K = make_kernel(kernel, self.n, self.dh, **kernel_params)
            self._K_base = self.K
        self.kernel_scale = scale
        self.thermodynamics = bool(thermodynamics)
        self.thermo_strength = _check_rate("thermo_strength", thermo_strength)
        check_range("start_day", start_day)
        self.time = float(start_day)
        if g0 is None:
            g = np.zeros(self.n + 1)
            g[0] = 1.0
        else:
            g = np.array(g0, dtype=float)
            if g.shape != (self.n + 1,):
                raise ValueError(f"g0 must have shape ({self.n + 1},) (open water first), "
                                 f"got {g.shape}")
            if not np.all(np.isfinite(g)) or np.any(g < -1e-12):
                raise ValueError("g0 must be finite and >= 0")
            if abs(g.sum() - 1.0) > 1e-9:
                raise ValueError(f"g0 must sum to 1, got {g.sum():.12g}")
            g = np.maximum(g, 0.0)
            g[0] = max(1.0 - g[1:].sum(), 0.0)
        self.g = g
        self._work = np.zeros(self.n + 1)
        self.substeps = 0

    def set_rafting(self, factor: float, h_raft: float | None = None) -> None:
        """Multiply the kernel by ``factor`` where both floes are thinner than
        ``h_raft`` [m] (eq 18 applied to any kernel), from the next step on;
        factor 1 switches rafting off. ``h_raft`` defaults to the current cut-off."""
        factor = _check_rate("factor", factor)
        h = self.h_raft if h_raft is None else float(h_raft)
        check_range("h_raft", h, 0.0, None)
        thin = self.h[1:] < h
        k = self._K_base.copy()
        k[np.ix_(thin, thin)] *= factor
        self.K = k
        self.rafting_factor, self.h_raft = factor, h

    @property
    def kernel_scale(self) -> float:
        return self._scale

    @kernel_scale.setter
    def kernel_scale(self, value) -> None:
        self._scale = _check_rate("kernel_scale", value)

    def _speed(self, t):
        if not self.thermodynamics or self.thermo_strength == 0.0:
            return np.zeros(self.n + 1)
        return self.thermo_strength * growth_rates(self.h, t) / self.dh

    def step(self, dt: float = GODLOVITCH.time_step) -> None:
        """Advance by ``dt`` days in forward-Euler substeps, each short enough
        that no class loses more than 90 % of itself (the limit is taken
        again before every substep); ``substeps`` counts them."""
        check_range("dt", dt, 0.0, None, low_open=True)
        dt = float(dt)
        end = self.time + dt
        left = dt
        while left > 0.0:
            # the limit is taken again before every substep, from the state
            # it starts from: ice formed in one substep speeds up the next
            speed = self._speed(self.time)
            worst = _max_outflow(self.g, self.K, self._scale, speed)
            m = max(1, int(math.ceil(worst * left / 0.9 - 1e-12)))
            h = left / m
            _thorndike_step(self.g, self.K, self._scale, speed, h, self._work)
            left -= h
            self.time = end - left if left > 0.0 else end
            self.substeps += 1

    def run(self, days: float, dt: float = GODLOVITCH.time_step, *, every: float | None = None,
            progress: bool = False):
        """Step for ``days`` days with steps of ``dt``; with ``every`` (days),
        return (times, g snapshots) taken every that many days (and at the
        end)."""
        check_range("dt", dt, 0.0, None, low_open=True)
        if every is not None:
            check_range("every", every, 0.0, None, low_open=True)
        dt = float(dt)
        steps = int(round(float(days) / dt))
        if steps < 0 or not math.isclose(steps * dt, days, rel_tol=1e-9, abs_tol=1e-12):
            raise ValueError(f"days ({days!r}) must be a non-negative multiple of dt ({dt!r})")
        per = None if every is None else max(1, int(round(float(every) / float(dt))))
        times, snaps = [self.time], [self.g.copy()]
        bar = None
        if progress:
            from tqdm.auto import tqdm
            bar = tqdm(total=steps, unit="step", desc="ITD", dynamic_ncols=True)
        for s in range(1, steps + 1):
            self.step(dt)
            if per is not None and (s % per == 0 or s == steps):
                times.append(self.time)
                snaps.append(self.g.copy())
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        if per is not None:
            return np.array(times), np.array(snaps)
        return None

    # -- read-outs for environments and scripts ---------------------------------------
    @property
    def open_water(self) -> float:
        return float(self.g[0])

    @property
    def mean_thickness(self) -> float:
        """Mean ice thickness over the whole area (open water counts as 0) [m]."""
        return float(np.dot(self.g, self.h))

    @property
    def season(self) -> float:
        """S(t): 1 mid-winter, 0 mid-summer."""
        return float(season(self.time))

    def density(self) -> np.ndarray:
        """g as a density per metre of thickness (g_k / Δh) for the ice classes."""
        return self.g[1:] / self.dh

    def tail_fit(self, h_min: float = 2.0) -> TailFit:
        """Log-linear fit of the distribution above ``h_min`` (default 2 m),
        leaving out the top class, where truncated stacking piles up."""
        return tail_fit(self.h[1:-1], self.g[1:-1], h_min)

    def tail_efolding(self, h_min: float = 2.0) -> float:
        """E-folding thickness λ of the tail above ``h_min`` [m]."""
        return self.tail_fit(h_min).efolding

    def __repr__(self):
        return (f"ThorndikeModel(n_classes={self.n}, dh={self.dh:g}, time={self.time:g} d, "
                f"open_water={self.open_water:.4f}, mean_thickness={self.mean_thickness:.3f} m)")


# -- fragmentation (Lensu) -----------------------------------------------------------

def solve_fragmentation(u0, t_eval, rate: float = 1.0) -> np.ndarray:
    """Lensu's pure fragmentation on masses 1 … n: a floe of mass k ≥ 2
    breaks at ``rate`` into masses j and k − j, j uniform on 1 … k − 1 (the
    discrete form of a uniform fragment distribution β = 1),

        du_j/dt = 2 rate Σ_{k>j} u_k / (k − 1) − rate u_j [j ≥ 2].

    Mass Σ k u_k is conserved exactly; the number of floes grows as e^{rate t}
    while the floes are much heavier than 1. Returns (len(t_eval), n).
    The system is linear and solved exactly by its matrix exponential."""
    from scipy.sparse.linalg import expm_multiply

    u0 = _check_numbers(u0)
    a = _check_rate("rate", rate)
    t = _check_times(t_eval)
    n = u0.size
    A = np.zeros((n, n))
    for k in range(2, n + 1):                 # a floe of mass k feeds every j < k
        A[: k - 1, k - 1] = 2.0 * a / (k - 1)
        A[k - 1, k - 1] = -a
    out = np.empty((t.size, n))
    for q, tq in enumerate(t):
        out[q] = expm_multiply(A * tq, u0) if tq > 0 else u0
    return np.maximum(out, 0.0)
