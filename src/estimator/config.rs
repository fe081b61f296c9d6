//! The estimator's parameters and their validation.

use crate::real::Real;

/// The largest |α̇̂| a prediction may reach, rad/s (a thousand times the orbit rate; beyond it
/// the estimate has diverged: [`Prediction::Diverged`](super::Prediction::Diverged)).
pub const MAX_ALPHA_RATE_RADPS: f64 = 1.0;

/// The estimator's parameters. Validated once by [`Estimator::new`](super::Estimator::new).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config<T> {
    /// Control period h, s.
    pub period_s: T,
    /// σ_α, the standard deviation of the swing sensor's α noise per sample, rad.
    pub alpha_noise_rad: T,
    /// The swing sensor's quantum, rad (0: not quantised); adds quantum²/12 to R.
    pub alpha_quantum_rad: T,
    /// √q_α̈: the density of the white noise on α̈, rad/s² per √Hz (rad·s^-3/2).
    pub accel_noise_density: T,
    /// √q_d: the density of the random walk of the disturbance d, rad/s² per √s
    /// (rad·s^-5/2).
    pub disturbance_drift_density: T,
    /// σ of α̇ at the start (and the cap on its variance), rad/s.
    pub initial_rate_std_radps: T,
    /// σ of d at the start (and the cap on its variance), rad/s².
    pub initial_disturbance_std_radps2: T,
    /// The χ² (one degree of freedom) gate on the NIS: samples above it are rejected.
    pub gate_nis: T,
    /// Consecutive rejections after which the next sample restarts α.
    pub max_rejections: u16,
}

impl<T: Real> Config<T> {
    /// The tuning for the paper's mission with a swing sensor of σ_α = 1e-4 rad at 1 s (the
    /// module docs say what each figure covers):
    ///
    /// - d's drift, 1e-11 rad/s² per √s. The disturbances d stands for change smoothly, by at
    ///   most ~3e-9 rad/s² over a quarter orbit (≈ 1 500 s). The filter's bandwidth is
    ///   (q_d/(σ_α² h))^(1/6) ≈ 5e-3 rad/s, a time constant of about 200 s, so it follows them;
    ///   a larger drift widens it (as q_d^(1/6)) and raises α̇̂'s noise (as q_d^(1/4)).
    /// - α̈ white noise 1e-9 rad/s² per √Hz, far below d's effect over a period and far above
    ///   the f32 rounding of α̇̂ (an ulp of 7e-12 rad/s per period).
    /// - At the start, α̇ within σ = 2e-3 rad/s (twice the orbit rate: any swing the law
    ///   survives) and d within 1e-6 rad/s².
    /// - The gate 16 (4σ); 10 consecutive rejections restart α.
    pub fn paper() -> Self {
        Self {
            period_s: T::ONE,
            alpha_noise_rad: T::from_f64(1e-4),
            alpha_quantum_rad: T::ZERO,
            accel_noise_density: T::from_f64(1e-9),
            disturbance_drift_density: T::from_f64(1e-11),
            initial_rate_std_radps: T::from_f64(2e-3),
            initial_disturbance_std_radps2: T::from_f64(1e-6),
            gate_nis: T::from_f64(16.0),
            max_rejections: 10,
        }
    }

    /// Checks every parameter against its admitted range (chosen so that the filter's
    /// variances and products stay finite and its divisions defined in f32); the first
    /// violation is returned.
    pub fn validate(&self) -> Result<(), ConfigError> {
        in_range("period_s", self.period_s, 0.05, 10.0)?;
        in_range("alpha_noise_rad", self.alpha_noise_rad, 1e-6, 0.5)?;
        in_range("alpha_quantum_rad", self.alpha_quantum_rad, 0.0, 0.5)?;
        in_range("accel_noise_density", self.accel_noise_density, 0.0, 1e-2)?;
        in_range(
            "disturbance_drift_density",
            self.disturbance_drift_density,
            1e-14,
            1e-4,
        )?;
        in_range(
            "initial_rate_std_radps",
            self.initial_rate_std_radps,
            1e-8,
            MAX_ALPHA_RATE_RADPS,
        )?;
        in_range(
            "initial_disturbance_std_radps2",
            self.initial_disturbance_std_radps2,
            1e-12,
            1e-2,
        )?;
        in_range("gate_nis", self.gate_nis, 1.0, 1e4)?;
        if self.max_rejections == 0 {
            return Err(ConfigError {
                param: "max_rejections",
                value: 0.0,
                min: 1.0,
                max: f64::from(u16::MAX),
            });
        }
        Ok(())
    }
}

/// `value` in [min, max] (NaN is not), or the error naming `param`. The bounds are compared
/// in `T` (so an f32 configuration may use the bounds themselves).
fn in_range<T: Real>(param: &'static str, value: T, min: f64, max: f64) -> Result<(), ConfigError> {
    if value >= T::from_f64(min) && value <= T::from_f64(max) {
        Ok(())
    } else {
        Err(ConfigError {
            param,
            value: value.to_f64(),
            min,
            max,
        })
    }
}

/// A rejected estimator parameter: its name (the field of [`Config`]), its value and the
/// range it must lie in.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConfigError {
    /// The field, e.g. `alpha_noise_rad`.
    pub param: &'static str,
    /// The offending value (widened to f64; NaN if it was NaN).
    pub value: f64,
    /// The smallest admitted value.
    pub min: f64,
    /// The largest admitted value.
    pub max: f64,
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "invalid estimator parameter {} = {}: must be in [{}, {}]",
            self.param, self.value, self.min, self.max
        )
    }
}
