//! The tension loop's stage in the step (docs/equations.md §17): between the law and the
//! envelope, it shapes the law's rate by the tension the tether carries (17.8) and adds the
//! admittance term that damps the tether's bounce (17.3), from the load cell at the reel.
//!
//! ```text
//!   u = clamp(u_law, u_s,prev + a_lo Δt, u_s,prev + a_hi Δt) + K(l)·HP[T_meas + m_r a_s]
//! ```
//!
//! u_s,prev is the last command sent less its admittance part (so the envelope's own limits are
//! seen: no wind-up); the window [a_lo, a_hi] comes from the washout's mean free tension and is
//! widened to the envelope's as the attitude error grows (§17.5). Without a load cell the
//! admittance term is 0 and the window is the configured fallback (§17.6).

use crate::config::TensionLoopConfig;
use crate::mass::MassModel;
use crate::real::Real;
use crate::tension::{washout_weight, AdmittanceGain, AttitudeShare, TensionWindow, Washout};

use crate::config::MAX_PLAUSIBLE_TENSION_N;
use crate::envelope::Bounds;

/// What the tension loop flies on (docs/equations.md §17.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TensionLoopMode {
    /// No load-cell sample yet: no admittance term, the fallback window.
    Waiting,
    /// The load cell is read: admittance term and tension window.
    Tracking,
    /// A few periods without a load-cell sample: no admittance term, the last mean tension's
    /// window.
    Coasting,
    /// The load cell is lost (more than `load_cell_timeout_ticks` periods without a sample): no
    /// admittance term, the fallback window, until the next sample.
    Lost,
}

/// The load cell as the loop knows it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LoadCell<T> {
    /// No sample yet.
    Waiting,
    /// Read at the last step; the washout's mean.
    Tracking(Washout<T>),
    /// `missing` periods without a sample since the last one; the washout as it was then.
    Coasting { washout: Washout<T>, missing: u32 },
    /// Lost.
    Lost,
}

impl<T> LoadCell<T> {
    fn mode(&self) -> TensionLoopMode {
        match self {
            LoadCell::Waiting => TensionLoopMode::Waiting,
            LoadCell::Tracking(_) => TensionLoopMode::Tracking,
            LoadCell::Coasting { .. } => TensionLoopMode::Coasting,
            LoadCell::Lost => TensionLoopMode::Lost,
        }
    }
}

/// What the stage needs from the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StageInput<T> {
    /// The law's rate (Eqs. 27, 29), m/s: finite (`law::solve` faults otherwise).
    pub(crate) law_rate_mps: T,
    /// Its acceleration (Eq. 30), m/s².
    pub(crate) law_accel_mps2: T,
    /// The last command sent, m/s.
    pub(crate) previous_mps: T,
    /// l, m.
    pub(crate) length_m: T,
    /// δ, the law's attitude error, rad.
    pub(crate) delta_rad: T,
    /// The load cell's sample of this step, N.
    pub(crate) tension_n: Option<T>,
}

/// What a safe action that brings the reel to rest needs from the step.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RestInput<T> {
    /// The last command sent, m/s.
    pub(crate) previous_mps: T,
    /// The safe action's largest change of rate in one period, m/s.
    pub(crate) step_mps: T,
    /// l, m.
    pub(crate) length_m: T,
    /// The load cell's sample of this step, N.
    pub(crate) tension_n: Option<T>,
}

/// What the stage decided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StageOutput<T> {
    /// The command requested of the envelope, m/s.
    pub(crate) rate_mps: T,
    /// Its acceleration, m/s²: the law's (Eq. 30) plus the admittance term's change over the
    /// period; the shaped ramp's slope when the window limited the law.
    pub(crate) accel_mps2: T,
    /// The window limited the law's rate.
    pub(crate) shaped: bool,
    /// The mode changed at this step (an event).
    pub(crate) mode_changed: Option<TensionLoopMode>,
}

