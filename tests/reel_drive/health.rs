//! (A module of `tests/reel_drive.rs`.) The reel drive's faults reach the outer controller's health: every
//! [`DriveFault`] through [`Controller::step_with_drive`], against the mapping of
//! [`DriveFault::outer_reaction`], on the paper's mission as the reel MCU senses it.

use tss_reel::controller::{
    Config, Controller, EventKind, Fault, Flags, Health, Input, Output, Sensor,
};
use tss_reel::recordings::mission;
use tss_reel::reel_drive::{DriveFault, DriveFaults, OuterReaction};

/// The mission's sample at `tick` (the mission's first hour has every sample).
fn input(tick: u32) -> Input<f32> {
    let [length_m, alpha_rad, alpha_rate_radps] =
        mission::sample(tick).expect("the first hour has every sample");
    Input {
        tick,
        length_m,
        reel_rate_mps: None,
        tension_n: None,
        alpha_rad: Some(alpha_rad),
        alpha_rate_radps: Some(alpha_rate_radps),
        orbit_rate_radps: mission::ORBIT_RATE_RADPS,
        true_anomaly_rad: 0.0,
    }
}

fn faults(list: &[DriveFault]) -> DriveFaults {
    let mut set = DriveFaults::NONE;
    for f in list {
        set.insert(*f);
    }
    set
}

/// A controller that has flown the mission's first `ticks` ticks with a quiet drive.
fn nominal_for(ticks: u32) -> Controller<f32> {
    let mut ctl = Controller::new(Config::paper()).expect("the paper's numbers are valid");
    for tick in 0..ticks {
        let out = ctl.step_with_drive(tick, Some(&input(tick)), DriveFaults::NONE);
        assert_eq!(out.health, Health::Nominal, "{tick}: {out:?}");
        while ctl.pop_event().is_some() {}
    }
    ctl
}

/// One period at tick 100 with `fault` after 100 quiet ones.
fn one_period_with(fault: DriveFault) -> (Controller<f32>, Output<f32>) {
    let mut ctl = nominal_for(100);
    let out = *ctl.step_with_drive(100, Some(&input(100)), faults(&[fault]));
    (ctl, out)
}

#[test]
fn a_quiet_drive_is_the_plain_step() {
    let mut with = nominal_for(0);
    let mut plain = Controller::new(Config::paper()).unwrap();
    for tick in 0..300 {
        let x = input(tick);
        assert_eq!(
            with.step_with_drive(tick, Some(&x), DriveFaults::NONE),
            plain.step(&x)
        );
    }
    // And without a sample, the missing step.
    assert_eq!(
        with.step_with_drive(300, None, DriveFaults::NONE),
        plain.step_missing(300)
    );
}

#[test]
fn reported_faults_leave_the_step_as_it_is() {
    for fault in [DriveFault::Tick, DriveFault::CommandInvalid] {
        assert_eq!(fault.outer_reaction(), OuterReaction::Report);
        let (_, out) = one_period_with(fault);
        let mut plain = nominal_for(100);
        assert_eq!(out, *plain.step(&input(100)), "{fault:?}");
        assert_eq!(out.health, Health::Nominal);
    }
}

#[test]
fn encoder_saturation_and_tension_faults_degrade_then_safe_hold_if_they_last() {
    let coast_ticks = Config::<f32>::paper().monitor.coast_ticks;
    for fault in [
        DriveFault::EncoderJump,
        DriveFault::EncoderMissing,
        DriveFault::DutySaturated,
        DriveFault::TensionOutOfRange,
    ] {
        assert_eq!(fault.outer_reaction(), OuterReaction::Degrade);
        let (mut ctl, out) = one_period_with(fault);
        // The period is a missing sample: coast on the last command.
        assert_eq!(out.health, Health::Degraded, "{fault:?}: {out:?}");
        assert_eq!(out.fault, Some(Fault::Sensor(Sensor::Missing)));
        assert!(out
            .flags
            .contains(Flags::SAFE_ACTION | Flags::HEALTH_CHANGED));
        let before = ctl.output().rate_cmd_mps;
        assert!(before > 0.0);
        // The fault persists: Degraded for the coast, then safe hold.
        let mut tick = 101;
        let mut health = out.health;
        while health == Health::Degraded {
            let out = ctl.step_with_drive(tick, Some(&input(tick)), faults(&[fault]));
            health = out.health;
            if health == Health::Degraded {
                assert_eq!(out.rate_cmd_mps, before, "coasting on the last command");
            } else {
                assert!(out.rate_cmd_mps < before, "safe hold ramps toward zero");
            }
            tick += 1;
        }
        assert_eq!(health, Health::SafeHold, "{fault:?}");
        assert_eq!(tick - 100, coast_ticks + 1, "{fault:?}");
        // A single faulty period after a quiet one recovers at the next quiet one.
        let (mut ctl, _) = one_period_with(fault);
        let out = ctl.step_with_drive(101, Some(&input(101)), DriveFaults::NONE);
        assert_eq!(out.health, Health::Nominal, "{fault:?}");
    }
}

#[test]
fn a_tripped_drive_forces_safe_hold_at_once_and_holds_it_while_tripped() {
    let recovery = Config::<f32>::paper().monitor.recovery_ticks;
    for fault in [DriveFault::MotorStall, DriveFault::Actuator] {
        assert_eq!(fault.outer_reaction(), OuterReaction::SafeHold);
        let (mut ctl, out) = one_period_with(fault);
        assert_eq!(out.health, Health::SafeHold, "{fault:?}: {out:?}");
        assert!(out
            .flags
            .contains(Flags::SAFE_ACTION | Flags::HEALTH_CHANGED));
        // The change is an event, as any health change is.
        let events: Vec<_> = core::iter::from_fn(|| ctl.pop_event()).collect();
        assert!(
            events.iter().any(|e| e.tick == 100
                && e.kind
                    == EventKind::Health {
                        from: Health::Nominal,
                        to: Health::SafeHold
                    }),
            "{events:?}"
        );
        // Safe hold ramps the command toward zero (the drive's brake holds meanwhile).
        let first = out.rate_cmd_mps.abs();
        let mut last = first;
        // Tripped for 3 × recovery periods: never leaves safe hold.
        for tick in 101..101 + 3 * recovery {
            let out = ctl.step_with_drive(tick, Some(&input(tick)), faults(&[fault]));
            assert_eq!(out.health, Health::SafeHold, "{fault:?} at {tick}");
            assert!(out.rate_cmd_mps.abs() <= last);
            last = out.rate_cmd_mps.abs();
        }
        assert_eq!(last, 0.0);
        // Cleared: recovery_ticks valid periods in a row, then the law again.
        let from = 101 + 3 * recovery;
        let mut tick = from;
        while ctl
            .step_with_drive(tick, Some(&input(tick)), DriveFaults::NONE)
            .health
            == Health::SafeHold
        {
            tick += 1;
        }
        assert_eq!(tick - from + 1, recovery, "{fault:?}");
        assert_eq!(ctl.output().health, Health::Nominal);
    }
}

#[test]
fn the_strongest_reaction_of_a_period_wins() {
    let (_, out) = one_period_with(DriveFault::TensionOutOfRange);
    assert_eq!(out.health, Health::Degraded);
    let mut ctl = nominal_for(100);
    let out = ctl.step_with_drive(
        100,
        Some(&input(100)),
        faults(&[
            DriveFault::Tick,
            DriveFault::EncoderJump,
            DriveFault::MotorStall,
        ]),
    );
    assert_eq!(out.health, Health::SafeHold);
}
