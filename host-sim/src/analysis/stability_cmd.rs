//! `tss-sim stability`: characteristic roots, D1, D2 and verdicts at one state (Eqs. 7, 9, 13,
//! 17–19), with the nalgebra eigenvalues of the full Jacobian of Eqs. 5b–5c as a cross-check.

use std::fmt::Write as _;

use serde::Serialize;
use tss_reel::equilibrium::{
    in_plane_equilibria, normalised_rate, Anomaly, ExistenceCheck, ExistenceMonitor,
};
use tss_reel::mass::MassModel;
use tss_reel::orbit::Orbit;
use tss_reel::stability::{
    equilibrium_stability, jacobian_eigenvalues, swing_accelerations, Complex,
    EquilibriumStability, FrozenCoefficients, ModeRoots, SwingState, Verdict,
};

use super::flags::{eccentricity, finite, invalid, positive, AnalysisCliError, OutputFormat};

/// |α̈|, |β̈| below this × θ̇² count as zero: the state is an equilibrium.
pub const EQUILIBRIUM_RESIDUAL_REL: f64 = 1e-9;

/// Which solution of Eq. 7 to take when `--alpha-deg` is not given.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Branch {
    /// α_e = ½ asin(sin2α_e), within 45° of the local vertical.
    #[default]
    Vertical,
    /// α_e = ±90° − ½ asin(sin2α_e), beyond 45° of the vertical.
    Horizontal,
}

/// Arguments of `tss-sim stability` (defaults: the paper's orbit and masses, 10 km, l̇ = 0).
#[derive(Debug, Clone, clap::Args)]
pub struct StabilityArgs {
    /// Tether length l, m (> 0).
    #[arg(long, default_value_t = 10_000.0, allow_hyphen_values = true)]
    pub length_m: f64,
    /// Reel rate l̇, m/s: > 0 deploying, < 0 retrieving, 0 station keeping.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub rate_mps: f64,
    /// In-plane angle α_e, deg (default: the equilibrium of Eq. 7, see --branch).
    #[arg(long, allow_hyphen_values = true)]
    pub alpha_deg: Option<f64>,
    /// Which equilibrium of Eq. 7 to use when --alpha-deg is not given.
    #[arg(long, value_enum, default_value_t = Branch::Vertical)]
    pub branch: Branch,
    /// Out-of-plane angle β_e, deg (equilibria: 0 or ±90).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub beta_deg: f64,
    /// α̇, deg/s, for the Jacobian at a state off equilibrium.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub alpha_rate_degps: f64,
    /// β̇, deg/s, for the Jacobian at a state off equilibrium.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub beta_rate_degps: f64,
    /// Semi-major axis a (the radius of a circular orbit), m.
    #[arg(
        long,
        visible_alias = "radius-m",
        default_value_t = 7_078_000.0,
        allow_hyphen_values = true
    )]
    pub semi_major_axis_m: f64,
    /// Orbit eccentricity e, in [0, 1).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub eccentricity: f64,
    /// True anomaly θ, deg.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub anomaly_deg: f64,
    /// m01, main satellite mass at release (tether on the reel), kg.
    #[arg(long, default_value_t = 10_000.0, allow_hyphen_values = true)]
    pub main_mass_kg: f64,
    /// m2, sub-satellite mass, kg.
    #[arg(long, default_value_t = 100.0, allow_hyphen_values = true)]
    pub sub_mass_kg: f64,
    /// ρ, tether linear density, kg/m (≥ 0).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub density_kg_per_m: f64,
    /// How to print the result.
    #[arg(long, value_enum, default_value_t = OutputFormat::Text)]
    pub format: OutputFormat,
}

/// Everything `stability` computes.
#[derive(Clone, Debug)]
pub struct StabilityReport {
    /// The frozen coefficients of Eqs. 5b–5c at this state.
    pub coefficients: FrozenCoefficients<f64>,
    /// x = (2+μ3) l̇/(ω l).
    pub normalised_rate: f64,
    /// The state analysed (α_e, β_e, and the rates given).
    pub state: SwingState<f64>,
    /// Whether α_e came from Eq. 7 (not from --alpha-deg).
    pub alpha_from_eq7: bool,
    /// (α̈, β̈) of Eqs. 5b–5c at the state, rad/s²; `None` at β = ±90°.
    pub residual: Option<(f64, f64)>,
    /// Whether the state is an equilibrium (zero rates, residual within tolerance).
    pub at_equilibrium: bool,
    /// Eq. 9 at θ.
    pub exists_at_theta: ExistenceCheck<f64>,
    /// Eq. 13 over the whole orbit.
    pub exists_whole_orbit: ExistenceCheck<f64>,
    /// The closed form of Eqs. 17–19.
    pub stability: EquilibriumStability<f64>,
    /// The Jacobian's eigenvalues, or why there are none.
    pub eigenvalues: Result<[Complex<f64>; 4], String>,
    /// max over the closed-form roots of |λ − nearest eigenvalue| / max |λ|.
    pub max_rel_mismatch: Option<f64>,
}

