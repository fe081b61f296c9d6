//! The onboard libration estimator: an extended Kalman filter on the in-plane dynamics
//! (Eq. 5b / 26 with β = 0) that estimates α and α̇ from a swing-angle sensor that measures α
//! only (no flight sensor measures α̇).
//!
//! # Model
//!
//! State x = (α, α̇, d): the in-plane angle, its rate, and d, an unmodelled angular
//! acceleration (a disturbance torque per unit inertia). Between samples, in the orbit plane
//! (β = 0), Eq. 5b reads
//!
//! ```text
//!   α̈ = −(θ̇ + α̇) s(t) − (3μ/(2R³)) sin 2α − θ̈ + d,    s = (2 + μ3) l̇/l,    ḋ = white noise,
//! ```
//!
//! driven by the reel's known rate and acceleration and the orbit's θ̇, θ̈ and μ/R³ ([`Drive`];
//! n, 0 and n² on a circular orbit, where it is Eq. 26's −(n + α̇) s − 1.5 n² sin 2α); α̈ also
//! receives white noise. d absorbs what the model leaves out: out-of-plane coupling (2β̇ tanβ
//! terms), tether elasticity, errors of the reel's rate or length or of the orbit's terms, and
//! an α-sensor bias (see *Observability*).
//!
//! # Discretisation (one control period h)
//!
//! The reel's rate is taken as a ramp over the period, l̇(t) = v + a t, and s is frozen at
//! its value at mid-period, s = (2 + μ3)(v + a h/2)/(l + v h/2 + a h²/8) (the midpoint rule:
//! second order in h). The Jacobian of the model at the current estimate is
//!
//! ```text
//!       [  0    1   0 ]
//!   A = [ −κ   −s   1 ],    κ = (3μ/R³) cos 2α̂ (the gravity-gradient stiffness),
//!       [  0    0   0 ]
//! ```
//!
//! and the estimate moves by the local-linearisation (exponential-Euler) step
//! x⁺ = x + h φ₁(Ah) f(x), φ₁(Z) = (e^Z − I)/Z, exact for the linearised model and with a
//! local error O(h³) for the nonlinear one; the covariance moves with Φ = e^{Ah} = I + h A φ₁(Ah).
//! φ₁ is its Taylor series to (Ah)³/24. With u = s h and k = κ h², the series' first neglected
//! term is of relative size (|u| + |k|)⁴/120: at most 5·10⁻⁴ inside the admitted
//! |u| ≤ [`MAX_STRETCH_PER_PERIOD`], 1.1·10⁻⁵ at the paper's release (l = 1 m, l̇ = 0.1 m/s,
//! u = 0.19), below 10⁻¹⁰ beyond l ≈ 20 m. The whole step's error against the simulator's plant
//! integrated finely (`tests/estimator/model_and_faults.rs::one_period_matches_the_plant`) is larger at the
//! release, where s changes by 10 % within the period and the midpoint rule dominates:
//! 7·10⁻⁴ of the period's α̇ change (1.3e-7 rad/s) and 1.5e-6 rad in α; 1.5·10⁻⁵ of it at
//! l = 20 m; from 100 m on, below 1e-10 rad and 1e-13 rad/s. Against σ_α = 1e-4 rad and an
//! α̇ uncertainty above 1e-7 rad/s at the release, the first minutes included, the period's
//! discretisation is not a noticeable error source. Against the period, the error grows as h³
//! (`::the_discretisation_error_against_the_period`: at l = 100 m, l̇ = 2 m/s, α̇ errs by
//! 4.7e-10 rad/s at h = 1 s, 4.5e-8 at 5 s, 2.7e-7 at 10 s; at 9 km, 6.2e-12 rad/s at 10 s).
//!
//! # Observability (what α alone reveals)
//!
//! With H = (1 0 0): H, HA = (0 1 0) and HA² = (−κ −s 1) are independent whatever κ and s, so
//! α, α̇ and d are always observable. An α-sensor **bias** b is a different matter: appended
//! as a fourth state (H = (1 0 1 0)), the observability matrix has rank 3 with d (a constant
//! bias and a constant torque d = κ b move the sensed equilibrium alike), and even without d
//! its rank drops where κ = 0, i.e. at α = ±45°, the whole deployment plateau of Eq. 34: a
//! bias is observable only through the gravity-gradient stiffness, over a libration period
//! (≈ 57 min). This filter therefore estimates d, not b: a bias b makes α̂ read α + b (no
//! filter on α alone can do better; the law then holds α_r − b), while α̇̂ stays unbiased
//! because d̂ → κ b takes up the stiffness mismatch: with a 1e-3 rad bias, in stage 1 of the
//! paper's mission from 1 h on, α̇̂'s error is 5.7e-8 rad/s RMS with a mean of −1.1e-8; the
//! same filter without d (its drift and prior at their floors) errs by 3.6e-6 rad/s RMS
//! (`tests/estimator/model_and_faults.rs::a_constant_sensor_bias_leaves_the_rate_unbiased`).
//!
//! # Tuning ([`Config::paper`]) and the noise it assumes
//!
//! - α noise σ_α = 1e-4 rad per sample (the flight sensor's floor), not quantised (a quantum q adds
//!   q²/12 to R).
//! - d drifts as a random walk of density 1e-11 rad/s² per √s: it spans 4e-10 rad/s² in a
//!   quarter orbit and 3e-9 rad/s² in a day. That covers, as slowly varying accelerations, a
//!   1e-3 rad α bias seen through κ (≤ 3n² b = 3.4e-9 rad/s²) and a 1 mm/s reel-rate error
//!   at 9 km (2n δl̇/l = 2.4e-10 rad/s²). It does not cover an eccentric orbit flown on the
//!   circular model: at e = 1e-3 (θ̈ up to 2e n² = 2.2e-9 rad/s², at orbital frequency) α̇̂
//!   errs by 1.7e-7 rad/s RMS in stage 1, 3.1e-8 with the true θ̈ and μ/R³ in the [`Drive`]
//!   (`tests/estimator/model_and_faults.rs::an_eccentric_orbit_needs_its_orbit_terms_in_the_drive`). The filter's bandwidth grows as q_d^(1/6), its α̇ noise
//!   roughly as q_d^(1/4): a faster drift buys tracking with noise.
//! - α̈ white noise of density 1e-9 rad/s² per √Hz: above the f32 rounding of one step.
//! - At the start, α̇ within σ = 2e-3 rad/s (twice the orbit rate: any swing the law
//!   survives) and d within 1e-6 rad/s².
//!
//! On the paper's mission with σ_α = 1e-4 rad (`tests/estimator.rs`), the f32 filter's α̇
//! error is 3.6e-8 rad/s RMS, 1.6e-7 rad/s at worst, and its sample-to-sample jitter equals
//! white noise of 2.8e-9 rad/s: far below the 1e-6 rad/s of white α̇ noise that slackens the
//! tether (docs/hazards.md O-5) and below the 1e-7 rad/s that does not. Over a Monte Carlo of
//! 50 missions whose truth carries exactly the assumed disturbances, the NEES averages 3.00
//! (3 degrees of freedom) and the NIS 1.00.
//!
//! # Gating and faults
//!
//! Each sample's innovation ν = z − α̂⁻ has variance S = P_αα⁻ + R; its normalised square
//! NIS = ν²/S is χ² with one degree of freedom when the filter is consistent. A sample with
//! NIS above [`Config::gate_nis`] (default 16: 4σ, a false rejection once in 16 000
//! samples) is **rejected**, reported as [`Measurement::Gated`], and the filter predicts
//! only. After [`Config::max_rejections`] consecutive rejections the next sample is taken as a
//! new start for α ([`Measurement::Reinitialised`]): a filter that gates everything out has
//! lost the sensor's track, and must not stay locked on its own prediction.
//!
//! # Covariance
//!
//! The covariance is stored as its upper triangle, so it is symmetric by construction. The
//! update is P⁺ = P⁻ − K pᵀ for the gain K = p/S (p = P⁻ e₁, P⁻'s α column; S = P_αα⁻ + R),
//! its α row evaluated as what it equals, R K (without the cancellation of p − P_αα⁻ K, which
//! loses the digits when P_αα⁻ ≫ R), its (α̇, d) block as P_ij − p_i K_j (see `Sym3::posterior`).
//! In exact arithmetic this is the Joseph form (I − KH) P⁻ (I − KH)ᵀ + K R Kᵀ for this gain.
//! The Joseph form's advantage, that an error δ of K enters P⁺ at second order only, is below
//! f32's resolution here: K is worked out from the same P⁻, so δ is K's own rounding, and the
//! first-order term p_i δ_j is at most two roundings of √(P_ii P_jj) (|p_i K_i| ≤ P_ii), the
//! size of the rounding the Joseph form itself carries in f32 (its correction c = p − S K is
//! that rounding). What keeps P positive semidefinite in f32 is the same for both
//! (`tests/estimator/model_and_faults.rs::updates_after_dropouts_of_any_length_keep_the_covariance_positive_definite`):
//! a negative rounding residue v on the diagonal becomes |v| (the residue cut to zero, plus the
//! non-negative diagonal |v|: positive semidefinite wherever the cut one is, and never less
//! certain), and the rounding load below. After each prediction a variance
//! above its cap ([`ALPHA_VARIANCE_CAP_RAD2`], the initial α̇ and d variances) is brought back
//! to the cap, its covariances scaled down with it (a congruence plus a non-negative diagonal,
//! which keeps P positive semidefinite), so a dropout of any length cannot overflow f32 and
//! ends no less certain than a fresh start. Each prediction also grows the variances by [`ROUNDING_LOAD`] of themselves,
//! the process noise of the f32 rounding: without it a dropout lasting hours takes P to rank
//! one, where rounding makes it indefinite.
//!
//! # Cost
//!
//! Plain scalars on the structure, not nalgebra matrices: Φ's d row is e₃ᵀ and P is symmetric,
//! so Φ P Φᵀ is 30 multiply-adds on the 6 stored entries; Ψ and Φ share two polynomials of the
//! series (12 operations), and the update of P for H = (1 0 0) is 3 products and 3
//! multiply-adds;
//! one sin_cos (of 2α̂, lent by the law in the controller) and two divisions a step.
//! `examples/bench_estimator.rs` counts a step's instructions on the Cortex-M4F over the paper
//! mission (with a sample, in a dropout, with a gated sample).

