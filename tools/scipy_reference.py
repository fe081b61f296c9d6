#!/usr/bin/env python3
"""The paper's mission in Python and scipy: the yardstick for the speed of `tss-sim`.

The same closed loop as `tss_sim::sim::run` on `scenarios/paper.toml`, ported from the Rust
sources: the plant of Eq. 5 (host-sim/src/plant.rs, src/orbit.rs, src/mass.rs), the reference
schedules with their quintic transitions and the stage-2 slew (src/schedule.rs), the implicit
range-rate law of Eqs. 27 + 29 (src/law.rs `solve`) with the decay blend restarted at stage 2
from the last command, the sequencer (src/controller.rs) and the envelope's rate limit
(src/envelope.rs; in the paper's mission no limit acts). Everything is in f64 and is read from
the scenario file.

Two ways to integrate it:

- `continuous` (default): the law is evaluated inside the right-hand side, so the reel rate is a
  function of the state at every instant, and `scipy.integrate.solve_ivp` integrates each
  stage in one call (adaptive RK45 or DOP853). This is the fast way to write it in scipy.
- `zoh`: as `tss-sim` does it: the command is computed once per 1 s control period and held
  (zero-order hold), one `solve_ivp` call per period (72 000 calls; slow, for reference).

Accuracy is judged where the paper reports numbers, the Table-1 lengths (7-8 h and 14-15 h,
every 180 s): a run's error is the largest difference there from the same formulation
integrated at rtol = 1e-12 (DOP853). By default the script times the loosest tolerance of
a ladder whose Table-1 error is below `--table1-tol` (default 1 mm, the paper's printed
resolution), and also the one that reaches `tss-sim`'s own Table-1 accuracy (RK4 at 1 s
differs from RK4 at 1/32 s by 1e-6 m there). Times are the best of `--repeat` runs of the
integration alone (parsing and set-up excluded).

    pip install scipy numpy          # only for this measurement; not part of CI
    tools/scipy_reference.py [--mode continuous|zoh] [--scenario scenarios/paper.toml]

Compare with `cargo bench -p tss-sim --bench paper_mission` (or `tss-sim run`).
"""
import argparse
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

EARTH_MU_M3PS2 = 3.986_004_418e14  # src/orbit.rs
MIN_DENOMINATOR_FRACTION = 0.01  # src/law.rs
REPO = Path(__file__).resolve().parent.parent


class Scenario:
    """The parameters of a scenario file, as host-sim/src/sim.rs maps them."""

    def __init__(self, path):
        with open(path, "rb") as f:
            s = tomllib.load(f)
        o, m, ini, c = s["orbit"], s["masses"], s["initial"], s["controller"]
        s1, s2, sim, env = s["stage1"], s["stage2"], s["simulation"], s["envelope"]
        self.a, self.e, self.theta0 = o["semi_major_axis_m"], o["eccentricity"], o["initial_true_anomaly_rad"]
        self.m01, self.m2, self.rho = m["main_initial_kg"], m["sub_kg"], s["tether"]["density_kg_per_m"]
        self.l0, self.ld0 = ini["length_m"], ini["length_rate_mps"]
        self.delta0, self.deltad0 = ini["delta_rad"], ini["delta_rate_radps"]
        self.beta0, self.betad0 = ini["beta_rad"], ini["beta_rate_radps"]
        self.period = c["period_s"]
        self.k1, self.k2 = c["k1_per_s"], c["k2_per_s2"]
        # BandSchedule(low_length, low_angle, low_slope, high_length, high_angle, high_slope)
        self.sched1 = (s1["band_start_m"], s1["deploy_angle_rad"], 0.0,
                       s1["keep_length_m"], 0.0, s1["keep_slope_rad_per_m"])
        self.c1 = s1["decay_rate_per_s"]
        self.sched2 = (s2["keep_length_m"], 0.0, s2["keep_slope_rad_per_m"],
                       s2["band_start_m"], s2["retrieve_angle_rad"], 0.0)
        self.c2, self.slew, self.t2 = s2["decay_rate_per_s"], s2["slew_rate_radps"], s2["start_time_s"]
        self.duration = sim["duration_s"]
        self.max_rate = env["max_rate_mps"]
        self.n = math.sqrt(EARTH_MU_M3PS2 / self.a**3)
        one_minus_e2 = 1.0 - self.e**2
        self.ecc_factor = one_minus_e2 * math.sqrt(one_minus_e2)


