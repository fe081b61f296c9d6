//! Orbit geometry of the truth model: the initial orbit's state, the orbit frame of a body, and
//! the angles α, β of a direction in it (docs/equations.md §0).

use super::environment::{self, Environment, Vec3};
use super::params::OrbitParams;

/// The angles of a direction in the centre of mass's orbit frame (docs/equations.md §0):
/// e_t = cosβ(cosα e_r + sinα e_θ) + sinβ e_h, and their rates in that frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Angles {
    /// α, rad.
    pub alpha_rad: f64,
    /// α̇, rad/s.
    pub alpha_rate_radps: f64,
    /// β, rad.
    pub beta_rad: f64,
    /// β̇, rad/s.
    pub beta_rate_radps: f64,
}

/// The in-plane basis of an orbit of inclination `i` with the node and perigee on x:
/// p̂ = x̂, q̂ = (0, cos i, sin i).
pub(super) fn plane_basis(inclination_rad: f64) -> (Vec3, Vec3) {
    let (si, ci) = inclination_rad.sin_cos();
    (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, ci, si))
}

/// Position and velocity on the orbit at its initial true anomaly: Keplerian, except that a
/// circular orbit (e = 0) with J2 on starts at the circular speed of the oblate field, so that
/// it stays circular as the scenario says. At the Keplerian speed √(μ/a) the J2 field's extra
/// pull, (3/2) J2 (R_e/a)² of the point mass's on the equator, would make it an orbit of
/// e ≈ 1.3e-3 at 700 km (a ±9 km radius swing once an orbit), which forces a libration of the
/// same order (docs/equations.md §16) that a controller told e = 0 cannot know: the 30 km keep
/// moved by ±20 m. The speed balances the orbit-averaged radial gravity,
/// v² = (μ/a) (1 + (3/2) J2 (R_e/a)² (1 − (3/2) sin² i)): exact on the equator (the radial
/// J2 pull is then constant round the circle), first order in J2 on an inclined orbit, whose
/// radial pull varies with latitude.
pub(super) fn orbit_state(o: &OrbitParams, env: &Environment) -> (Vec3, Vec3) {
    let (p_hat, q_hat) = plane_basis(o.inclination_rad);
    let a = o.orbit.semi_major_axis_m;
    let e = o.orbit.eccentricity;
    let semi_latus = a * (1.0 - e * e);
    let (s, c) = o.initial_true_anomaly_rad.sin_cos();
    let r = semi_latus / (1.0 + e * c);
    let oblate = if env.j2 && e == 0.0 {
        let re_a = environment::EARTH_EQUATORIAL_RADIUS_M / a;
        let si = o.inclination_rad.sin();
        1.0 + 1.5 * environment::EARTH_J2 * re_a * re_a * (1.0 - 1.5 * si * si)
    } else {
        1.0
    };
    let v = (o.orbit.mu_m3ps2 / semi_latus * oblate).sqrt();
    (
        (p_hat * c + q_hat * s) * r,
        (p_hat * (-s) + q_hat * (e + c)) * v,
    )
}

/// The orbit frame (e_r, e_θ, e_h) of a body at `r` moving at `v` (docs/equations.md §0).
pub(super) fn orbit_frame(r: &Vec3, v: &Vec3) -> (Vec3, Vec3, Vec3) {
    let e_r = r.normalize();
    let e_h = r.cross(v).normalize();
    (e_r, e_h.cross(&e_r), e_h)
}

/// α, β of the direction `d` and their rates from `d_rate` (its derivative in the rotating
/// orbit frame), with e_t = d/|d| = cosβ(cosα e_r + sinα e_θ) + sinβ e_h.
pub(super) fn direction_angles(
    d: &Vec3,
    d_rate: &Vec3,
    e_r: &Vec3,
    e_th: &Vec3,
    e_h: &Vec3,
) -> Angles {
    let (x, y, z) = (d.dot(e_r), d.dot(e_th), d.dot(e_h));
    let (xd, yd, zd) = (d_rate.dot(e_r), d_rate.dot(e_th), d_rate.dot(e_h));
    let rho2 = x * x + y * y;
    let norm = d.norm();
    let s = z / norm;
    let s_rate = (zd - s * (d.dot(d_rate) / norm)) / norm;
    Angles {
        alpha_rad: y.atan2(x),
        alpha_rate_radps: (x * yd - y * xd) / rho2,
        beta_rad: s.asin(),
        beta_rate_radps: s_rate / (1.0 - s * s).sqrt(),
    }
}