use crate::real::Real;

mod config;
mod covariance;
#[cfg(test)]
mod tests;

pub use config::{Config, ConfigError, MAX_ALPHA_RATE_RADPS};
pub use covariance::ROUNDING_LOAD;
use covariance::{above_or_nan, Sym3};

/// The largest |s h| = |(2 + μ3) l̇/l| h the one-step discretisation admits (see the module
/// docs: the Taylor series of φ₁ is then accurate to 5·10⁻⁴). The paper's release is 0.2.
pub const MAX_STRETCH_PER_PERIOD: f64 = 0.5;

/// The cap on α's variance, rad² (1 rad of standard deviation: beyond it α̂ says nothing).
pub const ALPHA_VARIANCE_CAP_RAD2: f64 = 1.0;

/// The largest orbit rate θ̇ a drive may give, rad/s (a 10⁻² rad/s orbit would be inside the
/// Earth); its square bounds |θ̈| and μ/R³, which keeps 3(μ/R³)h² small for the discretisation.
pub const MAX_ORBIT_RATE_RADPS: f64 = 1e-2;

/// The slowest circular orbit [`OrbitTerms::circular`] admits, rad/s (a year-long orbit is
/// 2·10⁻⁷ rad/s); its square stays a normal, positive f32.
pub const MIN_CIRCULAR_ORBIT_RATE_RADPS: f64 = 1e-10;

