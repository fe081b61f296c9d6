//! Mission-mode commands (docs/equations.md §7.1): hold, resume, retrieve, abort and a new
//! deployment, legal only where the sequencer allows them, applied at a period boundary; a
//! refused command changes nothing, and no sequence of commands makes a bad command.

use proptest::prelude::*;
use tss_reel::controller::{
    Config, Controller, EventKind, Flags, Input, Mode, ModeCommand, Output, Phase, Refusal,
};

const N_RADPS: f32 = 1.060_237_2e-3;

/// The paper's mission with a slow reel (5 mm/s²), so that bringing it to rest takes periods.
fn config() -> Config<f32> {
    let mut cfg = Config::paper();
    cfg.envelope.max_accel_mps2 = 5e-3;
    cfg
}

fn sample(tick: u32, length_m: f32, alpha_rad: f32) -> Input<f32> {
    Input {
        tick,
        length_m,
        reel_rate_mps: None,
        tension_n: None,
        alpha_rad: Some(alpha_rad),
        alpha_rate_radps: Some(0.0),
        orbit_rate_radps: N_RADPS,
        true_anomaly_rad: 0.0,
    }
}

/// A kinematic reel: the length follows the command over each 1 s period; α sits on α_r.
struct Flight {
    ctl: Controller<f32>,
    tick: u32,
    length_m: f32,
    out: Output<f32>,
}

impl Flight {
    fn new(cfg: Config<f32>, length_m: f32) -> Self {
        let mut ctl = Controller::new(cfg).unwrap();
        let out = *ctl.step(&sample(0, length_m, -0.6));
        Self {
            ctl,
            tick: 0,
            length_m,
            out,
        }
    }

    /// One period: the reel runs at the last command, then a step.
    fn step(&mut self) -> Output<f32> {
        self.length_m += self.out.rate_cmd_mps;
        self.tick += 1;
        let alpha = self.out.alpha_ref_rad;
        self.out = *self.ctl.step(&sample(self.tick, self.length_m, alpha));
        self.out
    }

    fn fly(&mut self, ticks: u32) -> Output<f32> {
        for _ in 0..ticks {
            self.step();
        }
        self.out
    }

    /// The commands applied so far, drained from the event queue.
    fn applied(&mut self) -> Vec<(u32, ModeCommand)> {
        core::iter::from_fn(|| self.ctl.pop_event())
            .filter_map(|e| match e.kind {
                EventKind::Command(c) => Some((e.tick, c)),
                _ => None,
            })
            .collect()
    }
}

#[test]
fn a_hold_brings_the_reel_to_rest_within_the_envelope_and_keeps_the_length() {
    let mut f = Flight::new(config(), 1.0);
    let out = f.fly(600);
    assert_eq!(out.phase, Phase::Deploy);
    let rate = out.rate_cmd_mps;
    assert!(rate > 0.05, "paying out at {rate} m/s");
    f.applied();
    assert_eq!(f.ctl.command(ModeCommand::Hold), Ok(()));
    // Applied at the next boundary, not before.
    assert_eq!(f.ctl.mode(), Mode::Flying);
    let a = config().envelope.max_accel_mps2;
    let mut prev = rate;
    let mut rest_tick = None;
    for _ in 0..2_000 {
        let out = f.step();
        assert!(
            out.flags.contains(Flags::HELD | Flags::SAFE_ACTION),
            "{out:?}"
        );
        assert!((out.rate_cmd_mps - prev).abs() <= a * 1.000_01, "{out:?}");
        assert!(out.rate_cmd_mps.abs() <= prev.abs());
        prev = out.rate_cmd_mps;
        if out.rate_cmd_mps == 0.0 && rest_tick.is_none() {
            rest_tick = Some(out.tick);
        }
        assert_eq!(out.phase, Phase::Deploy);
    }
    assert_eq!(f.applied(), vec![(601, ModeCommand::Hold)]);
    assert_eq!(f.ctl.mode(), Mode::Held { since_tick: 601 });
    // At rest after rate / a periods, and the length kept since.
    let rest = rest_tick.expect("at rest");
    assert_eq!(rest - 600, (rate / a).ceil() as u32);
    let held_m = f.length_m;
    f.fly(500);
    assert_eq!(f.length_m, held_m);
}

