//! The drive's cross-checks: its sensors against each other and against its own drum model,
//! for the faults no single reading shows (docs/hazards.md, HZ-R1 to HZ-R3).
//!
//! **The tension the drum's motion implies.** With the brake free the drum obeys
//! J ω̇ = τ + T r − b ω − c sat(ω) ([`DrumModel`](super::DrumModel)); the drive knows τ (its
//! duty × τ_max, the driver in torque mode), ω (the encoder) and the model, so the tether's
//! torque T r is what is left. A generalised momentum observer (De Luca and Mattone, 2003)
//! estimates it without differentiating the speed: with p = J ω the drum's momentum,
//!
//! ```text
//! p̂ₖ = p̂ₖ₋₁ + Δt (τₖ₋₁ + D̂ₖ₋₁ − b ωₖ − c sat(ωₖ))      (the model's momentum)
//! D̂ₖ = K (pₖ − p̂ₖ)                                      (the torque it misses: T r)
//! ```
//!
//! so that D̂ follows the true tether torque as a first-order lag of bandwidth K
//! ([`FaultLimits::observer_bandwidth_radps`](super::FaultLimits::observer_bandwidth_radps)),
//! plus the model's own error (friction, inertia). T̂ = D̂ / r is the implied tension. It
//! restarts at each release of the brake from the load cell's tension (no transient), and is
//! judged only while the drum is driven (released, not at rest, with a measured speed):
//!
//! - T̂ beyond the plausible range [min, max] by more than `tension_mismatch_n`: no tether can
//!   explain how the drum moves under the motor (a frozen encoder with the drum running away,
//!   a seized drum): [`DriveFault::NoResponse`], tripped;
//! - T̂ inside it but `tension_mismatch_n` away from the load cell's reading: the load cell is
//!   wrong, [`DriveFault::TensionMismatch`], and the drive stops using it.
//!
//! Each must last `no_response_ticks`. The third check needs no model: an integral pinned at
//! its clamp (± τ_max) for `no_response_ticks` is a drive whose drum does not answer the
//! torque (its error has not shrunk however long it integrated): [`DriveFault::NoResponse`].
//!
//! **Motion with the brake engaged.** The odometer counts the drum whatever the brake: a travel
//! of more than `brake_slip_m` from where the engaged brake first held it is a slipping brake,
//! [`DriveFault::BrakeSlip`].

use super::DriveFault;

/// The state of the cross-checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CrossChecks {
    /// The drum's momentum the model predicts, p̂, N m s.
    predicted_momentum_nms: f32,
    /// The tether's torque at the drum the observer finds, D̂ = T̂ r, N m.
    pub(super) implied_tether_nm: f32,
    /// Consecutive judged ticks with T̂ beyond any tether.
    implausible_ticks: u32,
    /// Consecutive judged ticks with T̂ away from the load cell.
    mismatch_ticks: u32,
    /// Consecutive driven ticks with the integral at its clamp.
    pub(super) pinned_ticks: u32,
    /// Whether the feed-forward uses the load cell (false after
    /// [`DriveFault::TensionMismatch`], until `clear_trip`).
    pub(super) load_cell_trusted: bool,
    /// The total count (modulo 2³²) where the engaged brake first held the drum; `None` while
    /// the brake is free, and until the first reading after it engaged.
    pub(super) held_at_count: Option<u32>,
}

/// The limits of the implied-tension checks, N at the drum's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TensionJudge {
    /// Below this T̂ no tether can explain the motion, N.
    pub(super) lowest_n: f32,
    /// Above this neither, N.
    pub(super) highest_n: f32,
    /// The largest |T̂ − reading| that is agreement, N.
    pub(super) mismatch_n: f32,
    /// Ticks a disagreement must last.
    pub(super) ticks: u32,
}

impl CrossChecks {
    /// Nothing judged yet, the load cell trusted.
    pub(super) const START: Self = Self {
        predicted_momentum_nms: 0.0,
        implied_tether_nm: 0.0,
        implausible_ticks: 0,
        mismatch_ticks: 0,
        pinned_ticks: 0,
        load_cell_trusted: true,
        held_at_count: None,
    };