/// The longest tether a drive may give, m (a thousand kilometres: any real tether).
pub const MAX_LENGTH_M: f64 = 1e6;

/// The largest |μ3| a drive may give (μ3 of a tether lighter than its satellite is ≪ 1).
pub const MAX_MU3: f64 = 1.0;

/// What drove the libration over the period that just ended: the reel and the orbit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive<T> {
    /// l at the start of the period, m.
    pub length_m: T,
    /// l̇ at the start of the period, m/s (the rate command held over it, or the measured rate).
    pub rate_mps: T,
    /// l̈ over the period, m/s² (0 for a rate held over the period).
    pub accel_mps2: T,
    /// μ3 at this length (Eq. 5; 0 for a massless tether).
    pub mu3: T,
    /// The orbit's θ̇, θ̈ and μ/R³ (checked when they were built).
    pub orbit: OrbitTerms<T>,
}

/// The orbit's terms of the libration dynamics: θ̇, θ̈ and μ/R³. They can only be built
/// checked, so the prediction need not check them again each period: θ̇ in
/// (0, [`MAX_ORBIT_RATE_RADPS`]], |θ̈| and μ/R³ at most its square, μ/R³ positive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitTerms<T> {
    rate_radps: T,
    accel_radps2: T,
    gravity_gradient_per_s2: T,
}