/// Validates the arguments and computes the report.
pub fn analyse(a: &StabilityArgs) -> Result<StabilityReport, AnalysisCliError> {
    let l = positive("--length-m", a.length_m)?;
    let rate = finite("--rate-mps", a.rate_mps)?;
    let beta = finite("--beta-deg", a.beta_deg)?.to_radians();
    let alpha_rate = finite("--alpha-rate-degps", a.alpha_rate_degps)?.to_radians();
    let beta_rate = finite("--beta-rate-degps", a.beta_rate_degps)?.to_radians();
    let sma = positive("--semi-major-axis-m", a.semi_major_axis_m)?;
    let e = eccentricity("--eccentricity", a.eccentricity)?;
    let theta = finite("--anomaly-deg", a.anomaly_deg)?.to_radians();
    let m01 = positive("--main-mass-kg", a.main_mass_kg)?;
    let m2 = positive("--sub-mass-kg", a.sub_mass_kg)?;
    let rho = finite("--density-kg-per-m", a.density_kg_per_m)?;
    if rho < 0.0 {
        return Err(invalid(
            "--density-kg-per-m",
            format!("must be >= 0 (got {rho})"),
        ));
    }
    if rho * l >= m01 {
        return Err(invalid(
            "--density-kg-per-m",
            format!(
                "the tether (rho*l = {} kg) must be lighter than --main-mass-kg",
                rho * l
            ),
        ));
    }
    let orbit = Orbit::elliptic(sma, e);
    let mass = MassModel {
        main_initial_kg: m01,
        sub_kg: m2,
        tether_density_kg_per_m: rho,
    };
    let core = |flag: &'static str| {
        move |err: tss_reel::equilibrium::AnalysisError| invalid(flag, err.to_string())
    };
    let c = FrozenCoefficients::from_orbit(&orbit, theta, &mass, l, rate)
        .map_err(core("--length-m/--rate-mps"))?;
    let w = orbit.mean_motion_radps();
    let x = normalised_rate(c.mu3, c.length_rate_ratio_per_s, w);
    let (alpha, alpha_from_eq7) = match a.alpha_deg {
        Some(deg) => (finite("--alpha-deg", deg)?.to_radians(), false),
        None => {
            let eq = in_plane_equilibria(e, theta, x).ok_or_else(|| {
                invalid(
                    "--rate-mps",
                    format!(
                        "no in-plane equilibrium at this theta for this rate (Eq. 8: \
                         sin 2alpha_e = {:.6} is outside [-1, 1]); give --alpha-deg to analyse \
                         a state anyway",
                        tss_reel::equilibrium::sin_two_alpha_e(e, theta, x)
                    ),
                )
            })?;
            let a = match a.branch {
                Branch::Vertical => eq.near_vertical_rad,
                Branch::Horizontal => eq.near_horizontal_rad,
            };
            (a, true)
        }
    };
    let state = SwingState {
        alpha_rad: alpha,
        alpha_rate_radps: alpha_rate,
        beta_rad: beta,
        beta_rate_radps: beta_rate,
    };
    let monitor = ExistenceMonitor::from_orbit(&orbit).map_err(core("--eccentricity"))?;
    let exists_at_theta = monitor
        .check(Anomaly::At(theta), c.mu3, c.length_rate_ratio_per_s)
        .map_err(core("--anomaly-deg"))?;
    let exists_whole_orbit = monitor
        .check(Anomaly::WholeOrbit, c.mu3, c.length_rate_ratio_per_s)
        .map_err(core("--rate-mps"))?;
    let stability = equilibrium_stability(&c, alpha, beta).map_err(core("--alpha-deg"))?;
    let residual = swing_accelerations(&c, &state).ok();
    let tol = EQUILIBRIUM_RESIDUAL_REL * c.anomaly_rate_radps.powi(2);
    let at_equilibrium = alpha_rate == 0.0
        && beta_rate == 0.0
        && (2.0 * beta).sin().abs() < 1e-12
        && residual.is_none_or(|(aa, bb)| aa.abs() <= tol && bb.abs() <= tol);
    let eigenvalues = jacobian_eigenvalues(&c, &state).map_err(|e| e.to_string());
    let max_rel_mismatch = eigenvalues
        .as_ref()
        .ok()
        .map(|ev| relative_mismatch(&roots(&stability), ev));
    Ok(StabilityReport {
        coefficients: c,
        normalised_rate: x,
        state,
        alpha_from_eq7,
        residual,
        at_equilibrium,
        exists_at_theta,
        exists_whole_orbit,
        stability,
        eigenvalues,
        max_rel_mismatch,
    })
}