# --- orbit and masses (src/orbit.rs, src/mass.rs) ------------------------------------------
def theta_rate(sc, th):
    k = 1.0 + sc.e * math.cos(th)
    return sc.n * k * k / sc.ecc_factor


def theta_accel(sc, th):
    rate = theta_rate(sc, th)
    return -2.0 * sc.e * rate * rate * math.sin(th) / (1.0 + sc.e * math.cos(th))


def gravity_gradient(sc, th):
    r = sc.a * (1.0 - sc.e**2) / (1.0 + sc.e * math.cos(th))
    return EARTH_MU_M3PS2 / r**3


def mu3(sc, l):
    mt = sc.rho * l
    m1 = sc.m01 - mt
    total = m1 + sc.m2 + mt
    half = mt / 2.0
    reduced = (m1 + half) * (sc.m2 + half) / total - mt / 6.0
    return 2.0 * (m1 * (sc.m2 + half) / (total * reduced) - 1.0)


# --- reference schedules (src/schedule.rs) --------------------------------------------------
def band(s, l):
    """α_r, ∂α_r/∂l of a BandSchedule (quintic Hermite transition, docs/equations.md §6)."""
    lo, a_lo, k_lo, hi, a_hi, k_hi = s
    if l <= lo:
        return a_lo + k_lo * (l - lo), k_lo
    if l >= hi:
        return a_hi + k_hi * (l - hi), k_hi
    h = hi - lo
    x = (l - lo) / h
    x2, x3, x4 = x * x, x * x * x, x * x * x * x
    x5 = x4 * x
    hv = (1 - 10 * x3 + 15 * x4 - 6 * x5, x - 6 * x3 + 8 * x4 - 3 * x5,
          -4 * x3 + 7 * x4 - 3 * x5, 10 * x3 - 15 * x4 + 6 * x5)
    d1 = (-30 * x2 + 60 * x3 - 30 * x4, 1 - 18 * x2 + 32 * x3 - 15 * x4,
          -12 * x2 + 28 * x3 - 15 * x4, 30 * x2 - 60 * x3 + 30 * x4)
    coef = (a_lo, h * k_lo, h * k_hi, a_hi)
    return (sum(c * w for c, w in zip(coef, hv)), sum(c * w for c, w in zip(coef, d1)) / h)


def reference(sc, stage2, tau, l):
    """(α_r, p = ∂α_r/∂l, r = ∂α_r/∂t) as Controller::reference computes it."""
    if not stage2:
        a, p = band(sc.sched1, l)
        return a, p, 0.0
    a, p = band(sc.sched2, l)
    ramp = sc.slew * tau
    if ramp < a:
        return ramp, 0.0, sc.slew
    return a, p, 0.0


# --- the law (src/law.rs solve) ---------------------------------------------------------------
def law_rate(sc, l, alpha, alpha_rate, n, a_r, p, r, e_blend, ld0):
    """y = l̇_real solving Eqs. 27 + 29 (the physical root), or None at a singular point."""
    l_prime = l / (2.0 + mu3(sc, l))
    delta = alpha - a_r
    gravity = 1.5 * n * n * math.sin(2.0 * alpha)
    w = n + alpha_rate - r
    g0 = sc.k1 * (alpha_rate - r) + sc.k2 * delta - gravity
    b = w + p * (e_blend * ld0 + (1.0 - e_blend) * l_prime * sc.k1)
    c = e_blend * ld0 * w + (1.0 - e_blend) * l_prime * g0
    if b <= MIN_DENOMINATOR_FRACTION * abs(n):
        return None
    disc = b * b - 4.0 * p * c
    if disc < 0.0:
        return None
    return 2.0 * c / (b + math.sqrt(disc))


