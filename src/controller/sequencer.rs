//! The mission sequencer (docs/equations.md §7): the two stages, their phases, the Eq. 29 blend each stage
//! (or a recovery) restarts, and the reference angle α_r of each phase (Eqs. 34, 35).
//!
//! ```text
//!   stage 1:  Deploy ──(l ≥ stage-1 keep − capture)──▶ Keep1
//!   stage 2:  Slew ──(α_r meets Eq. 35)──▶ Retrieve ──(l ≤ stage-2 keep + capture)──▶ Keep2
//! ```
//!
//! Stage 1 begins with the first step; stage 2 at its configured tick or on command, from
//! whichever stage-1 phase the mission is in.
//!
//! **Progress.** Deploy and Retrieve each head for a keep length. A phase that stops getting
//! closer to it (a 5° α bias leaves the paper's retrieval at 2 364 m for ever, HZ-14) is
//! detected: no new closest approach by [`Config::keep_capture_m`] within
//! [`PROGRESS_TIME_CONSTANTS`] × the slowest time constant of the stage's loop (the Eq. 28
//! envelope decay 2/k1, the Eq. 29 blend 1/c) is reported as stalled (the
//! controller's `NO_PROGRESS` flag and event). The watch restarts with each blend restart
//! (stage start, recovery) and each phase.

use crate::config::Config;
use crate::law::Blend;
use crate::real::Real;
use crate::schedule::{LibratingReference, PreparedBand, Reference};

use super::command::{transition, Effect, Mode, ModeCommand, Refusal};
use super::output::Phase;

/// The progress window, in time constants of the stage's loop (see the module docs): long
/// enough that the exponential approach of the paper's phases to their keep lengths always
/// gains the capture distance within it.
pub const PROGRESS_TIME_CONSTANTS: f64 = 5.0;

/// The closest approach of the current phase to its keep length.
#[derive(Clone, Copy, Debug)]
struct Approach<T> {
    /// The smallest distance to the keep length so far, m.
    closest_m: T,
    /// The tick it was reached at.
    tick: u32,
    /// The stall was reported.
    stalled: bool,
}

/// When stage 2 (retrieval) begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage2Start {
    /// At this mission time (ticks since the first step), unless asked for earlier.
    At(u32),
    /// Only when asked for.
    OnRequest,
    /// At the next step: it was asked for.
    Requested,
    /// It has begun.
    Begun,
}

/// The Eq. 29 blend of the current stage since it (re)started, carried forward one period at
/// a time ([`CarriedBlend::carry_to`]).
#[derive(Clone, Copy, Debug)]
struct CarriedBlend<T> {
    /// The tick it (re)started at.
    tick: u32,
    /// l̇0: the rate it started from, m/s.
    initial_rate_mps: T,
    /// c of the current stage, 1/s.
    decay_rate_per_s: T,
    /// The stage's constants per period.
    per_tick: BlendPerTick<T>,
    /// The blend at the last tick it was carried to, and that tick.
    last: (u32, Blend<T>),
    /// What E at that tick lacks of its value carried one period at a time: the roundings
    /// of the carried E, kept apart (compensated summation: Kahan, Higham §4.3).
    weight_low: T,
}

/// What one period does to a stage's Eq. 29 blend.
#[derive(Clone, Copy, Debug)]
struct BlendPerTick<T> {
    /// −cΔt·log₂e: E = e^{−cΔt·k} = 2^{−cΔt·log₂e·k} k ticks after the start (in f64,
    /// rounded once).
    log2_weight: T,
    /// 1 − e^{−cΔt}: the share of E that one period moves to 1 − E, to its own precision
    /// ([`Real::exp_and_complement`]: in f32 within two ulps; libm's f64 `expm1` would add
    /// 1.7 KB of soft-float code to the firmware).
    decayed_share: T,
}

