//! The operating envelope: reel speed, reel acceleration, and the hard length limits (docking
//! and spool). The command never leaves it, whatever the law asks.
//!
//! Limits apply in this order: speed, then acceleration (the change from the previous command),
//! then the length limits, which win over the acceleration limit when they must. Near a length
//! limit the allowed speed toward it follows the *discrete* braking curve of a staircase of
//! decrements a·Δt (a: acceleration limit, Δt: the period, d: distance left). Stepping down from
//! v ∈ [m aΔt, (m+1) aΔt) to zero covers D(v) = Δt[(m+1) v − aΔt m(m+1)/2]; the largest v with
//! D(v) ≤ d is
//!
//! ```text
//!   m = ⌊√(1/4 + 2d/(aΔt²)) − 1/2⌋,      v = (d/Δt + aΔt m(m+1)/2) / (m+1),
//! ```
//!
//! and after one period at that speed the bound is exactly v − aΔt: the reel stops at the limit
//! without ever exceeding its acceleration limit (the continuous √(2ad), evaluated once a
//! period, would ask for up to 1.8 a). The distance
//! is measured to the limit less a guard of [`LENGTH_GUARD_REL`] × the limit, which covers the
//! f32 rounding of the sensed length.
//!
//! With the controller's protection ([`crate::config::ProtectionConfig`], docs/equations.md
//! §14) two more bounds enter: the tension bound, a window of commands inside the acceleration
//! window (the acceleration limit wins where they disagree), and the drive's overrun: a drive
//! with lag τ runs τ|v| beyond the commands before it stops, so the distance to a length limit
//! is measured less that overrun, which makes the staircase exact for the drive.

use crate::real::Real;

/// Guard kept from each length limit, relative to the limit (≈ one f32 ulp: 3.6 mm at 30 km),
/// so that the rounding of an f32 length cannot leave the tether resting just past it.
pub const LENGTH_GUARD_REL: f64 = 1.2e-7;

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

/// Which limits acted on a command: a set of bits, so that a step merges them into its status
/// flags with one OR ([`Saturation::RATE`], [`Saturation::ACCEL`] and [`Saturation::LENGTH`]
/// are the controller's `Flags` bits of the same names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Saturation(pub u32);

impl Saturation {
    /// The speed limit acted.
    pub const RATE: u32 = 1 << 0;
    /// The acceleration limit acted.
    pub const ACCEL: u32 = 1 << 1;
    /// A length limit (docking or spool) acted.
    pub const LENGTH: u32 = 1 << 2;
    /// The tension bound of the protection acted.
    pub const TENSION: u32 = 1 << 9;

    /// The speed limit acted.
    pub fn rate(self) -> bool {
        self.0 & Self::RATE != 0
    }
    /// The acceleration limit acted.
    pub fn accel(self) -> bool {
        self.0 & Self::ACCEL != 0
    }
    /// A length limit acted.
    pub fn length(self) -> bool {
        self.0 & Self::LENGTH != 0
    }
    /// The tension bound acted.
    pub fn tension(self) -> bool {
        self.0 & Self::TENSION != 0
    }
    /// Some limit acted.
    pub fn any(self) -> bool {
        self.0 != 0
    }
}

/// What the envelope needs from the protection at one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bounds<T> {
    /// The commands the tether carries, [lowest, highest], m/s, from the tension bound (None:
    /// no tension sample, or no protection). The envelope keeps its acceleration limit over it.
    pub(crate) tension_rate_mps: Option<(T, T)>,
    /// The commanded acceleration the tether carries, [lowest, highest], m/s² (the bound on
    /// Eq. 30's reported value; the drive's acceleration itself when it follows the command).
    pub(crate) tension_accel_mps2: Option<(T, T)>,
    /// How far the drive runs toward the spool end beyond the commands, m (τ·max(v, 0)).
    pub(crate) overrun_out_m: T,
    /// How far the drive runs toward docking beyond the commands, m (τ·max(−v, 0)).
    pub(crate) overrun_in_m: T,
    /// The share of the acceleration limit the braking staircase toward a length limit uses:
    /// (1 − e^{−h})/h with a lag (the drive's peak acceleration is then the limit), else 1.
    pub(crate) braking_fraction: T,
}