/// What the loop's laws take of the reduced mass m_r: m_r itself, the tension window (17.8)
/// and the admittance gain (17.5)–(17.6) at it.
#[derive(Clone, Copy, Debug)]
struct AtMass<T> {
    radial_kg: T,
    window: TensionWindow<T>,
    gain: AdmittanceGain<T>,
}

impl<T: Real> AtMass<T> {
    fn new(cfg: &TensionLoopConfig<T>, radial_kg: T, period_s: T) -> Self {
        Self {
            radial_kg,
            window: TensionWindow::new(
                cfg.min_tension_n,
                cfg.max_tension_n,
                cfg.overshoot,
                T::ONE / radial_kg,
            ),
            gain: AdmittanceGain::new(
                cfg.axial_stiffness_n,
                radial_kg,
                cfg.damping_ratio,
                period_s,
            ),
        }
    }
}

/// The least braking a safe action keeps while the tension window (17.8) would allow less, as a
/// share of its ramp's (docs/equations.md §17.8): a slack or nearly slack tether still lets the
/// reel come to rest, within 1/share times the plain ramp's periods.
pub const LEAST_BRAKING_SHARE: f64 = 0.25;

/// The window (17.8) of the washout `w` with this period's band-passed free tension `bounce_n`:
/// judged on the mean and on this period's free tension, whichever is the worse for the motion
/// (the mean lags a free tension that changes, as in the slew).
fn window_of<T: Real>(window: &TensionWindow<T>, w: &Washout<T>, bounce_n: T) -> (T, T) {
    let this_period_n = w.mean_n + bounce_n;
    // (The band-passed part of a plausible sample is finite: one comparison orders them.)
    if bounce_n < T::ZERO {
        window.of(this_period_n, w.mean_n)
    } else {
        window.of(w.mean_n, this_period_n)
    }
}

/// The tension loop's state.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TensionStage<T> {
    cfg: TensionLoopConfig<T>,
    masses: MassModel<T>,
    /// The laws at m_r of a massless tether (that of every length), worked out once; `None`
    /// for a tether with mass (m_r of each step's length).
    fixed_mass: Option<AtMass<T>>,
    /// The attitude's share of the authority (§17.5) over the configured yield band.
    share: AttitudeShare<T>,
    /// β of the washout (17.3).
    washout_weight: T,
    /// The envelope's acceleration limit, m/s² (the window's width at full attitude share).
    envelope_accel_mps2: T,
    /// Control period, s.
    period_s: T,
    load_cell: LoadCell<T>,
    /// The admittance part of the last command sent, m/s (0 after a step the stage did not
    /// decide: a safe action).
    last_admittance_mps: T,
    /// a_s, the shaped rate's change over the last period, m/s² (the acceleration the reel was
    /// asked for deliberately: its tension is added back to the load cell's, 17.3).
    last_shaped_accel_mps2: T,
    /// The attitude's share of the authority at the last step (§17.5).
    attitude_share: T,
}

impl<T: Real> TensionStage<T> {
    /// The stage of a validated configuration.
    pub(crate) fn new(
        cfg: TensionLoopConfig<T>,
        masses: MassModel<T>,
        period_s: T,
        envelope_accel_mps2: T,
    ) -> Self {
        let fixed_mass = (masses.tether_density_kg_per_m == T::ZERO)
            .then(|| AtMass::new(&cfg, masses.coefficients(T::ZERO).radial_kg, period_s));
        Self {
            cfg,
            masses,
            fixed_mass,
            share: AttitudeShare::new(cfg.yield_from_rad, cfg.yield_full_rad),
            washout_weight: washout_weight(cfg.washout_s, period_s),
            envelope_accel_mps2,
            period_s,
            load_cell: LoadCell::Waiting,
            last_admittance_mps: T::ZERO,
            last_shaped_accel_mps2: T::ZERO,
            attitude_share: T::ZERO,
        }
    }

