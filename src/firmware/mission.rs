//! What the firmware does on each control tick: the reel controller flying a recorded stretch
//! of the paper's mission.
//!
//! The built-in test input ([`tss_reel::recordings::replay`]) is the first 720 s of `scenarios/paper.toml`
//! as the reel MCU senses it, recorded from `tss-sim`, with a sensor dropout injected at ticks
//! 400..450 (longer than the controller's 30-tick coast, so it goes Degraded → SafeHold and
//! recovers). The replay ([`tss_reel::recordings::sensors::Replay`], shared with the
//! NUCLEO-G474RE firmware) implements the [`tss_reel::hal`] sensor traits; the reel drive is a
//! telemetry sink that folds every command into a digest; the main loop hands each command
//! ([`Mission::output`]) to the inner loop ([`super::reel`]), which makes a simulated drum
//! follow it. The controller is the flight one: `tss_reel::controller::Controller<f32>` with
//! the flight configuration (`Config::flight`: the paper's mission on the onboard estimator,
//! from the recorded α alone and the encoder's rate), stepped once per law period through
//! [`tss_reel::hal::control_cycle`].
//!
//! The contract with the main loop in `main.rs`:
//! - [`CONTROL_PERIOD_MS`]: the law's period (the inner loop's ticks divide it);
//! - [`MAX_TICKS`]: a hard bound on the run in law periods (a mission still running then is a
//!   failure);
//! - [`Mission::new`] once, then [`Mission::step`] once per law period with the period index
//!   `0, 1, 2, …`, returning [`Flow::Continue`], [`Flow::Finished`] or [`Flow::Failed`].
//!
//! What is logged at `info`/`warn` is checked against `expected/firmware.log` by
//! `scripts/firmware-log`, and every logged command (and the digest of all of them) is checked
//! bit for bit against the same core compiled for the host by `tests/firmware_replay.rs`.

use tss_reel::controller::{Config, Controller, Output};
use tss_reel::hal::{control_cycle, Cycle, Devices, ErrorKind, ErrorType, ReelDrive};
use tss_reel::link::{fnv1a_f32, fnv1a_start};
use tss_reel::recordings::replay::{
    DROPOUT_FROM_TICK, DROPOUT_UNTIL_TICK, ORBIT_RATE_RADPS, PERIOD_S, SAMPLES,
};
use tss_reel::recordings::sensors::Replay;

/// Control period, ms: 1 s, the period of the paper's scenario and of the recording.
pub const CONTROL_PERIOD_MS: u32 = 1_000;

// The recording's period is the firmware's.
const _: () = assert!(PERIOD_S == 1.0 && CONTROL_PERIOD_MS == 1_000);
// The period must be one SysTick can produce.
const _: () = assert!(super::clock::reload_for(CONTROL_PERIOD_MS).is_some());

/// Hard bound on the number of ticks of one run (the replay plus a margin).
pub const MAX_TICKS: u32 = SAMPLES.len() as u32 + 10;

/// A status line every this many ticks.
const LOG_EVERY_TICKS: u32 = 60;

/// What the main loop does after a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum Flow {
    /// Wait for the next tick and step again.
    Continue,
    /// The mission is over: exit with success.
    Finished,
    /// Something is wrong (it has been logged): exit with failure.
    Failed,
}

/// The reel drive of the replay: a telemetry sink that checks and fingerprints each command.
struct TelemetryReel {
    /// FNV-1a over the bit patterns of all rate commands ([`fnv1a_f32`], as the PIL link's
    /// `Report` frame and `tests/firmware_replay.rs`).
    digest: u32,
    /// Commands received.
    count: u32,
}

impl ErrorType for TelemetryReel {
    type Error = ErrorKind;
}

impl ReelDrive for TelemetryReel {
    fn command(&mut self, output: &Output<f32>) -> Result<(), ErrorKind> {
        if !output.rate_cmd_mps.is_finite() {
            return Err(ErrorKind::Device);
        }
        self.digest = fnv1a_f32(self.digest, output.rate_cmd_mps);
        self.count = self.count.saturating_add(1);
        Ok(())
    }
}