impl<T: Real> Bounds<T> {
    /// Nothing beyond the envelope (no protection configured).
    pub(crate) fn none() -> Self {
        Self {
            tension_rate_mps: None,
            tension_accel_mps2: None,
            overrun_out_m: T::ZERO,
            overrun_in_m: T::ZERO,
            braking_fraction: T::ONE,
        }
    }
}

impl<T: Real> Envelope<T> {
    /// Limits `requested_mps` given the previous command `previous_mps`, the best-known
    /// tether length `length_m` and the time `dt_s` since the previous command.
    ///
    /// The result is finite and within ±`max_rate_mps` whenever `previous_mps` is (a NaN
    /// request is treated as a request to keep the previous command).
    #[inline]
    pub fn limit(
        &self,
        requested_mps: T,
        previous_mps: T,
        length_m: T,
        dt_s: T,
    ) -> (T, Saturation) {
        let requested_mps = if requested_mps.is_nan() {
            previous_mps
        } else {
            requested_mps
        };
        PreparedEnvelope::new(*self).limit_request(
            requested_mps,
            previous_mps,
            length_m,
            dt_s,
            &Bounds::none(),
        )
    }

    /// The largest speed toward a limit `room_m` away from which the reel can still stop at
    /// it, decelerating by at most `accel_mps2`·Δt per period (see the module docs).
    fn braking_speed(room_m: T, dt_s: T, accel_mps2: T) -> T {
        let half = T::from_f64(0.5);
        let dv = accel_mps2 * dt_s;
        let m = ((T::from_f64(0.25) + T::from_f64(2.0) * room_m / (dv * dt_s)).sqrt() - half)
            .max(T::ZERO)
            .floor();
        // Rounding can leave v a hair above (m+1)·aΔt; the next m covers it.
        (room_m / dt_s + dv * m * (m + T::ONE) * half) / (m + T::ONE)
    }
}

/// An [`Envelope`] with the numbers every command needs worked out once (the controller keeps
/// one): 2a, and each length limit less its guard, each rounded once exactly as
/// [`Envelope::limit`] would form it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PreparedEnvelope<T> {
    env: Envelope<T>,
    /// 2a, m/s².
    two_accel_mps2: T,
    /// The spool limit less its guard, m.
    spool_guarded_m: T,
    /// The docking limit plus its guard, m.
    dock_guarded_m: T,
}

impl<T: Real> PreparedEnvelope<T> {
    pub(crate) fn new(env: Envelope<T>) -> Self {
        let guard = T::from_f64(LENGTH_GUARD_REL);
        Self {
            env,
            two_accel_mps2: T::from_f64(2.0) * env.max_accel_mps2,
            spool_guarded_m: env.max_length_m * (T::ONE - guard),
            dock_guarded_m: env.min_length_m * (T::ONE + guard),
        }
    }

