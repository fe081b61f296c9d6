//! The tension loop's mathematics (docs/equations.md §17): the admittance gain scheduled on the
//! length, the washout that splits the load cell's free tension into its mean and its bounce, the
//! tension window that shapes the law's command, and the attitude's share of authority. Pure
//! functions and one small filter; the stage that flies them is `controller::tension`.
//!
//! The tether's longitudinal mode ("bounce") of an unstretched length l, axial stiffness EA, with
//! the sub-satellite's reduced mass m_r on it, has ω_b = √(EA/(m_r l)) (17.2). A reel rate
//! u = u_s + K·HP[T + m_r a_s] closes it to s² + K k s + k/m_r (k = EA/l, 17.4), so
//!
//! ```text
//!   K(l) = 2 ζ_d √(l/(EA m_r)),   at most g_max l/(EA Δt)                  (17.5), (17.6)
//! ```
//!
//! gives it the damping ratio ζ_d where a 1-Hz command can act, and fades out (K ∝ l) on a
//! tether so short that its bounce is faster than the period.
//!
//! ```
//! use tss_reel::tension::admittance_gain_mps_per_n;
//!
//! // 0.5 mm Dyneema (EA = 10 kN), the paper's 99 kg, ζ_d = 0.6, a 1 s period.
//! let k_30km = admittance_gain_mps_per_n(30_000.0_f64, 1e4, 99.0, 0.6, 1.0);
//! assert!((k_30km - 0.2089).abs() < 1e-4); // 2·0.6·√(30 000/(10⁴·99)) m/s per N
//! // At 30 km the loop gives the bounce k·K/2 = 0.035 s⁻¹ of damping rate: ζ = 0.6.
//! let (k, omega) = (1e4 / 30_000.0, (1e4_f64 / (99.0 * 30_000.0)).sqrt());
//! assert!((k * k_30km / (2.0 * omega) - 0.6).abs() < 1e-9);
//! ```

use crate::real::Real;

/// g_max of (17.6): the most the admittance term may change the stretch's error in one period,
/// K·(EA/l)·Δt. At 1 the discrete loop is at the edge of its stability (a dead-beat
/// correction); at 0.5 the mode still decays at every length for a tether up to 1.5 times stiffer
/// than the loop is told (docs/equations.md §17.2–17.3).
pub const MAX_GAIN_PERIOD_PRODUCT: f64 = 0.5;

/// K(l), the admittance gain of (17.5) capped by (17.6), m/s per N: the reel rate per newton of
/// high-passed free tension that gives the bounce of a tether of unstretched length `length_m`,
/// axial stiffness `stiffness_n` (EA, N) and reduced mass `radial_kg` the damping ratio
/// `damping_ratio`, where the control period `period_s` can represent it.
pub fn admittance_gain_mps_per_n<T: Real>(
    length_m: T,
    stiffness_n: T,
    radial_kg: T,
    damping_ratio: T,
    period_s: T,
) -> T {
    AdmittanceGain::new(stiffness_n, radial_kg, damping_ratio, period_s).at(length_m)
}

/// K(l) of (17.5)–(17.6) for one tether, reduced mass, damping ratio and period: the parts that
/// do not depend on the length, worked out once ([`admittance_gain_mps_per_n`] at any length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdmittanceGain<T> {
    /// 2 ζ_d.
    two_damping_ratio: T,
    /// EA m_r, N kg.
    stiffness_mass_n_kg: T,
    /// EA Δt, N s.
    stiffness_period_n_s: T,
}

impl<T: Real> AdmittanceGain<T> {
    /// The gain of a tether of axial stiffness `stiffness_n` (EA, N) with the reduced mass
    /// `radial_kg`, the damping ratio `damping_ratio` and the control period `period_s`.
    pub fn new(stiffness_n: T, radial_kg: T, damping_ratio: T, period_s: T) -> Self {
        Self {
            two_damping_ratio: T::from_f64(2.0) * damping_ratio,
            stiffness_mass_n_kg: stiffness_n * radial_kg,
            stiffness_period_n_s: stiffness_n * period_s,
        }
    }

