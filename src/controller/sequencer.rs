//! The mission sequencer (SPEC §7): the two stages, their phases, the Eq. 29 blend each stage
//! (or a recovery) restarts, and the reference angle α_r of each phase (Eqs. 34, 35).
//!
//! ```text
//!   stage 1:  Deploy ──(l ≥ stage-1 keep − capture)──▶ Keep1
//!   stage 2:  Slew ──(α_r meets Eq. 35)──▶ Retrieve ──(l ≤ stage-2 keep + capture)──▶ Keep2
//! ```
//!
//! Stage 1 begins with the first step; stage 2 at its configured tick or on command, from
//! whichever stage-1 phase the mission is in.

use crate::config::Config;
use crate::law::Blend;
use crate::real::Real;
use crate::schedule::{PreparedBand, Reference};

use super::output::{Flags, Phase};

/// When stage 2 (retrieval) begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage2Start {
    /// At the first step at or after this tick, unless asked for earlier.
    At(u32),
    /// Only when asked for.
    OnRequest,
    /// At the next step: it was asked for.
    Requested,
    /// It has begun.
    Begun,
}

/// The Eq. 29 blend of the current stage since it (re)started.
#[derive(Clone, Copy, Debug)]
struct BlendStart<T> {
    /// The tick it (re)started at.
    tick: u32,
    /// l̇0: the rate it started from, m/s.
    initial_rate_mps: T,
    /// c of the current stage, 1/s.
    decay_rate_per_s: T,
    /// −cΔt·log₂e: E = e^{−cΔt·k} = 2^{−cΔt·log₂e·k} k ticks after the start.
    log2_weight_per_tick: T,
}

/// The sequencer's state and what it needs of the configuration.
#[derive(Clone, Debug)]
pub(super) struct Sequencer<T> {
    phase: Phase,
    /// The tick the current stage began at.
    stage_start_tick: u32,
    stage2: Stage2Start,
    blend: BlendStart<T>,
    /// The Eq. 34 schedule of stage 1, prepared.
    stage1_band: PreparedBand<T>,
    /// The Eq. 35 schedule of stage 2, prepared.
    stage2_band: PreparedBand<T>,
    /// c of the stage-1 and stage-2 blends, 1/s.
    decay_rate_per_s: [T; 2],
    /// −cΔt·log₂e of the stage-1 and stage-2 blends.
    log2_weight_per_tick: [T; 2],
    /// Deploy becomes Keep1 at this length: the stage-1 keep length less the capture, m.
    keep1_entry_m: T,
    /// Retrieve becomes Keep2 at this length: the stage-2 keep length plus the capture, m.
    keep2_entry_m: T,
    slew_rate_radps: T,
    period_s: T,
}