impl<T: Real> OrbitTerms<T> {
    /// The terms θ̇ (rad/s), θ̈ (rad/s²) and μ/R³ (1/s²) of an orbit at one instant, or the
    /// first out of range ([`DriveInput::OrbitRate`], [`DriveInput::OrbitAccel`],
    /// [`DriveInput::GravityGradient`]).
    pub fn new(
        rate_radps: T,
        accel_radps2: T,
        gravity_gradient_per_s2: T,
    ) -> Result<Self, DriveError> {
        let max = T::from_f64(MAX_ORBIT_RATE_RADPS);
        let refuse = |input, value: T| {
            Err(DriveError {
                input,
                value: value.to_f64(),
            })
        };
        if !(rate_radps > T::ZERO && rate_radps <= max) {
            return refuse(DriveInput::OrbitRate, rate_radps);
        }
        if above_or_nan(accel_radps2.abs(), max * max) {
            return refuse(DriveInput::OrbitAccel, accel_radps2);
        }
        if !(gravity_gradient_per_s2 > T::ZERO && gravity_gradient_per_s2 <= max * max) {
            return refuse(DriveInput::GravityGradient, gravity_gradient_per_s2);
        }
        Ok(Self {
            rate_radps,
            accel_radps2,
            gravity_gradient_per_s2,
        })
    }

    /// The terms of a circular orbit of rate n (rad/s): θ̇ = n, θ̈ = 0, μ/R³ = n². Refused
    /// unless n is in [[`MIN_CIRCULAR_ORBIT_RATE_RADPS`], [`MAX_ORBIT_RATE_RADPS`]] (its
    /// square is then in range too).
    pub fn circular(rate_radps: T) -> Result<Self, DriveError> {
        let (min, max) = (
            T::from_f64(MIN_CIRCULAR_ORBIT_RATE_RADPS),
            T::from_f64(MAX_ORBIT_RATE_RADPS),
        );
        if rate_radps >= min && rate_radps <= max {
            Ok(Self::circular_in_range(rate_radps))
        } else {
            Err(DriveError {
                input: DriveInput::OrbitRate,
                value: rate_radps.to_f64(),
            })
        }
    }

    /// The terms of a circular orbit of rate n (rad/s), for an n its caller has checked
    /// against a band inside [[`MIN_CIRCULAR_ORBIT_RATE_RADPS`], [`MAX_ORBIT_RATE_RADPS`]]
    /// (the controller's monitor, whose band the controller checks once, at construction).
    pub(crate) fn circular_in_range(rate_radps: T) -> Self {
        Self {
            rate_radps,
            accel_radps2: T::ZERO,
            gravity_gradient_per_s2: rate_radps * rate_radps,
        }
    }

    /// θ̇, rad/s.
    pub fn rate_radps(&self) -> T {
        self.rate_radps
    }

    /// θ̈, rad/s².
    pub fn accel_radps2(&self) -> T {
        self.accel_radps2
    }

    /// μ/R³, 1/s².
    pub fn gravity_gradient_per_s2(&self) -> T {
        self.gravity_gradient_per_s2
    }
}

/// The input of a [`Drive`] that was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DriveInput {
    /// `length_m`: not in (0, [`MAX_LENGTH_M`]].
    Length,
    /// `rate_mps`: not finite.
    Rate,
    /// `accel_mps2`: not finite.
    Accel,
    /// θ̇ ([`OrbitTerms`]): not in (0, [`MAX_ORBIT_RATE_RADPS`]].
    OrbitRate,
    /// θ̈ ([`OrbitTerms`]): |θ̈| above [`MAX_ORBIT_RATE_RADPS`]² or not finite.
    OrbitAccel,
    /// μ/R³ ([`OrbitTerms`]): not in (0, [`MAX_ORBIT_RATE_RADPS`]²].
    GravityGradient,
    /// `mu3`: |μ3| > [`MAX_MU3`] or not finite.
    Mu3,
    /// |(2 + μ3) l̇/l| h at mid-period above [`MAX_STRETCH_PER_PERIOD`] (or the length at
    /// mid-period not positive): the reel changes l too fast for one step.
    Stretch,
}

/// A refused drive: which input, and its value (the value of |s h| for `Stretch`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveError {
    /// The input at fault.
    pub input: DriveInput,
    /// Its value (widened to f64).
    pub value: f64,
}

/// The estimate and its uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate<T> {
    /// α̂, rad.
    pub alpha_rad: T,
    /// α̇̂, rad/s.
    pub alpha_rate_radps: T,
    /// d̂, the unmodelled angular acceleration, rad/s².
    pub disturbance_radps2: T,
    /// Var(α̂), rad².
    pub alpha_var_rad2: T,
    /// Var(α̇̂), rad²/s².
    pub alpha_rate_var_rad2ps2: T,
    /// Var(d̂), rad²/s⁴.
    pub disturbance_var_rad2ps4: T,
    /// Cov(α̂, α̇̂), rad²/s.
    pub alpha_rate_cov_rad2ps: T,
    /// Cov(α̂, d̂), rad²/s².
    pub alpha_disturbance_cov_rad2ps2: T,
    /// Cov(α̇̂, d̂), rad²/s³.
    pub rate_disturbance_cov_rad2ps3: T,
}