    /// K at the unstretched length `length_m`, m/s per N: 2 ζ_d √(l/(EA m_r)), at most
    /// g_max l/(EA Δt), never negative.
    pub fn at(&self, length_m: T) -> T {
        let designed = self.two_damping_ratio * (length_m / self.stiffness_mass_n_kg).sqrt();
        let cap = T::from_f64(MAX_GAIN_PERIOD_PRODUCT) * length_m / self.stiffness_period_n_s;
        designed.min(cap).max(T::ZERO)
    }
}

/// The weight β = 1 − e^{−Δt/τ_w} of a new sample in the washout's mean (17.3).
pub fn washout_weight<T: Real>(washout_s: T, period_s: T) -> T {
    (-(period_s / washout_s)).exp_and_complement().1
}

/// The washout of (17.3): the mean free tension x̄ (a first-order low-pass of time constant τ_w)
/// and the band-passed part that the admittance term acts on: x − x̄ of the two-sample mean
/// x_k = ½(f_k + f_k−1) of the load cell's free tension f, whose zero at the period's Nyquist
/// frequency keeps the term from answering the reel's own period-to-period steps (the reel
/// segment's damper feeds them through to the load cell at once: the command then alternated
/// every period and, through the drum's friction, biased the 30-km keep by a metre).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Washout<T> {
    /// x̄, N.
    pub mean_n: T,
    /// f_k−1, the last sample, N.
    pub last_n: T,
}

impl<T: Real> Washout<T> {
    /// A washout that starts at the sample `free_n` (its high-passed part 0: no bump).
    pub fn starting_at(free_n: T) -> Self {
        Self {
            mean_n: free_n,
            last_n: free_n,
        }
    }

    /// One period with the sample `free_n` and the weight `weight` ([`washout_weight`]):
    /// x = ½(f + f_prev), x̄ ← x̄ + β(x − x̄); returns the band-passed part x − x̄, N.
    pub fn update(&mut self, free_n: T, weight: T) -> T {
        let x = T::from_f64(0.5) * (free_n + self.last_n);
        self.last_n = free_n;
        self.mean_n = self.mean_n + weight * (x - self.mean_n);
        x - self.mean_n
    }
}

/// The share of the mean free tension a braking may take away at most, on a tether whose mean
/// tension is below twice `min_tension_n` (docs/equations.md §17.4): the early deployment's
/// millinewtons are then halved, not held against a floor they never reach.
pub const FLOOR_SHARE_OF_MEAN: f64 = 0.5;

/// The accelerations, [a_lo, a_hi] in m/s², that keep a taut tether within [T_lo,
/// `max_tension_n`] with the elastic overshoot allowance `overshoot` (κ ≥ 1), at the reduced
/// mass whose reciprocal is `inv_radial_per_kg` (17.8): a_hi = (x_low − T_lo)/(κ m_r) from the
/// lower estimate of the free tension `low_free_n` (a braking lowers it), a_lo = −(T_hi −
/// x_high)/(κ m_r) from the higher `high_free_n` (an acceleration of a wind-in raises it), with
/// the floor T_lo = min(`min_tension_n`, x_low/2) ([`FLOOR_SHARE_OF_MEAN`]). The window never
/// forces a motion: a_hi ≥ 0 ≥ a_lo (a tension outside the band stops the shaping from moving it
/// further out; it does not drive the reel for its sake).
pub fn tension_window_mps2<T: Real>(
    low_free_n: T,
    high_free_n: T,
    min_tension_n: T,
    max_tension_n: T,
    overshoot: T,
    inv_radial_per_kg: T,
) -> (T, T) {
    TensionWindow::new(min_tension_n, max_tension_n, overshoot, inv_radial_per_kg)
        .of(low_free_n, high_free_n)
}

/// The tension window of (17.8) for one band, overshoot allowance and reduced mass, worked
/// out once ([`tension_window_mps2`] of any free tension).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TensionWindow<T> {
    /// T_lo before the floor's share of the mean, N.
    min_tension_n: T,
    /// T_hi, N.
    max_tension_n: T,
    /// 1/(κ m_r): the acceleration per newton of margin, m/s² per N.
    accel_per_n: T,
}

