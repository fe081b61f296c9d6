//! What a step tells its caller: the phase, the input health, the fault behind a safe action,
//! the status flags, and the [`Output`] that carries the command and the parts it was made of.

use crate::envelope::Saturation;
use crate::law::LawFault;
use crate::monitor::Sensor;

/// Mission phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Phase {
    /// Stage 1, paying out.
    Deploy,
    /// Stage 1, holding at the stage-1 keep length.
    Keep1,
    /// Stage 2, α_r slewing to its plateau.
    Slew,
    /// Stage 2, winding in.
    Retrieve,
    /// Stage 2, holding at the stage-2 keep length.
    Keep2,
}

/// Health of the controller's inputs: the fault state machine.
///
/// ```text
///            bad sample / law fault             fault counter > coast_ticks × G
///   Nominal ─────────────────────────▶ Degraded ───────────────────────────▶ SafeHold
///      ▲ ◀──────── next good sample ───────┘                                    │
///      └──────────────── recovery_ticks good samples in a row ──────────────────┘
///                        (the Eq. 29 blend restarts from the current rate)
/// ```
///
/// The fault counter is leaky (persistence and rate, as flight FDIR counts): + G for every
/// bad sample, − 1 for every good one, G = `monitor.good_samples_per_bad`. So coast_ticks + 1
/// bad samples in a row reach safe hold, and so does an intermittent sensor that delivers,
/// sustained, fewer than G good samples per bad one; recovery clears the counter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Health {
    /// Valid samples; the law commands the reel.
    Nominal,
    /// No usable sample (or no law solution) for at most `coast_ticks`: the reel coasts on its
    /// last command while the length is predicted from the integrated command.
    Degraded,
    /// Too long without a usable sample (or too few usable ones): the rate is ramped to zero
    /// at `monitor.safe_hold_decel_mps2` (within the acceleration limit) and held there until
    /// the sensors recover.
    SafeHold,
}

/// Why this step's command is not the law's value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// A sample was missing or rejected.
    Sensor(Sensor),
    /// The law is at one of its singular points.
    Law(LawFault),
    /// The swing the law flies on (sensed α, or α̂) is beyond
    /// [`MAX_LIBRATION_RAD`](super::MAX_LIBRATION_RAD): a libration outside the law's domain,
    /// on its way to a tumble. Safe hold at once.
    Libration,
}

/// Status bits reported with every command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Flags(pub u32);

impl Flags {
    /// The law asked for more than the rate limit.
    pub const RATE_SATURATED: u32 = Saturation::RATE;
    /// The change from the previous command exceeded the acceleration limit.
    pub const ACCEL_SATURATED: u32 = Saturation::ACCEL;
    /// A length limit (docking or spool) restricted the command.
    pub const LENGTH_LIMITED: u32 = Saturation::LENGTH;
    /// The command is a safe action, not the law's value (see [`Output::fault`]).
    pub const SAFE_ACTION: u32 = 1 << 3;
    /// The blend (Eq. 29) restarted at this step (a stage began, or the controller recovered).
    pub const BLEND_RESTART: u32 = 1 << 4;
    /// α_r is slewing (stage 2 start).
    pub const SLEWING: u32 = 1 << 5;
    /// [`Output::health`] changed at this step.
    pub const HEALTH_CHANGED: u32 = 1 << 6;
    /// The commanded l̇/l lies outside the region where an equilibrium exists over the whole
    /// orbit (Eq. 13; see [`Output::equilibrium_margin`]). Reported, not acted on: the paper's
    /// own deployment starts far outside it (l̇/l = 0.1 s⁻¹ at l = 1 m).
    pub const NO_EQUILIBRIUM: u32 = 1 << 7;
    /// The phase (Deploy or Retrieve) has stopped getting closer to its keep length (see
    /// [`crate::controller::PROGRESS_TIME_CONSTANTS`]). Reported, not acted on: the law still
    /// holds the tether in an equilibrium (a sensor bias moves it, HZ-4); stopping the reel
    /// would end the progress for good and can slacken a short tether; the ground decides.
    pub const NO_PROGRESS: u32 = 1 << 8;
    /// [`Output::phase`] changed at this step.
    pub const PHASE_CHANGED: u32 = 1 << 10;
    /// The protection's tension bound restricted the command (or its reported acceleration):
    /// the law asked for an acceleration the tether does not carry (docs/equations.md §14).
    pub const TENSION_LIMITED: u32 = Saturation::TENSION;
    /// The tension loop's window limited the law's rate to an acceleration the tether carries
    /// (docs/equations.md §17.4).
    pub const TENSION_SHAPED: u32 = 1 << 11;
    /// The tension loop flies without its load cell: it was lost (docs/equations.md §17.6).
    pub const LOAD_CELL_LOST: u32 = 1 << 12;
    /// The reel is held by command ([`super::Mode::Held`]; with [`Flags::SAFE_ACTION`]).
    pub const HELD: u32 = 1 << 13;
    /// The mission is aborted to a safe hold ([`super::Mode::Aborted`]; with
    /// [`Flags::SAFE_ACTION`]).
    pub const ABORTED: u32 = 1 << 14;