/// A sample's innovation against the prediction.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Innovation<T> {
    /// ν = z − α̂⁻, rad.
    pub innovation_rad: T,
    /// S = Var(α̂⁻) + R, rad².
    pub variance_rad2: T,
    /// NIS = ν²/S (χ², one degree of freedom, for a consistent filter).
    pub nis: T,
}

/// What the prediction over the last period did.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Prediction {
    /// The estimate was carried over the period.
    Predicted,
    /// There was no estimate to carry (before the first sample, or after a loss).
    NoEstimate,
    /// The drive was refused: the estimate is dropped (it cannot be carried over a period
    /// whose motion is unknown) and the next sample starts afresh.
    InvalidDrive(DriveError),
    /// The predicted estimate left the physical range (|α̇̂| > [`MAX_ALPHA_RATE_RADPS`] or not
    /// finite, e.g. a long dropout through an unstable retrieval): dropped as above.
    Diverged,
}

/// What became of this period's α sample.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Measurement<T> {
    /// Used in the update.
    Accepted(Innovation<T>),
    /// Rejected by the χ² gate (NIS > `gate_nis`): an outlier, for the fault logic to count.
    Gated(Innovation<T>),
    /// No sample this period: prediction only.
    Missing,
    /// A sample that is not a finite angle in [−π, π]: ignored, as a missing one.
    Invalid,
    /// The first sample (or the first after a loss) started the estimate.
    Initialised,
    /// After `max_rejections` consecutive rejections, this sample restarted α (α̇̂ and d̂ are
    /// kept, with their variances reset to the start's).
    Reinitialised(Innovation<T>),
}

/// One period of the estimator, explained.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output<T> {
    /// The estimate after this period's sample, if there is one.
    pub estimate: Option<Estimate<T>>,
    /// What the prediction did.
    pub prediction: Prediction,
    /// What became of the sample.
    pub measurement: Measurement<T>,
}

/// The filter's state while it has an estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Track<T> {
    alpha: T,
    rate: T,
    disturbance: T,
    p: Sym3<T>,
    /// Consecutive gated samples.
    rejections: u16,
    /// sin 2α and cos 2α of this `alpha`, lent by a caller that computed them
    /// ([`Estimator::lend_sin_cos_two_alpha`]), for the next prediction.
    trig: Option<(T, T)>,
}

/// The libration estimator (see the module docs).
///
/// ```
/// use tss_reel::estimator::{Config, Drive, Estimator, Measurement, OrbitTerms};
/// let mut est = Estimator::<f32>::new(Config::paper()).unwrap();
/// // A circular orbit: θ̇ = n, θ̈ = 0, μ/R³ = n².
/// let orbit = OrbitTerms::circular(1.06e-3).unwrap();
/// let drive = Drive { length_m: 9_000.0, rate_mps: 1.0, accel_mps2: 0.0, mu3: 0.0, orbit };
/// let out = est.step(&drive, Some(-0.78));
/// assert_eq!(out.measurement, Measurement::Initialised);
/// let out = est.step(&drive, Some(-0.78));
/// assert!(matches!(out.measurement, Measurement::Accepted(_)));
/// let e = out.estimate.unwrap();
/// assert!(e.alpha_rate_var_rad2ps2 < 4e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimator<T> {
    config: Config<T>,
    /// R = σ_α² + quantum²/12, rad².
    measurement_var: T,
    /// Q: the process noise of one period.
    process: Sym3<T>,
    /// The variance caps of α, α̇, d.
    caps: [T; 3],
    /// h², s² (worked out once: the prediction's k = κ h² and Φ_αd = h² w).
    period_sq_s2: T,
    track: Option<Track<T>>,
}