impl<T: Real> BlendPerTick<T> {
    /// The constants of the decay rate `decay_rate_per_s` (c) at the period `period_s` (Δt).
    fn new(decay_rate_per_s: T, period_s: T) -> Self {
        let c_dt = decay_rate_per_s.to_f64() * period_s.to_f64();
        Self {
            log2_weight: T::from_f64(-c_dt * core::f64::consts::LOG2_E),
            decayed_share: T::from_f64(-c_dt).exp_and_complement().1,
        }
    }
}

impl<T: Real> CarriedBlend<T> {
    /// The blend of a stage with `per_tick`, (re)starting at `tick` from `initial_rate_mps`:
    /// E = 1.
    fn new(tick: u32, initial_rate_mps: T, decay_rate_per_s: T, per_tick: BlendPerTick<T>) -> Self {
        Self {
            tick,
            initial_rate_mps,
            decay_rate_per_s,
            per_tick,
            last: (tick, Blend::from_weight(T::ONE)),
            weight_low: T::ZERO,
        }
    }

    /// Carries E forward to `tick` and returns E = e^{−cτ} and 1 − E there, τ = k·Δt the time
    /// since the blend (re)started k ticks before (Eq. 29), each to its own relative precision
    /// (docs/equations.md §5.2).
    ///
    /// One period after the last tick it was carried to (each step of a mission without
    /// gaps), the period's decay takes the share q = 1 − e^{−cΔt} of E away: E′ = E − qE, with
    /// the subtraction's rounding kept apart in `weight_low` and paid back the next period
    /// (compensated summation, Kahan; Higham §4.3), so E stays within a few roundings of
    /// e^{−cτ} however many periods it is carried, and 1 − E′ = (1 − E′_hi) − E′_lo keeps its
    /// own precision (the first difference is exact for E′ ≥ ½). After a gap in the calls E is
    /// worked out afresh as 2^{k·(−cΔt·log₂e)}.
    fn carry_to(&mut self, tick: u32) -> Blend<T> {
        let (last_tick, last) = self.last;
        let now = match tick.wrapping_sub(last_tick) {
            0 => last,
            1 => {
                // E_lo·q is below the roundings of E itself: left out.
                let taken = last.weight * self.per_tick.decayed_share - self.weight_low;
                let weight = last.weight - taken;
                // Exact (Fast2Sum: E ≥ taken): what the subtraction rounded away.
                self.weight_low = (last.weight - weight) - taken;
                Blend {
                    weight,
                    complement: (T::ONE - weight) - self.weight_low,
                }
            }
            _ => {
                let k = T::from_u32(tick.wrapping_sub(self.tick));
                self.weight_low = T::ZERO;
                Blend::from_log2(self.per_tick.log2_weight * k)
            }
        };
        self.last = (tick, now);
        now
    }
}

/// The sequencer's state and what it needs of the configuration.
#[derive(Clone, Debug)]
pub(super) struct Sequencer<T> {
    phase: Phase,
    /// The tick of the first step.
    mission_start_tick: u32,
    /// The tick the current stage began at.
    stage_start_tick: u32,
    stage2: Stage2Start,
    /// When stage 2 begins as configured (a new deployment starts from it again).
    configured_stage2: Stage2Start,
    blend: CarriedBlend<T>,
    /// How many times a blend has (re)started (wrapping): a restart is an event.
    blend_restarts: u32,
    /// The Eq. 34 schedule of stage 1, prepared.
    stage1_band: PreparedBand<T>,
    /// The Eq. 35 schedule of stage 2, prepared.
    stage2_band: PreparedBand<T>,
    /// On an eccentric orbit, the forced libration the reference adds (docs/equations.md §16).
    librating: Option<LibratingReference<T>>,
    /// c of the stage-1 and stage-2 blends, 1/s.
    decay_rate_per_s: [T; 2],
    /// What a period does to the stage-1 and stage-2 blends.
    blend_per_tick: [BlendPerTick<T>; 2],
    /// Deploy becomes Keep1 at this length: the stage-1 keep length less the capture, m.
    keep1_entry_m: T,
    /// Retrieve becomes Keep2 at this length: the stage-2 keep length plus the capture, m.
    keep2_entry_m: T,
    slew_rate_radps: T,
    period_s: T,
    /// The current phase's closest approach to its keep length (`None` when the watch has
    /// just (re)started or the phase has no target length).
    approach: Option<Approach<T>>,
    /// The progress window of stage 1 and stage 2, ticks.
    progress_window_ticks: [u32; 2],
    /// The progress a window must make, m.
    min_progress_m: T,
    /// Flying, or held by command.
    mode: Mode,
    /// A command accepted and waiting for the next period boundary.
    pending: Option<ModeCommand>,
}