/// The four closed-form roots: λ1, λ2 (in-plane), λ3, λ4 (out-of-plane).
pub fn roots(s: &EquilibriumStability<f64>) -> [Complex<f64>; 4] {
    [
        s.in_plane.roots[0],
        s.in_plane.roots[1],
        s.out_of_plane.roots[0],
        s.out_of_plane.roots[1],
    ]
}

/// max over `a` of the distance to the nearest unused element of `b`, over max |a|.
pub fn relative_mismatch(a: &[Complex<f64>; 4], b: &[Complex<f64>; 4]) -> f64 {
    let scale = a.iter().map(|z| z.re.hypot(z.im)).fold(0.0, f64::max);
    let mut used = [false; 4];
    let mut worst: f64 = 0.0;
    for z in a {
        let best = b
            .iter()
            .enumerate()
            .filter(|(i, _)| !used[*i])
            .map(|(i, w)| (i, (z.re - w.re).hypot(z.im - w.im)))
            .min_by(|p, q| p.1.total_cmp(&q.1));
        if let Some((i, d)) = best {
            used[i] = true;
            worst = worst.max(if scale > 0.0 { d / scale } else { d });
        }
    }
    worst
}

fn verdict_name(v: Verdict) -> &'static str {
    match v {
        Verdict::Stable => "stable",
        Verdict::Marginal => "marginal",
        Verdict::Unstable => "unstable",
    }
}

fn regime(x: f64) -> &'static str {
    if x > 0.0 {
        "deploying"
    } else if x < 0.0 {
        "retrieving"
    } else {
        "station keeping"
    }
}

fn complex(z: &Complex<f64>) -> String {
    format!("{:+.6e} {:+.6e}i", z.re, z.im)
}

fn mode_line(name: &str, roots: &str, d: &str, m: &ModeRoots<f64>) -> String {
    format!(
        "{name:<24} {roots} = {}, {}   {d} = {:+.6e} 1/s^2   -> {}",
        complex(&m.roots[0]),
        complex(&m.roots[1]),
        m.discriminant_per_s2,
        verdict_name(m.verdict)
    )
}

/// The report for people.
pub fn format_text(a: &StabilityArgs, r: &StabilityReport) -> String {
    let c = &r.coefficients;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "State     l = {} m, ldot = {} m/s ({}), alpha_e = {:.6} deg{}, beta_e = {} deg",
        a.length_m,
        a.rate_mps,
        regime(a.rate_mps),
        r.state.alpha_rad.to_degrees(),
        if r.alpha_from_eq7 { " (Eq. 7)" } else { "" },
        a.beta_deg
    );
    let _ = writeln!(
        s,
        "Orbit     a = {} m, e = {}, theta = {} deg: thetadot = {:.6e} rad/s, mu/R^3 = {:.6e} 1/s^2",
        a.semi_major_axis_m, a.eccentricity, a.anomaly_deg, c.anomaly_rate_radps, c.gravity_gradient_per_s2
    );
    let _ = writeln!(
        s,
        "Rate      mu3 = {:.6e}, ldot/l = {:.6e} 1/s, x = (2+mu3) ldot/(omega l) = {:.6}",
        c.mu3, c.length_rate_ratio_per_s, r.normalised_rate
    );
    for (name, ex) in [
        ("Eq. 9 at theta", &r.exists_at_theta),
        ("Eq. 13 whole orbit", &r.exists_whole_orbit),
    ] {
        let _ = writeln!(
            s,
            "Exists    {name}: {:.6} <= x <= {:.6}: {} (margin {:+.6}, {:+.6e} 1/s)",
            ex.lower,
            ex.upper,
            if ex.exists { "yes" } else { "NO" },
            ex.margin,
            ex.margin_per_s
        );
    }
    match r.residual {
        Some((aa, bb)) => {
            let _ = writeln!(
                s,
                "Residual  Eqs. 5b-5c at the state: alpha_dd = {aa:+.3e}, beta_dd = {bb:+.3e} rad/s^2 ({})",
                if r.at_equilibrium { "an equilibrium" } else { "NOT an equilibrium: the closed form does not apply" }
            );
        }
        None => {
            let _ = writeln!(s, "Residual  Eq. 5b is singular at beta = +-90 deg");
        }
    }
    let st = &r.stability;
    let _ = writeln!(s, "Roots (Eqs. 17-19, closed form), 1/s:");
    let _ = writeln!(
        s,
        "  {}",
        mode_line("in-plane (alpha)", "l1,2", "D1", &st.in_plane)
    );
    let _ = writeln!(
        s,
        "  {}",
        mode_line("out-of-plane (beta)", "l3,4", "D2", &st.out_of_plane)
    );
    let _ = writeln!(s, "Verdict   {}", verdict_name(st.verdict));
    let _ = writeln!(
        s,
        "Cross-check: eigenvalues of the 4x4 Jacobian of Eqs. 5b-5c (nalgebra Schur), 1/s:"
    );
    match &r.eigenvalues {
        Ok(ev) => {
            for z in ev {
                let _ = writeln!(s, "  {}", complex(z));
            }
            if let Some(m) = r.max_rel_mismatch {
                let _ = writeln!(s, "  max |closed form - eigenvalue| / max |root| = {m:.3e}");
            }
        }
        Err(e) => {
            let _ = writeln!(s, "  none: {e}");
        }
    }
    s
}