    /// The protection's tension bounds (docs/equations.md §14) widened by the attitude's share
    /// of this step (§17.5): at a share of 1 the protection's floor no longer holds the reel
    /// against the law (O-11), the envelope's acceleration limit `envelope_accel_mps2` is what
    /// is left. `previous_mps` is the last command, `dt_s` the period.
    pub(crate) fn share_bounds(&self, mut b: Bounds<T>, previous_mps: T, dt_s: T) -> Bounds<T> {
        let w = self.attitude_share;
        if w <= T::ZERO {
            return b;
        }
        let a = self.envelope_accel_mps2;
        let widen = |lo: T, hi: T, lo_end: T, hi_end: T| {
            (
                lo - w * (lo - lo_end).max(T::ZERO),
                hi + w * (hi_end - hi).max(T::ZERO),
            )
        };
        b.tension_rate_mps = b
            .tension_rate_mps
            .map(|(lo, hi)| widen(lo, hi, previous_mps - a * dt_s, previous_mps + a * dt_s));
        b.tension_accel_mps2 = b.tension_accel_mps2.map(|(lo, hi)| widen(lo, hi, -a, a));
        b
    }

    /// The loop's mode after the last step.
    pub(crate) fn mode(&self) -> TensionLoopMode {
        self.load_cell.mode()
    }

    /// A step in which the law did not run (a safe action): the command sent is not the stage's,
    /// so the next step shapes from it as it is.
    pub(crate) fn skipped(&mut self) {
        self.last_admittance_mps = T::ZERO;
        self.last_shaped_accel_mps2 = T::ZERO;
    }

    /// A step of a safe action that brings the reel to rest, on a sample the monitor accepted
    /// (docs/equations.md §17.8): the safe action's ramp toward rest of the last command less
    /// its admittance part (so the ramp comes to rest whatever the term did), each step at most
    /// `x.step_mps` and, while the loop tracks the load cell, no steeper than the tension window
    /// (17.8) allows but at least [`LEAST_BRAKING_SHARE`] of `x.step_mps`, plus the admittance
    /// term (17.3), at most `x.step_mps` either way (17.9). Without a tracked load cell: the plain ramp. Returns the rate to
    /// request of the limits, m/s, and the loop's mode if it changed at this step (an event).
    pub(crate) fn bring_to_rest(&mut self, x: &RestInput<T>) -> (T, Option<TensionLoopMode>) {
        let at_mass = self.at_mass(x.length_m);
        let before = self.load_cell.mode();
        let bounce_n = self.read_load_cell(x.tension_n, at_mass.radial_kg);
        let (brake_pay_out_mps, brake_wind_in_mps) = match &self.load_cell {
            LoadCell::Tracking(w) => {
                let (a_lo, a_hi) = window_of(&at_mass.window, w, bounce_n);
                let dt = self.period_s;
                let least = x.step_mps * T::from_f64(LEAST_BRAKING_SHARE);
                // (a_lo ≤ 0 ≤ a_hi, finite: the window of a plausible sample's washout.)
                (
                    (-a_lo * dt).clamp_finite(least, x.step_mps),
                    (a_hi * dt).clamp_finite(least, x.step_mps),
                )
            }
            LoadCell::Waiting | LoadCell::Coasting { .. } | LoadCell::Lost => {
                (x.step_mps, x.step_mps)
            }
        };
        let anchor_mps = x.previous_mps - self.last_admittance_mps;
        let ramp_mps = anchor_mps - anchor_mps.clamp_finite(-brake_wind_in_mps, brake_pay_out_mps);
        self.last_shaped_accel_mps2 = (ramp_mps - anchor_mps) / self.period_s;
        // The term's authority in a safe action: the ramp's own change in one period (the
        // product of a plausible sample's washout and a finite gain is finite).
        let admittance_mps =
            (at_mass.gain.at(x.length_m) * bounce_n).clamp_finite(-x.step_mps, x.step_mps);
        self.last_admittance_mps = admittance_mps;
        let after = self.load_cell.mode();
        (
            ramp_mps + admittance_mps,
            (after != before).then_some(after),
        )
    }

