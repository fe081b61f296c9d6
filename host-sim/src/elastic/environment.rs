//! The orbital environment of the truth model: Earth's gravity (point mass, optional J2) and an
//! optional exponential atmosphere with drag (cross-flow on tether segments, a bluff body's drag
//! on the end bodies). Everything is shipped in code: nothing is read or downloaded at run time.
//!
//! Frame: Earth-centred inertial, z along Earth's spin axis (the J2 symmetry axis). The
//! atmosphere co-rotates with the Earth.

use nalgebra::Vector3;

/// A vector in the Earth-centred inertial frame (m, m/s, N…).
pub type Vec3 = Vector3<f64>;

/// Earth's equatorial radius R_e, m (WGS-84): the J2 reference radius and the sphere that
/// altitudes are measured from.
pub const EARTH_EQUATORIAL_RADIUS_M: f64 = 6_378_137.0;

/// Earth's second zonal harmonic J2 (EGM-96, unnormalised).
pub const EARTH_J2: f64 = 1.082_626_68e-3;

/// Earth's rotation rate ω_E, rad/s (IERS): the atmosphere's angular velocity.
pub const EARTH_ROTATION_RADPS: f64 = 7.292_115_146_7e-5;

/// Gravity and atmosphere switches of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Earth's gravitational parameter μ, m³/s².
    pub mu_m3ps2: f64,
    /// Add the J2 (oblateness) acceleration to the point-mass gravity.
    pub j2: bool,
    /// Apply atmospheric drag (the exponential atmosphere of [`atmosphere_density_kgpm3`]).
    pub drag: bool,
    /// Replace the exact gravity difference between a node and the reference particle by its
    /// first-order (gravity-gradient) term μ/R³·(3(ρ·R̂)R̂ − ρ), as the paper's Eq. 5 does;
    /// for verification against the rigid plant only (it drops the (l/R) and (l/R)² terms,
    /// 0.4 % of the gradient at 30 km). Ignores J2 on the difference.
    pub linear_gradient: bool,
}

impl Environment {
    /// Gravitational acceleration at `r` (m from Earth's centre), m/s²: −μ r/|r|³, plus J2
    /// when enabled: a_J2 = −(3/2) J2 μ R_e²/|r|⁵ · (x(1 − 5z²/r²), y(1 − 5z²/r²), z(3 − 5z²/r²)).
    #[inline]
    pub fn gravity(&self, r: &Vec3) -> Vec3 {
        let inv_r2 = 1.0 / r.norm_squared();
        let inv_r3 = inv_r2 * inv_r2.sqrt();
        let point = r * (-self.mu_m3ps2 * inv_r3);
        if !self.j2 {
            return point;
        }
        let k =
            -1.5 * EARTH_J2 * self.mu_m3ps2 * EARTH_EQUATORIAL_RADIUS_M.powi(2) * inv_r3 * inv_r2;
        let z2 = r.z * r.z * inv_r2;
        point
            + Vec3::new(
                k * r.x * (1.0 - 5.0 * z2),
                k * r.y * (1.0 - 5.0 * z2),
                k * r.z * (3.0 - 5.0 * z2),
            )
    }

    /// The gravity of a node at `r_ref + rho` relative to that at `r_ref`, m/s² (exact, or the
    /// gravity gradient's first-order term when `linear_gradient` is set); `g_ref` is
    /// [`Environment::gravity`] at `r_ref`.
    #[inline]
    pub fn gravity_relative(&self, r_ref: &Vec3, g_ref: &Vec3, rho: &Vec3) -> Vec3 {
        if self.linear_gradient {
            let r2 = r_ref.norm_squared();
            let k = self.mu_m3ps2 / (r2 * r2.sqrt());
            let u = r_ref / r2.sqrt();
            (u * (3.0 * u.dot(rho)) - rho) * k
        } else {
            self.gravity(&(r_ref + rho)) - g_ref
        }
    }