/// One CSV row of `stability --format csv`.
#[derive(Clone, Debug, Serialize)]
pub struct StabilityCsvRow {
    /// α_e, rad.
    pub alpha_e_rad: f64,
    /// β_e, rad.
    pub beta_e_rad: f64,
    /// θ̇, rad/s.
    pub anomaly_rate_radps: f64,
    /// μ/R³, 1/s².
    pub gravity_gradient_per_s2: f64,
    /// μ3.
    pub mu3: f64,
    /// l̇/l, 1/s.
    pub length_rate_ratio_per_s: f64,
    /// x = (2+μ3) l̇/(ω l).
    pub normalised_rate: f64,
    /// Eq. 9 at θ holds.
    pub exists_at_theta: bool,
    /// Eq. 13 over the orbit holds.
    pub exists_whole_orbit: bool,
    /// Whether the state is an equilibrium.
    pub at_equilibrium: bool,
    /// D1, 1/s².
    pub d1_per_s2: f64,
    /// D2, 1/s².
    pub d2_per_s2: f64,
    /// λ1..λ4, real and imaginary parts, 1/s.
    pub lambda1_re: f64,
    /// Im λ1.
    pub lambda1_im: f64,
    /// Re λ2.
    pub lambda2_re: f64,
    /// Im λ2.
    pub lambda2_im: f64,
    /// Re λ3.
    pub lambda3_re: f64,
    /// Im λ3.
    pub lambda3_im: f64,
    /// Re λ4.
    pub lambda4_re: f64,
    /// Im λ4.
    pub lambda4_im: f64,
    /// In-plane verdict.
    pub in_plane_verdict: &'static str,
    /// Out-of-plane verdict.
    pub out_of_plane_verdict: &'static str,
    /// Overall verdict.
    pub verdict: &'static str,
    /// Jacobian eigenvalues (empty at β = ±90°).
    pub eig1_re: Option<f64>,
    /// Im.
    pub eig1_im: Option<f64>,
    /// Re.
    pub eig2_re: Option<f64>,
    /// Im.
    pub eig2_im: Option<f64>,
    /// Re.
    pub eig3_re: Option<f64>,
    /// Im.
    pub eig3_im: Option<f64>,
    /// Re.
    pub eig4_re: Option<f64>,
    /// Im.
    pub eig4_im: Option<f64>,
    /// max relative mismatch closed form vs eigenvalues.
    pub max_rel_mismatch: Option<f64>,
}

