//! A simulated reel behind the drive's hardware traits: motor, drum, brake, encoder and load
//! cell in f32, for the QEMU firmware (which has no motor) and the host tests, as the replay
//! is behind the outer sensors' traits.
//!
//! The drum obeys J ω̇ = τ + T r − b ω − c sgn ω (pay-out positive, as
//! [`super::DrumModel`]), with stiction at rest (a drum at rest stays there while
//! |τ + T r| ≤ c), a motor torque τ = duty × τ_max in the direction pin's sense while the
//! driver is enabled, and a spring brake that adds [`SimDrum::brake_nm`] to the friction
//! while its pin is low (infinite, as built: it holds the drum whatever the torque). It is
//! deliberately not the speed loop's own model: [`SimDrum::mismatched`] has 10 % more inertia
//! and 20 % / 25 % more viscous / Coulomb friction than the drive feeds forward (as the host
//! tests' drum). The encoder counts the drum's angle as a wrapping hardware counter, the angle
//! kept as an integer count plus a fraction (no drift however long it runs); the load cell
//! reads the tether's pull, a constant (the recorded mission has no tension channel).
//!
//! One [`SimDrum::advance`] per inner tick (semi-implicit Euler, `substeps` per tick), after
//! the drive has set its outputs. The trait handles ([`SimEncoder`], [`SimLoadCell`],
//! [`SimPwm`], [`SimPin`]) share the drum through a `RefCell`, as four peripherals share one
//! motor; none of them fails.

use core::cell::RefCell;
use core::convert::Infallible;
use core::f32::consts::TAU;

use super::config::DriveConfig;
use super::hal::{ErrorKind, ErrorType, LoadCell, QuadratureEncoder};

/// The simulated motor, drum, brake and sensors.
#[derive(Clone, Debug, PartialEq)]
pub struct SimDrum {
    /// Inertia referred to the drum, kg m².
    pub inertia_kgm2: f32,
    /// Viscous friction, N m per rad/s.
    pub viscous_nm_per_radps: f32,
    /// Coulomb friction, N m.
    pub coulomb_nm: f32,
    /// Drum radius, m.
    pub radius_m: f32,
    /// Motor torque at duty 1, N m.
    pub max_torque_nm: f32,
    /// Encoder counts per drum revolution.
    pub counts_per_rev: f32,
    /// The hardware counter's width, bits.
    pub encoder_bits: u32,
    /// The tether's pull at the reel, N.
    pub tension_n: f32,
    /// The brake's holding torque, N m (`f32::INFINITY`: it never slips).
    pub brake_nm: f32,
    /// Integration substeps per [`SimDrum::advance`].
    pub substeps: u32,
    /// Drum rate, rad/s (pay-out positive).
    rate_radps: f32,
    /// Whole encoder counts turned since start.
    counts: i64,
    /// The fraction of a count turned beyond `counts`, in [0, 1).
    count_fraction: f32,
    /// The PWM duty, in counts of `max_duty`.
    duty_counts: u16,
    /// The PWM's full scale.
    max_duty: u16,
    /// Direction pin high (pay out).
    paying_out: bool,
    /// Brake pin high (released).
    brake_released: bool,
    /// Enable pin high (driver on).
    enabled: bool,
}

impl SimDrum {
    /// The drive's own drum model (`cfg.drum`, geometry and torque), at rest, brake engaged,
    /// pulled with `tension_n`.
    pub fn matching(cfg: &DriveConfig, tension_n: f32) -> Self {
        Self {
            inertia_kgm2: cfg.drum.inertia_kgm2,
            viscous_nm_per_radps: cfg.drum.viscous_nm_per_radps,
            coulomb_nm: cfg.drum.coulomb_nm,
            radius_m: cfg.geometry.drum_radius_m,
            max_torque_nm: cfg.max_torque_nm,
            counts_per_rev: cfg.geometry.counts_per_drum_rev() as f32,
            encoder_bits: cfg.geometry.encoder_bits,
            tension_n,
            brake_nm: f32::INFINITY,
            substeps: 4,
            rate_radps: 0.0,
            counts: 0,
            count_fraction: 0.0,
            duty_counts: 0,
            max_duty: 1000,
            paying_out: true,
            brake_released: false,
            enabled: false,
        }
    }