    /// The potential energy per unit mass at `r` whose gradient gives [`Environment::gravity`],
    /// J/kg: −μ/r, plus (J2) (μ R_e² J2/(2 r³))(3z²/r² − 1).
    pub fn potential_jpkg(&self, r: &Vec3) -> f64 {
        let rn = r.norm();
        let point = -self.mu_m3ps2 / rn;
        if !self.j2 {
            return point;
        }
        let z2 = r.z * r.z / (rn * rn);
        point
            + 0.5 * self.mu_m3ps2 * EARTH_EQUATORIAL_RADIUS_M.powi(2) * EARTH_J2 / rn.powi(3)
                * (3.0 * z2 - 1.0)
    }

    /// Air density at `r`, kg/m³ (0 when drag is off).
    #[inline]
    pub fn air_density_kgpm3(&self, r: &Vec3) -> f64 {
        if self.drag {
            atmosphere_density_kgpm3(altitude_m(r))
        } else {
            0.0
        }
    }
}

/// The altitude of `r` above the equatorial sphere, m.
#[inline]
pub fn altitude_m(r: &Vec3) -> f64 {
    r.norm() - EARTH_EQUATORIAL_RADIUS_M
}

/// The velocity of the co-rotating atmosphere at `r`, m/s: ω_E ẑ × r.
#[inline]
pub fn air_velocity_mps(r: &Vec3) -> Vec3 {
    Vec3::new(-EARTH_ROTATION_RADPS * r.y, EARTH_ROTATION_RADPS * r.x, 0.0)
}

/// Drag force on a bluff body, N: −½ ρ_a C_d A |v| v with v its velocity through the air.
#[inline]
pub fn body_drag_n(air_density_kgpm3: f64, cd_area_m2: f64, v_air_mps: &Vec3) -> Vec3 {
    v_air_mps * (-0.5 * air_density_kgpm3 * cd_area_m2 * v_air_mps.norm())
}

/// Drag force on a straight cylinder (a tether segment) by the cross-flow principle, N: only
/// the component of the air velocity normal to the axis `axis_unit` acts,
/// F = −½ ρ_a C_d d L |v_n| v_n (`cd_diameter_length_m2` = C_d d L).
#[inline]
pub fn cylinder_drag_n(
    air_density_kgpm3: f64,
    cd_diameter_length_m2: f64,
    axis_unit: &Vec3,
    v_air_mps: &Vec3,
) -> Vec3 {
    let v_n = v_air_mps - axis_unit * axis_unit.dot(v_air_mps);
    v_n * (-0.5 * air_density_kgpm3 * cd_diameter_length_m2 * v_n.norm())
}

/// One band of the exponential atmosphere: ρ = ρ0 exp(−(h − h0)/H) for h0 ≤ h < next h0.
struct Band {
    base_km: f64,
    density_kgpm3: f64,
    scale_height_km: f64,
}