impl<T: Real> Estimator<T> {
    /// A filter with no estimate yet, or the first invalid parameter.
    pub fn new(config: Config<T>) -> Result<Self, ConfigError> {
        config.validate()?;
        let h = config.period_s;
        let f = T::from_f64;
        let qw = config.accel_noise_density.sq();
        let qd = config.disturbance_drift_density.sq();
        let (h2, h3) = (h * h, h * h * h);
        let (h4, h5) = (h2 * h2, h2 * h3);
        // Q = ∫₀ʰ e^{Aτ} G q Gᵀ e^{Aᵀτ} dτ for white noise on α̈ (q_α̈) and on ḋ (q_d), with A
        // reduced to its integrator chain over one period (the damping s and stiffness κ change
        // Q by O(s h), O(κ h²): far below the precision of a noise density).
        let process = Sym3 {
            aa: qw * h3 / f(3.0) + qd * h5 / f(20.0),
            aw: qw * h2 / f(2.0) + qd * h4 / f(8.0),
            ad: qd * h3 / f(6.0),
            ww: qw * h + qd * h3 / f(3.0),
            wd: qd * h2 / f(2.0),
            dd: qd * h,
        };
        Ok(Self {
            config,
            measurement_var: config.alpha_noise_rad.sq() + config.alpha_quantum_rad.sq() / f(12.0),
            process,
            caps: [
                f(ALPHA_VARIANCE_CAP_RAD2),
                config.initial_rate_std_radps.sq(),
                config.initial_disturbance_std_radps2.sq(),
            ],
            period_sq_s2: h2,
            track: None,
        })
    }

    /// The validated parameters.
    pub fn config(&self) -> &Config<T> {
        &self.config
    }

    /// R, the α measurement variance, rad².
    pub fn measurement_var_rad2(&self) -> T {
        self.measurement_var
    }

    /// The current estimate, if any.
    pub fn estimate(&self) -> Option<Estimate<T>> {
        self.track.as_ref().map(Track::estimate)
    }

    /// Starts (or restarts) the estimate at a known α and α̇ (e.g. at release, where the
    /// deployer holds the sub-satellite), with the variances of a first sample (R) and of the
    /// start (`initial_rate_std_radps`², `initial_disturbance_std_radps2`²). Refused (the
    /// filter unchanged) unless both are finite, |α| ≤ π and |α̇| ≤ [`MAX_ALPHA_RATE_RADPS`].
    pub fn initialise(&mut self, alpha_rad: T, alpha_rate_radps: T) -> Result<(), Measurement<T>> {
        let pi = T::from_f64(core::f64::consts::PI);
        let rate_ok = alpha_rate_radps.abs() <= T::from_f64(MAX_ALPHA_RATE_RADPS);
        if !(alpha_rad.abs() <= pi && rate_ok) {
            return Err(Measurement::Invalid);
        }
        self.track = Some(self.start(alpha_rad, alpha_rate_radps, T::ZERO));
        Ok(())
    }

    /// One control period: carries the estimate over the period that just ended under
    /// `drive`, then updates it with this period's α sample (`None`: a dropout).
    pub fn step(&mut self, drive: &Drive<T>, alpha_rad: Option<T>) -> Output<T> {
        let prediction = self.predict_period(drive);
        let measurement = self.update_with(alpha_rad);
        Output {
            estimate: self.estimate(),
            prediction,
            measurement,
        }
    }

    /// The first half of [`Estimator::step`]: carries the estimate over one period under
    /// `drive` (a caller whose calls skipped periods carries it over each, then updates once).
    pub fn predict_period(&mut self, drive: &Drive<T>) -> Prediction {
        match &self.track {
            None => Prediction::NoEstimate,
            Some(track) => match self.predict(track, drive) {
                Ok(next) => {
                    self.track.insert(next).p.cap(&self.caps);
                    Prediction::Predicted
                }
                Err(p) => {
                    self.track = None;
                    p
                }
            },
        }
    }

    /// The second half of [`Estimator::step`]: the update with this period's α sample
    /// (`None`: a dropout, nothing to do).
    pub fn update_with(&mut self, alpha_rad: Option<T>) -> Measurement<T> {
        match alpha_rad {
            None => Measurement::Missing,
            // One comparison: false for NaN.
            Some(z) if above_or_nan(z.abs(), T::from_f64(core::f64::consts::PI)) => {
                Measurement::Invalid
            }
            Some(z) => self.update(z),
        }
    }

    /// α̂, α̇̂ and Var(α̂), if there is an estimate (what the controller's law and its
    /// usability test read, without the rest of [`Estimate`]).
    pub(crate) fn alpha_rate_and_variance(&self) -> Option<(T, T, T)> {
        self.track.as_ref().map(|t| (t.alpha, t.rate, t.p.aa))
    }

    /// Lends the filter sin 2α and cos 2α (computed as `(2·α).sin_cos()` in `T`) of an α the
    /// caller computed them for: when it is the estimate's α̂, the next prediction uses them
    /// instead of computing its own (the law computes them for the same α̂). Ignored otherwise.
    pub fn lend_sin_cos_two_alpha(&mut self, alpha_rad: T, sin_two_alpha: T, cos_two_alpha: T) {
        if let Some(t) = &mut self.track {
            if t.alpha == alpha_rad {
                t.trig = Some((sin_two_alpha, cos_two_alpha));
            }
        }
    }