    /// Restarts the observer at a release: the drum's momentum as measured, the tether's torque
    /// as the feed-forward takes it.
    pub(super) fn start_observer(&mut self, momentum_nms: f32, tether_nm: f32) {
        self.predicted_momentum_nms = momentum_nms;
        self.implied_tether_nm = tether_nm;
        self.implausible_ticks = 0;
        self.mismatch_ticks = 0;
    }

    /// One observer step over `dt_s`, the motor having applied `applied_nm` since the last one,
    /// the drum now at `momentum_nms` with the model's friction `friction_nm`.
    pub(super) fn observe(
        &mut self,
        momentum_nms: f32,
        applied_nm: f32,
        friction_nm: f32,
        dt_s: f32,
        gain_per_s: f32,
    ) {
        self.predicted_momentum_nms += dt_s * (applied_nm + self.implied_tether_nm - friction_nm);
        self.implied_tether_nm = gain_per_s * (momentum_nms - self.predicted_momentum_nms);
    }

    /// Judges the implied tension `implied_n` against the plausible range and against the load
    /// cell's `reading_n` (`None`: no usable reading this tick), over `gap_ticks`: the fault a
    /// lasting disagreement is.
    pub(super) fn judge_tension(
        &mut self,
        implied_n: f32,
        reading_n: Option<f32>,
        gap_ticks: u32,
        j: &TensionJudge,
    ) -> Option<DriveFault> {
        if implied_n < j.lowest_n || implied_n > j.highest_n {
            self.implausible_ticks = self.implausible_ticks.saturating_add(gap_ticks);
            if self.implausible_ticks >= j.ticks {
                return Some(DriveFault::NoResponse);
            }
        } else {
            self.implausible_ticks = 0;
        }
        match reading_n {
            Some(t) if self.load_cell_trusted && (implied_n - t).abs() > j.mismatch_n => {
                self.mismatch_ticks = self.mismatch_ticks.saturating_add(gap_ticks);
                if self.mismatch_ticks >= j.ticks {
                    self.load_cell_trusted = false;
                    return Some(DriveFault::TensionMismatch);
                }
            }
            _ => self.mismatch_ticks = 0,
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
        let (j, dt, k) = (0.05_f32, 1e-3_f32, 20.0_f32);
        let mut c = CrossChecks::START;
        c.start_observer(0.0, 0.0);
        let mut w = 0.0_f32;
        for _ in 0..250 {
            w += dt * (-1.0 + 2.0) / j;
            c.observe(j * w, -1.0, 0.0, dt, k);
        }
        // 250 ms is 5 time constants: e^−5 = 0.7 % of the step left.
        assert!(
            (c.implied_tether_nm - 2.0).abs() < 0.02,
            "{}",
            c.implied_tether_nm
        );
    }

    #[test]
    fn a_lasting_disagreement_is_a_fault_a_passing_one_is_not() {
        let j = TensionJudge {
            lowest_n: -25.0,
            highest_n: 220.0,
            mismatch_n: 20.0,
            ticks: 10,
        };
        let mut c = CrossChecks::START;
        for _ in 0..9 {
            assert_eq!(c.judge_tension(-30.0, Some(20.0), 1, &j), None);
        }
        // A tick back inside restarts the count.
        assert_eq!(c.judge_tension(20.0, Some(20.0), 1, &j), None);
        for _ in 0..9 {
            assert_eq!(c.judge_tension(-30.0, Some(-5.0), 1, &j), None);
        }
        assert_eq!(
            c.judge_tension(-30.0, Some(-5.0), 1, &j),
            Some(DriveFault::NoResponse)
        );
        // Plausible but far from the reading: the load cell is dropped, once.
        let mut c = CrossChecks::START;
        for _ in 0..9 {
            assert_eq!(c.judge_tension(20.0, Some(199.0), 1, &j), None);
        }
        assert_eq!(
            c.judge_tension(20.0, Some(199.0), 1, &j),
            Some(DriveFault::TensionMismatch)
        );
        assert!(!c.load_cell_trusted);
        for _ in 0..20 {
            assert_eq!(c.judge_tension(20.0, Some(199.0), 1, &j), None);
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
