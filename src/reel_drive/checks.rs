//! The drive's cross-checks: its sensors against each other and against its own drum model,
//! for the faults no single reading shows (docs/hazards.md, HZ-R1 to HZ-R3).
//!
//! **The tension the drum's motion implies.** With the brake free the drum obeys
//! J ω̇ = τ + T r − b ω − c sat(ω) ([`DrumModel`](super::DrumModel)); the drive knows τ (its
//! duty × τ_max, the driver in torque mode), ω (the encoder) and the model, so the tether's
//! torque T r is what is left. A generalised momentum observer (De Luca and Mattone, 2003)
//! estimates it without differentiating the speed. Written on the drum's surface speed v = ω r
//! (its momentum J ω = (J / r) v):
//!
//! ```text
//! v̂ₖ = v̂ₖ₋₁ + Δt (r / J) (τₖ₋₁ + D̂ₖ₋₁ − b ω − c sat(ω))    (the model's speed)
//! D̂ₖ = K (J / r) (vₖ − v̂ₖ)                                 (the torque it misses: T r)
//! ```
//!
//! so that D̂ follows the true tether torque as a first-order lag of bandwidth K
//! ([`FaultLimits::observer_bandwidth_radps`](super::FaultLimits::observer_bandwidth_radps)),
//! plus the model's own error (friction, inertia). The friction is the feed-forward's, at the
//! reference the drum follows (the speed loop keeps the two close; where they part, as in a
//! runaway, the friction is the smaller term by far). T̂ = D̂ / r is the implied tension. It
//! restarts at each release of the brake from the tension the feed-forward uses (no
//! transient: v̂ starts D̂ / (K J / r) below the measured speed), and is judged only while
//! the drum is driven (released, not at rest, with a measured speed), against that tension
//! T_ff:
//!
//! - |T̂ − T_ff| within `tension_mismatch_n`: they agree (and T̂, within the tolerance of a
//!   tension inside [min, max], is a plausible one);
//! - T̂ beyond the plausible range [min, max] by more than `tension_mismatch_n`: no tether can
//!   explain how the drum moves under the motor (a frozen encoder with the drum running away,
//!   a seized drum): [`DriveFault::NoResponse`], tripped;
//! - T̂ inside it but `tension_mismatch_n` away from the load cell's: the load cell is wrong,
//!   [`DriveFault::TensionMismatch`], and the drive stops using it (T_ff = 0 from then on:
//!   only the first test is left).
//!
//! Each must last `no_response_ticks`. Once the load cell is dropped, a loop pinned at its
//! limit (the duty saturated, or the integral at its clamp ± τ_max) is a drum that does not
//! answer the torque as well (with the load cell trusted, a wrong reading pins it too):
//! [`DriveFault::NoResponse`].
//!
//! **Motion with the brake engaged.** The odometer counts the drum whatever the brake: a travel
//! of more than `brake_slip_m` from where the engaged brake first held it is a slipping brake,
//! [`DriveFault::BrakeSlip`].

use super::faults::DriveFault;

/// The state of the cross-checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CrossChecks {
    /// The drum's surface speed the model predicts, v̂, m/s.
    predicted_speed_mps: f32,
    /// The tether's torque at the drum the observer finds, D̂ = T̂ r, N m.
    pub(super) implied_tether_nm: f32,
    /// Consecutive judged ticks with the drum not answering the torque (T̂ beyond any tether,
    /// or, the load cell dropped, the integral at its clamp).
    unanswered_ticks: u32,
    /// Consecutive judged ticks with T̂ away from the load cell, while it is trusted.
    mismatch_ticks: u32,
    /// Whether the feed-forward uses the load cell (false after
    /// [`DriveFault::TensionMismatch`], until [`CrossChecks::trust_load_cell`]).
    load_cell_trusted: bool,
    /// The total count (modulo 2³²) where the engaged brake first held the drum; `None` while
    /// the brake is free, and until the first reading after it engaged.
    pub(super) held_at_count: Option<u32>,
}

/// The limits of the implied-tension checks, as tether torques at the drum (tension × r).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TensionJudge {
    /// Below this D̂ no tether can explain the motion, N m.
    pub(super) lowest_nm: f32,
    /// Above this neither, N m.
    pub(super) highest_nm: f32,
    /// The largest |D̂ − T_ff r| that is agreement, N m.
    pub(super) mismatch_nm: f32,
    /// Ticks a disagreement must last.
    pub(super) ticks: u32,
}

