//! The initial state: the rigid plant's straight line, pre-stretched to static equilibrium.
//!
//! The rigid plant starts a straight rod along (α(0), β(0)) at l(0), rotating with the orbit
//! frame and the line (α̇(0), β̇(0)), paying out at l̇(0). A tether started there *unstretched*
//! carries no tension at t = 0 and falls into a bounce about its static stretch (amplitude: the
//! stretch itself, so the tension swings between 0 and twice its static value). Instead every
//! segment starts stretched to carry the tension the rigid motion needs (docs/truth-model.md,
//! "Initial state"):
//!
//! The line's direction e_t turns at w = ė_t (inertial) = (orbit frame's ω) × e_t + (its rate
//! in that frame from α̇, β̇). A node at x along the line (from the centre of mass) moving
//! rigidly with it accelerates along e_t by −|w|² x (the Coriolis term of the paid-out
//! tether's outward motion is normal to e_t, and the paid-out rate is held: l̈ = 0). The net
//! force along e_t that node i needs from the tether is therefore
//!
//!   F_i = −m_i [ (g(R_c + x_i e_t) − ḡ)·e_t + |w|² x_i ] − (momentum flux at the reel)·e_t,
//!
//! with ḡ the mass-weighted mean gravity (the centre of mass's acceleration). Segment s pulls
//! node s outward and node s + 1 inward with T_s, so from the sub-satellite inward
//! T_(b) = −F_(b+1) and T_(s) = T_(s+1) − F_(s+1): the tension of Eq. 5a at l̈ = 0 (for two
//! bodies, T = m_r l [(θ̇+α̇)² cos²β + β̇² + (μ/R³)(3cos²α cos²β − 1)]), distributed over the
//! beads. The sum of all F_i vanishes (ḡ and the centre of mass are mass-weighted), so the
//! main satellite's balance holds too. Each segment is stretched to carry its T_s,
//! d = L + T·max(L, l_k)/EA (none where T ≤ 0: a tether cannot push, the segment starts straight
//! and slack), which moves the nodes and so x_i: the fixed point converges by the factor
//! T/EA (≪ 1) per iteration.
//!
//! The paid-out tether (every node beyond the main satellite) moves out at l̇·d_0/L_0, the
//! unstretched rate times the reel segment's stretch ratio: the segments beyond it keep their
//! length and the reel segment its strain, so no damper acts at t = 0.

use super::environment::{Environment, Vec3};
use super::tether::{Layout, TetherParams};

/// The most fixed-point iterations of the stretch (each gains the factor T/EA, ~1e-3 or less).
const MAX_ITERATIONS: usize = 50;

/// The line the tether starts on: its direction, that direction's inertial rate, and the orbit
/// frame's angular velocity.
#[derive(Clone, Copy, Debug)]
pub(super) struct Line {
    /// Unit vector e_t from the main satellite towards the sub-satellite.
    pub direction: Vec3,
    /// ė_t relative to the orbit frame (from α̇ and β̇), 1/s.
    pub direction_rate: Vec3,
    /// The orbit frame's angular velocity θ̇ e_h, rad/s.
    pub frame_rate: Vec3,
}

/// The tether's initial nodes, relative to the centre of mass.
#[derive(Clone, Debug)]
pub(super) struct Equilibrium {
    /// Positions, m.
    pub pos: Vec<Vec3>,
    /// Velocities, m/s.
    pub vel: Vec<Vec3>,
    /// The reel segment's tension, N.
    pub reel_tension_n: f64,
}

/// The statically stretched straight tether (module doc) of `layout` with the node `masses`,
/// `paid_out_m` paid out, the material moving out at `rate_mps` (unstretched) and the reel
/// paying out at `reel_rate_mps` (0 while locked), the centre of mass at `r_c`.
#[allow(clippy::too_many_arguments)]
pub(super) fn equilibrium(
    tether: &TetherParams,
    env: &Environment,
    layout: &Layout,
    masses: &[f64],
    paid_out_m: f64,
    rate_mps: f64,
    reel_rate_mps: f64,
    r_c: &Vec3,
    line: &Line,
) -> Equilibrium {
    let n = layout.nodes();
    let lengths: Vec<f64> = (0..n - 1)
        .map(|s| layout.segment_m(tether, paid_out_m, s))
        .collect();
    let total: f64 = masses.iter().sum();
    let e_t = line.direction;
    let w = line.direction_rate + line.frame_rate.cross(&e_t);
    let w2 = w.norm_squared();
    let g_c = env.gravity(r_c);
    let chord = |l: f64, t: f64| {
        if t > 0.0 {
            l + t * l.max(tether.min_stiffness_length_m) / tether.axial_stiffness_n
        } else {
            l
        }
    };
    // Momentum flux at the reel (mod.rs): paying out, node 1 gains ½ρl̇ (v_0 − v_1); winding in,
    // node 0 gains ½ρ|l̇| (v_1 − v_0).
    let q = 0.5 * tether.density_kg_per_m * reel_rate_mps;

    let mut tension = vec![0.0; n - 1];
    let mut x = vec![0.0; n];
    let mut along = rate_mps;
    for _ in 0..MAX_ITERATIONS {
        let mut next = vec![0.0; n];
        for s in 0..n - 1 {
            next[s + 1] = next[s] + chord(lengths[s], tension[s]);
        }
        let x_c = masses.iter().zip(&next).map(|(m, x)| m * x).sum::<f64>() / total;
        let converged = next
            .iter()
            .zip(&x)
            .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + a.abs()));
        x = next;
        along = rate_mps * (x[1] - x[0]) / lengths[0];
        // Gravity along the line relative to the centre of mass's, per unit mass.
        let g: Vec<f64> = x
            .iter()
            .map(|xi| {
                env.gravity_relative(r_c, &g_c, &(e_t * (xi - x_c)))
                    .dot(&e_t)
            })
            .collect();
        let g_mean = masses.iter().zip(&g).map(|(m, g)| m * g).sum::<f64>() / total;
        let mut force: Vec<f64> = (0..n)
            .map(|i| -masses[i] * (g[i] - g_mean + w2 * (x[i] - x_c)))
            .collect();
        if q > 0.0 {
            force[1] += q * along;
        } else if q < 0.0 {
            force[0] += q * along;
        }
        tension[n - 2] = -force[n - 1];
        for s in (0..n - 2).rev() {
            tension[s] = tension[s + 1] - force[s + 1];
        }
        if converged {
            break;
        }
    }

    let x_c = masses.iter().zip(&x).map(|(m, x)| m * x).sum::<f64>() / total;
    let mut pos = Vec::with_capacity(n);
    let mut vel = Vec::with_capacity(n);
    for (i, xi) in x.iter().enumerate() {
        let q = e_t * *xi;
        let out = if i == 0 { 0.0 } else { along };
        pos.push(q);
        vel.push(e_t * out + line.direction_rate * *xi + line.frame_rate.cross(&q));
    }
    let vc = vel.iter().zip(masses).map(|(v, m)| v * *m).sum::<Vec3>() / total;
    pos.iter_mut().for_each(|p| *p -= e_t * x_c);
    vel.iter_mut().for_each(|v| *v -= vc);
    Equilibrium {
        pos,
        vel,
        reel_tension_n: tension[0].max(0.0),
    }
}