impl<T: Real> Sequencer<T> {
    /// The sequencer before the first step: stage 1, Deploy, the blend from l̇0.
    pub(super) fn new(cfg: &Config<T>) -> Self {
        // −cΔt·log₂e, in f64 and rounded once.
        let dt = cfg.period_s.to_f64();
        let log2_weight = |c: T| T::from_f64(-c.to_f64() * dt * core::f64::consts::LOG2_E);
        let decay_rate_per_s = [cfg.stage1.decay_rate_per_s, cfg.stage2.decay_rate_per_s];
        let log2_weight_per_tick = decay_rate_per_s.map(log2_weight);
        Self {
            phase: Phase::Deploy,
            stage_start_tick: 0,
            stage2: match cfg.stage2.start_tick {
                Some(tick) => Stage2Start::At(tick),
                None => Stage2Start::OnRequest,
            },
            blend: BlendStart {
                tick: 0,
                initial_rate_mps: cfg.initial_rate_mps,
                decay_rate_per_s: decay_rate_per_s[0],
                log2_weight_per_tick: log2_weight_per_tick[0],
            },
            stage1_band: cfg.stage1.schedule.prepare(),
            stage2_band: cfg.stage2.schedule.prepare(),
            decay_rate_per_s,
            log2_weight_per_tick,
            keep1_entry_m: cfg.stage1.schedule.high_length_m - cfg.keep_capture_m,
            keep2_entry_m: cfg.stage2.schedule.low_length_m + cfg.keep_capture_m,
            slew_rate_radps: cfg.stage2.slew_rate_radps,
            period_s: cfg.period_s,
        }
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
    pub(super) fn begin_stage1(&mut self, tick: u32, flags: &mut Flags) {
        self.stage_start_tick = tick;
        self.restart_blend(tick, self.blend.initial_rate_mps, flags);
    }

    /// Begins stage 2 if it is due at `tick` (at its tick or on request): α_r slews, and the
    /// blend restarts from the current rate `rate_mps`.
    pub(super) fn begin_stage2_if_due(&mut self, tick: u32, rate_mps: T, flags: &mut Flags) {
        let due = match self.stage2 {
            Stage2Start::At(start) => tick >= start,
            Stage2Start::Requested => true,
            Stage2Start::OnRequest | Stage2Start::Begun => false,
        };
        if due {
            self.stage2 = Stage2Start::Begun;
            self.stage_start_tick = tick;
            self.phase = Phase::Slew;
            self.restart_blend(tick, rate_mps, flags);
        }
    }

    /// Restarts the current stage's Eq. 29 blend at `tick` from `rate_mps`.
    pub(super) fn restart_blend(&mut self, tick: u32, rate_mps: T, flags: &mut Flags) {
        let stage = self.stage();
        self.blend = BlendStart {
            tick,
            initial_rate_mps: rate_mps,
            decay_rate_per_s: self.decay_rate_per_s[stage],
            log2_weight_per_tick: self.log2_weight_per_tick[stage],
        };
        flags.set(Flags::BLEND_RESTART);
    }

    /// E = e^{−cτ} and 1 − E at `tick`, τ = k·Δt the time since the blend (re)started k ticks
    /// before (Eq. 29), as 2^{k·(−cΔt·log₂e)}. A tick before the start counts as the start.
    // Inlined into both callers (the step and the safe action): with `reference`, 37
    // instructions less on the mission's worst step (scripts/bench-target: 580 → 543).
    #[inline(always)]
    pub(super) fn blend(&self, tick: u32) -> Blend<T> {
        let k = T::from_u32(tick.saturating_sub(self.blend.tick));
        Blend::from_log2(self.blend.log2_weight_per_tick * k)
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
    // Inlined into both callers (the step and the safe action): with `blend`, 37 instructions
    // less on the mission's worst step (scripts/bench-target: 580 → 543).
    #[inline(always)]
    pub(super) fn reference(&self, tick: u32, length_m: T) -> Reference<T> {
        let band = match self.phase {
            Phase::Deploy | Phase::Keep1 => &self.stage1_band,
            Phase::Slew => {
                let ticks = tick.saturating_sub(self.stage_start_tick);
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
        }
    }

    /// The phase after a step of the law at `length_m`: Deploy becomes Keep1 at the stage-1
    /// keep length (less the capture), Slew becomes Retrieve once α_r meets the Eq. 35
    /// schedule (for good), Retrieve becomes Keep2 at the stage-2 keep length (plus the
    /// capture). The keep phases last until the next stage or the end.
    pub(super) fn advance_phase(&mut self, length_m: T, slewing: bool) {
        match self.phase {
            Phase::Deploy if length_m >= self.keep1_entry_m => self.phase = Phase::Keep1,
            Phase::Slew if !slewing => self.phase = Phase::Retrieve,
            Phase::Retrieve if length_m <= self.keep2_entry_m => self.phase = Phase::Keep2,
            Phase::Deploy | Phase::Keep1 | Phase::Slew | Phase::Retrieve | Phase::Keep2 => {}
        }
    }
}