impl<T: Real> Sequencer<T> {
    /// The sequencer before the first step: stage 1, Deploy, the blend from l̇0.
    pub(super) fn new(cfg: &Config<T>) -> Self {
        let dt = cfg.period_s.to_f64();
        let decay_rate_per_s = [cfg.stage1.decay_rate_per_s, cfg.stage2.decay_rate_per_s];
        let blend_per_tick = decay_rate_per_s.map(|c| BlendPerTick::new(c, cfg.period_s));
        // The slowest time constant of each stage's loop: 2/k1 (Eq. 28's envelope, e^{−k1 t/2})
        // and 1/c (Eq. 29; none when c = 0), in periods.
        let envelope_s = 2.0 / cfg.gains.k1_per_s.to_f64();
        let window = |c: T| {
            let blend_s = if c > T::ZERO { 1.0 / c.to_f64() } else { 0.0 };
            let ticks = PROGRESS_TIME_CONSTANTS * envelope_s.max(blend_s) / dt;
            // (`as` saturates: a window beyond u32 never elapses.)
            libm::ceil(ticks) as u32
        };
        let stage2 = match cfg.stage2.start_tick {
            Some(tick) => Stage2Start::At(tick),
            None => Stage2Start::OnRequest,
        };
        Self {
            phase: Phase::Deploy,
            mission_start_tick: 0,
            stage_start_tick: 0,
            stage2,
            configured_stage2: stage2,
            blend: CarriedBlend::new(
                0,
                cfg.initial_rate_mps,
                decay_rate_per_s[0],
                blend_per_tick[0],
            ),
            blend_restarts: 0,
            stage1_band: cfg.stage1.schedule.prepare(),
            stage2_band: cfg.stage2.schedule.prepare(),
            librating: LibratingReference::new(&cfg.orbit),
            decay_rate_per_s,
            blend_per_tick,
            keep1_entry_m: cfg.stage1.schedule.high_length_m - cfg.keep_capture_m,
            keep2_entry_m: cfg.stage2.schedule.low_length_m + cfg.keep_capture_m,
            slew_rate_radps: cfg.stage2.slew_rate_radps,
            period_s: cfg.period_s,
            approach: None,
            progress_window_ticks: decay_rate_per_s.map(window),
            min_progress_m: cfg.keep_capture_m,
            mode: Mode::Flying,
            pending: None,
        }
    }

    /// The mode (flying, or held by command).
    pub(super) fn mode(&self) -> Mode {
        self.mode
    }

    /// A command waits for the next period boundary.
    pub(super) fn command_waits(&self) -> bool {
        self.pending.is_some()
    }

    /// Takes `command` for the next period boundary if it is legal in the current mode and
    /// phase ([`transition`]) and no other command waits; a refused one changes nothing.
    pub(super) fn command(&mut self, command: ModeCommand) -> Result<(), Refusal> {
        if self.pending.is_some() {
            return Err(Refusal::Pending);
        }
        transition(self.mode, self.phase, command, 0)?;
        self.pending = Some(command);
        Ok(())
    }

