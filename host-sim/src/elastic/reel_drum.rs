//! The reel mechanism of the truth model: a drum driven by a motor through a speed loop, with
//! inertia, viscous and Coulomb friction (stick–slip), a torque limit and a holding brake, loaded
//! by the tether's tension at the reel (the shape of WinchModels.jl's winch).
//!
//! Drum speed ω > 0 pays tether out at l̇ = r ω. Its equation of motion while slipping:
//!
//!   J ω̇ = τ_m + r T_reel − b ω − τ_c sgn(ω)
//!
//! with τ_m the motor torque, T_reel the tension at the reel (it pulls tether off the drum),
//! b the viscous and τ_c the Coulomb friction (plus the brake's torque while it is applied).
//!
//! **Speed loop** (modelled in the plant for now): the controller's rate command u becomes the
//! speed command ω_c = u/r, and a PI loop τ = K_p(ω_c − ω) + K_i ∫(ω_c − ω) dt with
//! K_p = 2Jω_b, K_i = Jω_b² (a double closed-loop pole at −ω_b for the bare inertia; friction
//! and tension are disturbances its integrator rejects) is clamped to ±τ_max. The integrator
//! stops while the clamp acts in the direction of the error (anti-windup).
//!
//! **Stick–slip without chatter** (Karnopp's idea, with the switch taken between integration
//! steps rather than inside a velocity band): the drum is either *stuck* (ω = 0 held exactly,
//! the friction balancing whatever drives it) or *slipping* in a direction fixed over one step.
//! A stuck drum breaks away when the driving torque |τ_m + r T| exceeds the static friction τ_s
//! (plus the brake); a slipping drum whose speed reaches or crosses zero within a step sticks if
//! the driving torque is then within τ_s, else slips on in the new direction. Nothing switches
//! inside a step, and a drum held within its static friction stays at exactly zero speed.
//!
//! **Brake**: applied while the command is exactly zero (a hold); it adds `brake_nm` to both
//! the static and the Coulomb friction.

/// The drum, motor and speed loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrumParams {
    /// Drum radius r, m (the tether's lever arm).
    pub radius_m: f64,
    /// Inertia of motor and drum J, referred to the drum, kg·m².
    pub inertia_kgm2: f64,
    /// Viscous friction b, N·m·s/rad.
    pub viscous_nms: f64,
    /// Coulomb (sliding) friction τ_c, N·m.
    pub coulomb_nm: f64,
    /// Static (breakaway) friction τ_s ≥ τ_c, N·m.
    pub static_nm: f64,
    /// Motor torque limit τ_max, N·m.
    pub max_torque_nm: f64,
    /// Holding brake torque, N·m (applied while the command is zero).
    pub brake_nm: f64,
    /// Speed-loop bandwidth ω_b, rad/s.
    pub speed_bandwidth_radps: f64,
}

/// Whether the drum is stuck or slipping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Motion {
    /// Held at ω = 0 by static friction.
    Stuck,
    /// Turning; the sign (±1) of the direction the Coulomb friction opposes over this step.
    Slipping(f64),
}

impl DrumParams {
    /// Proportional gain K_p = 2Jω_b, N·m·s/rad.
    pub fn kp(&self) -> f64 {
        2.0 * self.inertia_kgm2 * self.speed_bandwidth_radps
    }

    /// Integral gain K_i = Jω_b², N·m/rad.
    pub fn ki(&self) -> f64 {
        self.inertia_kgm2 * self.speed_bandwidth_radps.powi(2)
    }

    /// The speed loop: motor torque (clamped) and the integrator's rate (0 while the clamp
    /// acts in the error's direction), from the speed command and the drum's speed and integral.
    #[inline]
    pub fn speed_loop(
        &self,
        command_radps: f64,
        speed_radps: f64,
        integral_rad: f64,
    ) -> (f64, f64) {
        let error = command_radps - speed_radps;
        let demand = self.kp() * error + self.ki() * integral_rad;
        let torque = demand.clamp(-self.max_torque_nm, self.max_torque_nm);
        let winding_up = (demand > self.max_torque_nm && error > 0.0)
            || (demand < -self.max_torque_nm && error < 0.0);
        (torque, if winding_up { 0.0 } else { error })
    }

    /// Static and Coulomb friction with the brake applied or not, N·m.
    pub fn friction_nm(&self, brake: bool) -> (f64, f64) {
        let b = if brake { self.brake_nm } else { 0.0 };
        (self.static_nm + b, self.coulomb_nm + b)
    }