impl CrossChecks {
    /// Nothing judged yet, the load cell trusted.
    pub(super) const START: Self = Self {
        predicted_speed_mps: 0.0,
        implied_tether_nm: 0.0,
        unanswered_ticks: 0,
        mismatch_ticks: 0,
        load_cell_trusted: true,
        held_at_count: None,
    };

    /// Whether the feed-forward uses the load cell.
    pub(super) fn load_cell_trusted(&self) -> bool {
        self.load_cell_trusted
    }

    /// Trusts the load cell again, its disagreement counted afresh.
    pub(super) fn trust_load_cell(&mut self) {
        self.load_cell_trusted = true;
        self.mismatch_ticks = 0;
    }

    /// Restarts the observer at a release: the drum's speed as measured, the tether's torque
    /// as the feed-forward takes it. D̂ = K (J / r) (v − v̂) holds that torque when the model's
    /// speed lags the measured one by D̂ / (K J / r); `mps_per_nm` = r / (K J).
    pub(super) fn start_observer(&mut self, speed_mps: f32, tether_nm: f32, mps_per_nm: f32) {
        self.predicted_speed_mps = speed_mps - tether_nm * mps_per_nm;
        self.implied_tether_nm = tether_nm;
        self.unanswered_ticks = 0;
        self.mismatch_ticks = 0;
    }

    /// One observer step: the drum now at `speed_mps`, the motor's torque less the model's
    /// friction `net_nm` since the last step, `speed_per_impulse` = Δt r / J (m/s per N m over
    /// the step) and `gain_nm_per_mps` = K J / r.
    pub(super) fn observe(
        &mut self,
        speed_mps: f32,
        net_nm: f32,
        speed_per_impulse: f32,
        gain_nm_per_mps: f32,
    ) {
        self.predicted_speed_mps += speed_per_impulse * (net_nm + self.implied_tether_nm);
        self.implied_tether_nm = gain_nm_per_mps * (speed_mps - self.predicted_speed_mps);
    }

    /// Judges the implied tether torque against `used_nm`, the torque of the tension the
    /// feed-forward uses (T_ff r), over `gap_ticks`: the fault a lasting disagreement is.
    /// `pinned` says whether the loop is at its limit, the duty saturated or the integral at
    /// its clamp (judged only once the load cell is dropped: a load cell that is wrong pins the
    /// loop too).
    pub(super) fn judge_tension(
        &mut self,
        used_nm: f32,
        pinned: bool,
        gap_ticks: u32,
        j: &TensionJudge,
    ) -> Option<DriveFault> {
        let implied_nm = self.implied_tether_nm;
        let trusted = self.load_cell_trusted;
        if trusted && (implied_nm - used_nm).abs() <= j.mismatch_nm {
            self.unanswered_ticks = 0;
            self.mismatch_ticks = 0;
            return None;
        }
        let unanswered =
            implied_nm < j.lowest_nm || implied_nm > j.highest_nm || (!trusted && pinned);
        if unanswered {
            // (Cannot wrap: below `ticks` ≤ 2³¹ − 1, for the drive trips at it, plus a gap
            // below 2³¹.)
            self.unanswered_ticks = self.unanswered_ticks.wrapping_add(gap_ticks);
            if self.unanswered_ticks >= j.ticks {
                return Some(DriveFault::NoResponse);
            }
            return None;
        }
        self.unanswered_ticks = 0;
        if trusted {
            // (Cannot wrap: below `ticks` while the load cell is trusted, for it is dropped at
            // `ticks` and trusted again from 0, plus a gap below 2³¹.)
            self.mismatch_ticks = self.mismatch_ticks.wrapping_add(gap_ticks);
            if self.mismatch_ticks >= j.ticks {
                self.load_cell_trusted = false;
                return Some(DriveFault::TensionMismatch);
            }
        }
        None
    }