    /// At the period boundary `tick` (time moved to it), the reel at `rate_mps`: applies the
    /// command that waits, if any, and returns it. A hold ends with its effect on the
    /// mission's clock: the stage-2 start and the slew are moved on by the ticks it lasted, so
    /// the phase held goes on as it was, its blend restarted from the current rate. A new
    /// deployment is stage 1 afresh from now, from the current rate, stage 2 as configured.
    pub(super) fn apply_pending(&mut self, tick: u32, rate_mps: T) -> Option<ModeCommand> {
        let command = self.pending.take()?;
        // Judged when it was given, against the mode and phase it meets here (nothing changes
        // them between two steps): not refused now.
        let (mode, effect) = transition(self.mode, self.phase, command, tick).ok()?;
        match effect {
            Effect::None => {}
            Effect::Resume { held_since_tick } => {
                let held_ticks = tick.wrapping_sub(held_since_tick);
                self.mission_start_tick = self.mission_start_tick.wrapping_add(held_ticks);
                self.stage_start_tick = self.stage_start_tick.wrapping_add(held_ticks);
                self.restart_blend(tick, rate_mps);
            }
            Effect::BeginStage2 => self.request_stage2(),
            Effect::NewDeployment => {
                self.phase = Phase::Deploy;
                self.stage2 = self.configured_stage2;
                self.mission_start_tick = tick;
                self.stage_start_tick = tick;
                self.restart_blend(tick, rate_mps);
            }
        }
        self.mode = mode;
        Some(command)
    }

    /// The current phase.
    pub(super) fn phase(&self) -> Phase {
        self.phase
    }

    /// Asks for stage 2 to begin at the next step (no effect once it has begun).
    pub(super) fn request_stage2(&mut self) {
        if self.stage2 != Stage2Start::Begun {
            self.stage2 = Stage2Start::Requested;
        }
    }

    /// The current stage: 0 (deploy, keep) or 1 (slew, retrieve, keep).
    fn stage(&self) -> usize {
        match self.phase {
            Phase::Deploy | Phase::Keep1 => 0,
            Phase::Slew | Phase::Retrieve | Phase::Keep2 => 1,
        }
    }

    /// Begins stage 1 at the first step: its blend starts from l̇0.
    pub(super) fn begin_stage1(&mut self, tick: u32) {
        self.mission_start_tick = tick;
        self.stage_start_tick = tick;
        self.restart_blend(tick, self.blend.initial_rate_mps);
    }

    /// Begins stage 2 if it is due at `tick` (at its tick or on request): α_r slews, and the
    /// blend restarts from the current rate `rate_mps`.
    /// Not while the reel is held by command (the mission's clock stops; see
    /// [`Sequencer::apply_pending`]).
    pub(super) fn begin_stage2_if_due(&mut self, tick: u32, rate_mps: T) {
        if self.mode.holds() {
            return;
        }
        let due = match self.stage2 {
            // Mission time: ticks since the first step (modulo 2³², as every tick difference).
            Stage2Start::At(start) => tick.wrapping_sub(self.mission_start_tick) >= start,
            Stage2Start::Requested => true,
            Stage2Start::OnRequest | Stage2Start::Begun => false,
        };
        if due {
            self.stage2 = Stage2Start::Begun;
            self.stage_start_tick = tick;
            self.phase = Phase::Slew;
            self.restart_blend(tick, rate_mps);
        }
    }

    /// Restarts the current stage's Eq. 29 blend at `tick` from `rate_mps`.
    pub(super) fn restart_blend(&mut self, tick: u32, rate_mps: T) {
        let stage = self.stage();
        self.blend = CarriedBlend::new(
            tick,
            rate_mps,
            self.decay_rate_per_s[stage],
            self.blend_per_tick[stage],
        );
        self.approach = None;
        self.blend_restarts = self.blend_restarts.wrapping_add(1);
    }

    /// How many times a blend has (re)started (wrapping).
    pub(super) fn blend_restarts(&self) -> u32 {
        self.blend_restarts
    }

    /// Carries the current stage's Eq. 29 blend forward to `tick` and returns E = e^{−cτ}
    /// and 1 − E there ([`CarriedBlend::carry_to`]). `tick` is an accepted tick: at or after
    /// the start, modulo 2³² (see `clock`), and at or after the last one carried to.
    pub(super) fn carry_blend_to(&mut self, tick: u32) -> Blend<T> {
        self.blend.carry_to(tick)
    }

