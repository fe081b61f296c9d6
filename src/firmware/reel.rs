//! The inner loop of the QEMU firmware: the speed loop ([`tss_reel::reel_drive::SpeedLoop`])
//! over embedded-hal ([`HalReelDrive`]) driving a simulated reel ([`SimDrum`]: motor, drum,
//! brake, encoder, load cell behind the drive's traits, as the replay is behind the outer
//! sensors'), one [`Reel::tick`] per inner tick.
//!
//! ## The two rates (see `src/main.rs`)
//! SysTick fires at the inner rate ([`INNER_RATE_HZ`], 1 kHz; [`INNER_PERIOD_MS`] is the
//! setting, any whole number of ms up to 10, so at least 100 Hz). The main loop wakes on each
//! tick; every [`OUTER_PERIOD_TICKS`] ticks (1 s, the law's period) it first runs the outer
//! step ([`super::mission::Mission::step`]) and hands its command to the drive, then, every
//! tick, the inner step. A foreground loop, not preemption: the outer step (≤ 925
//! instructions on the estimator, `scripts/bench-target`) and an inner step (≤ 209, with the
//! driver and drum model around it well under 1 000) fit in one inner period (25 000 instructions at 25 MHz),
//! so the inner loop is never late; a tick that is, is an overrun, counted by the clock
//! ([`super::clock::ControlClock::overruns`]) and logged. (The NUCLEO-G474RE firmware runs the
//! inner loop in the SysTick exception instead, preempting the outer: the same rates and
//! order, on its real timers.)

use core::cell::RefCell;

use tss_reel::controller::Output;
use tss_reel::reel_drive::hal::{HalReelDrive, MotorPins};
use tss_reel::reel_drive::sim::{PinRole, SimDrum, SimEncoder, SimLoadCell, SimPin, SimPwm};
use tss_reel::reel_drive::{Brake, DriveConfig, DriveFaults, RateCommand, SpeedLoop};

/// The inner period, ms: the setting (1 to 10 ms: 1 kHz down to the speed loop's 100 Hz).
pub const INNER_PERIOD_MS: u32 = 1;

/// The inner (speed-loop) rate, Hz.
pub const INNER_RATE_HZ: u32 = 1_000 / INNER_PERIOD_MS;

/// Inner ticks per law period (the law's period is 1 s).
pub const OUTER_PERIOD_TICKS: u32 = 1_000 / INNER_PERIOD_MS;

const _: () = assert!(INNER_PERIOD_MS >= 1 && INNER_PERIOD_MS <= 10);
const _: () = assert!(OUTER_PERIOD_TICKS * INNER_PERIOD_MS == 1_000);
const _: () = assert!(super::clock::reload_for(INNER_PERIOD_MS).is_some());

/// The tether's pull on the simulated drum, N (the recording has no tension channel).
pub const SIM_TENSION_N: f32 = 2.0;

/// The drive over the simulated reel.
type SimDrive<'a> =
    HalReelDrive<SimEncoder<'a>, SimLoadCell<'a>, SimPwm<'a>, SimPin<'a>, SimPin<'a>, SimPin<'a>>;

/// The drive's configuration: the reference reel at [`INNER_RATE_HZ`].
pub fn drive_config() -> DriveConfig {
    let mut cfg = DriveConfig::example();
    cfg.inner_rate_hz = INNER_RATE_HZ;
    cfg.outer_period_ticks = OUTER_PERIOD_TICKS;
    cfg
}

/// The simulated reel for [`drive_config`]: its drum model off the drive's (see
/// [`SimDrum::mismatched`]).
pub fn sim_drum() -> SimDrum {
    SimDrum::mismatched(&drive_config(), SIM_TENSION_N)
}

/// The inner loop's state: the drive over the simulated reel, and what it saw over the
/// current law period.
pub struct Reel<'a> {
    drum: &'a RefCell<SimDrum>,
    drive: SimDrive<'a>,
    /// The faults of every inner tick of this law period.
    period_faults: DriveFaults,
}

impl<'a> Reel<'a> {
    /// The drive over `drum`, in its safe state (brake engaged, driver off).
    pub fn new(drum: &'a RefCell<SimDrum>) -> Self {
        let speed = SpeedLoop::new(drive_config()).unwrap_or_else(|e| {
            defmt::error!("drive configuration rejected: {}", e);
            super::exit::failure()
        });
        let pins = MotorPins {
            pwm: SimPwm(drum),
            direction: SimPin(drum, PinRole::Direction),
            brake: SimPin(drum, PinRole::Brake),
            enable: SimPin(drum, PinRole::Enable),
        };
        let drive = HalReelDrive::new(speed, SimEncoder(drum), SimLoadCell(drum), pins)
            .unwrap_or_else(|_| super::exit::failure());
        Self {
            drum,
            drive,
            period_faults: DriveFaults::NONE,
        }
    }

    /// The law's command of this period, from inner tick `tick` on.
    pub fn command(&mut self, output: &Output<f32>, tick: u32) {
        // A non-finite command is a drive fault the speed loop reports every tick (and brings
        // the drum to rest for): nothing more to do here.
        let _ = self.drive.set_command(RateCommand::from(output), tick);
    }

    /// One inner tick: read, step the speed loop, set the outputs; then the drum moves for one
    /// inner period under them.
    ///
    /// Out of line on purpose: the flight ELF's symbol for the inner loop, from which
    /// `scripts/panic-check` (with `TSS_PANIC_ROOT`) proves that no panic is reachable.
    #[inline(never)]
    pub fn tick(&mut self, tick: u32) {
        let _ = self.drive.tick(tick);
        self.period_faults = self.period_faults.union(self.drive.speed_loop().faults());
        if let Ok(mut drum) = self.drum.try_borrow_mut() {
            drum.advance(INNER_PERIOD_MS as f32 * 1e-3);
        }
    }

    /// Logs the law period `period` that just ended: the command it had, and where the drum
    /// got to under it (speed from the encoder, duty, brake, the period's faults); then starts
    /// the next period's fault set.
    ///
    /// Returns the period's faults (the union of its ticks'), for the law's next step
    /// ([`tss_reel::hal::control_cycle`]), and starts the next period's set.
    pub fn log_period(&mut self, period: u32, command: &Output<f32>) -> DriveFaults {
        let out = self.drive.output();
        let brake = match out.brake {
            Brake::Engaged => "engaged",
            Brake::Releasing { .. } => "releasing",
            Brake::Released { .. } => "released",
            Brake::MotorHold => "motor-hold",
            Brake::Tripped(_) => "tripped",
        };
        defmt::info!(
            "t={=u32} drive: cmd={=f32} m/s v={=f32} m/s duty={=f32} brake={=str} faults={=u16:#x}",
            period,
            command.rate_cmd_mps,
            out.speed_mps,
            out.duty,
            brake,
            self.period_faults.bits()
        );
        core::mem::replace(&mut self.period_faults, DriveFaults::NONE)
    }
}
