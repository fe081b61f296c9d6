//! The recorded mission as sensors: [`Replay`] implements the [`crate::hal`] sensor traits
//! over [`super::replay`], so that a firmware without the real sensors flies the recording
//! through the same [`crate::hal::control_cycle`] as it would fly them.
//!
//! Both firmwares use it as the outer law's sensor source: the QEMU one
//! (`src/firmware/mission.rs`) for its built-in test run, the NUCLEO-G474RE one
//! (`src/board/nucleo_g474re.rs`) because the board has only the drum's encoder and the load
//! cell. It lives here, with the data, and not in `tss_reel::firmware`: the board build does not
//! enable the `firmware` feature, and both builds enable `recordings`. It is a device of the
//! boundary layer, so it imports [`crate::hal`] and nothing above it; [`crate::hal`] itself does
//! not depend on the `recordings` feature.

use super::replay::{DROPOUT_FROM_TICK, DROPOUT_UNTIL_TICK, ORBIT_RATE_RADPS, PERIOD_S, SAMPLES};
use crate::hal::{ErrorKind, ErrorType, LengthSensor, OrbitRateSource, SwingSensor, TensionSensor};

/// The first 720 s of the paper's mission ([`super::replay`]) as the reel MCU's length
/// encoder (length and rate), swing sensor (α), load cell (none) and orbit source, one sample per control period (tick), with the
/// injected dropout: no length or swing sample at ticks
/// [`DROPOUT_FROM_TICK`]`..`[`DROPOUT_UNTIL_TICK`], nor past the end of the recording
/// ([`ErrorKind::NoSample`], which [`crate::hal::control_cycle`] turns into a missing step).
/// The orbit rate is the paper's circular orbit's, [`ORBIT_RATE_RADPS`], at every tick.
///
/// It has no state: every reading is a function of the tick, so one value (it is `Copy`) serves
/// as all three devices of a [`crate::hal::Devices`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Replay;

impl Replay {
    /// The sensed (l m, α rad, α̇ rad/s) at control period `tick`, as the length and swing
    /// sensors deliver them: [`ErrorKind::NoSample`] in the dropout and past the recording.
    pub fn sample(tick: u32) -> Result<&'static [f32; 3], ErrorKind> {
        if (DROPOUT_FROM_TICK..DROPOUT_UNTIL_TICK).contains(&tick) {
            return Err(ErrorKind::NoSample);
        }
        SAMPLES.get(tick as usize).ok_or(ErrorKind::NoSample)
    }
}

impl ErrorType for Replay {
    type Error = ErrorKind;
}

impl LengthSensor for Replay {
    fn read_length_m(&mut self, tick: u32) -> Result<f32, ErrorKind> {
        Self::sample(tick).map(|s| s[0])
    }
    /// The encoder's rate: the recorded length's change over the period that ended at `tick`
    /// (none at the first tick, nor when either end is missing). The replay is open loop: the
    /// recorded tether moved as the recording's reel did, not as this controller commands, so
    /// the estimator must be driven by what the reel did.
    fn read_rate_mps(&mut self, tick: u32) -> Result<f32, ErrorKind> {
        let before = Self::sample(tick.checked_sub(1).ok_or(ErrorKind::NoSample)?)?;
        Self::sample(tick).map(|now| (now[0] - before[0]) / PERIOD_S)
    }
}

/// α only: the recording's α̇ is not a sensor that flies.
impl SwingSensor for Replay {
    fn read_alpha_rad(&mut self, tick: u32) -> Result<f32, ErrorKind> {
        Self::sample(tick).map(|s| s[1])
    }
}

/// The recording has no load cell.
impl TensionSensor for Replay {
    fn read_tension_n(&mut self, _tick: u32) -> Result<f32, ErrorKind> {
        Err(ErrorKind::NoSample)
    }
}