    /// [`Envelope::limit`] for a request that is not NaN: the controller's (the law's
    /// solution is checked finite, a safe action asks for the previous command or zero), so the
    /// step does not test it again.
    ///
    /// `bounds` are the protection's: the tension window (inside the acceleration window: the
    /// acceleration limit wins) and the drive's overrun, by which the room to each length limit
    /// is shortened.
    // Inlined, as `limit_law`.
    #[inline(always)]
    pub(crate) fn limit_request(
        &self,
        requested_mps: T,
        previous_mps: T,
        length_m: T,
        dt_s: T,
        bounds: &Bounds<T>,
    ) -> (T, Saturation) {
        let env = &self.env;
        let mut sat = Saturation::default();
        let vmax = env.max_rate_mps;
        let mut y = requested_mps;
        if y.abs() > vmax {
            sat.0 |= Saturation::RATE;
            y = y.clamp_to(-vmax, vmax);
        }
        let dv = env.max_accel_mps2 * dt_s;
        if (y - previous_mps).abs() > dv {
            sat.0 |= Saturation::ACCEL;
            y = y.clamp_to(previous_mps - dv, previous_mps + dv);
        }
        if let Some((lo, hi)) = bounds.tension_rate_mps {
            let (lo, hi) = (lo.min(previous_mps + dv), hi.max(previous_mps - dv));
            if y > hi || y < lo {
                sat.0 |= Saturation::TENSION;
                y = y.clamp_to(lo, hi);
            }
        }
        // Only the length limit ahead of the motion can bind: the spool end when paying out,
        // docking when winding in. Far from it (the braking distance at y, plus two periods,
        // fits in the room left) the command passes as it is. (A negative room, past the
        // limit, is never far for a speed toward it; the braking curve sees it as zero.)
        // A lagging drive brakes on a staircase of a·(1 − e^{−h})/h per period: its peak
        // acceleration, just after each step, is then a (docs/equations.md §14).
        let two = T::from_f64(2.0);
        let brake_mps2 = env.max_accel_mps2 * bounds.braking_fraction;
        let far = |v: T, room: T| {
            v * (v / (self.two_accel_mps2 * bounds.braking_fraction) + two * dt_s) <= room
        };
        let (up, down) = if y > T::ZERO {
            let up_room = self.spool_guarded_m - length_m - bounds.overrun_out_m;
            if far(y, up_room) {
                return (Self::settle(y, vmax, sat), sat);
            }
            let up = Envelope::braking_speed(up_room.max(T::ZERO), dt_s, brake_mps2);
            (up, -vmax)
        } else if y < T::ZERO {
            let down_room = length_m - self.dock_guarded_m - bounds.overrun_in_m;
            if far(-y, down_room) {
                return (Self::settle(y, vmax, sat), sat);
            }
            let down = Envelope::braking_speed(down_room.max(T::ZERO), dt_s, brake_mps2);
            (vmax, -down)
        } else {
            // Zero (or NaN, when `previous_mps` is: the documented fallback is −vmax).
            return (y.clamp_to(-vmax, vmax), sat);
        };
        if y > up || y < down {
            sat.0 |= Saturation::LENGTH;
            y = y.clamp_to(down, up);
            let guard_m = env.max_length_m * T::from_f64(LENGTH_GUARD_REL);
            let (lo, hi) = (previous_mps - dv, previous_mps + dv);
            if y < lo && (lo - y) * dt_s <= guard_m {
                y = lo;
            } else if y > hi && (y - hi) * dt_s <= guard_m {
                y = hi;
            }
        }
        (y.clamp_finite(-vmax, vmax), sat)
    }

    /// The law's request limited ([`Self::limit_request`]) and the acceleration reported with
    /// it ([`Self::commanded_accel`]): the command, its acceleration, and every limit that acted
    /// on either.
    // Inlined into the step with constant bounds when there is no protection (the flight
    // configuration): out of line the outer step exceeded its ceiling (scripts/bench-target).
    #[inline(always)]
    pub(crate) fn limit_law(
        &self,
        requested_mps: T,
        eq30_mps2: T,
        previous_mps: T,
        length_m: T,
        dt_s: T,
        bounds: &Bounds<T>,
    ) -> (T, T, Saturation) {
        let (rate, sat) = self.limit_request(requested_mps, previous_mps, length_m, dt_s, bounds);
        let (accel, accel_sat) =
            self.commanded_accel(eq30_mps2, rate, previous_mps, dt_s, sat, bounds);
        (rate, accel, Saturation(sat.0 | accel_sat.0))
    }