class Control:
    """The controller's command for a state: stage, blend and envelope (rate limit)."""

    def __init__(self, sc):
        self.sc = sc
        self.stage2_ld0 = None  # the blend's start rate in stage 2 (the last stage-1 command)
        self.last = sc.ld0  # the last command computed
        self.singular = 0  # evaluations at a singular point of the law

    def rate(self, t, x, stage2):
        sc = self.sc
        th, l, alpha, alpha_rate = x[0], x[1], x[2], x[3]
        start = sc.t2 if stage2 else 0.0
        tau = t - start
        a_r, p, r = reference(sc, stage2, tau, l)
        c, ld0 = (sc.c2, self.stage2_ld0) if stage2 else (sc.c1, sc.ld0)
        y = law_rate(sc, l, alpha, alpha_rate, theta_rate(sc, th), a_r, p, r,
                     math.exp(-c * tau), ld0)
        if y is None:
            # A singular point (n + δ̇ → 0, which the paper's run nears in its first minutes:
            # docs/equations.md §5): the controller would coast on its last command. Only the solver's trial
            # stages get here; its error control rejects them.
            self.singular += 1
            return self.last
        self.last = max(-sc.max_rate, min(sc.max_rate, y))
        return self.last


# --- the plant (host-sim/src/plant.rs) ---------------------------------------------------------
def derivative(sc, x, rate):
    th, l, alpha, alpha_rate, beta, beta_rate = x
    th_rate = theta_rate(sc, th)
    th_accel = theta_accel(sc, th)
    gg = gravity_gradient(sc, th)
    spin = th_rate + alpha_rate
    stretch = (2.0 + mu3(sc, l)) * rate / l
    alpha_accel = (-spin * (stretch - 2.0 * beta_rate * math.tan(beta))
                   - 1.5 * gg * math.sin(2.0 * alpha) - th_accel)
    beta_accel = (-stretch * beta_rate - 0.5 * spin * spin * math.sin(2.0 * beta)
                  - 1.5 * gg * math.cos(alpha) ** 2 * math.sin(2.0 * beta))
    return [th_rate, rate, alpha_rate, alpha_accel, beta_rate, beta_accel]


def initial_state(sc):
    a_r, p = band(sc.sched1, sc.l0)
    return [sc.theta0, sc.l0, a_r + sc.delta0, sc.deltad0 + p * sc.ld0, sc.beta0, sc.betad0]


def table1_times():
    """The probe instants of Table 1 (host-sim/src/table1.rs): 7-8 h and 14-15 h every 0.05 h."""
    return [round(3600.0 * (h0 + 0.05 * i)) for h0 in (7.0, 14.0) for i in range(21)]


def tolerances(rtol):
    # atol per state: θ, l, α, α̇, β, β̇ (rad, m, rad/s), scaled to their sizes in the mission.
    return rtol, rtol * np.array([1.0, 1e3, 1.0, 1e-3, 1.0, 1e-3])


def run_continuous(sc, rtol, method):
    """Both stages, one solve_ivp call each; returns (Table-1 lengths, RHS evaluations)."""
    ctl = Control(sc)
    probes = set(table1_times())
    rt, at = tolerances(rtol)
    x0 = initial_state(sc)
    out, nfev = [], 0
    for stage2, (t0, t1) in ((False, (0.0, sc.t2)), (True, (sc.t2, sc.duration))):
        if stage2:
            # The blend restarts from the command in force just before stage 2 (docs/equations.md §7).
            ctl.stage2_ld0 = ctl.rate(t0, x0, False)
        teval = sorted({t for t in probes if t0 <= t <= t1} | {t1})
        sol = solve_ivp(lambda t, x: derivative(sc, x, ctl.rate(t, x, stage2)), (t0, t1), x0,
                        method=method, rtol=rt, atol=at, t_eval=teval)
        if sol.status != 0:
            raise RuntimeError(sol.message)
        out += [l for t, l in zip(sol.t, sol.y[1]) if t in probes]
        nfev += sol.nfev
        x0 = list(sol.y[:, -1])
    return np.array(out), nfev