    /// Drops the estimate: the next sample starts afresh (a caller that cannot say what
    /// drove the libration over a period).
    pub fn reset(&mut self) {
        self.track = None;
    }

    /// A fresh track at α with α̇ and d given, and the start's variances.
    fn start(&self, alpha: T, rate: T, disturbance: T) -> Track<T> {
        Track {
            alpha,
            rate,
            disturbance,
            p: Sym3 {
                aa: self.measurement_var,
                aw: T::ZERO,
                ad: T::ZERO,
                ww: self.caps[1],
                wd: T::ZERO,
                dd: self.caps[2],
            },
            rejections: 0,
            trig: None,
        }
    }

    /// The drive's s = (2 + μ3) l̇/l at mid-period, 1/s, or the input at fault.
    ///
    /// The rate and the acceleration need no test of their own: a NaN or an infinity in
    /// either makes s NaN or infinite, and a finite but absurd one makes |s h| too large. The
    /// orbit's terms were checked when they were built ([`OrbitTerms`]).
    fn stretch(&self, drive: &Drive<T>) -> Result<T, DriveError> {
        let f = T::from_f64;
        let (l, v, a, mu3) = (drive.length_m, drive.rate_mps, drive.accel_mps2, drive.mu3);
        let h = self.config.period_s;
        let half_h = f(0.5) * h;
        let rate_mid = v + a * half_h;
        let length_mid = l + (v + f(0.5) * a * half_h) * half_h;
        let s = (f(2.0) + mu3) * rate_mid / length_mid;
        let u = s * h;
        let inputs_in_range = l > T::ZERO && l <= f(MAX_LENGTH_M) && mu3.abs() <= f(MAX_MU3);
        if inputs_in_range && length_mid > T::ZERO && u.abs() <= f(MAX_STRETCH_PER_PERIOD) {
            Ok(s)
        } else {
            Err(refusal(drive, u))
        }
    }

    /// The estimate and covariance carried over one period (module docs, *Discretisation*),
    /// before the caps (which the caller applies in place, `Sym3::cap`).
    fn predict(&self, t: &Track<T>, drive: &Drive<T>) -> Result<Track<T>, Prediction> {
        let f = T::from_f64;
        let s = self.stretch(drive).map_err(Prediction::InvalidDrive)?;
        let h = self.config.period_s;
        // 3μ/(2R³), and κ = (3μ/R³) cos 2α̂.
        let gradient = f(1.5) * drive.orbit.gravity_gradient_per_s2;
        let (sin2a, cos2a) = t.trig.unwrap_or_else(|| (f(2.0) * t.alpha).sin_cos());
        let stiffness = f(2.0) * gradient * cos2a;
        // Eq. 5b at the estimate: f(x) = (α̇, α̈, 0).
        let spin = drive.orbit.rate_radps + t.rate;
        let accel = -spin * s - gradient * sin2a - drive.orbit.accel_radps2 + t.disturbance;
        // Ψ = φ₁(Ah) = I + Ah/2 + (Ah)²/6 + (Ah)³/24 with u = s h and k = κ h², factored on
        // two shared polynomials (exactly the series' terms, regrouped):
        //   c = 1/6 − u/24,   w = 1/2 − u c − k/24,
        //   Ψ_αα = 1 − k c,  Ψ_αα̇ = Ψ_α̇d = h w,  Ψ_αd = h² c,  hΨ_α̇α = −k w,
        //   Ψ_α̇α̇ = ψ = Ψ_αα − u w
        // (Ψ's d row is e₃ᵀ). Φ = I + h A Ψ then reads
        //   Φ = [ 1 − k w          h ψ              h² w ]
        //       [ −κ h ψ           1 − k w − u ψ    h ψ  ]
        //       [ 0                0                1    ].
        let u = s * h;
        let k = stiffness * self.period_sq_s2;
        let c = f(1.0 / 6.0) - u * f(1.0 / 24.0);
        let w = f(0.5) - u * c - k * f(1.0 / 24.0);
        let psi_aa = T::ONE - k * c;
        let psi = psi_aa - u * w;
        let h_psi = h * psi;
        let phi_aa = T::ONE - k * w;
        // x⁺ = x + h Ψ f(x): α⁺ = α + h(Ψ_αα α̇ + h w α̈), α̇⁺ = (1 − k w) α̇ + h ψ α̈.
        let alpha = t.alpha + h * (psi_aa * t.rate + h * w * accel);
        let rate = phi_aa * t.rate + h_psi * accel;
        // α̇⁺ bounds α⁺: h ψ α̈ = α̇⁺ − (1 − k w) α̇, so
        //   α⁺ − α = h Ψ_αα α̇ + (h w/ψ)(α̇⁺ − (1 − k w) α̇),
        // a few h at most for |α̇|, |α̇⁺| ≤ 1 (|u| ≤ 1/2 and |k| < 0.1 keep ψ near 1, w near 1/2);
        // α̂ starts and is updated within [−π, π] plus a gated innovation. A NaN or an infinity
        // in the state or the drive reaches α̇⁺, so its test alone finds a diverged estimate.
        if above_or_nan(rate.abs(), f(MAX_ALPHA_RATE_RADPS)) {
            return Err(Prediction::Diverged);
        }
        let phi = [
            [phi_aa, h_psi, self.period_sq_s2 * w],
            [-(stiffness * h * psi), phi_aa - u * psi, h_psi],
        ];
        let p = t.p.propagated(&phi).rounding_loaded().plus(&self.process);
        Ok(Track {
            alpha,
            rate,
            disturbance: t.disturbance,
            p,
            rejections: t.rejections,
            trig: None,
        })
    }