impl<T: Real> TensionWindow<T> {
    /// The window of the band [`min_tension_n`, `max_tension_n`] with the elastic overshoot
    /// allowance `overshoot` (κ ≥ 1), at the reduced mass whose reciprocal is
    /// `inv_radial_per_kg`.
    pub fn new(min_tension_n: T, max_tension_n: T, overshoot: T, inv_radial_per_kg: T) -> Self {
        Self {
            min_tension_n,
            max_tension_n,
            accel_per_n: inv_radial_per_kg / overshoot,
        }
    }

    /// [a_lo, a_hi], m/s², from the lower and the higher estimate of the free tension
    /// (`low_free_n`, `high_free_n`, N): see [`tension_window_mps2`].
    pub fn of(&self, low_free_n: T, high_free_n: T) -> (T, T) {
        let per_n = self.accel_per_n;
        let floor_n = self
            .min_tension_n
            .min(T::from_f64(FLOOR_SHARE_OF_MEAN) * low_free_n);
        let hi = (low_free_n - floor_n) * per_n;
        let lo = (high_free_n - self.max_tension_n) * per_n;
        (lo.min(T::ZERO), hi.max(T::ZERO))
    }
}

/// The attitude's share w ∈ [0, 1] of the authority over the command (docs/equations.md §17.5):
/// 0 while |δ| ≤ `from_rad`, 1 from `full_rad` on, linear between. The tension window is widened
/// to the envelope's by w.
pub fn attitude_share<T: Real>(delta_rad: T, from_rad: T, full_rad: T) -> T {
    AttitudeShare::new(from_rad, full_rad).at(delta_rad)
}

/// The attitude's share of (§17.5) for one yield band, worked out once ([`attitude_share`] of
/// any δ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AttitudeShare<T> {
    /// |δ| where the share begins, rad.
    from_rad: T,
    /// The band's width, rad (the share is 1 at its end).
    width_rad: T,
}

impl<T: Real> AttitudeShare<T> {
    /// The share that is 0 while |δ| ≤ `from_rad` and 1 from `full_rad` on.
    pub fn new(from_rad: T, full_rad: T) -> Self {
        Self {
            from_rad,
            width_rad: full_rad - from_rad,
        }
    }

