//! The load cell of a recording: the tension at the reel in the recorded state, from Eq. 5a
//! (docs/equations.md §2) solved for it,
//!
//! ```text
//!   T_t = m_r (−μ1 l̇²/l + μ2 l [(n + α̇)² + n² (3 cos²α − 1)] − l̈)
//! ```
//!
//! on the paper's circular orbit (θ̇ = n, μ/R³ = n²), in-plane (β = 0). The recordings carry
//! l, α and α̇ but no tension (the rigid plant's tether is a rod); the benchmarks give the
//! flight configuration's tension loop this reading, so that the loop's path with a working
//! load cell is the one timed. l̇ and l̈ are central differences over [`SPAN_TICKS`] periods
//! of the recorded length (the mission's recording is linear between its 5-s samples: over
//! one period its second difference would be zero but at the samples).

use crate::mass::MassModel;

/// The half-width of the central differences of the length, control periods (the mission's
/// recording interval).
pub const SPAN_TICKS: u32 = 5;

/// The tension a load cell at the reel reads at control tick `tick` of a recording sampled by
/// `sample` ((l m, α rad, α̇ rad/s) per tick, `None` where there is none) with control period
/// `period_s`, masses `masses` and orbit rate `orbit_rate_radps`, N. `None` where the
/// recording has no sample at `tick` or its neighbours `tick ± SPAN_TICKS` (the first and
/// last ticks, a dropout).
pub fn tension_n(
    sample: impl Fn(u32) -> Option<[f32; 3]>,
    tick: u32,
    period_s: f32,
    masses: &MassModel<f32>,
    orbit_rate_radps: f32,
) -> Option<f32> {
    let [l, alpha, alpha_rate] = sample(tick)?;
    let before = sample(tick.checked_sub(SPAN_TICKS)?)?[0];
    let after = sample(tick.checked_add(SPAN_TICKS)?)?[0];
    let span_s = SPAN_TICKS as f32 * period_s;
    let rate_mps = (after - before) / (2.0 * span_s);
    let accel_mps2 = (after - 2.0 * l + before) / (span_s * span_s);
    let c = masses.coefficients(l);
    let n = orbit_rate_radps;
    let cos_alpha = libm::cosf(alpha);
    let gradient = n * n * (3.0 * cos_alpha * cos_alpha - 1.0);
    let swing = (n + alpha_rate) * (n + alpha_rate);
    let coriolis = if l > 0.0 {
        c.mu1 * rate_mps * rate_mps / l
    } else {
        0.0
    };
    Some(c.radial_kg * (-coriolis + c.mu2 * l * (swing + gradient) - accel_mps2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tether held radial at a constant length, not swinging: the gravity gradient's
    /// 3 m_r n² l.
    #[test]
    fn a_still_radial_tether_carries_the_gravity_gradient() {
        let masses = MassModel::paper();
        let n = 1.06e-3_f32;
        let still = |_| Some([20_000.0, 0.0, 0.0]);
        let t = tension_n(still, 10, 1.0, &masses, n).unwrap();
        let m_r = masses.coefficients(0.0).radial_kg;
        let expected = 3.0 * m_r * n * n * 20_000.0;
        assert!((t - expected).abs() < 1e-5 * expected, "{t} vs {expected}");
    }

    /// Reeling in at a constant acceleration adds m_r |l̈|; no neighbour, no reading.
    #[test]
    fn a_wind_in_acceleration_adds_to_the_tension_and_the_ends_read_nothing() {
        let masses = MassModel::paper();
        let m_r = masses.coefficients(0.0).radial_kg;
        let a = -0.01_f32;
        let reeled = |tick: u32| {
            let t = tick as f32;
            (tick <= 100).then_some([1_000.0 + 0.5 * a * t * t, 0.0, 0.0])
        };
        let n = 1.06e-3_f32;
        let l = 1_000.0 + 0.5 * a * 50.0 * 50.0;
        let t = tension_n(reeled, 50, 1.0, &masses, n).unwrap();
        let expected = m_r * (3.0 * n * n * l - a);
        assert!((t - expected).abs() < 1e-3 * expected, "{t} vs {expected}");
        assert_eq!(tension_n(reeled, 2, 1.0, &masses, n), None);
        assert_eq!(tension_n(reeled, 97, 1.0, &masses, n), None);
    }
}
