//! What a tension law reads in one period: the sensed sample, in f64.

/// What a tension law reads in one period (the sensed sample, in f64).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensed {
    /// Sensed length, m.
    pub length_m: f64,
    /// The reel's rate l̇, m/s (measured, or from the sensed lengths).
    pub rate_mps: f64,
    /// Sensed α, rad (`None`: no swing sample this period).
    pub alpha_rad: Option<f64>,
    /// Sensed α̇, rad/s (`None`: no rate sensor).
    pub alpha_rate_radps: Option<f64>,
    /// Orbit rate θ̇ = Ω, rad/s.
    pub orbit_rate_radps: f64,
}