/// The report as one CSV row.
pub fn csv_row(r: &StabilityReport) -> StabilityCsvRow {
    let l = roots(&r.stability);
    let ev = r.eigenvalues.as_ref().ok();
    let e = |i: usize, im: bool| {
        ev.and_then(|v| v.get(i))
            .map(|z| if im { z.im } else { z.re })
    };
    let c = &r.coefficients;
    StabilityCsvRow {
        alpha_e_rad: r.state.alpha_rad,
        beta_e_rad: r.state.beta_rad,
        anomaly_rate_radps: c.anomaly_rate_radps,
        gravity_gradient_per_s2: c.gravity_gradient_per_s2,
        mu3: c.mu3,
        length_rate_ratio_per_s: c.length_rate_ratio_per_s,
        normalised_rate: r.normalised_rate,
        exists_at_theta: r.exists_at_theta.exists,
        exists_whole_orbit: r.exists_whole_orbit.exists,
        at_equilibrium: r.at_equilibrium,
        d1_per_s2: r.stability.in_plane.discriminant_per_s2,
        d2_per_s2: r.stability.out_of_plane.discriminant_per_s2,
        lambda1_re: l[0].re,
        lambda1_im: l[0].im,
        lambda2_re: l[1].re,
        lambda2_im: l[1].im,
        lambda3_re: l[2].re,
        lambda3_im: l[2].im,
        lambda4_re: l[3].re,
        lambda4_im: l[3].im,
        in_plane_verdict: verdict_name(r.stability.in_plane.verdict),
        out_of_plane_verdict: verdict_name(r.stability.out_of_plane.verdict),
        verdict: verdict_name(r.stability.verdict),
        eig1_re: e(0, false),
        eig1_im: e(0, true),
        eig2_re: e(1, false),
        eig2_im: e(1, true),
        eig3_re: e(2, false),
        eig3_im: e(2, true),
        eig4_re: e(3, false),
        eig4_im: e(3, true),
        max_rel_mismatch: r.max_rel_mismatch,
    }
}

/// Runs `tss-sim stability`.
pub fn run_stability(args: &StabilityArgs) -> anyhow::Result<()> {
    let report = analyse(args)?;
    match args.format {
        OutputFormat::Text => print!("{}", format_text(args, &report)),
        OutputFormat::Csv => {
            super::extent::write_csv(std::io::stdout().lock(), &[csv_row(&report)])?
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args() -> StabilityArgs {
        StabilityArgs {
            length_m: 10_000.0,
            rate_mps: 2.0,
            alpha_deg: None,
            branch: Branch::Vertical,
            beta_deg: 0.0,
            alpha_rate_degps: 0.0,
            beta_rate_degps: 0.0,
            semi_major_axis_m: 7_078_000.0,
            eccentricity: 0.0,
            anomaly_deg: 0.0,
            main_mass_kg: 10_000.0,
            sub_mass_kg: 100.0,
            density_kg_per_m: 0.0,
            format: OutputFormat::Text,
        }
    }

    #[test]
    fn deployment_on_the_paper_orbit_is_stable_and_cross_checks() {
        let r = analyse(&args()).unwrap();
        assert!(r.at_equilibrium && r.alpha_from_eq7);
        assert_eq!(r.stability.verdict, Verdict::Stable);
        assert!(r.max_rel_mismatch.unwrap() < 1e-9);
        // Hand value: sin2α_e = −(2/3)·2·2e-4/n.
        let n = r.coefficients.anomaly_rate_radps;
        let s = -(2.0 / 3.0) * 2.0 * 2e-4 / n;
        assert!(((2.0 * r.state.alpha_rad).sin() - s).abs() < 1e-12);
    }

    #[test]
    fn retrieval_is_unstable_and_errors_name_flags() {
        let r = analyse(&StabilityArgs {
            rate_mps: -2.0,
            ..args()
        })
        .unwrap();
        assert_eq!(r.stability.verdict, Verdict::Unstable);
        for (bad, flag) in [
            (
                StabilityArgs {
                    length_m: 0.0,
                    ..args()
                },
                "--length-m",
            ),
            (
                StabilityArgs {
                    eccentricity: 1.0,
                    ..args()
                },
                "--eccentricity",
            ),
            (
                StabilityArgs {
                    sub_mass_kg: -1.0,
                    ..args()
                },
                "--sub-mass-kg",
            ),
            (
                StabilityArgs {
                    rate_mps: f64::NAN,
                    ..args()
                },
                "--rate-mps",
            ),
            (
                StabilityArgs {
                    rate_mps: 100.0,
                    ..args()
                },
                "--rate-mps",
            ),
        ] {
            let err = analyse(&bad).unwrap_err().to_string();
            assert!(err.starts_with(flag), "{err}");
        }
    }

    #[test]
    fn beta_at_ninety_degrees_has_no_jacobian_but_a_verdict() {
        let r = analyse(&StabilityArgs {
            beta_deg: 90.0,
            ..args()
        })
        .unwrap();
        assert!(r.eigenvalues.is_err());
        assert_eq!(r.stability.out_of_plane.verdict, Verdict::Unstable);
        let row = csv_row(&r);
        assert!(row.eig1_re.is_none());
    }
}