    /// Whether the drum, at total count `total` with the brake engaged, has moved more than
    /// `slip_counts` from where the brake first held it.
    pub(super) fn brake_slipped(&mut self, total: u32, slip_counts: u32) -> bool {
        let held = *self.held_at_count.get_or_insert(total);
        (total.wrapping_sub(held) as i32).unsigned_abs() > slip_counts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A drum of J = 0.05 kg m² without friction, a tether torque of 2 N m against a motor
    /// torque of −1 N m: it accelerates at 20 rad/s², and the observer finds the 2 N m within
    /// a few of its time constants.
    #[test]
    fn the_observer_finds_the_torque_the_model_misses() {
        let (j_per_r, dt, k) = (0.5_f32, 1e-3_f32, 20.0_f32);
        let mut c = CrossChecks::START;
        c.start_observer(0.0, 0.0, 1.0 / (k * j_per_r));
        let mut v = 0.0_f32;
        for _ in 0..250 {
            v += dt * (-1.0 + 2.0) / j_per_r;
            c.observe(v, -1.0, dt / j_per_r, k * j_per_r);
        }
        // 250 ms is 5 time constants: e^−5 = 0.7 % of the step left.
        assert!(
            (c.implied_tether_nm - 2.0).abs() < 0.02,
            "{}",
            c.implied_tether_nm
        );
    }

    /// Restarted at a tether torque of 2 N m that the motor holds (−2 N m), the drum still:
    /// the observer goes on finding the 2 N m, without a transient.
    #[test]
    fn the_observer_restarts_at_the_torque_it_is_given() {
        let (j_per_r, dt, k) = (0.5_f32, 1e-3_f32, 20.0_f32);
        let mut c = CrossChecks::START;
        c.start_observer(0.3, 2.0, 1.0 / (k * j_per_r));
        for _ in 0..10 {
            c.observe(0.3, -2.0, dt / j_per_r, k * j_per_r);
            assert!(
                (c.implied_tether_nm - 2.0).abs() < 1e-4,
                "{}",
                c.implied_tether_nm
            );
        }
    }

    #[test]
    fn a_lasting_disagreement_is_a_fault_a_passing_one_is_not() {
        // (Torques of a 0.1 m drum: −2.5 … 22 N m is −25 … 220 N.)
        let j = TensionJudge {
            lowest_nm: -2.5,
            highest_nm: 22.0,
            mismatch_nm: 2.0,
            ticks: 10,
        };
        let judge = |c: &mut CrossChecks, implied_nm: f32, used_nm: f32| {
            c.implied_tether_nm = implied_nm;
            c.judge_tension(used_nm, false, 1, &j)
        };
        let mut c = CrossChecks::START;
        for _ in 0..9 {
            assert_eq!(judge(&mut c, -3.0, 2.0), None);
        }
        // A tick back in agreement restarts the count.
        assert_eq!(judge(&mut c, 2.0, 2.0), None);
        for _ in 0..9 {
            assert_eq!(judge(&mut c, -3.0, -0.5), None);
        }
        assert_eq!(judge(&mut c, -3.0, -0.5), Some(DriveFault::NoResponse));
        // Plausible but far from the load cell's: the load cell is dropped, once.
        let mut c = CrossChecks::START;
        for _ in 0..9 {
            assert_eq!(judge(&mut c, 2.0, 19.9), None);
        }
        assert_eq!(judge(&mut c, 2.0, 19.9), Some(DriveFault::TensionMismatch));
        assert!(!c.load_cell_trusted);
        // Trusted again, the disagreement must last its ticks once more.
        let mut again = c;
        again.trust_load_cell();
        for _ in 0..9 {
            assert_eq!(judge(&mut again, 2.0, 19.9), None);
        }
        assert_eq!(
            judge(&mut again, 2.0, 19.9),
            Some(DriveFault::TensionMismatch)
        );
        // Untrusted, only the plausibility is judged.
        for _ in 0..20 {
            assert_eq!(judge(&mut c, 2.0, 0.0), None);
        }
        for _ in 0..9 {
            assert_eq!(judge(&mut c, 23.0, 0.0), None);
        }
        assert_eq!(judge(&mut c, 23.0, 0.0), Some(DriveFault::NoResponse));
        // Untrusted, a pinned integral is a drum that does not answer; trusted, it is not
        // judged (a wrong load cell pins it too).
        c.implied_tether_nm = 2.0;
        assert_eq!(c.judge_tension(0.0, false, 1, &j), None);
        for _ in 0..9 {
            assert_eq!(c.judge_tension(0.0, true, 1, &j), None);
        }
        assert_eq!(
            c.judge_tension(0.0, true, 1, &j),
            Some(DriveFault::NoResponse)
        );
        let mut c = CrossChecks::START;
        c.implied_tether_nm = 2.0;
        for _ in 0..20 {
            assert_eq!(c.judge_tension(2.0, true, 1, &j), None);
        }
    }

    #[test]
    fn travel_under_the_engaged_brake_is_measured_from_where_it_first_held() {
        let mut c = CrossChecks::START;
        assert!(!c.brake_slipped(u32::MAX - 5, 100));
        assert!(!c.brake_slipped(94, 100));
        assert!(c.brake_slipped(95, 100));
        assert!(c.brake_slipped(u32::MAX - 107, 100));
    }
}