    /// ω̇ of the drum, rad/s², under `drive_nm` = τ_m + r T_reel.
    #[inline]
    pub fn accel_radps2(
        &self,
        motion: Motion,
        drive_nm: f64,
        speed_radps: f64,
        brake: bool,
    ) -> f64 {
        match motion {
            Motion::Stuck => 0.0,
            Motion::Slipping(dir) => {
                let (_, coulomb) = self.friction_nm(brake);
                (drive_nm - self.viscous_nms * speed_radps - coulomb * dir) / self.inertia_kgm2
            }
        }
    }

    /// The motion at the start of a step: a stuck drum breaks away when the driving torque
    /// exceeds the static friction; a slipping one keeps its direction (or takes the driving
    /// torque's when its speed is exactly zero).
    pub fn motion_for_step(
        &self,
        motion: Motion,
        drive_nm: f64,
        speed_radps: f64,
        brake: bool,
    ) -> Motion {
        let (stat, _) = self.friction_nm(brake);
        match motion {
            Motion::Stuck if drive_nm.abs() <= stat => Motion::Stuck,
            Motion::Stuck => Motion::Slipping(drive_nm.signum()),
            Motion::Slipping(_) if speed_radps != 0.0 => Motion::Slipping(speed_radps.signum()),
            Motion::Slipping(_) => Motion::Slipping(drive_nm.signum()),
        }
    }

    /// After a step that started at `speed_start` and ended at `speed_end`: if the speed
    /// reached or crossed zero and the driving torque is within the static friction, the drum
    /// sticks (its speed set to exactly 0). Returns the motion and the speed to carry on with.
    pub fn after_step(
        &self,
        motion: Motion,
        speed_start: f64,
        speed_end: f64,
        drive_nm: f64,
        brake: bool,
    ) -> (Motion, f64) {
        let (stat, _) = self.friction_nm(brake);
        match motion {
            Motion::Stuck => (Motion::Stuck, 0.0),
            Motion::Slipping(dir) => {
                let reached_zero = speed_end * dir <= 0.0 || speed_start * speed_end <= 0.0;
                if reached_zero && drive_nm.abs() <= stat {
                    (Motion::Stuck, 0.0)
                } else {
                    (motion, speed_end)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drum() -> DrumParams {
        DrumParams {
            radius_m: 0.1,
            inertia_kgm2: 0.05,
            viscous_nms: 1e-3,
            coulomb_nm: 0.2,
            static_nm: 0.3,
            max_torque_nm: 2.0,
            brake_nm: 5.0,
            speed_bandwidth_radps: 5.0,
        }
    }

    #[test]
    fn a_drum_within_its_static_friction_stays_stuck() {
        let d = drum();
        assert_eq!(
            d.motion_for_step(Motion::Stuck, 0.29, 0.0, false),
            Motion::Stuck
        );
        assert_eq!(
            d.motion_for_step(Motion::Stuck, -0.31, 0.0, false),
            Motion::Slipping(-1.0)
        );
        // The brake holds more.
        assert_eq!(
            d.motion_for_step(Motion::Stuck, 5.2, 0.0, true),
            Motion::Stuck
        );
        assert_eq!(d.accel_radps2(Motion::Stuck, 1.0, 0.0, false), 0.0);
    }

    #[test]
    fn a_slipping_drum_that_stops_within_static_friction_sticks() {
        let d = drum();
        let m = Motion::Slipping(1.0);
        assert_eq!(
            d.after_step(m, 0.01, -0.001, 0.1, false),
            (Motion::Stuck, 0.0)
        );
        assert_eq!(d.after_step(m, 0.01, 0.005, 0.1, false), (m, 0.005));
        // Driven beyond the static friction it reverses instead.
        assert_eq!(d.after_step(m, 0.01, -0.001, -1.0, false), (m, -0.001));
        assert_eq!(
            d.motion_for_step(m, -1.0, -0.001, false),
            Motion::Slipping(-1.0)
        );
    }

    #[test]
    fn the_speed_loop_clamps_and_stops_winding_up() {
        let d = drum();
        let (t, di) = d.speed_loop(100.0, 0.0, 0.0);
        assert_eq!((t, di), (2.0, 0.0));
        let (t, di) = d.speed_loop(1.0, 0.0, 0.0);
        assert!((t - 0.5).abs() < 1e-12 && di == 1.0);
    }
}