    /// As [`SimDrum::matching`], with 10 % more inertia and 20 % / 25 % more viscous / Coulomb
    /// friction than the drive's model: the feed-forward is not exact.
    pub fn mismatched(cfg: &DriveConfig, tension_n: f32) -> Self {
        let mut d = Self::matching(cfg, tension_n);
        d.inertia_kgm2 *= 1.1;
        d.viscous_nm_per_radps *= 1.2;
        d.coulomb_nm *= 1.25;
        d
    }

    /// Drum surface speed, m/s.
    pub fn speed_mps(&self) -> f32 {
        self.rate_radps * self.radius_m
    }

    /// Tether paid out since start, m.
    pub fn paid_out_m(&self) -> f32 {
        (self.counts as f32 + self.count_fraction) / self.counts_per_rev * TAU * self.radius_m
    }

    /// The motor torque the outputs ask for now, N m.
    fn motor_torque_nm(&self) -> f32 {
        if !self.enabled {
            return 0.0;
        }
        let magnitude =
            f32::from(self.duty_counts) / f32::from(self.max_duty.max(1)) * self.max_torque_nm;
        if self.paying_out {
            magnitude
        } else {
            -magnitude
        }
    }

    /// `dt_s` of motion under the outputs as they are set now.
    pub fn advance(&mut self, dt_s: f32) {
        let friction_nm = if self.brake_released {
            self.coulomb_nm
        } else {
            self.coulomb_nm + self.brake_nm
        };
        if !friction_nm.is_finite() {
            self.rate_radps = 0.0;
            return;
        }
        let h = dt_s / self.substeps.max(1) as f32;
        let drive_nm = self.motor_torque_nm() + self.tension_n * self.radius_m;
        let counts_per_rad = self.counts_per_rev / TAU;
        for _ in 0..self.substeps.max(1) {
            let w = self.rate_radps;
            let next = if w == 0.0 && drive_nm.abs() <= friction_nm {
                // Stiction (and the brake): the drum stays at rest.
                0.0
            } else {
                let sense = if w != 0.0 { w } else { drive_nm };
                let coulomb = if sense > 0.0 {
                    friction_nm
                } else {
                    -friction_nm
                };
                let accel =
                    (drive_nm - self.viscous_nm_per_radps * w - coulomb) / self.inertia_kgm2;
                let n = w + accel * h;
                // Friction stops the drum; it does not reverse it.
                if w != 0.0 && (n > 0.0) != (w > 0.0) {
                    0.0
                } else {
                    n
                }
            };
            self.count_fraction += 0.5 * (w + next) * h * counts_per_rad;
            let whole = libm::floorf(self.count_fraction);
            self.counts += whole as i64;
            self.count_fraction -= whole;
            self.rate_radps = next;
        }
    }

    /// The hardware counter: the whole counts, modulo 2^bits.
    pub fn raw_count(&self) -> u32 {
        let mask = if self.encoder_bits >= 32 {
            u32::MAX
        } else {
            (1_u32 << self.encoder_bits) - 1
        };
        (self.counts as u32) & mask
    }
}

/// The drum's encoder.
#[derive(Clone, Copy, Debug)]
pub struct SimEncoder<'a>(pub &'a RefCell<SimDrum>);

/// The tension load cell.
#[derive(Clone, Copy, Debug)]
pub struct SimLoadCell<'a>(pub &'a RefCell<SimDrum>);

/// The motor's PWM.
#[derive(Clone, Copy, Debug)]
pub struct SimPwm<'a>(pub &'a RefCell<SimDrum>);

/// Which of the motor driver's pins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PinRole {
    /// Direction (high: pay out).
    Direction,
    /// Brake (high: released).
    Brake,
    /// Driver enable (high: on).
    Enable,
}

/// One of the motor driver's pins.
#[derive(Clone, Copy, Debug)]
pub struct SimPin<'a>(pub &'a RefCell<SimDrum>, pub PinRole);

impl ErrorType for SimEncoder<'_> {
    type Error = ErrorKind;
}

impl QuadratureEncoder for SimEncoder<'_> {
    fn read_count(&mut self) -> Result<u32, ErrorKind> {
        // (Every borrow is one of these short, non-overlapping calls.)
        self.0
            .try_borrow()
            .map(|d| d.raw_count())
            .map_err(|_| ErrorKind::Device)
    }
}

impl ErrorType for SimLoadCell<'_> {
    type Error = ErrorKind;
}