    /// The loop's laws at the reduced mass of the length `length_m`.
    #[inline]
    fn at_mass(&self, length_m: T) -> AtMass<T> {
        match self.fixed_mass {
            Some(m) => m,
            None => AtMass::new(
                &self.cfg,
                self.masses.coefficients(length_m).radial_kg,
                self.period_s,
            ),
        }
    }

    /// The load cell's sample `tension_n` of this step (17.3), with the reduced mass
    /// `radial_kg`: the washout of the free tension it measures, and the mode that follows
    /// (§17.6). Returns the band-passed free tension the admittance term acts on, N (0 without
    /// a sample to act on).
    #[inline]
    fn read_load_cell(&mut self, tension_n: Option<T>, radial_kg: T) -> T {
        // (One comparison: false for NaN and the infinities too.)
        let plausible = T::from_f64(MAX_PLAUSIBLE_TENSION_N);
        let sample = tension_n.filter(|t| t.abs() <= plausible);
        match (sample, &mut self.load_cell) {
            (Some(t), LoadCell::Tracking(w) | LoadCell::Coasting { washout: w, .. }) => {
                let mut w = *w;
                let free_n = t + radial_kg * self.last_shaped_accel_mps2;
                let hp = w.update(free_n, self.washout_weight);
                self.load_cell = LoadCell::Tracking(w);
                hp
            }
            (Some(t), LoadCell::Waiting | LoadCell::Lost) => {
                let free_n = t + radial_kg * self.last_shaped_accel_mps2;
                self.load_cell = LoadCell::Tracking(Washout::starting_at(free_n));
                T::ZERO
            }
            (None, LoadCell::Tracking(w)) => {
                self.load_cell = LoadCell::Coasting {
                    washout: *w,
                    missing: 1,
                };
                T::ZERO
            }
            (None, LoadCell::Coasting { washout, missing }) => {
                self.load_cell = if *missing >= self.cfg.load_cell_timeout_ticks {
                    LoadCell::Lost
                } else {
                    LoadCell::Coasting {
                        washout: *washout,
                        missing: *missing + 1,
                    }
                };
                T::ZERO
            }
            (None, LoadCell::Waiting | LoadCell::Lost) => T::ZERO,
        }
    }