    /// w at the attitude error `delta_rad` (0 for NaN).
    pub fn at(&self, delta_rad: T) -> T {
        ((delta_rad.abs() - self.from_rad) / self.width_rad).clamp_to(T::ZERO, T::ONE)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    const EA: f64 = 1e4;
    const M: f64 = 99.0;

    /// The free-flying sub-satellite on an elastic tether (17.1) paid out by a reel whose rate
    /// follows a command held over each 1-s period through a first-order lag `lag_s`, the command
    /// the admittance term (17.3) of the load cell's sample at the start of the period, told a
    /// tether of stiffness `told_n`. From a 1-N tension disturbance (the tether stretched by
    /// 1 N/k at rest), the largest |tension deviation| over each of `windows` bounce periods.
    fn bounce_envelope(
        length_m: f64,
        stiffness_n: f64,
        told_n: f64,
        lag_s: f64,
        windows: usize,
    ) -> Vec<f64> {
        let (k, c) = (stiffness_n / length_m, 1000.0 / length_m);
        let gain = admittance_gain_mps_per_n(length_m, told_n, M, 0.6, 1.0);
        let beta = washout_weight(100.0, 1.0);
        let (mut stretch, mut closing, mut reel) = (1.0 / k, 0.0, 0.0);
        let tension = |s: f64, v: f64, u: f64| k * s + c * (v - u);
        let mut washout = Washout::starting_at(0.0);
        let period = 2.0 * core::f64::consts::PI / (stiffness_n / (M * length_m)).sqrt();
        let per_window = (period.ceil() as usize).max(2);
        let h = 1e-3;
        let mut peaks = Vec::new();
        let mut peak: f64 = 0.0;
        for tick in 0..windows * per_window {
            let t = tension(stretch, closing, reel);
            peak = peak.max(t.abs());
            if (tick + 1) % per_window == 0 {
                peaks.push(peak);
                peak = 0.0;
            }
            let command = gain * washout.update(t, beta);
            for _ in 0..1000 {
                // m_r r̈ = −T (the deviation from the free tension); the stretch grows with the
                // sub-satellite's outward speed less the reel's.
                reel += h * (command - reel) / lag_s;
                closing += h * (-tension(stretch, closing, reel) / M);
                stretch += h * (closing - reel);
            }
        }
        peaks
    }

    /// (17.5) with (17.4): the gain gives the designed damping ratio where it is not capped, and
    /// the cap (17.6) holds K·k·Δt at g_max below that.
    #[test]
    fn the_gain_gives_the_designed_damping_ratio_and_is_capped_by_the_period() {
        for l in [1_000.0, 2_000.0, 10_000.0, 30_000.0] {
            let gain = admittance_gain_mps_per_n(l, EA, M, 0.6, 1.0);
            let zeta = gain * (EA / l * M).sqrt() / 2.0;
            assert!((zeta - 0.6).abs() < 1e-12, "{l}: ζ = {zeta}");
            assert!(gain * EA / l < MAX_GAIN_PERIOD_PRODUCT, "{l}");
        }
        // Short: the bounce (1.4 rad/s at 50 m) is faster than a 1-s command damps; K ∝ l.
        for l in [10.0, 50.0] {
            let gain = admittance_gain_mps_per_n(l, EA, M, 0.6, 1.0);
            assert!(
                (gain * EA / l - MAX_GAIN_PERIOD_PRODUCT).abs() < 1e-12,
                "{l}"
            );
        }
        // Where the cap takes over: 2ζ_d √(l/(EA m)) = g l/(EA Δt) … l = EA Δt² (2ζ/g)²/m ≈ 580 m.
        let corner = EA * (2.0 * 0.6 / MAX_GAIN_PERIOD_PRODUCT).powi(2) / M;
        let below = admittance_gain_mps_per_n(corner * 0.99, EA, M, 0.6, 1.0);
        let above = admittance_gain_mps_per_n(corner * 1.01, EA, M, 0.6, 1.0);
        assert!(below * EA / (corner * 0.99) < MAX_GAIN_PERIOD_PRODUCT + 1e-12);
        assert!(above * EA / (corner * 1.01) < MAX_GAIN_PERIOD_PRODUCT);
        // Nothing at zero length; never negative or NaN for a valid configuration.
        assert_eq!(admittance_gain_mps_per_n(0.0, EA, M, 0.6, 1.0), 0.0);
    }

    /// The held, lagging loop damps the bounce at every length from 300 m to 30 km, for a tether
    /// half as stiff to 1.5 times as stiff as the loop is told (§17.2–17.3): after five bounce
    /// periods the tension's deviation is below a fifth of the disturbance (0.3 % structural
    /// damping alone leaves more than 80 % of it at 30 km: the next test).
    #[test]
    fn the_held_lagging_loop_damps_the_bounce_at_every_length_and_stiffness() {
        for l in [300.0, 1_000.0, 2_000.0, 10_000.0, 30_000.0] {
            for ratio in [0.5, 1.0, 1.5] {
                let peaks = bounce_envelope(l, ratio * EA, EA, 0.2, 6);
                assert!(
                    peaks[5] < 0.2 * peaks[0],
                    "l = {l}, EA × {ratio}: {peaks:?}"
                );
            }
        }
        // At 50 and 100 m the bounce (1.0–1.7 rad/s) nears the period's Nyquist rate: the capped
        // term damps the told tether and never feeds a stiffer one.
        for l in [50.0, 100.0] {
            for ratio in [0.5, 1.0, 1.5] {
                let peaks = bounce_envelope(l, ratio * EA, EA, 0.2, 6);
                assert!(
                    peaks.iter().all(|&p| p <= peaks[0]),
                    "{l}, EA × {ratio}: {peaks:?}"
                );
            }
        }
    }

    /// The tether's own damping alone (the loop told an infinitely stiff tether: K = 0) keeps the
    /// bounce: the test above measures the loop, not the plant's damping.
    #[test]
    fn without_the_loop_the_bounce_stays() {
        let peaks = bounce_envelope(30_000.0, EA, f64::INFINITY, 0.2, 6);
        assert!(peaks[5] > 0.8 * peaks[0], "{peaks:?}");
    }

    /// The washout passes the bounce and removes a constant: a load-cell bias, or the free tension
    /// itself, leaves no command (no length drift).
    #[test]
    fn the_washout_removes_a_constant_and_passes_the_bounce() {
        let beta = washout_weight(100.0, 1.0);
        assert!((beta - (1.0 - (-0.01_f64).exp())).abs() < 1e-15);
        let mut w = Washout::starting_at(0.0);
        // A 3-N step (a bias appearing): half of it the first period (the two-sample mean),
        // then the high-passed part decays with τ_w.
        let first = w.update(3.0, beta);
        assert!((first - 1.5 * (1.0 - beta)).abs() < 1e-12);
        let mut last = 0.0;
        for _ in 0..1_000 {
            last = w.update(3.0, beta);
        }
        assert!(last.abs() < 1e-3, "{last}");
        assert!((w.mean_n - 3.0).abs() < 1e-3);
        // A period-2 alternation (the reel's own steps) does not pass at all.
        let mut w = Washout::starting_at(0.0);
        for k in 0..100 {
            let hp = w.update(if k % 2 == 0 { 1.0 } else { -1.0 }, beta);
            if k > 0 {
                assert!(hp.abs() < 1e-2, "{k}: {hp}");
            }
        }
        // A 108-s bounce (30 km) passes with at least 97 % of its amplitude.
        let mut w = Washout::starting_at(0.0);
        let omega = 2.0 * core::f64::consts::PI / 108.0;
        let mut amplitude: f64 = 0.0;
        for k in 0..3_000 {
            let hp = w.update((omega * f64::from(k)).sin(), beta);
            if k > 1_000 {
                amplitude = amplitude.max(hp.abs());
            }
        }
        assert!(amplitude > 0.97 && amplitude < 1.03, "{amplitude}");
    }

    #[test]
    fn the_window_is_what_the_tension_carries_and_never_forces_a_motion() {
        let inv_m = 1.0 / M;
        // 7.5 N at 25 km, keep 0.1 N, at most 15 N, κ = 1.5.
        let (lo, hi) = tension_window_mps2(7.5, 7.5, 0.1, 15.0, 1.5, inv_m);
        assert!((hi - 7.4 / (1.5 * M)).abs() < 1e-15);
        assert!((lo + 7.5 / (1.5 * M)).abs() < 1e-15);
        // A mean below twice the floor: half of it may be taken away.
        let (_, hi) = tension_window_mps2(0.05, 0.05, 0.1, 15.0, 1.5, inv_m);
        assert!((hi - 0.025 / (1.5 * M)).abs() < 1e-15);
        // A slack tether: no braking of a wind-in (a_hi = 0) but no forced wind-in either.
        let (lo, hi) = tension_window_mps2(-0.05, -0.05, 0.1, 15.0, 1.5, inv_m);
        assert_eq!(hi, 0.0);
        assert!(lo < 0.0);
        // The braking is judged on the lower estimate, the wind-in's start on the higher.
        let (lo, hi) = tension_window_mps2(5.0, 9.0, 0.1, 15.0, 1.5, inv_m);
        assert!((hi - 4.9 / (1.5 * M)).abs() < 1e-15);
        assert!((lo + 6.0 / (1.5 * M)).abs() < 1e-15);
        // Above the ceiling: the reverse.
        let (lo, hi) = tension_window_mps2(16.0, 16.0, 0.1, 15.0, 1.5, inv_m);
        assert_eq!(lo, 0.0);
        assert!(hi > 0.0);
    }

    #[test]
    fn the_attitude_takes_the_authority_between_its_two_angles() {
        assert_eq!(attitude_share(0.1_f64, 0.2, 0.5), 0.0);
        assert_eq!(attitude_share(-0.2_f64, 0.2, 0.5), 0.0);
        assert!((attitude_share(-0.35_f64, 0.2, 0.5) - 0.5).abs() < 1e-12);
        assert_eq!(attitude_share(0.6_f64, 0.2, 0.5), 1.0);
        assert_eq!(attitude_share(f64::NAN, 0.2, 0.5), 0.0);
    }
}
