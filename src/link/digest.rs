//! Fingerprints: FNV-1a over bytes and f32 bit patterns, and the digest of a controller
//! configuration.

const FNV_OFFSET: u32 = 0x811c_9dc5;
const FNV_PRIME: u32 = 0x0100_0193;

/// FNV-1a (32-bit) of `bytes`, continuing from `hash` (start with [`fnv1a_start`]).
pub fn fnv1a(hash: u32, bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .fold(hash, |h, &b| (h ^ u32::from(b)).wrapping_mul(FNV_PRIME))
}

/// The FNV-1a offset basis, the digest of nothing.
pub const fn fnv1a_start() -> u32 {
    FNV_OFFSET
}

/// FNV-1a continued over the bit pattern of `x` (little-endian).
pub fn fnv1a_f32(hash: u32, x: f32) -> u32 {
    fnv1a(hash, &x.to_bits().to_le_bytes())
}

/// A fingerprint of a controller configuration: FNV-1a over the bit pattern of every field, in
/// declaration order. The firmware sends it in [`Hello`](super::Hello); the plant compares it with the
/// configuration its scenario describes, so a PIL run cannot fly a different controller than the
/// host-linked run it is compared with. Every struct is destructured without `..`: a new field
/// anywhere in the configuration does not compile until it is added here.
pub fn config_digest(cfg: &crate::controller::Config<f32>) -> u32 {
    use crate::config::{RateSource, Stage1Config, Stage2Config};
    use crate::controller::{Config, Envelope, MonitorConfig};
    use crate::estimator;
    use crate::law::Gains;
    use crate::mass::MassModel;
    use crate::orbit::Orbit;
    use crate::schedule::BandSchedule;

    let Config {
        period_s,
        orbit,
        masses,
        gains,
        initial_rate_mps,
        stage1,
        stage2,
        keep_capture_m,
        envelope,
        monitor,
        protection,
        rate_source,
        tension_loop,
    } = cfg;
    let Orbit {
        semi_major_axis_m,
        eccentricity,
        mu_m3ps2,
    } = orbit;
    let MassModel {
        main_initial_kg,
        sub_kg,
        tether_density_kg_per_m,
    } = masses;
    let Gains {
        k1_per_s,
        k2_per_s2,
    } = gains;
    let Stage1Config {
        schedule: s1,
        decay_rate_per_s: c1,
    } = stage1;
    let Stage2Config {
        schedule: s2,
        slew_rate_radps,
        decay_rate_per_s: c2,
        start_tick,
    } = stage2;
    let Envelope {
        max_rate_mps,
        max_accel_mps2,
        min_length_m,
        max_length_m,
    } = envelope;
    let MonitorConfig {
        coast_ticks,
        recovery_ticks,
        length_jump_m,
        alpha_jump_rad,
        stuck_ticks,
        stuck_motion_rad,
        max_alpha_rate_radps,
        min_orbit_rate_radps,
        max_orbit_rate_radps,
        good_samples_per_bad,
        safe_hold_decel_mps2,
    } = monitor;
    let schedule = |h: u32, s: &BandSchedule<f32>| {
        let BandSchedule {
            low_length_m,
            low_angle_rad,
            low_slope_rad_per_m,
            high_length_m,
            high_angle_rad,
            high_slope_rad_per_m,
        } = s;
        [
            low_length_m,
            low_angle_rad,
            low_slope_rad_per_m,
            high_length_m,
            high_angle_rad,
            high_slope_rad_per_m,
        ]
        .into_iter()
        .fold(h, |h, &x| fnv1a_f32(h, x))
    };
    let mut h = [
        period_s,
        semi_major_axis_m,
        eccentricity,
        mu_m3ps2,
        main_initial_kg,
        sub_kg,
        tether_density_kg_per_m,
        k1_per_s,
        k2_per_s2,
        initial_rate_mps,
        c1,
        slew_rate_radps,
        c2,
        keep_capture_m,
        max_rate_mps,
        max_accel_mps2,
        min_length_m,
        max_length_m,
        length_jump_m,
        alpha_jump_rad,
        stuck_motion_rad,
        max_alpha_rate_radps,
        min_orbit_rate_radps,
        max_orbit_rate_radps,
        safe_hold_decel_mps2,
    ]
    .into_iter()
    .fold(fnv1a_start(), |h, &x| fnv1a_f32(h, x));
    h = schedule(h, s1);
    h = schedule(h, s2);
    let start = start_tick.map_or([0u8; 5], |t| {
        let b = t.to_le_bytes();
        [1, b[0], b[1], b[2], b[3]]
    });
    h = fnv1a(h, &start);
    for n in [
        coast_ticks,
        recovery_ticks,
        stuck_ticks,
        good_samples_per_bad,
    ] {
        h = fnv1a(h, &n.to_le_bytes());
    }
    // The rate source: nothing for the rate sensor (the digest of a configuration from before
    // there was a choice is unchanged), a tag and the estimator's parameters otherwise.
    match rate_source {
        RateSource::Sensor => {}
        RateSource::Estimator(est) => {
            let estimator::Config {
                period_s,
                alpha_noise_rad,
                alpha_quantum_rad,
                accel_noise_density,
                disturbance_drift_density,
                initial_rate_std_radps,
                initial_disturbance_std_radps2,
                gate_nis,
                max_rejections,
            } = est;
            h = fnv1a(h, &[1]);
            h = [
                period_s,
                alpha_noise_rad,
                alpha_quantum_rad,
                accel_noise_density,
                disturbance_drift_density,
                initial_rate_std_radps,
                initial_disturbance_std_radps2,
                gate_nis,
            ]
            .into_iter()
            .fold(h, |h, &x| fnv1a_f32(h, x));
            h = fnv1a(h, &max_rejections.to_le_bytes());
        }
    }
    // The protection, when configured (an unprotected configuration's digest is unchanged).
    if let Some(p) = protection {
        let crate::controller::ProtectionConfig {
            min_tension_n,
            max_tension_n,
            tension_filter_s,
            drive_lag_s,
            rate_resolution_mps,
        } = p;
        h = fnv1a(h, &[2]);
        for x in [
            min_tension_n,
            max_tension_n,
            tension_filter_s,
            drive_lag_s,
            rate_resolution_mps,
        ] {
            h = fnv1a_f32(h, *x);
        }
    }
    // The tension loop, when configured (a configuration without one digests as before).
    if let Some(t) = tension_loop {
        let crate::controller::TensionLoopConfig {
            axial_stiffness_n,
            damping_ratio,
            washout_s,
            min_tension_n,
            max_tension_n,
            overshoot,
            fallback_accel_mps2,
            load_cell_timeout_ticks,
            yield_from_rad,
            yield_full_rad,
        } = t;
        h = fnv1a(h, &[3]);
        for x in [
            axial_stiffness_n,
            damping_ratio,
            washout_s,
            min_tension_n,
            max_tension_n,
            overshoot,
            fallback_accel_mps2,
            yield_from_rad,
            yield_full_rad,
        ] {
            h = fnv1a_f32(h, *x);
        }
        h = fnv1a(h, &load_cell_timeout_ticks.to_le_bytes());
    }
    h
}
