//! The speed loop's reference: a ramp toward the commanded rate (module docs of
//! [`super`], step 2).

use super::config::DriveConfig;

/// What shapes every ramp, worked out once from the configuration (so that the ramp has no
/// division but the one of its length).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct RampLimits {
    /// The inner ticks per second, 1/s.
    ticks_per_s: f32,
    /// The inner tick, s.
    tick_s: f32,
    /// Law periods per second: the slope that reaches a command within one period is its
    /// change times this, 1/s.
    outer_period_per_s: f32,
    /// The steepest slope, m/s².
    max_accel_mps2: f32,
}

impl RampLimits {
    /// The limits of a validated configuration.
    pub(super) fn new(cfg: &DriveConfig) -> Self {
        Self {
            ticks_per_s: cfg.inner_rate_hz as f32,
            tick_s: cfg.tick_s(),
            outer_period_per_s: cfg.inner_rate_hz as f32 / cfg.outer_period_ticks as f32,
            max_accel_mps2: cfg.max_accel_mps2,
        }
    }
}

/// The ramp the reference follows toward the commanded rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Ramp {
    /// Reference at `start_tick`, m/s.
    pub(super) start_mps: f32,
    pub(super) start_tick: u32,
    /// The commanded rate it stops at, m/s.
    pub(super) target_mps: f32,
    /// Signed slope toward the target (0 if already there), m/s².
    pub(super) slope_mps2: f32,
    /// The slope × tick: the reference's change per tick, m/s.
    pub(super) step_mps: f32,
    /// Ticks from `start_tick` until the target is reached (integer time: the reference is the
    /// target from then on, and never passes it before).
    pub(super) ramp_ticks: u32,
}

impl Ramp {
    /// At rest, and staying there.
    pub(super) const REST: Self = Self {
        start_mps: 0.0,
        start_tick: 0,
        target_mps: 0.0,
        slope_mps2: 0.0,
        step_mps: 0.0,
        ramp_ticks: 0,
    };

    /// The ramp from `start_mps` at `tick` toward the commanded rate `target_mps` (finite):
    /// its slope is the command's (Eq. 30) acceleration `accel_mps2` if that points toward the
    /// target, at least what reaches the target within one law period, at most the limits'
    /// steepest.
    pub(super) fn toward(
        target_mps: f32,
        accel_mps2: f32,
        start_mps: f32,
        tick: u32,
        limits: &RampLimits,
    ) -> Self {
        let dv = target_mps - start_mps;
        let law = if accel_mps2 * dv > 0.0 {
            accel_mps2.abs()
        } else {
            0.0
        };
        let per_period = dv.abs() * limits.outer_period_per_s;
        let fastest = if law > per_period { law } else { per_period };
        let magnitude = if fastest > limits.max_accel_mps2 {
            limits.max_accel_mps2
        } else {
            fastest
        };
        // Whole ticks to the target, rounded up (`as` saturates; 0 when already there).
        let ticks = dv.abs() / magnitude * limits.ticks_per_s;
        let whole = ticks as u32;
        let slope_mps2 = magnitude.copysign(dv);
        Self {
            start_mps,
            start_tick: tick,
            target_mps,
            slope_mps2,
            step_mps: slope_mps2 * limits.tick_s,
            ramp_ticks: if (whole as f32) < ticks {
                whole.saturating_add(1)
            } else {
                whole
            },
        }
    }

    /// The reference speed and acceleration at `tick`: the ramp, stopped at its target. (Only
    /// used while the brake is free; the ramp restarts from rest when it is released.)
    pub(super) fn at(&self, tick: u32) -> (f32, f32) {
        let age_ticks = tick.wrapping_sub(self.start_tick);
        if age_ticks >= self.ramp_ticks {
            (self.target_mps, 0.0)
        } else {
            (
                self.start_mps + self.step_mps * age_ticks as f32,
                self.slope_mps2,
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Brake, DriveConfig, DriveInput, RateCommand, SpeedLoop};

    fn command(rate_mps: f32, accel_mps2: f32) -> RateCommand {
        RateCommand {
            rate_mps,
            accel_mps2,
            safe_hold: false,
        }
    }

    #[test]
    fn the_ramp_meets_the_command_within_a_period_and_never_passes_it() {
        let mut s = SpeedLoop::new(DriveConfig::example()).unwrap();
        // A limited command: 1 m/s reached at 1 m/s² (Eq. 30 value = the ramp's slope).
        s.set_command(command(1.0, 1.0), 0).unwrap();
        assert_eq!(s.ramp.at(500), (0.5, 1.0));
        assert_eq!(s.ramp.at(1000), (1.0, 0.0));
        assert_eq!(s.ramp.at(5000), (1.0, 0.0));
        // With the brake free, the next command ramps from the reference; an acceleration
        // pointing away from the command does not move the reference away.
        s.brake = Brake::Released { rest_ticks: 0 };
        s.set_command(command(0.5, 2.0), 1000).unwrap();
        let (v, a) = s.ramp.at(1500);
        assert!((v - 0.75).abs() < 1e-6 && a == -0.5, "{v} {a}");
    }

    /// The drive flying a drum that follows its reference exactly (the encoder counts the
    /// reference's travel), under 20 N.
    struct Follower {
        s: SpeedLoop,
        travel_m: f64,
        m_per_count: f64,
    }

    impl Follower {
        fn step(&mut self, tick: u32) -> Brake {
            let count = (self.travel_m / self.m_per_count).floor() as i64 as u32;
            self.s.step(&DriveInput {
                tick,
                encoder_count: Some(count),
                tension_n: Some(20.0),
            });
            let out = self.s.output();
            self.travel_m += f64::from(out.ref_rate_mps) * 1e-3;
            out.brake
        }
    }

    #[test]
    fn the_ramp_starts_from_rest_at_every_release() {
        let cfg = DriveConfig::example();
        let mut f = Follower {
            s: SpeedLoop::new(cfg).unwrap(),
            travel_m: 0.0,
            m_per_count: f64::from(cfg.geometry.m_per_count()),
        };
        // 1 m/s at 1 m/s², commanded while the brake is on: the ramp starts at the release.
        f.s.set_command(command(1.0, 1.0), 0).unwrap();
        let mut tick = 0;
        while !matches!(f.step(tick), Brake::Released { .. }) {
            tick += 1;
        }
        let released = tick;
        assert!(released > 0);
        assert_eq!(f.s.output().ref_rate_mps, 0.0);
        for t in released + 1..=released + 500 {
            f.step(t);
        }
        assert!((f.s.output().ref_rate_mps - 0.5).abs() < 1e-6);
        assert!(f.s.output().faults.is_empty(), "{:?}", f.s.output());
        // Tripped mid-ramp and cleared, under the same command: the drum was held, so the
        // next release starts the ramp from rest again (not from where it stood).
        f.s.trip(super::super::DriveFault::Actuator);
        f.s.clear_trip();
        let mut tick = released + 501;
        while !matches!(f.step(tick), Brake::Released { .. }) {
            tick += 1;
        }
        assert_eq!(f.s.output().ref_rate_mps, 0.0);
        for t in tick + 1..=tick + 100 {
            f.step(t);
        }
        assert!((f.s.output().ref_rate_mps - 0.1).abs() < 1e-6);
    }
}