impl LoadCell for SimLoadCell<'_> {
    fn read_tension_n(&mut self) -> Result<f32, ErrorKind> {
        self.0
            .try_borrow()
            .map(|d| d.tension_n)
            .map_err(|_| ErrorKind::Device)
    }
}

impl embedded_hal::pwm::ErrorType for SimPwm<'_> {
    type Error = Infallible;
}

impl embedded_hal::pwm::SetDutyCycle for SimPwm<'_> {
    fn max_duty_cycle(&self) -> u16 {
        self.0.try_borrow().map(|d| d.max_duty).unwrap_or(1)
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        if let Ok(mut d) = self.0.try_borrow_mut() {
            d.duty_counts = duty.min(d.max_duty);
        }
        Ok(())
    }
}

impl embedded_hal::digital::ErrorType for SimPin<'_> {
    type Error = Infallible;
}

impl embedded_hal::digital::OutputPin for SimPin<'_> {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.set(false);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        self.set(true);
        Ok(())
    }
}

impl SimPin<'_> {
    fn set(&self, high: bool) {
        if let Ok(mut d) = self.0.try_borrow_mut() {
            match self.1 {
                PinRole::Direction => d.paying_out = high,
                PinRole::Brake => d.brake_released = high,
                PinRole::Enable => d.enabled = high,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drum() -> SimDrum {
        SimDrum::matching(&DriveConfig::example(), 0.0)
    }

    #[test]
    fn the_brake_holds_whatever_the_torque() {
        let mut d = drum();
        d.enabled = true;
        d.duty_counts = 1000;
        d.tension_n = 100.0;
        for _ in 0..1000 {
            d.advance(1e-3);
        }
        assert_eq!(d.speed_mps(), 0.0);
        assert_eq!(d.raw_count(), 0);
    }

    #[test]
    fn a_constant_torque_reaches_the_viscous_speed_and_the_count_follows() {
        // τ − c = b ω at the end: ω = (τ − c) / b.
        let mut d = drum();
        d.brake_released = true;
        d.enabled = true;
        d.duty_counts = 100; // 0.5 N m
        let omega = (0.5 - d.coulomb_nm) / d.viscous_nm_per_radps;
        // Time constant J / b = 5 s: 60 s is 12 of them.
        for _ in 0..60_000 {
            d.advance(1e-3);
        }
        assert!(
            (d.rate_radps - omega).abs() < 1e-3 * omega,
            "{}",
            d.rate_radps
        );
        // The counted length is the integral of the speed: the paid-out length grows by
        // ω r per second at the end.
        let before = d.paid_out_m();
        for _ in 0..1000 {
            d.advance(1e-3);
        }
        let per_s = d.paid_out_m() - before;
        assert!((per_s - omega * d.radius_m).abs() < 1e-3 * omega * d.radius_m);
    }

    #[test]
    fn stiction_holds_a_drum_at_rest_below_the_coulomb_torque() {
        let mut d = drum();
        d.brake_released = true;
        d.enabled = true;
        d.duty_counts = 30; // 0.15 N m < c = 0.2 N m
        for _ in 0..1000 {
            d.advance(1e-3);
        }
        assert_eq!(d.speed_mps(), 0.0);
    }

    #[test]
    fn a_weak_brake_slips_under_a_torque_beyond_it() {
        // 20 N at 0.1 m is 2 N m: a 1 N m brake (with 0.2 N m of friction) slips, and the
        // drum accelerates at (2 − 1.2) / J, less its viscous friction (1 % by 0.1 s).
        let mut d = SimDrum::matching(&DriveConfig::example(), 20.0);
        d.brake_nm = 1.0;
        for _ in 0..100 {
            d.advance(1e-3);
        }
        let expect = 0.8 / d.inertia_kgm2 * 0.1 * d.radius_m;
        assert!(
            (d.speed_mps() - expect).abs() < 0.02 * expect,
            "{}",
            d.speed_mps()
        );
        let mut d = SimDrum::matching(&DriveConfig::example(), 20.0);
        d.brake_nm = 2.0;
        d.advance(1e-3);
        assert_eq!(d.speed_mps(), 0.0);
    }

    #[test]
    fn the_counter_wraps_at_its_width() {
        let mut d = drum();
        d.counts = 65_536 + 5;
        assert_eq!(d.raw_count(), 5);
        d.counts = -1;
        assert_eq!(d.raw_count(), 0xFFFF);
    }
}
