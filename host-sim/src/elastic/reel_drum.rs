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

use crate::plant::DriveFigures;

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

/// The flight speed loop on this drum: `tss_reel::reel_drive::SpeedLoop` (f32, the reel MCU's
/// code) closes the loop at its inner rate, reading a quantised encoder (the drum's angle
/// floored to whole counts, in a wrapping counter) and the tension at the reel, and its duty
/// becomes the motor torque, held over the tick (the drum's own PI loop above is not used).
/// The drum integrates with the stick–slip rules of [`DrumParams`], `substeps` semi-implicit
/// Euler steps per inner tick, the spring brake held whenever the drive has it engaged.
///
/// It flies one law period at a time ([`FlightDrum::period`]), the tension held over it, and
/// keeps the figures the summary reports ([`DriveFigures`]).
#[derive(Clone, Debug)]
pub struct FlightDrum {
    params: DrumParams,
    speed: tss_reel::reel_drive::SpeedLoop,
    motion: Motion,
    rate_radps: f64,
    /// The drum's angle in encoder counts (f64: exact to a count for 2^52 counts).
    angle_counts: f64,
    counts_per_rad: f64,
    encoder_mask: u32,
    /// Duty → drum torque, N·m at duty 1 (the drive's `max_torque_nm`).
    torque_per_duty_nm: f64,
    tick: u32,
    substeps: u32,
    figures: DriveFigures,
    /// The drive's faults since they were last taken ([`FlightDrum::take_faults`]).
    faults: tss_reel::reel_drive::DriveFaults,
}

impl FlightDrum {
    /// The drive configuration for this drum: the reference reel's
    /// (`DriveConfig::example`) with the drum's radius, inertia, friction and torque limit,
    /// the PI crossing over at the same 30 rad/s (kp = 30 J / r, its zero at a quarter of
    /// that), at `inner_rate_hz` under a law period of `period_s`.
    pub fn drive_config(
        params: &DrumParams,
        inner_rate_hz: u32,
        period_s: f64,
    ) -> tss_reel::reel_drive::DriveConfig {
        let mut cfg = tss_reel::reel_drive::DriveConfig::example();
        cfg.inner_rate_hz = inner_rate_hz;
        cfg.outer_period_ticks = (period_s * f64::from(inner_rate_hz)).round() as u32;
        cfg.geometry.drum_radius_m = params.radius_m as f32;
        cfg.drum.inertia_kgm2 = params.inertia_kgm2 as f32;
        cfg.drum.viscous_nm_per_radps = params.viscous_nms as f32;
        cfg.drum.coulomb_nm = params.coulomb_nm as f32;
        cfg.max_torque_nm = params.max_torque_nm as f32;
        let crossover_radps = 30.0;
        let kp = crossover_radps * params.inertia_kgm2 / params.radius_m;
        cfg.gains.kp_nm_per_mps = kp as f32;
        cfg.gains.ki_nm_per_m = (kp * crossover_radps / 4.0) as f32;
        // The drum's own limits, not the reference reel's.
        cfg.max_speed_mps = cfg.max_speed_mps.min(cfg.faults.max_encoder_rate_mps);
        // At rest below 1 mm/s (half a count of the speed window), not the reference reel's
        // 5 mm/s: the paper's law deploys as slowly as 2.7 mm/s (stage 1, near 930 s), and a
        // brake engaging there stops the drum under a tether of 1 mN, which catches the
        // sub-satellite and sends it back (slack from 780 s on in paper-drive).
        cfg.brake.rest_speed_mps = 1e-3;
        cfg
    }

