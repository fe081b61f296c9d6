//! The physical reel drive between the controller's rate command and the tether.
//!
//! An ideal reel (the paper's assumption, docs/equations.md §7) runs at the commanded rate at once. A real
//! drive lags and saturates: its rate v follows the command u as a first-order lag,
//! dv/dt = (g − v)/τ with g = u clamped to the drive's own rate limit, and |dv/dt| is clamped to
//! the drive's acceleration limit. Over one control period u is constant (zero-order hold), so
//! v(t) has a closed form: a ramp at the acceleration limit while the lag would demand more,
//! then the exponential approach. The plant integrates the tether with that v(t) (see
//! `sim`), and the tension of Eq. 5a takes l̈ = dv/dt.

/// A reel drive's parameters: its lag and its own saturation (separate from the controller's
/// envelope).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReelDrive {
    /// Lag time constant τ, s (0 = the rate follows the command at once).
    pub lag_s: f64,
    /// The drive's rate limit, m/s (inf = none).
    pub max_rate_mps: f64,
    /// The drive's acceleration limit, m/s² (inf = none).
    pub max_accel_mps2: f64,
}

impl ReelDrive {
    /// The ideal drive of the paper: no lag, no saturation.
    pub const IDEAL: Self = Self {
        lag_s: 0.0,
        max_rate_mps: f64::INFINITY,
        max_accel_mps2: f64::INFINITY,
    };

    /// `true` if the drive lags or saturates.
    pub fn is_ideal(&self) -> bool {
        *self == Self::IDEAL
    }
}

impl Default for ReelDrive {
    fn default() -> Self {
        Self::IDEAL
    }
}

/// The drive's lag and saturation, and its current rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reel {
    /// Lag time constant τ, s (0 = none).
    pub lag_s: f64,
    /// The drive's rate limit, m/s (inf = none).
    pub max_rate_mps: f64,
    /// The drive's acceleration limit, m/s² (inf = none).
    pub max_accel_mps2: f64,
    /// The actual reel rate l̇ now, m/s.
    pub rate_mps: f64,
}

/// How one control period went for the drive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReelSaturation {
    /// The command was beyond the drive's rate limit.
    pub rate: bool,
    /// The drive ran at its acceleration limit for part of the period.
    pub accel: bool,
}

impl Reel {
    /// The drive `cfg`, running at `initial_rate_mps` (clamped to its limit).
    pub fn new(cfg: &ReelDrive, initial_rate_mps: f64) -> Self {
        Self {
            lag_s: cfg.lag_s,
            max_rate_mps: cfg.max_rate_mps,
            max_accel_mps2: cfg.max_accel_mps2,
            rate_mps: initial_rate_mps.clamp(-cfg.max_rate_mps, cfg.max_rate_mps),
        }
    }

    /// `true` if the drive is the ideal one: no lag, no saturation (then v = u exactly).
    pub fn is_ideal(&self) -> bool {
        ReelDrive {
            lag_s: self.lag_s,
            max_rate_mps: self.max_rate_mps,
            max_accel_mps2: self.max_accel_mps2,
        }
        .is_ideal()
    }

    /// The rate the drive heads for under command `command_mps` (its own rate limit applied).
    pub fn target_mps(&self, command_mps: f64) -> f64 {
        command_mps.clamp(-self.max_rate_mps, self.max_rate_mps)
    }

    /// The rate `t_s` seconds after the command `command_mps` began, from the current rate.
    pub fn rate_after(&self, command_mps: f64, t_s: f64) -> f64 {
        let g = self.target_mps(command_mps);
        let d0 = g - self.rate_mps;
        if d0 == 0.0 {
            return g;
        }
        let a = self.max_accel_mps2;
        let tau = self.lag_s;
        // |g − v| shrinks at the acceleration limit while the lag would demand more than a
        // (|g − v|/τ > a, i.e. |g − v| > aτ), then exponentially with time constant τ.
        let knee = a * tau; // inf·0 cannot occur: tau = 0 with a = inf is handled below
        let gap = if tau == 0.0 {
            if a == f64::INFINITY {
                0.0
            } else {
                (d0.abs() - a * t_s).max(0.0)
            }
        } else if d0.abs() > knee {
            let t_ramp = (d0.abs() - knee) / a;
            if t_s <= t_ramp {
                d0.abs() - a * t_s
            } else {
                knee * (-(t_s - t_ramp) / tau).exp()
            }
        } else if t_s == 0.0 {
            d0.abs() // e^(−0/τ) = 1 exactly: the start of a period needs no exponential
        } else {
            d0.abs() * (-t_s / tau).exp()
        };
        g - d0.signum() * gap
    }