    /// The acceleration reported with a command `rate_mps` that followed `previous_mps`: a
    /// limited command's slope over the period; otherwise Eq. 30's `eq30_mps2`, bounded like
    /// every commanded quantity (Eq. 30 is the law's derivative, which leaves the envelope where
    /// the law's rate jumps, a blend restart from a held rate) by the acceleration limit and by
    /// the tension bound (the acceleration limit wins). With an ideal reel it is the l̈ of
    /// Eq. 5a's tension (the paper's Fig. 4).
    // Inlined, as `limit_law`.
    #[inline(always)]
    pub(crate) fn commanded_accel(
        &self,
        eq30_mps2: T,
        rate_mps: T,
        previous_mps: T,
        dt_s: T,
        sat: Saturation,
        bounds: &Bounds<T>,
    ) -> (T, Saturation) {
        if sat.any() {
            return ((rate_mps - previous_mps) / dt_s, Saturation::default());
        }
        let amax = self.env.max_accel_mps2;
        let mut a = eq30_mps2;
        let mut sat = Saturation::default();
        if a.abs() > amax {
            sat.0 |= Saturation::ACCEL;
            a = a.clamp_finite(-amax, amax);
        }
        if let Some((lo, hi)) = bounds.tension_accel_mps2 {
            let (lo, hi) = (lo.min(amax), hi.max(-amax));
            if a > hi || a < lo {
                sat.0 |= Saturation::TENSION;
                a = a.clamp_finite(lo, hi);
            }
        }
        (a, sat)
    }

    /// The command when no length limit acts: `y` is already within ±`vmax` unless the
    /// acceleration clamp moved it (toward a `previous_mps` that could lie outside).
    fn settle(y: T, vmax: T, sat: Saturation) -> T {
        if sat.accel() || sat.tension() {
            y.clamp_finite(-vmax, vmax)
        } else {
            y
        }
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
        assert!(s.rate() && !s.accel());
        let (y, s) = env().limit(-3.0, 2.0, 20_000.0, 1.0);
        assert!((y - 1.9).abs() < 1e-12);
        assert!(s.accel() && !s.rate());
    }

    #[test]
    fn braking_curve_near_the_spool_end() {
        // 50 m left (less the guard) at 0.1 m/s², 1 s: 0.1 (√(1/4 + 2·d/0.1) − 1/2) m/s.
        // m = ⌊√(1/4 + 2d/0.1) − 1/2⌋ = 31, v = (d + 0.1·31·32/2)/32.
        let d = 40_000.0 * (1.0 - LENGTH_GUARD_REL) - 39_950.0;
        let (y, s) = env().limit(5.0, 5.0, 39_950.0, 1.0);
        let m = ((0.25 + 2.0 * d / 0.1_f64).sqrt() - 0.5).floor();
        assert_eq!(m, 31.0);
        let expect = (d + 0.1 * m * (m + 1.0) / 2.0) / (m + 1.0);
        assert!((y - expect).abs() < 1e-12 && s.length(), "{y} vs {expect}");
        // At the limit nothing more goes out, but winding in is allowed.
        assert_eq!(env().limit(1.0, 0.0, 40_000.0, 1.0).0, 0.0);
        assert_eq!(env().limit(-0.05, 0.0, 40_000.0, 1.0).0, -0.05);
    }

    #[test]
    fn docking_limit_holds() {
        let (y, s) = env().limit(-1.0, -0.1, 0.6, 1.0);
        assert!(
            s.length() && y >= -0.1 - 1e-12 && 0.6 + y >= 0.5 - 1e-12,
            "{y}"
        );
    }

    #[test]
    fn braking_to_a_limit_never_exceeds_the_acceleration_limit() {
        // From full speed 500 m before the spool end, the reel follows the curve down to rest
        // at the limit with every decrement within a·Δt.
        let e = env();
        let (mut l, mut v) = (39_500.0_f64, 10.0_f64);
        for _ in 0..2_000 {
            let (y, _) = e.limit(10.0, v, l, 1.0);
            assert!((y - v).abs() <= 0.1 * (1.0 + 1e-9), "{v} -> {y} at {l}");
            v = y;
            l += v;
            assert!(l <= 40_000.0, "past the spool end: {l}");
        }
        assert!(
            v.abs() < 1e-9 && 40_000.0 - l < 0.1,
            "stopped at {l} with {v}"
        );
    }

    #[test]
    fn nan_request_keeps_the_previous_command() {
        assert_eq!(env().limit(f64::NAN, 2.0, 100.0, 1.0).0, 2.0);
    }
}