#[test]
fn resume_goes_on_with_the_phase_held_and_its_clock() {
    // Stage 2 at 1 000 s of mission time; a hold of 2 000 s from 500 s moves it to 3 000 s.
    let mut cfg = config();
    cfg.stage2.start_tick = Some(1_000);
    let mut f = Flight::new(cfg, 1.0);
    f.fly(499);
    f.ctl.command(ModeCommand::Hold).unwrap();
    f.fly(2_000);
    assert_eq!(f.out.phase, Phase::Deploy);
    assert!(f.out.flags.contains(Flags::HELD));
    f.ctl.command(ModeCommand::Resume).unwrap();
    let out = f.step();
    assert_eq!(f.ctl.mode(), Mode::Flying);
    assert_eq!(out.phase, Phase::Deploy);
    assert!(out.flags.contains(Flags::BLEND_RESTART));
    assert!(!out.flags.contains(Flags::SAFE_ACTION | Flags::HELD));
    // The blend starts from rest: the command leaves zero within the acceleration limit.
    assert!(out.rate_cmd_mps.abs() <= 5e-3 * 1.000_01);
    f.fly(499);
    assert_eq!(
        (f.out.tick, f.out.phase),
        (2_999, Phase::Deploy),
        "stage 2 not before 3 000 s"
    );
    let out = f.step();
    assert_eq!(out.tick, 3_000);
    assert!(
        matches!(out.phase, Phase::Slew | Phase::Retrieve),
        "{out:?}"
    );
}

#[test]
fn retrieve_begins_stage_2_from_stage_1_only() {
    let mut f = Flight::new(config(), 1.0);
    f.fly(100);
    f.ctl.command(ModeCommand::Hold).unwrap();
    f.fly(10);
    // From a hold, retrieval ends it.
    f.ctl.command(ModeCommand::Retrieve).unwrap();
    // (At 110 m the slew meets Eq. 35 at once: retrieval.)
    let out = f.step();
    assert!(
        matches!(out.phase, Phase::Slew | Phase::Retrieve),
        "{out:?}"
    );
    assert_eq!(f.ctl.mode(), Mode::Flying);
    assert_eq!(
        f.ctl.command(ModeCommand::Retrieve),
        Err(Refusal::NotInStage1)
    );
}

#[test]
fn an_abort_holds_for_good_until_a_new_deployment() {
    let mut cfg = config();
    cfg.stage2.start_tick = Some(300);
    let mut f = Flight::new(cfg, 1.0);
    f.fly(400);
    assert_eq!(f.out.phase, Phase::Keep2);
    f.ctl.command(ModeCommand::Abort).unwrap();
    f.fly(3_000);
    assert!(f.out.flags.contains(Flags::ABORTED | Flags::SAFE_ACTION));
    assert_eq!(f.out.rate_cmd_mps, 0.0);
    for c in [ModeCommand::Resume, ModeCommand::Hold, ModeCommand::Abort] {
        assert!(f.ctl.command(c).is_err(), "{c:?}");
    }
    assert_eq!(f.ctl.mode(), Mode::Aborted);
    f.ctl.command(ModeCommand::StartDeployment).unwrap();
    let out = f.step();
    assert_eq!((out.phase, f.ctl.mode()), (Phase::Deploy, Mode::Flying));
    assert!(out
        .flags
        .contains(Flags::BLEND_RESTART | Flags::PHASE_CHANGED));
    // The new mission's clock: stage 2 again 300 s after the new start.
    let start = out.tick;
    f.fly(299);
    assert_eq!(f.out.phase, Phase::Deploy);
    assert_eq!(f.step().tick - start, 300);
    assert_ne!(f.out.phase, Phase::Deploy);
}