    /// The update with this period's sample (module docs, *Gating*, *Covariance*), in place.
    /// `z`: an angle, |z| ≤ π (as [`Estimator::update_with`] checks, and the controller's
    /// monitor before it).
    pub(crate) fn update(&mut self, z: T) -> Measurement<T> {
        let r = self.measurement_var;
        let (gate_nis, max_rejections) = (self.config.gate_nis, self.config.max_rejections);
        let Some(t) = &mut self.track else {
            self.track = Some(self.start(z, T::ZERO, T::ZERO));
            return Measurement::Initialised;
        };
        let nu = z - t.alpha;
        let var = t.p.aa + r;
        let inv = T::ONE / var;
        let innovation = Innovation {
            innovation_rad: nu,
            variance_rad2: var,
            nis: nu * nu * inv,
        };
        if innovation.nis > gate_nis {
            if t.rejections >= max_rejections {
                let (rate, disturbance) = (t.rate, t.disturbance);
                self.track = Some(self.start(z, rate, disturbance));
                return Measurement::Reinitialised(innovation);
            }
            t.rejections += 1;
            return Measurement::Gated(innovation);
        }
        // K = P Hᵀ / S, H = (1 0 0).
        let gain = [t.p.aa * inv, t.p.aw * inv, t.p.ad * inv];
        t.alpha = t.alpha + gain[0] * nu;
        t.rate = t.rate + gain[1] * nu;
        t.disturbance = t.disturbance + gain[2] * nu;
        t.p = t.p.posterior(&gain, r);
        t.rejections = 0;
        t.trig = None;
        Measurement::Accepted(innovation)
    }
}

/// Which input of a refused drive is at fault (in the order of [`DriveInput`]), `u` = s h.
fn refusal<T: Real>(drive: &Drive<T>, u: T) -> DriveError {
    let f = T::from_f64;
    let (l, mu3) = (drive.length_m, drive.mu3);
    let (input, value) = if !(l > T::ZERO && l <= f(MAX_LENGTH_M)) {
        (DriveInput::Length, l)
    } else if !drive.rate_mps.is_finite() {
        (DriveInput::Rate, drive.rate_mps)
    } else if !drive.accel_mps2.is_finite() {
        (DriveInput::Accel, drive.accel_mps2)
    } else if mu3.is_nan() || mu3.abs() > f(MAX_MU3) {
        (DriveInput::Mu3, mu3)
    } else {
        (DriveInput::Stretch, u)
    };
    DriveError {
        input,
        value: value.to_f64(),
    }
}

impl<T: Real> Track<T> {
    fn estimate(&self) -> Estimate<T> {
        Estimate {
            alpha_rad: self.alpha,
            alpha_rate_radps: self.rate,
            disturbance_radps2: self.disturbance,
            alpha_var_rad2: self.p.aa,
            alpha_rate_var_rad2ps2: self.p.ww,
            disturbance_var_rad2ps4: self.p.dd,
            alpha_rate_cov_rad2ps: self.p.aw,
            alpha_disturbance_cov_rad2ps2: self.p.ad,
            rate_disturbance_cov_rad2ps3: self.p.wd,
        }
    }
}