    /// l̇0 of the current blend, m/s.
    pub(super) fn blend_initial_rate_mps(&self) -> T {
        self.blend.initial_rate_mps
    }

    /// c of the current blend, 1/s.
    pub(super) fn blend_decay_rate_per_s(&self) -> T {
        self.blend.decay_rate_per_s
    }

    /// α_r and its derivatives at this tick and length: Eq. 34 in stage 1; in stage 2, the
    /// slew from the stage's start until it first meets Eq. 35 ([`Phase::Slew`]), then Eq. 35.
    // Inlined into the step: out of line the outer step exceeded its ceiling
    // (scripts/bench-target).
    #[inline(always)]
    pub(super) fn reference(&self, tick: u32, length_m: T) -> Reference<T> {
        let band = match self.phase {
            Phase::Deploy | Phase::Keep1 => &self.stage1_band,
            Phase::Slew => {
                let ticks = tick.wrapping_sub(self.stage_start_tick);
                let tau_s = T::from_u32(ticks) * self.period_s;
                return self
                    .stage2_band
                    .eval_slewed(self.slew_rate_radps, tau_s, length_m);
            }
            Phase::Retrieve | Phase::Keep2 => &self.stage2_band,
        };
        Reference {
            angle: band.eval(length_m),
            time_rate_radps: T::ZERO,
            slewing: false,
            orbit: None,
        }
    }

    /// [`Sequencer::reference`] at true anomaly θ (rad): on an eccentric orbit, with the forced
    /// libration and the orbit's terms (docs/equations.md §16), and with NaN orbit terms when θ
    /// is not finite (the law then faults: the safe action); on a circular one, the same.
    // Inlined, as `reference`.
    #[inline(always)]
    pub(super) fn reference_at(&self, tick: u32, length_m: T, true_anomaly_rad: T) -> Reference<T> {
        let base = self.reference(tick, length_m);
        match &self.librating {
            None => base,
            Some(r) if true_anomaly_rad.is_finite() => r.eval(base, true_anomaly_rad),
            Some(_) => LibratingReference::without_anomaly(base),
        }
    }

    /// The phase after a step of the law at `length_m` (sensed at `tick`), and whether it
    /// still gets closer to its keep length (see the module docs). Deploy becomes Keep1 at
    /// the stage-1 keep length (less the capture), Slew becomes Retrieve once α_r meets the
    /// Eq. 35 schedule (for good), Retrieve becomes Keep2 at the stage-2 keep length (plus the
    /// capture). The keep phases last until the next stage or the end.
    pub(super) fn advance_phase(&mut self, tick: u32, length_m: T, slewing: bool) {
        match self.phase {
            Phase::Deploy if length_m >= self.keep1_entry_m => self.enter(Phase::Keep1),
            Phase::Deploy => {
                let distance_m = self.keep1_entry_m - length_m;
                self.watch(tick, distance_m, self.progress_window_ticks[0])
            }
            Phase::Slew if !slewing => {
                self.enter(Phase::Retrieve);
                let distance_m = length_m - self.keep2_entry_m;
                self.watch(tick, distance_m, self.progress_window_ticks[1])
            }
            Phase::Retrieve if length_m <= self.keep2_entry_m => self.enter(Phase::Keep2),
            Phase::Retrieve => {
                let distance_m = length_m - self.keep2_entry_m;
                self.watch(tick, distance_m, self.progress_window_ticks[1])
            }
            Phase::Keep1 | Phase::Slew | Phase::Keep2 => {}
        }
    }

    /// A new phase: its progress watch starts afresh (a keep phase has none).
    fn enter(&mut self, phase: Phase) {
        self.phase = phase;
        self.approach = None;
    }

    /// Watches the progress of a phase `distance_m` from its keep length at `tick`: stalled
    /// ([`Sequencer::stalled`]) when no new closest approach (by the capture distance) came
    /// within `window_ticks`.
    fn watch(&mut self, tick: u32, distance_m: T, window_ticks: u32) {
        match &mut self.approach {
            Some(a) if distance_m > a.closest_m - self.min_progress_m => {
                if tick.wrapping_sub(a.tick) > window_ticks {
                    a.stalled = true;
                }
            }
            _ => {
                self.approach = Some(Approach {
                    closest_m: distance_m,
                    tick,
                    stalled: false,
                });
            }
        }
    }