/// The paper's circular orbit: θ̇ = n at every tick, θ = 0 (not used at e = 0).
impl OrbitRateSource for Replay {
    fn read_orbit_rate_radps(&mut self, _tick: u32) -> Result<f32, ErrorKind> {
        Ok(ORBIT_RATE_RADPS)
    }
    fn read_true_anomaly_rad(&mut self, _tick: u32) -> Result<f32, ErrorKind> {
        Ok(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::{Config, Controller, Input, Output};
    use crate::hal::{control_cycle, Devices, ReelDrive};

    /// Every tick of the recording, the dropout's edges and past the end.
    #[test]
    fn reads_the_recording_except_in_the_dropout_and_past_the_end() {
        let mut r = Replay;
        for tick in 0..SAMPLES.len() as u32 + 5 {
            let dropout = (DROPOUT_FROM_TICK..DROPOUT_UNTIL_TICK).contains(&tick);
            let length = r.read_length_m(tick);
            let swing = r.read_alpha_rad(tick);
            match SAMPLES.get(tick as usize) {
                Some(s) if !dropout => {
                    assert_eq!(length, Ok(s[0]), "tick {tick}");
                    assert_eq!(swing, Ok(s[1]), "tick {tick}");
                }
                _ => {
                    assert_eq!(length, Err(ErrorKind::NoSample), "tick {tick}");
                    assert_eq!(swing, Err(ErrorKind::NoSample), "tick {tick}");
                }
            }
            assert_eq!(r.read_orbit_rate_radps(tick), Ok(ORBIT_RATE_RADPS));
        }
        // The dropout is inside the recording, so both of its edges are seen above.
        assert!(0 < DROPOUT_FROM_TICK && (DROPOUT_UNTIL_TICK as usize) < SAMPLES.len());
        assert!(Replay::sample(DROPOUT_FROM_TICK - 1).is_ok());
        assert!(Replay::sample(DROPOUT_FROM_TICK).is_err());
        assert!(Replay::sample(DROPOUT_UNTIL_TICK - 1).is_err());
        assert!(Replay::sample(DROPOUT_UNTIL_TICK).is_ok());
    }

    struct LastCommand(Option<Output<f32>>);

    impl ErrorType for LastCommand {
        type Error = ErrorKind;
    }

    impl ReelDrive for LastCommand {
        fn command(&mut self, output: &Output<f32>) -> Result<(), ErrorKind> {
            self.0 = Some(*output);
            Ok(())
        }
    }

    /// The firmwares' path (the replay as devices, through `control_cycle`) commands the reel
    /// exactly as stepping the controller on the recording directly does, with `step_missing`
    /// in the dropout: what `tests/firmware_replay.rs` computes on the host and compares
    /// against the QEMU firmware's log.
    #[test]
    fn flown_through_control_cycle_it_commands_what_the_recording_does() {
        let mut via_devices = Controller::new(Config::<f32>::flight()).unwrap();
        let mut direct = Controller::new(Config::<f32>::flight()).unwrap();
        let mut dev = Devices {
            length: Replay,
            swing: Replay,
            orbit: Replay,
            reel: LastCommand(None),
            tension: Replay,
        };
        let mut dropouts = 0;
        for (tick, s) in SAMPLES.iter().enumerate() {
            let tick = tick as u32;
            let cycle = control_cycle(
                &mut via_devices,
                tick,
                &mut dev,
                crate::reel_drive::DriveFaults::NONE,
            );
            let expected = if (DROPOUT_FROM_TICK..DROPOUT_UNTIL_TICK).contains(&tick) {
                dropouts += 1;
                assert_eq!(cycle.sensor_error, Some(ErrorKind::NoSample));
                assert_eq!(cycle.input, None, "tick {tick}");
                *direct.step_missing(tick)
            } else {
                assert_eq!(cycle.sensor_error, None, "tick {tick}");
                let input = Input {
                    tick,
                    length_m: s[0],
                    reel_rate_mps: Replay.read_rate_mps(tick).ok(),
                    tension_n: None,
                    alpha_rad: Some(s[1]),
                    alpha_rate_radps: None,
                    orbit_rate_radps: ORBIT_RATE_RADPS,
                    true_anomaly_rad: 0.0,
                };
                // The sample the controller stepped on, for its housekeeping.
                assert_eq!(cycle.input, Some(input), "tick {tick}");
                *direct.step(&input)
            };
            let sent = dev.reel.0.take().expect("a command every tick");
            assert_eq!(
                sent.rate_cmd_mps.to_bits(),
                expected.rate_cmd_mps.to_bits(),
                "tick {tick}"
            );
            assert_eq!(sent, expected, "tick {tick}");
        }
        assert_eq!(dropouts, DROPOUT_UNTIL_TICK - DROPOUT_FROM_TICK);
    }
}