    /// The drum `params` at rest (stuck, brake engaged), flown by a speed loop of `cfg`.
    pub fn new(
        params: DrumParams,
        cfg: tss_reel::reel_drive::DriveConfig,
    ) -> Result<Self, tss_reel::reel_drive::DriveConfigError> {
        let speed = tss_reel::reel_drive::SpeedLoop::new(cfg)?;
        let bits = cfg.geometry.encoder_bits;
        Ok(Self {
            params,
            speed,
            motion: Motion::Stuck,
            rate_radps: 0.0,
            angle_counts: 0.0,
            counts_per_rad: f64::from(cfg.geometry.counts_per_drum_rev()) / std::f64::consts::TAU,
            encoder_mask: if bits >= 32 {
                u32::MAX
            } else {
                (1 << bits) - 1
            },
            torque_per_duty_nm: f64::from(cfg.max_torque_nm),
            tick: 0,
            substeps: 4,
            figures: DriveFigures {
                tension_range_n: (f64::INFINITY, f64::NEG_INFINITY),
                ..DriveFigures::default()
            },
            faults: tss_reel::reel_drive::DriveFaults::NONE,
        })
    }

    /// The union of the drive's faults over the ticks since the last call (a law period's,
    /// for `Controller::step_with_drive`, as the board hands them to the outer step).
    pub fn take_faults(&mut self) -> tss_reel::reel_drive::DriveFaults {
        std::mem::replace(&mut self.faults, tss_reel::reel_drive::DriveFaults::NONE)
    }