    /// The current phase was found stalled and has not progressed since.
    pub(super) fn stalled(&self) -> bool {
        self.approach.is_some_and(|a| a.stalled)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |a − b| in units of the f32 spacing at b.
    fn ulps(a: f32, b: f64) -> f64 {
        let spacing = f64::from(f32::from_bits((b as f32).abs().to_bits() + 1) - (b as f32).abs());
        (f64::from(a) - b).abs() / spacing
    }

    #[test]
    fn the_blend_one_period_at_a_time_is_the_exponential() {
        // Both stages' decay rates (1e-3 and 5e-4 1/s), carried over 100 000 periods (E down
        // to 4e-44 and 2e-22) from a start at a tick near the wrap of the counter.
        let cfg = Config::<f32>::paper();
        let rates = [cfg.stage1.decay_rate_per_s, cfg.stage2.decay_rate_per_s];
        for (stage, c) in rates.map(f64::from).into_iter().enumerate() {
            let mut s = Sequencer::new(&cfg);
            let start = u32::MAX - 10;
            s.phase = [Phase::Deploy, Phase::Retrieve][stage];
            s.restart_blend(start, 0.0);
            let (mut worst_weight, mut worst_complement) = (0.0_f64, 0.0_f64);
            for k in 0..100_000_u32 {
                let b = s.carry_blend_to(start.wrapping_add(k));
                let tau_s = f64::from(k) * f64::from(cfg.period_s);
                let weight = (-c * tau_s).exp();
                // The per-period constant's rounding (relative 2⁻²⁴ of q) adds up to cτ·2⁻²⁴
                // of E, as the exponent's does in 2^{k·(−cΔt·log₂e)}: measured per cτ beyond 1.
                if weight > 1e-30 {
                    let per = (c * tau_s).max(1.0);
                    worst_weight = worst_weight.max(ulps(b.weight, weight) / per);
                }
                worst_complement = worst_complement.max(ulps(b.complement, -(-c * tau_s).exp_m1()));
            }
            // Carried, E and 1 − E stay within 2 ulps each (E: per cτ beyond 1; measured
            // 1.23 and 1.26 for stage 1).
            // Uncompensated (E − qE and 1 − E + qE rounded each period): 6.4 and 302.
            assert!(
                worst_weight <= 2.0,
                "stage {stage}: E off by {worst_weight} ulps"
            );
            assert!(
                worst_complement <= 2.0,
                "stage {stage}: 1 − E off by {worst_complement} ulps"
            );
        }
    }

    #[test]
    fn after_a_gap_the_blend_is_worked_out_afresh_from_its_start() {
        let cfg = Config::<f32>::paper();
        let mut s = Sequencer::new(&cfg);
        s.restart_blend(100, 0.0);
        for tick in 100..=600 {
            s.carry_blend_to(tick);
        }
        // 600 → 900 (a gap of 300 periods), then the same tick again.
        let after_gap = s.carry_blend_to(900);
        let afresh = Blend::<f32>::from_log2(s.blend.per_tick.log2_weight * 800.0);
        assert_eq!(after_gap.weight, afresh.weight);
        assert_eq!(after_gap.complement, afresh.complement);
        assert_eq!(s.carry_blend_to(900).weight, afresh.weight);
        // And the next period carries on from it.
        let next = s.carry_blend_to(901);
        let exact = (-f64::from(cfg.stage1.decay_rate_per_s) * 801.0).exp();
        assert!(ulps(next.weight, exact) <= 4.0);
        // A restart is E = 1 at its tick.
        s.restart_blend(901, 0.0);
        let restarted = s.carry_blend_to(901);
        assert_eq!((restarted.weight, restarted.complement), (1.0, 0.0));
    }
}