    /// The drive's acceleration dv/dt at `t_s` into the command, m/s².
    pub fn accel_after(&self, command_mps: f64, t_s: f64) -> f64 {
        let g = self.target_mps(command_mps);
        let v = self.rate_after(command_mps, t_s);
        let gap = g - v;
        if gap == 0.0 {
            return 0.0;
        }
        let demanded = if self.lag_s == 0.0 {
            gap.signum() * f64::INFINITY
        } else {
            gap / self.lag_s
        };
        demanded.clamp(-self.max_accel_mps2, self.max_accel_mps2)
    }

    /// Which limits act on a command held for `period_s` from the current rate.
    pub fn saturation(&self, command_mps: f64, period_s: f64) -> ReelSaturation {
        let g = self.target_mps(command_mps);
        let d0 = (g - self.rate_mps).abs();
        let needs_ramp = if self.lag_s == 0.0 {
            d0 > 0.0 && self.max_accel_mps2 < f64::INFINITY
        } else {
            d0 > self.max_accel_mps2 * self.lag_s
        };
        ReelSaturation {
            rate: g != command_mps,
            accel: needs_ramp && period_s > 0.0,
        }
    }

    /// Holds `command_mps` for `period_s`: the drive's rate at the end of the period.
    pub fn advance(&mut self, command_mps: f64, period_s: f64) {
        self.rate_mps = self.rate_after(command_mps, period_s);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reel(lag_s: f64, max_rate_mps: f64, max_accel_mps2: f64, rate_mps: f64) -> Reel {
        Reel {
            lag_s,
            max_rate_mps,
            max_accel_mps2,
            rate_mps,
        }
    }

    #[test]
    fn the_ideal_reel_runs_at_the_command() {
        let r = Reel::new(&ReelDrive::IDEAL, 0.1);
        assert!(r.is_ideal());
        assert_eq!(r.rate_after(3.0, 0.0), 3.0);
        assert_eq!(r.rate_after(3.0, 0.5), 3.0);
        assert_eq!(r.accel_after(3.0, 0.5), 0.0);
        assert_eq!(r.saturation(3.0, 1.0), ReelSaturation::default());
    }

    #[test]
    fn a_pure_lag_is_exponential() {
        let r = reel(2.0, f64::INFINITY, f64::INFINITY, 0.0);
        let v = r.rate_after(1.0, 2.0);
        assert!((v - (1.0 - (-1.0f64).exp())).abs() < 1e-15, "{v}");
        assert!((r.accel_after(1.0, 0.0) - 0.5).abs() < 1e-15);
        assert!((r.accel_after(1.0, 2.0) - (1.0 - v) / 2.0).abs() < 1e-15);
    }

    #[test]
    fn acceleration_limit_ramps_then_the_lag_takes_over() {
        // Gap 1 m/s, τ = 2 s, a = 0.1 m/s²: the lag alone would demand 0.5 m/s². Ramp until
        // the gap is aτ = 0.2 m/s (8 s), then exponential.
        let r = reel(2.0, f64::INFINITY, 0.1, 0.0);
        assert!((r.rate_after(1.0, 4.0) - 0.4).abs() < 1e-12);
        assert_eq!(r.accel_after(1.0, 4.0), 0.1);
        assert!((r.rate_after(1.0, 8.0) - 0.8).abs() < 1e-12);
        let v10 = r.rate_after(1.0, 10.0);
        assert!((v10 - (1.0 - 0.2 * (-1.0f64).exp())).abs() < 1e-12);
        assert!(r.saturation(1.0, 1.0).accel);
        // Continuous at the knee.
        assert!((r.rate_after(1.0, 8.0 - 1e-9) - r.rate_after(1.0, 8.0 + 1e-9)).abs() < 1e-9);
        // And downward.
        let r = reel(0.0, f64::INFINITY, 0.1, 1.0);
        assert!((r.rate_after(-1.0, 5.0) - 0.5).abs() < 1e-12);
        assert_eq!(r.accel_after(-1.0, 5.0), -0.1);
        assert_eq!(r.rate_after(-1.0, 25.0), -1.0);
        assert_eq!(r.accel_after(-1.0, 25.0), 0.0);
    }

    #[test]
    fn at_the_start_of_a_period_the_rate_is_the_exponential_at_zero() {
        for (lag, rate, command) in [(0.5, 0.3, 2.0), (2.0, -1.0, -1.5), (1.0, 4.0, 3.999)] {
            let r = reel(lag, f64::INFINITY, f64::INFINITY, rate);
            let g = r.target_mps(command);
            let d0 = g - r.rate_mps;
            let expect = g - d0.signum() * (d0.abs() * (-0.0 / lag).exp());
            assert_eq!(r.rate_after(command, 0.0).to_bits(), expect.to_bits());
        }
    }

    #[test]
    fn rate_limit_clamps_the_target() {
        let mut r = reel(0.0, 10.0, f64::INFINITY, 0.0);
        assert_eq!(r.rate_after(13.0, 0.5), 10.0);
        assert!(r.saturation(13.0, 1.0).rate && !r.saturation(9.0, 1.0).rate);
        r.advance(-13.0, 1.0);
        assert_eq!(r.rate_mps, -10.0);
    }
}