/// The mission's state between ticks.
pub struct Mission {
    controller: Controller<f32>,
    devices: Devices<Replay, Replay, Replay, TelemetryReel, Replay>,
}

impl Mission {
    /// Sets the mission up (called once, before the first tick).
    // No `Default`: setting up may end the run (a rejected configuration exits with failure),
    // which a default value must not do.
    #[allow(clippy::new_without_default)]
    pub fn new() -> Self {
        // The paper's mission flown on the estimator (α only: the recording's α̇ is not a
        // flight sensor); valid by construction: a rejection would be a build
        // defect, reported on the first tick.
        let controller = Controller::new(Config::flight());
        if let Err(e) = &controller {
            defmt::error!("controller configuration rejected: {}", e);
        }
        Self {
            controller: controller.unwrap_or_else(|_| super::exit::failure()),
            devices: Devices {
                length: Replay,
                swing: Replay,
                orbit: Replay,
                reel: TelemetryReel {
                    digest: fnv1a_start(),
                    count: 0,
                },
                tension: Replay,
            },
        }
    }

    /// The controller's last output (its command for the current law period).
    pub fn output(&self) -> &Output<f32> {
        self.controller.output()
    }

    /// One control cycle: read the replay's sensors, step the controller
    /// ([`Controller::step`], or `step_missing` in a dropout), command the reel.
    ///
    /// Out of line on purpose: it is the flight ELF's symbol for the control path, from which
    /// `scripts/panic-check` proves that no panic is reachable.
    #[inline(never)]
    fn control(&mut self, tick: u32) -> Cycle {
        control_cycle(&mut self.controller, tick, &mut self.devices)
    }

    /// One control step at tick `tick` (0 for the first).
    pub fn step(&mut self, tick: u32) -> Flow {
        if tick == 0 {
            defmt::info!(
                "replay: {=usize} s of scenarios/paper.toml, n = {=f32} rad/s, dropout at ticks {=u32}..{=u32}",
                SAMPLES.len(),
                ORBIT_RATE_RADPS,
                DROPOUT_FROM_TICK,
                DROPOUT_UNTIL_TICK
            );
        }
        if tick as usize >= SAMPLES.len() {
            let reel = &self.devices.reel;
            defmt::info!(
                "replay done: {=u32} commands, digest={=u32:#010x}, events dropped: {=u32}",
                reel.count,
                reel.digest,
                self.controller.events_dropped()
            );
            return Flow::Finished;
        }

        let cycle = self.control(tick);
        // In detail (`DEFMT_LOG=debug`): what this cycle sensed and what it commanded.
        match Replay::sample(tick) {
            // (The recording's α̇ is not a sensor that flies: the controller estimates it.)
            Ok(&[length_m, alpha_rad, _]) => defmt::debug!(
                "t={=u32} sensed: l={=f32} m alpha={=f32} rad n={=f32} rad/s",
                tick,
                length_m,
                alpha_rad,
                ORBIT_RATE_RADPS
            ),
            Err(e) => defmt::debug!("t={=u32} sensed: nothing ({})", tick, e),
        }
        defmt::debug!("t={=u32} output: {}", tick, self.controller.output());
        if let Some(e) = cycle.reel_error {
            defmt::error!("t={=u32} reel refused the command: {}", tick, e);
            return Flow::Failed;
        }
        // Every health or phase change, fault and blend restart, once, from the controller's
        // bounded event queue.
        let mut events = false;
        while let Some(ev) = self.controller.pop_event() {
            defmt::warn!("t={=u32} event: {}", ev.tick, ev.kind);
            events = true;
        }
        if events || tick.is_multiple_of(LOG_EVERY_TICKS) {
            let o = self.controller.output();
            defmt::info!(
                "t={=u32} {} {}: l={=f32} m alpha_ref={=f32} rad delta={=f32} rad cmd={=f32} m/s accel={=f32} m/s2 E={=f32} flags={=u32:#x}",
                tick,
                o.phase,
                o.health,
                o.length_estimate_m,
                o.alpha_ref_rad,
                o.delta_rad,
                o.rate_cmd_mps,
                o.accel_cmd_mps2,
                o.blend_weight,
                o.flags.0
            );
        }
        Flow::Continue
    }
}
