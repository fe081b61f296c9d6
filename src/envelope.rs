//! The operating envelope: reel speed, reel acceleration, and the hard length limits (docking
//! and spool). The command never leaves it, whatever the law asks.
//!
//! Limits apply in this order: speed, then acceleration (the change from the previous command),
//! then the length limits, which win over the acceleration limit when they must. Near a length
//! limit the allowed speed toward it follows the braking curve v ≤ √(2 a d) (d: distance left,
//! a: acceleration limit), so the reel can stop within its acceleration limit; it is also held
//! to d/dt so that one period cannot carry the tether past the limit.

use crate::real::Real;

/// Rate, acceleration and length limits of the reel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Envelope<T> {
    /// Largest reel speed in either direction, m/s.
    pub max_rate_mps: T,
    /// Largest change of reel speed per second, m/s².
    pub max_accel_mps2: T,
    /// Shortest tether (docking), m.
    pub min_length_m: T,
    /// Longest tether (spool capacity), m.
    pub max_length_m: T,
}

/// Which limits acted on a command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Saturation {
    /// The speed limit.
    pub rate: bool,
    /// The acceleration limit.
    pub accel: bool,
    /// A length limit (docking or spool).
    pub length: bool,
}

impl<T: Real> Envelope<T> {
    /// Limits `requested_mps` given the previous command `previous_mps`, the best-known
    /// tether length `length_m` and the time `dt_s` since the previous command.
    ///
    /// The result is finite and within ±`max_rate_mps` whenever `previous_mps` is (a NaN
    /// request is treated as a request to keep the previous command).
    pub fn limit(
        &self,
        requested_mps: T,
        previous_mps: T,
        length_m: T,
        dt_s: T,
    ) -> (T, Saturation) {
        let mut sat = Saturation::default();
        let vmax = self.max_rate_mps;
        let mut y = if requested_mps.is_nan() {
            previous_mps
        } else {
            requested_mps
        };
        if y.abs() > vmax {
            sat.rate = true;
            y = y.clamp_to(-vmax, vmax);
        }
        let dv = self.max_accel_mps2 * dt_s;
        if (y - previous_mps).abs() > dv {
            sat.accel = true;
            y = y.clamp_to(previous_mps - dv, previous_mps + dv);
        }
        let two = T::from_f64(2.0);
        let up_room = (self.max_length_m - length_m).max(T::ZERO);
        let down_room = (length_m - self.min_length_m).max(T::ZERO);
        let up = (up_room / dt_s).min((two * self.max_accel_mps2 * up_room).sqrt());
        let down = -(down_room / dt_s).min((two * self.max_accel_mps2 * down_room).sqrt());
        if y > up || y < down {
            sat.length = true;
            y = y.clamp_to(down, up);
        }
        (y.clamp_to(-vmax, vmax), sat)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env() -> Envelope<f64> {
        Envelope {
            max_rate_mps: 10.0,
            max_accel_mps2: 0.1,
            min_length_m: 0.5,
            max_length_m: 40_000.0,
        }
    }

    #[test]
    fn inside_the_envelope_nothing_changes() {
        let (y, s) = env().limit(5.0, 4.95, 20_000.0, 1.0);
        assert_eq!(y, 5.0);
        assert_eq!(s, Saturation::default());
    }

    #[test]
    fn speed_then_acceleration() {
        let (y, s) = env().limit(30.0, 9.95, 20_000.0, 1.0);
        assert_eq!(y, 10.0);
        assert!(s.rate && !s.accel);
        let (y, s) = env().limit(-3.0, 2.0, 20_000.0, 1.0);
        assert!((y - 1.9).abs() < 1e-12);
        assert!(s.accel && !s.rate);
    }

    #[test]
    fn braking_curve_near_the_spool_end() {
        // 50 m left at 0.1 m/s²: at most √(2·0.1·50) = √10 m/s toward the limit.
        let (y, s) = env().limit(5.0, 5.0, 39_950.0, 1.0);
        assert!((y - 10f64.sqrt()).abs() < 1e-12 && s.length);
        // At the limit nothing more goes out, but winding in is allowed.
        assert_eq!(env().limit(1.0, 0.0, 40_000.0, 1.0).0, 0.0);
        assert_eq!(env().limit(-0.05, 0.0, 40_000.0, 1.0).0, -0.05);
    }

    #[test]
    fn docking_limit_holds() {
        let (y, s) = env().limit(-1.0, -0.1, 0.6, 1.0);
        assert!(
            s.length && y >= -0.1 - 1e-12 && 0.6 + y >= 0.5 - 1e-12,
            "{y}"
        );
    }

    #[test]
    fn nan_request_keeps_the_previous_command() {
        assert_eq!(env().limit(f64::NAN, 2.0, 100.0, 1.0).0, 2.0);
    }
}