/// Vallado, *Fundamentals of Astrodynamics and Applications* (4th ed.), Table 8-4: the
/// exponential atmosphere (CIRA-72 below 25 km… U.S. Standard 1976 above), by base altitude.
#[rustfmt::skip]
const BANDS: [Band; 28] = [
    Band { base_km: 0.0, density_kgpm3: 1.225, scale_height_km: 7.249 },
    Band { base_km: 25.0, density_kgpm3: 3.899e-2, scale_height_km: 6.349 },
    Band { base_km: 30.0, density_kgpm3: 1.774e-2, scale_height_km: 6.682 },
    Band { base_km: 40.0, density_kgpm3: 3.972e-3, scale_height_km: 7.554 },
    Band { base_km: 50.0, density_kgpm3: 1.057e-3, scale_height_km: 8.382 },
    Band { base_km: 60.0, density_kgpm3: 3.206e-4, scale_height_km: 7.714 },
    Band { base_km: 70.0, density_kgpm3: 8.770e-5, scale_height_km: 6.549 },
    Band { base_km: 80.0, density_kgpm3: 1.905e-5, scale_height_km: 5.799 },
    Band { base_km: 90.0, density_kgpm3: 3.396e-6, scale_height_km: 5.382 },
    Band { base_km: 100.0, density_kgpm3: 5.297e-7, scale_height_km: 5.877 },
    Band { base_km: 110.0, density_kgpm3: 9.661e-8, scale_height_km: 7.263 },
    Band { base_km: 120.0, density_kgpm3: 2.438e-8, scale_height_km: 9.473 },
    Band { base_km: 130.0, density_kgpm3: 8.484e-9, scale_height_km: 12.636 },
    Band { base_km: 140.0, density_kgpm3: 3.845e-9, scale_height_km: 16.149 },
    Band { base_km: 150.0, density_kgpm3: 2.070e-9, scale_height_km: 22.523 },
    Band { base_km: 180.0, density_kgpm3: 5.464e-10, scale_height_km: 29.740 },
    Band { base_km: 200.0, density_kgpm3: 2.789e-10, scale_height_km: 37.105 },
    Band { base_km: 250.0, density_kgpm3: 7.248e-11, scale_height_km: 45.546 },
    Band { base_km: 300.0, density_kgpm3: 2.418e-11, scale_height_km: 53.628 },
    Band { base_km: 350.0, density_kgpm3: 9.518e-12, scale_height_km: 53.298 },
    Band { base_km: 400.0, density_kgpm3: 3.725e-12, scale_height_km: 58.515 },
    Band { base_km: 450.0, density_kgpm3: 1.585e-12, scale_height_km: 60.828 },
    Band { base_km: 500.0, density_kgpm3: 6.967e-13, scale_height_km: 63.822 },
    Band { base_km: 600.0, density_kgpm3: 1.454e-13, scale_height_km: 71.835 },
    Band { base_km: 700.0, density_kgpm3: 3.614e-14, scale_height_km: 88.667 },
    Band { base_km: 800.0, density_kgpm3: 1.170e-14, scale_height_km: 124.64 },
    Band { base_km: 900.0, density_kgpm3: 5.245e-15, scale_height_km: 181.05 },
    Band { base_km: 1000.0, density_kgpm3: 3.019e-15, scale_height_km: 268.00 },
];

/// Air density of the exponential atmosphere (Vallado Table 8-4) at `altitude_m` above the
/// equatorial sphere, kg/m³. Below 0 m the sea-level band is used; above 1000 km the last
/// band continues.
pub fn atmosphere_density_kgpm3(altitude_m: f64) -> f64 {
    let h_km = altitude_m / 1000.0;
    let band = BANDS
        .iter()
        .rev()
        .find(|b| h_km >= b.base_km)
        .unwrap_or(&BANDS[0]);
    band.density_kgpm3 * (-(h_km - band.base_km) / band.scale_height_km).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_atmosphere_matches_its_table_and_is_continuous_enough() {
        assert_eq!(atmosphere_density_kgpm3(0.0), 1.225);
        assert_eq!(atmosphere_density_kgpm3(700_000.0), 3.614e-14);
        // Each band's exponential lands within 3 % of the next band's base value.
        for w in BANDS.windows(2) {
            let below = atmosphere_density_kgpm3(w[1].base_km * 1000.0 - 1e-6);
            let rel = (below - w[1].density_kgpm3).abs() / w[1].density_kgpm3;
            assert!(
                rel < 0.03,
                "{} km: {below} vs {}",
                w[1].base_km,
                w[1].density_kgpm3
            );
        }
    }

    #[test]
    fn gravity_is_the_gradient_of_the_potential() {
        let env = Environment {
            mu_m3ps2: 3.986_004_418e14,
            j2: true,
            drag: false,
            linear_gradient: false,
        };
        let r = Vec3::new(4.0e6, -3.0e6, 4.5e6);
        let g = env.gravity(&r);
        let h = 1.0;
        for k in 0..3 {
            let mut e = Vec3::zeros();
            e[k] = h;
            let d = -(env.potential_jpkg(&(r + e)) - env.potential_jpkg(&(r - e))) / (2.0 * h);
            assert!((d - g[k]).abs() < 1e-8 * g.norm(), "{k}: {d} vs {}", g[k]);
        }
    }

    #[test]
    fn cross_flow_drag_ignores_the_axial_flow() {
        let axis = Vec3::new(1.0, 0.0, 0.0);
        assert_eq!(
            cylinder_drag_n(1.0, 1.0, &axis, &Vec3::new(5.0, 0.0, 0.0)).norm(),
            0.0
        );
        let f = cylinder_drag_n(1.0, 2.0, &axis, &Vec3::new(5.0, 3.0, 0.0));
        assert_eq!(f, Vec3::new(0.0, -9.0, 0.0));
    }
}