    /// One step of the law: the command to request of the envelope.
    pub(crate) fn step(&mut self, x: &StageInput<T>) -> StageOutput<T> {
        let dt = self.period_s;
        let at_mass = self.at_mass(x.length_m);
        let before = self.load_cell.mode();

        // The load cell: the free tension it measures (17.3), its mean and its bounce.
        let bounce_n = self.read_load_cell(x.tension_n, at_mass.radial_kg);

        // The window (17.8), widened by the attitude's share (§17.5).
        let c = &self.cfg;
        let (a_lo, a_hi) = match &self.load_cell {
            LoadCell::Tracking(w) | LoadCell::Coasting { washout: w, .. } => {
                window_of(&at_mass.window, w, bounce_n)
            }
            LoadCell::Waiting | LoadCell::Lost => (-c.fallback_accel_mps2, c.fallback_accel_mps2),
        };
        let share = self.share.at(x.delta_rad);
        self.attitude_share = share;
        let (a_lo, a_hi) = if share > T::ZERO {
            let a_env = self.envelope_accel_mps2;
            (
                a_lo - share * (a_env + a_lo).max(T::ZERO),
                a_hi + share * (a_env - a_hi).max(T::ZERO),
            )
        } else {
            (a_lo, a_hi)
        };

        // The shaped law (17.8), from the last command less its admittance part.
        let anchor_mps = x.previous_mps - self.last_admittance_mps;
        let (lo, hi) = (anchor_mps + a_lo * dt, anchor_mps + a_hi * dt);
        // (The law's rate is finite: `law::solve` faults otherwise.)
        let shaped_mps = x.law_rate_mps.clamp_finite(lo, hi);
        let shaped = shaped_mps != x.law_rate_mps;
        self.last_shaped_accel_mps2 = (shaped_mps - anchor_mps) / dt;

        // The admittance term (17.3), K(l) of (17.5)–(17.6).
        let gain = at_mass.gain.at(x.length_m);
        let admittance_mps = gain * bounce_n;
        let rate_mps = shaped_mps + admittance_mps;
        let accel_mps2 = if shaped {
            (rate_mps - x.previous_mps) / dt
        } else {
            x.law_accel_mps2 + (admittance_mps - self.last_admittance_mps) / dt
        };
        self.last_admittance_mps = admittance_mps;

        let after = self.load_cell.mode();
        StageOutput {
            rate_mps,
            accel_mps2,
            shaped,
            mode_changed: (after != before).then_some(after),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tension::admittance_gain_mps_per_n;

    fn stage() -> TensionStage<f64> {
        TensionStage::new(
            TensionLoopConfig::dyneema_half_mm(),
            MassModel::paper(),
            1.0,
            15.0,
        )
    }

    fn input(law_rate_mps: f64, previous_mps: f64, tension_n: Option<f64>) -> StageInput<f64> {
        StageInput {
            law_rate_mps,
            law_accel_mps2: 0.0,
            previous_mps,
            length_m: 2_000.0,
            delta_rad: 0.0,
            tension_n,
        }
    }

    /// A steady load cell leaves the law's rate as it is: the washout's mean is the tension,
    /// nothing is high-passed, and a law inside the window is not shaped.
    #[test]
    fn a_steady_tether_leaves_the_law_alone() {
        let mut s = stage();
        let mut previous = -0.001;
        for _ in 0..10 {
            let out = s.step(&input(-0.001, previous, Some(0.67)));
            assert!((out.rate_mps - -0.001).abs() < 1e-12, "{out:?}");
            assert!(!out.shaped);
            previous = out.rate_mps;
        }
        assert_eq!(s.mode(), TensionLoopMode::Tracking);
    }

    /// A tension above the mean pays out (K > 0) by K(l) times the high-passed part.
    #[test]
    fn a_pull_pays_out_by_the_scheduled_gain() {
        let mut s = stage();
        let _ = s.step(&input(0.0, 0.0, Some(0.67)));
        let out = s.step(&input(0.0, 0.0, Some(1.67)));
        let m_r = MassModel::<f64>::paper().coefficients(0.0).radial_kg;
        let gain = admittance_gain_mps_per_n(2_000.0, 1e4, m_r, 0.6, 1.0);
        let beta = washout_weight(100.0, 1.0);
        // The two-sample mean: half the step, high-passed.
        let hp = 0.5 * (1.0 - beta);
        assert!((out.rate_mps - gain * hp).abs() < 1e-12, "{out:?}");
    }

    /// The slew's −125 m/s is shaped to what the tension carries: the wind-in starts at a_lo and
    /// the braking afterwards is limited to a_hi.
    #[test]
    fn a_rate_step_is_shaped_to_the_tension_window() {
        let mut s = stage();
        let m_r = MassModel::<f64>::paper().coefficients(0.0).radial_kg;
        let t = 7.5;
        let _ = s.step(&input(0.0, 0.0, Some(t)));
        let out = s.step(&input(-125.0, 0.0, Some(t)));
        assert!(out.shaped);
        let a_lo = -(18.0 - t) / (1.5 * m_r);
        assert!((out.rate_mps - a_lo).abs() < 1e-9, "{out:?}");
        // The braking from −5 m/s toward 0: at most a_hi per period (the mean free tension is
        // the load cell's plus m_r a_s: the tension the braking takes away is added back).
        let mut s = stage();
        let _ = s.step(&input(-5.0, -5.0, Some(t)));
        let out = s.step(&input(0.0, -5.0, Some(t)));
        let a_hi = (t - 0.1) / (1.5 * m_r);
        assert!((out.rate_mps - (-5.0 + a_hi)).abs() < 1e-9, "{out:?}");
    }

    /// A tumbling attitude takes the authority: at |δ| ≥ yield_full_rad the window is the
    /// envelope's.
    #[test]
    fn the_window_gives_way_to_the_attitude() {
        let mut s = stage();
        let _ = s.step(&input(0.0, 0.0, Some(0.2)));
        let x = StageInput {
            delta_rad: 0.6,
            ..input(2.0, 0.0, Some(0.2))
        };
        let out = s.step(&x);
        assert!(!out.shaped);
        assert!((out.rate_mps - 2.0).abs() < 1e-3, "{out:?}");
    }

    /// The load cell fails: it coasts on the last mean for the timeout, then it is lost (the
    /// fallback window, no admittance term); a sample restarts it without a bump.
    #[test]
    fn a_failed_load_cell_coasts_then_is_lost_and_a_sample_restarts_it() {
        let mut s = stage();
        assert_eq!(s.mode(), TensionLoopMode::Waiting);
        // Waiting: the fallback window.
        let out = s.step(&input(1.0, 0.0, None));
        assert!((out.rate_mps - 0.1).abs() < 1e-12);
        assert_eq!(out.mode_changed, None);
        let out = s.step(&input(0.0, 0.0, Some(3.0)));
        assert_eq!(out.mode_changed, Some(TensionLoopMode::Tracking));
        assert_eq!(out.rate_mps, 0.0);
        let mut modes = [TensionLoopMode::Waiting; 7];
        let bad = [
            None,
            Some(f64::NAN),
            Some(f64::INFINITY),
            Some(-2e5),
            None,
            None,
            None,
        ];
        for (k, t) in bad.into_iter().enumerate() {
            let out = s.step(&input(0.0, 0.0, t));
            assert_eq!(out.rate_mps, 0.0, "no admittance term without a sample");
            modes[k] = s.mode();
        }
        use TensionLoopMode::{Coasting, Lost};
        assert_eq!(
            modes,
            [Coasting, Coasting, Coasting, Coasting, Coasting, Lost, Lost]
        );
        // Lost: the fallback window.
        let out = s.step(&input(1.0, 0.0, None));
        assert!((out.rate_mps - 0.1).abs() < 1e-12);
        // Back: tracking from that sample, no bump.
        let out = s.step(&input(0.0, 0.0, Some(9.0)));
        assert_eq!(out.mode_changed, Some(TensionLoopMode::Tracking));
        assert_eq!(out.rate_mps, 0.0);
    }

    /// Every special value in the load cell, the law's rate and δ: a finite command within the
    /// window of the last one, whenever the law's rate is finite.
    #[test]
    fn bad_samples_never_make_a_bad_command() {
        let specials = [
            None,
            Some(f64::NAN),
            Some(f64::INFINITY),
            Some(f64::NEG_INFINITY),
            Some(f64::MAX),
            Some(-f64::MAX),
            Some(0.0),
            Some(-1.0),
            Some(3.0),
            Some(1e4),
        ];
        let mut s = stage();
        let mut previous = 0.0;
        for k in 0..400 {
            let law = if k % 3 == 0 { 10.0 } else { -10.0 };
            let x = StageInput {
                delta_rad: [0.0, 0.3, 1.0, f64::NAN][k % 4],
                ..input(law, previous, specials[k % specials.len()])
            };
            let out = s.step(&x);
            assert!(out.rate_mps.is_finite(), "{k}: {out:?}");
            previous = out.rate_mps;
        }
    }

    fn rest(previous_mps: f64, tension_n: Option<f64>) -> RestInput<f64> {
        RestInput {
            previous_mps,
            step_mps: 0.01,
            length_m: 2_400.0,
            tension_n,
        }
    }

    /// Bringing a wind-in to rest on a tracked load cell (§17.8): the braking no steeper than the
    /// window lets the free tension carry (0.73 N at 2.4 km: 0.0047 m/s², not the ramp's 0.01),
    /// never below a quarter of the ramp's, the tension it takes away added back to the free
    /// tension; at rest, only the admittance term of a bounce.
    #[test]
    fn a_stop_on_a_tracked_load_cell_brakes_within_the_window_then_damps() {
        let mut s = stage();
        let m_r = MassModel::<f64>::paper().coefficients(0.0).radial_kg;
        let t = 0.73;
        let _ = s.step(&input(-0.36, -0.36, Some(t)));
        let mut previous = -0.36;
        let a_hi = (t - 0.1) / (1.5 * m_r);
        let mut accel = 0.0;
        let mut ticks = 0;
        while previous.abs() > 1e-4 {
            // The load cell reads the free tension less what the last braking took away.
            let (rate, mode) = s.bring_to_rest(&rest(previous, Some(t - m_r * accel)));
            assert_eq!(mode, None);
            accel = rate - previous;
            assert!(accel > 0.0 && accel <= 1.001 * a_hi, "{ticks}: {accel}");
            assert!(rate <= 1e-4, "{ticks}: no overshoot into a pay-out");
            previous = rate;
            ticks += 1;
            assert!(ticks < 100, "at rest within 0.36/a_hi periods");
        }
        assert!(
            (f64::from(ticks) - (0.36 / a_hi).ceil()).abs() <= 1.0,
            "{ticks}"
        );
        // At rest, a bounce: the command is K times its band-passed part, around 0; at most the
        // ramp's own change in one period.
        let gain = admittance_gain_mps_per_n(2_400.0, 1e4, m_r, 0.6, 1.0);
        for _ in 0..3 {
            previous = s.bring_to_rest(&rest(previous, Some(t))).0;
        }
        let (rate, _) = s.bring_to_rest(&rest(previous, Some(t + 0.1)));
        assert!(
            rate > previous && rate - previous <= gain * 0.1,
            "a pull pays out: {previous} → {rate}"
        );
        let (back, _) = s.bring_to_rest(&rest(rate, Some(t)));
        assert!(back < rate, "{back}");
        let (rate, _) = s.bring_to_rest(&rest(back, Some(t + 10.0)));
        assert_eq!(rate, 0.01, "a 10-N pull: the term's authority");
        // A slack tether (the window closed): still a quarter of the ramp's braking.
        let mut s = stage();
        let _ = s.step(&input(-0.36, -0.36, Some(0.0)));
        let (rate, _) = s.bring_to_rest(&rest(-0.36, Some(0.0)));
        assert!(
            (rate - (-0.36 + LEAST_BRAKING_SHARE * 0.01)).abs() < 1e-12,
            "{rate}"
        );
    }

    /// A load cell the loop does not track (never read, lost, or an implausible sample) is not
    /// used by a safe action: the plain ramp of the last command, to the bit.
    #[test]
    fn a_stop_without_a_tracked_load_cell_is_the_plain_ramp() {
        let plain = |v: f64| v - v.clamp(-0.01, 0.01);
        // Waiting: none read yet.
        let mut s = stage();
        assert_eq!(s.bring_to_rest(&rest(-0.36, None)).0, plain(-0.36));
        // Lost after the timeout; a wild sample, NaN, ±∞: still the plain ramp.
        let mut s = stage();
        let _ = s.step(&input(-0.36, -0.36, Some(0.73)));
        let mut previous = -0.36;
        for _ in 0..6 {
            previous = s.step(&input(-0.36, previous, None)).rate_mps;
        }
        assert_eq!(s.mode(), TensionLoopMode::Lost);
        for t in [None, Some(f64::NAN), Some(f64::INFINITY), Some(-1e6)] {
            let (rate, mode) = s.bring_to_rest(&rest(previous, t));
            assert_eq!(rate, plain(previous), "{t:?}");
            assert_eq!(mode, None);
            previous = rate;
        }
        assert_eq!(s.mode(), TensionLoopMode::Lost);
    }
}
