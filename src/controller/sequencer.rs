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
//! envelope decay 2/k1, the Eq. 29 blend 1/c) is reported as [`Progress::Stalled`] (the
//! controller's `NO_PROGRESS` flag and event). The watch restarts with each blend restart
//! (stage start, recovery) and each phase.

use crate::config::Config;
use crate::law::Blend;
use crate::real::Real;
use crate::schedule::{LibratingReference, PreparedBand, Reference};

use super::output::{Flags, Phase};

/// The progress window, in time constants of the stage's loop (see the module docs): long
/// enough that the exponential approach of the paper's phases to their keep lengths always
/// gains the capture distance within it.
pub const PROGRESS_TIME_CONSTANTS: f64 = 5.0;

/// Whether the phase is getting closer to its keep length.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Progress {
    /// Closer within the window (or a phase without a target length).
    OnTrack,
    /// No closer for longer than the window.
    Stalled {
        /// The stall was found at this step.
        first: bool,
    },
}

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
    /// The tick of the first step.
    mission_start_tick: u32,
    /// The tick the current stage began at.
    stage_start_tick: u32,
    stage2: Stage2Start,
    blend: BlendStart<T>,
    /// The Eq. 34 schedule of stage 1, prepared.
    stage1_band: PreparedBand<T>,
    /// The Eq. 35 schedule of stage 2, prepared.
    stage2_band: PreparedBand<T>,
    /// On an eccentric orbit, the forced libration the reference adds (docs/equations.md §16).
    librating: Option<LibratingReference<T>>,
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
    /// The current phase's closest approach to its keep length (`None` when the watch has
    /// just (re)started or the phase has no target length).
    approach: Option<Approach<T>>,
    /// The progress window of stage 1 and stage 2, ticks.
    progress_window_ticks: [u32; 2],
    /// The progress a window must make, m.
    min_progress_m: T,
}

impl<T: Real> Sequencer<T> {
    /// The sequencer before the first step: stage 1, Deploy, the blend from l̇0.
    pub(super) fn new(cfg: &Config<T>) -> Self {
        // −cΔt·log₂e, in f64 and rounded once.
        let dt = cfg.period_s.to_f64();
        let log2_weight = |c: T| T::from_f64(-c.to_f64() * dt * core::f64::consts::LOG2_E);
        let decay_rate_per_s = [cfg.stage1.decay_rate_per_s, cfg.stage2.decay_rate_per_s];
        let log2_weight_per_tick = decay_rate_per_s.map(log2_weight);
        // The slowest time constant of each stage's loop: 2/k1 (Eq. 28's envelope, e^{−k1 t/2})
        // and 1/c (Eq. 29; none when c = 0), in periods.
        let envelope_s = 2.0 / cfg.gains.k1_per_s.to_f64();
        let window = |c: T| {
            let blend_s = if c > T::ZERO { 1.0 / c.to_f64() } else { 0.0 };
            let ticks = PROGRESS_TIME_CONSTANTS * envelope_s.max(blend_s) / dt;
            // (`as` saturates: a window beyond u32 never elapses.)
            libm::ceil(ticks) as u32
        };
        Self {
            phase: Phase::Deploy,
            mission_start_tick: 0,
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
            librating: LibratingReference::new(&cfg.orbit),
            decay_rate_per_s,
            log2_weight_per_tick,
            keep1_entry_m: cfg.stage1.schedule.high_length_m - cfg.keep_capture_m,
            keep2_entry_m: cfg.stage2.schedule.low_length_m + cfg.keep_capture_m,
            slew_rate_radps: cfg.stage2.slew_rate_radps,
            period_s: cfg.period_s,
            approach: None,
            progress_window_ticks: decay_rate_per_s.map(window),
            min_progress_m: cfg.keep_capture_m,
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
        self.mission_start_tick = tick;
        self.stage_start_tick = tick;
        self.restart_blend(tick, self.blend.initial_rate_mps, flags);
    }

    /// Begins stage 2 if it is due at `tick` (at its tick or on request): α_r slews, and the
    /// blend restarts from the current rate `rate_mps`.
    pub(super) fn begin_stage2_if_due(&mut self, tick: u32, rate_mps: T, flags: &mut Flags) {
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
        self.approach = None;
        flags.set(Flags::BLEND_RESTART);
    }

    /// E = e^{−cτ} and 1 − E at `tick`, τ = k·Δt the time since the blend (re)started k ticks
    /// before (Eq. 29), as 2^{k·(−cΔt·log₂e)}. `tick` is an accepted tick: at or after the
    /// start, modulo 2³² (see `clock`).
    // Inlined into both callers (the step and the safe action): with `reference`, 37
    // instructions less on the mission's worst step (scripts/bench-target: 580 → 543).
    #[inline(always)]
    pub(super) fn blend(&self, tick: u32) -> Blend<T> {
        let k = T::from_u32(tick.wrapping_sub(self.blend.tick));
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
    // One `match` on the phase for both (rather than one to advance it, one to watch it):
    // 5 instructions less on the mission's worst step (scripts/bench-target: 565 → 560).
    pub(super) fn advance_phase(&mut self, tick: u32, length_m: T, slewing: bool) -> Progress {
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
            Phase::Keep1 | Phase::Slew | Phase::Keep2 => Progress::OnTrack,
        }
    }

    /// A new phase: its progress watch starts afresh (a keep phase has none).
    fn enter(&mut self, phase: Phase) -> Progress {
        self.phase = phase;
        self.approach = None;
        Progress::OnTrack
    }

    /// The progress of a phase `distance_m` from its keep length at `tick`: stalled when no
    /// new closest approach (by the capture distance) came within `window_ticks`.
    fn watch(&mut self, tick: u32, distance_m: T, window_ticks: u32) -> Progress {
        match &mut self.approach {
            Some(a) if distance_m > a.closest_m - self.min_progress_m => {
                if tick.wrapping_sub(a.tick) <= window_ticks {
                    return Progress::OnTrack;
                }
                let first = !a.stalled;
                a.stalled = true;
                Progress::Stalled { first }
            }
            _ => {
                self.approach = Some(Approach {
                    closest_m: distance_m,
                    tick,
                    stalled: false,
                });
                Progress::OnTrack
            }
        }
    }

    /// The current phase was found stalled and has not progressed since.
    pub(super) fn stalled(&self) -> bool {
        self.approach.is_some_and(|a| a.stalled)
    }
}