def run_zoh(sc, rtol, method):
    """As tss-sim: one command per control period, held; one solve_ivp call per period."""
    ctl = Control(sc)
    probes = set(table1_times())
    rt, at = tolerances(rtol)
    x = initial_state(sc)
    out, nfev, last = [], 0, sc.ld0
    ticks = int(round(sc.duration / sc.period))
    t2_tick = int(round(sc.t2 / sc.period))
    for k in range(ticks + 1):
        t = k * sc.period
        if k in probes:
            out.append(x[1])
        if k == ticks:
            break
        stage2 = k >= t2_tick
        if k == t2_tick:
            ctl.stage2_ld0 = last
        y = ctl.rate(t, x, stage2)
        last = y
        sol = solve_ivp(lambda _t, s: derivative(sc, s, y), (t, t + sc.period), x,
                        method=method, rtol=rt, atol=at)
        x = list(sol.y[:, -1])
        nfev += sol.nfev
    return np.array(out), nfev


def timed(fn, repeat):
    best, result = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenario", default=str(REPO / "scenarios/paper.toml"))
    ap.add_argument("--mode", choices=("continuous", "zoh"), default="continuous")
    ap.add_argument("--method", default="RK45", help="solve_ivp method (RK45, DOP853, LSODA, ...)")
    ap.add_argument("--table1-tol", type=float, default=1e-3,
                    help="Table-1 accuracy to reach, m (default 1 mm)")
    ap.add_argument("--ours-tol", type=float, default=1e-6,
                    help="tss-sim's own Table-1 accuracy, m (RK4 at 1 s vs 1/32 s)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--rtol", type=float, action="append",
                    help="time these tolerances only (repeatable) instead of the ladder")
    a = ap.parse_args()
    sc = Scenario(a.scenario)
    run = run_continuous if a.mode == "continuous" else run_zoh
    repeat = a.repeat if a.mode == "continuous" else 1

    t0 = time.perf_counter()
    ref, _ = run(sc, 1e-12, "DOP853")
    print(f"{a.mode}: reference run (DOP853, rtol 1e-12) in {time.perf_counter() - t0:.2f} s")
    print(f"  Table-1 lengths at 7.00 h / 15.00 h: {ref[0]:.4f} m / {ref[-1]:.4f} m")
    found = {}
    for rtol in a.rtol or (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11):
        secs, (lengths, nfev) = timed(lambda: run(sc, rtol, a.method), repeat)
        err = float(np.max(np.abs(lengths - ref)))
        print(f"  {a.method} rtol {rtol:.0e}: {secs:7.3f} s, {nfev:7d} RHS evaluations, "
              f"Table-1 error {err:.2e} m")
        for name, tol in (("table1", a.table1_tol), ("ours", a.ours_tol)):
            if name not in found and err <= tol:
                found[name] = (rtol, secs, err)
        if "ours" in found:
            break
    for name, tol, what in (("table1", a.table1_tol, "Table 1's printed resolution"),
                            ("ours", a.ours_tol, "tss-sim's own Table-1 accuracy")):
        if name in found:
            rtol, secs, err = found[name]
            print(f"scipy {a.mode} {a.method} at {what} ({tol:g} m): rtol {rtol:.0e}, "
                  f"{secs:.3f} s (error {err:.1e} m)")
        else:
            print(f"scipy {a.mode} {a.method}: {what} ({tol:g} m) not reached")
    return 0


if __name__ == "__main__":
    sys.exit(main())