    /// Drum surface speed, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.rate_radps * self.params.radius_m
    }

    /// The figures so far.
    pub fn figures(&self) -> &DriveFigures {
        &self.figures
    }

    /// The speed loop (its odometer, brake, last output).
    pub fn speed_loop(&self) -> &tss_reel::reel_drive::SpeedLoop {
        &self.speed
    }

    /// Starts a law period: the law's `command` reaches the drive, the tether pulling with
    /// `tension_n` at the reel.
    pub fn begin_period(&mut self, command: tss_reel::reel_drive::RateCommand, tension_n: f64) {
        let _ = self.speed.set_command(command, self.tick);
        self.note_tension(tension_n);
    }

    fn note_tension(&mut self, tension_n: f64) {
        let f = &mut self.figures;
        f.tension_range_n.0 = f.tension_range_n.0.min(tension_n);
        f.tension_range_n.1 = f.tension_range_n.1.max(tension_n);
    }

    /// The drum's angle `angle_rad` (from the start) as the encoder's wrapping count.
    fn encoder_count(&self, angle_rad: f64) -> u32 {
        ((angle_rad * self.counts_per_rad).floor() as i64 as u32) & self.encoder_mask
    }

    /// One inner tick of the flight speed loop: reads the encoder at the drum's angle
    /// `angle_rad` (from the start) and the load cell's `tension_n`; returns the motor torque to
    /// hold over the tick, N·m, and whether the brake is engaged. Close it with
    /// [`FlightDrum::end_tick`] once the drum has moved.
    pub fn start_tick(&mut self, angle_rad: f64, tension_n: f64) -> (f64, bool) {
        use tss_reel::reel_drive::DriveInput;
        self.speed.step(&DriveInput {
            tick: self.tick,
            encoder_count: Some(self.encoder_count(angle_rad)),
            tension_n: Some(tension_n as f32),
        });
        let out = self.speed.motor();
        self.note_tension(tension_n);
        let brake = !out.brake.brake_released();
        let motor_nm = (f64::from(out.duty) * self.torque_per_duty_nm)
            .clamp(-self.params.max_torque_nm, self.params.max_torque_nm);
        (motor_nm, brake)
    }

    /// Ends the tick [`FlightDrum::start_tick`] began, the drum turning at `speed_mps` (surface)
    /// at its end: the tracking, saturation and fault figures. Returns |drum speed − reference|
    /// with the brake released, m/s.
    pub fn end_tick(&mut self, speed_mps: f64) -> Option<f64> {
        let out = self.speed.output();
        let f = &mut self.figures;
        f.ticks += 1;
        f.saturated_ticks += u64::from(out.saturated);
        f.fault_bits |= out.faults.bits();
        self.faults = self.faults.union(out.faults);
        self.tick = self.tick.wrapping_add(1);
        if matches!(out.brake, tss_reel::reel_drive::Brake::Released { .. }) {
            let error = speed_mps - f64::from(out.ref_rate_mps);
            f.released_ticks += 1;
            f.sum_sq_error += error * error;
            f.max_error_mps = f.max_error_mps.max(error.abs());
            Some(error.abs())
        } else {
            None
        }
    }

    /// Ends a law period under `command_mps`, the drum at `speed_mps`.
    pub fn end_period(&mut self, command_mps: f64, speed_mps: f64) {
        let end_error = (speed_mps - command_mps).abs();
        let f = &mut self.figures;
        f.max_period_end_error_mps = f.max_period_end_error_mps.max(end_error);
    }

    /// Spins the drum up to `rate_mps` (surface) before the mission starts, the tether not yet
    /// pulling: the speed loop releases its brake, ramps to the rate within a law period and
    /// holds it for another, the drum integrated here ([`FlightDrum::period`]). The mission's
    /// initial condition is a reel already paying out at l̇(0) (as the motor reel starts,
    /// `ElasticPlant::new`): started braked instead, the drum held the tether while the
    /// sub-satellite left at l̇(0), and the jerk (7.4 N at the reel within the first second)
    /// sent it back, the tether slack from then on. The figures restart at the end (the
    /// spin-up is not the mission's). Returns the drum's travel, m (pay-out positive).
    pub fn spin_up(&mut self, rate_mps: f64) -> f64 {
        let command = tss_reel::reel_drive::RateCommand {
            rate_mps: rate_mps as f32,
            accel_mps2: 0.0,
            safe_hold: false,
        };
        let ticks = self.speed.config().outer_period_ticks;
        self.period(command, 0.0, ticks);
        self.period(command, 0.0, ticks);
        self.figures = DriveFigures {
            tension_range_n: (f64::INFINITY, f64::NEG_INFINITY),
            ..DriveFigures::default()
        };
        self.faults = tss_reel::reel_drive::DriveFaults::NONE;
        self.angle_counts / self.counts_per_rad * self.params.radius_m
    }

    /// The drum's rate, rad/s (pay-out positive), and its stick–slip state.
    pub fn drum_state(&self) -> (f64, Motion) {
        (self.rate_radps, self.motion)
    }

    /// The last tick's duty, −1…1.
    pub fn duty(&self) -> f64 {
        f64::from(self.speed.output().duty)
    }

    /// One law period of `ticks` inner ticks under the law's `command`, the tether pulling
    /// with `tension_n` at the reel, the drum integrated here. Returns the drum's surface speed
    /// at its end, m/s, and the period's largest |drum speed − reference| with the brake
    /// released, m/s.
    pub fn period(
        &mut self,
        command: tss_reel::reel_drive::RateCommand,
        tension_n: f64,
        ticks: u32,
    ) -> (f64, f64) {
        let mut period_max_mps: f64 = 0.0;
        self.begin_period(command, tension_n);
        let dt = 1.0 / f64::from(self.speed.config().inner_rate_hz);
        let h = dt / f64::from(self.substeps);
        for _ in 0..ticks {
            let angle_rad = self.angle_counts / self.counts_per_rad;
            let (motor_nm, brake) = self.start_tick(angle_rad, tension_n);
            let drive_nm = motor_nm + self.params.radius_m * tension_n;
            for _ in 0..self.substeps {
                let p = &self.params;
                self.motion = p.motion_for_step(self.motion, drive_nm, self.rate_radps, brake);
                let start = self.rate_radps;
                let end = start + h * p.accel_radps2(self.motion, drive_nm, start, brake);
                let (motion, rate) = p.after_step(self.motion, start, end, drive_nm, brake);
                self.angle_counts += 0.5 * (start + rate) * h * self.counts_per_rad;
                self.motion = motion;
                self.rate_radps = rate;
            }
            if let Some(e) = self.end_tick(self.speed_mps()) {
                period_max_mps = period_max_mps.max(e);
            }
        }
        self.end_period(f64::from(command.rate_mps), self.speed_mps());
        (self.speed_mps(), period_max_mps)
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