    /// `true` if every bit of `mask` is set.
    pub fn contains(self, mask: u32) -> bool {
        self.0 & mask == mask
    }
    pub(super) fn set(&mut self, mask: u32) {
        self.0 |= mask;
    }
    pub(super) fn set_if(&mut self, cond: bool, mask: u32) {
        self.0 |= if cond { mask } else { 0 };
    }
}

/// What one step decided, and why: the command and the parts it was made of.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output<T> {
    /// The tick this output belongs to.
    pub tick: u32,
    /// Mission phase after this step.
    pub phase: Phase,
    /// Input health after this step.
    pub health: Health,
    /// Reel-rate command l̇_real for the coming period, m/s (finite, inside the envelope).
    pub rate_cmd_mps: T,
    /// Commanded reel acceleration (Eq. 30, sign corrected; the ramp's slope when a limit or
    /// safe action shapes the command), m/s². Inside ±`max_accel_mps2` (Eq. 30's value is
    /// bounded, [`Flags::ACCEL_SATURATED`]), except where a length limit had to override the
    /// acceleration limit ([`Flags::LENGTH_LIMITED`]).
    pub accel_cmd_mps2: T,
    /// The Eq. 27 value l̇ before the blend, m/s (0 when the law did not run).
    pub law_rate_mps: T,
    /// Blend weight E = e^{−cτ} of Eq. 29.
    pub blend_weight: T,
    /// Reference angle α_r, rad.
    pub alpha_ref_rad: T,
    /// α̇_r = (∂α_r/∂l) l̇_real + ∂α_r/∂t, rad/s.
    pub alpha_ref_rate_radps: T,
    /// δ = α − α_r, rad (0 when the law did not run). α is the sensed angle or, flying on the
    /// estimator, α̂ = α_r + δ.
    pub delta_rad: T,
    /// δ̇ = α̇ − α̇_r, rad/s (0 when the law did not run). α̇ is the sensed rate or, flying on
    /// the estimator, α̇̂ = α̇_r + δ̇.
    pub delta_rate_radps: T,
    /// Flying on the estimator: the normalised innovation squared ν²/S of this period's α
    /// sample (χ² with one degree of freedom for a consistent filter; above the gate, the
    /// sample was rejected: [`super::Sensor::AlphaGated`]). `None` without a sample that met
    /// an estimate, and on the rate sensor.
    pub nis: Option<T>,
    /// The length the controller works with: the sensed one, or the prediction from the
    /// integrated command while coasting, m.
    pub length_estimate_m: T,
    /// Signed margin of the commanded x = (2+μ3) l̇/(ωl) inside the whole-orbit existence
    /// region [max Retr, min Depl] of Eq. 13: > 0 inside, < 0 outside (dimensionless).
    pub equilibrium_margin: T,
    /// Status bits.
    pub flags: Flags,
    /// The fault behind a safe action, if any.
    pub fault: Option<Fault>,
}