#[test]
fn one_command_at_a_time_and_each_refusal_names_its_rule() {
    let mut f = Flight::new(config(), 1.0);
    f.fly(10);
    assert_eq!(f.ctl.command(ModeCommand::Resume), Err(Refusal::NotHeld));
    assert_eq!(
        f.ctl.command(ModeCommand::StartDeployment),
        Err(Refusal::NotAborted)
    );
    f.ctl.command(ModeCommand::Hold).unwrap();
    assert_eq!(f.ctl.command(ModeCommand::Abort), Err(Refusal::Pending));
    f.step();
    assert_eq!(f.ctl.command(ModeCommand::Hold), Err(Refusal::AlreadyHeld));
    f.ctl.command(ModeCommand::Abort).unwrap();
    f.step();
    assert_eq!(
        f.ctl.command(ModeCommand::Abort),
        Err(Refusal::AlreadyAborted)
    );
    assert_eq!(
        f.ctl.command(ModeCommand::Retrieve),
        Err(Refusal::NotInStage1)
    );
}

/// What the proptest does each period.
#[derive(Clone, Copy, Debug)]
enum Action {
    /// A period with a sample (α off the reference by this much, rad).
    Step(f32),
    /// A period without a sample.
    Missing,
    /// A command, before the next period.
    Command(ModeCommand),
}

fn action() -> impl Strategy<Value = Action> {
    prop_oneof![
        20 => (-0.05f32..0.05).prop_map(Action::Step),
        1 => Just(Action::Missing),
        3 => prop::sample::select(ModeCommand::ALL.to_vec()).prop_map(Action::Command),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    /// Any sequence of commands among samples and dropouts, from any phase of the mission:
    /// every command finite, inside the rate limit and within the acceleration limit of the
    /// one before; a refused command changes nothing (the controller's next output is the one
    /// it would have given without it); while held the rate only falls to rest.
    #[test]
    fn no_command_sequence_makes_a_bad_command(
        start_ticks in 0u32..400,
        stage2 in prop::option::of(50u32..600),
        actions in prop::collection::vec(action(), 1..400),
    ) {
        let mut cfg = config();
        cfg.stage2.start_tick = stage2;
        let env = cfg.envelope;
        let mut f = Flight::new(cfg, 1.0);
        f.fly(start_ticks);
        for a in actions {
            let prev = f.out.rate_cmd_mps;
            let out = match a {
                Action::Step(alpha_off) => {
                    f.length_m += f.out.rate_cmd_mps;
                    f.tick += 1;
                    let alpha = f.out.alpha_ref_rad + alpha_off;
                    f.out = *f.ctl.step(&sample(f.tick, f.length_m, alpha));
                    f.out
                }
                Action::Missing => {
                    f.length_m += f.out.rate_cmd_mps;
                    f.tick += 1;
                    f.out = *f.ctl.step_missing(f.tick);
                    f.out
                }
                Action::Command(c) => {
                    let before = f.ctl.clone();
                    if f.ctl.command(c).is_err() {
                        let mut twin = before.clone();
                        let next = sample(f.tick + 1, f.length_m + prev, f.out.alpha_ref_rad);
                        prop_assert_eq!(f.ctl.mode(), before.mode());
                        prop_assert_eq!(*f.ctl.clone().step(&next), *twin.step(&next));
                    }
                    continue;
                }
            };
            prop_assert!(out.rate_cmd_mps.is_finite() && out.accel_cmd_mps2.is_finite());
            prop_assert!(out.rate_cmd_mps.abs() <= env.max_rate_mps);
            if !out.flags.contains(Flags::LENGTH_LIMITED) {
                prop_assert!((out.rate_cmd_mps - prev).abs() <= env.max_accel_mps2 * 1.000_01 + 1e-7, "{:?}", out);
            }
            if out.flags.contains(Flags::HELD) || out.flags.contains(Flags::ABORTED) {
                prop_assert!(out.rate_cmd_mps.abs() <= prev.abs(), "{:?}", out);
                prop_assert!(out.flags.contains(Flags::SAFE_ACTION));
            }
            prop_assert!(f.length_m >= env.min_length_m - 1.0 && f.length_m <= env.max_length_m);
        }
    }
}
