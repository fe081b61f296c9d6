//! Drum odometry from integer encoder counts: the paid-out length and the drum speed.
//!
//! The hardware counter is `bits` wide and wraps. Each accepted reading adds the signed change
//! since the previous one, taken modulo 2^bits (shifted to the top of an `i32` and back, which
//! sign-extends it), to a 64-bit total count. Everything else is a function of integers:
//!
//! - paid-out length = total count × (2π r / counts per drum revolution): no float is ever
//!   accumulated, so the length does not drift however long the reel runs; pay out and wind
//!   back the same counts and the length is exactly 0 again;
//! - drum speed = (total now − total W ticks ago) × m per count / (W × tick): a window
//!   difference of integers, so the quantisation is one count over W ticks (15.3 µm / 8 ms ≈
//!   1.9 mm/s for [`DriveConfig::example`]) and nothing is integrated. The totals are kept
//!   per tick in a ring indexed by the tick. A tick without an accepted reading (missing,
//!   rejected, or skipped by an overrun) holds the speed of the last accepted one, and gets
//!   the total that speed predicts (the window's mean change per tick, a shift: W is a power
//!   of two), so the speed does not dip; the next accepted reading brings the true total back.
//!
//! A reading that moved further than the drum can turn in the ticks since the last accepted
//! one (at [`FaultLimits::max_encoder_rate_mps`]) is an encoder jump: it is rejected, the total
//! keeps its last value, and the next reading is compared with the last accepted one. A
//! counter that glitched for one reading is thus recovered; one that lost counts for good keeps
//! failing the check until the drive trips.
//!
//! [`FaultLimits::max_encoder_rate_mps`]: super::FaultLimits::max_encoder_rate_mps

use super::config::{DriveConfig, SPEED_WINDOW_CAPACITY};

/// Length of the ring of per-tick totals (a power of two above the largest window, so the
/// slot of a tick is its low bits).
const RING: usize = 16;
const _: () = assert!(RING.is_power_of_two() && RING > SPEED_WINDOW_CAPACITY);

/// Why a reading was not accepted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CountFault {
    /// The count changed faster than the drum can turn.
    Jump,
    /// No reading this tick.
    Missing,
}

/// The drum's odometer: integer total count, paid-out length and windowed speed.
#[derive(Clone, Debug)]
pub struct Odometer {
    /// 32 − counter width: a raw change shifted left by this and back sign-extends it.
    shift: u32,
    max_counts_per_tick: u32,
    m_per_count: f32,
    /// m/s per count of the window: m per count / (window × tick), precomputed so that the
    /// step has no division (VDIV: 14 cycles on the Cortex-M4F).
    mps_per_window_count: f32,
    window: u32,
    /// log2 of the window (validated a power of two).
    window_log2: u32,
    /// The last accepted raw counter value and its tick; `None` before the first reading and
    /// after a [`resync`](Self::resync): the next reading is then the reference, not a change.
    accepted: Option<Accepted>,
    /// Counts since the first reading (pay-out positive).
    total_counts: i64,
    /// The tick of the last update.
    last_tick: u32,
    /// The total at each of the last [`RING`] ticks, modulo 2³², in the slot `tick % RING`
    /// (the window's difference of two of them is exact: it is bounded by the jump check, far
    /// below 2³¹).
    totals: [u32; RING],
    /// The window's last measurement, kept beside the ring (see [`Window`]).
    last: Window,
}

/// The total at `last_tick` and the window's change at the last accepted reading: what the
/// speed and a tick without an accepted reading need. A tick without an accepted reading
/// predicts its total from them and holds the speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Window {
    /// The total at `last_tick`, modulo 2³² (the ring's slot of `last_tick`).
    total: u32,
    /// The total's change over the window ending at the last accepted reading, counts (0 until
    /// the second reading, and after a [`resync`](Odometer::resync)).
    change: i32,
}

/// The last accepted reading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Accepted {
    raw: u32,
    tick: u32,
}

impl Odometer {
    /// An odometer for a validated configuration, at total count 0.
    pub fn new(cfg: &DriveConfig) -> Self {
        let m_per_count = cfg.geometry.m_per_count();
        Self {
            shift: 32_u32.saturating_sub(cfg.geometry.encoder_bits),
            max_counts_per_tick: cfg.max_counts_per_tick(),
            m_per_count,
            mps_per_window_count: m_per_count * cfg.inner_rate_hz as f32
                / cfg.speed_window_ticks as f32,
            window: cfg.speed_window_ticks,
            window_log2: cfg.speed_window_ticks.trailing_zeros(),
            accepted: None,
            total_counts: 0,
            last_tick: 0,
            totals: [0; RING],
            last: Window {
                total: 0,
                change: 0,
            },
        }
    }

    /// Takes the counter reading of `tick` (`None`: no reading). Ticks must increase (the
    /// speed loop checks that before it calls this). The first reading sets the origin.
    pub fn update(&mut self, tick: u32, raw: Option<u32>) -> Result<(), CountFault> {
        let gap_ticks = tick.wrapping_sub(self.last_tick);
        if gap_ticks != 1 {
            self.skip(gap_ticks.wrapping_sub(1));
        }
        self.update_next(tick, raw).0
    }

    /// [`update`](Self::update) for the tick after the last update's, or after the ticks
    /// [`skip`](Self::skip) gave their totals (the speed loop's step knows the gap, and tells
    /// an overrun apart once). Returns the drum speed after it as well
    /// ([`speed_mps`](Self::speed_mps)).
    pub(super) fn update_next(
        &mut self,
        tick: u32,
        raw: Option<u32>,
    ) -> (Result<(), CountFault>, f32) {
        self.last_tick = tick;
        let result = self.count(tick, raw);
        let now = match result {
            Ok(()) => {
                let now = self.total_counts as u32;
                let then = self.totals[tick.wrapping_sub(self.window) as usize % RING];
                self.last = Window {
                    total: now,
                    change: now.wrapping_sub(then) as i32,
                };
                now
            }
            Err(_) => {
                let now = self.predicted_total();
                self.last.total = now;
                now
            }
        };
        self.totals[tick as usize % RING] = now;
        (result, self.speed_mps())
    }

    /// Gives the `skipped` ticks after the last update their predicted totals (ticks skipped
    /// by an overrun).
    pub(super) fn skip(&mut self, skipped: u32) {
        for _ in 0..skipped.min(RING as u32) {
            self.last_tick = self.last_tick.wrapping_add(1);
            self.last.total = self.predicted_total();
            self.totals[self.last_tick as usize % RING] = self.last.total;
        }
    }

    /// The total of a tick without an accepted reading, the one after the last update's: the
    /// last total plus the window's mean change per tick at the last accepted reading (rounded
    /// down), so that the drum keeps that speed. Without a reference to predict from (before
    /// the first reading, after a `resync`) the change is 0 and the total stays, which every
    /// slot then holds.
    fn predicted_total(&self) -> u32 {
        let per_tick = self.last.change >> self.window_log2;
        self.last.total.wrapping_add(per_tick as u32)
    }

    /// The total count after the reading `raw` of `tick`, if it is accepted.
    fn count(&mut self, tick: u32, raw: Option<u32>) -> Result<(), CountFault> {
        let raw = raw.ok_or(CountFault::Missing)?;
        let Some(last) = &mut self.accepted else {
            // The reference reading: the total stays (0 at the first). The ring already holds
            // the total in every slot (see `resync`), so the speed restarts at 0.
            self.accepted = Some(Accepted { raw, tick });
            return Ok(());
        };
        // The change modulo 2^bits, sign-extended: exact for |change| < 2^(bits−1).
        let change =
            ((raw.wrapping_sub(last.raw).wrapping_shl(self.shift)) as i32).wrapping_shr(self.shift);
        let allowed = self
            .max_counts_per_tick
            .saturating_mul(tick.wrapping_sub(last.tick));
        if change.unsigned_abs() > allowed {
            return Err(CountFault::Jump);
        }
        *last = Accepted { raw, tick };
        self.total_counts = self.total_counts.wrapping_add(i64::from(change));
        Ok(())
    }

    /// Forgets the counter's reference: the next reading is taken as the new one, and the
    /// total count continues from where it is. For a counter that was lost (an encoder trip):
    /// after a long gap a change of the counter is ambiguous modulo 2^bits, so the travel
    /// during the outage is not counted, and the paid-out length must be re-referenced by the
    /// outer loop's length sensor.
    ///
    /// Every slot of the window's ring then holds the total, and keeps holding it until the
    /// next reading (the reference) is accepted, so that the speed restarts from 0 there (the
    /// ring is filled here, outside the step; the construction's zeros are the first
    /// reference's total).
    pub fn resync(&mut self) {
        self.accepted = None;
        self.totals = [self.total_counts as u32; RING];
        self.last = Window {
            total: self.total_counts as u32,
            change: 0,
        };
    }

    /// Ticks since the last accepted reading at `tick` (`None` before the first).
    pub fn ticks_since_accepted(&self, tick: u32) -> Option<u32> {
        self.accepted.map(|a| tick.wrapping_sub(a.tick))
    }

    /// Counts since the first reading (pay-out positive).
    pub fn total_counts(&self) -> i64 {
        self.total_counts
    }

    /// Tether paid out since the first reading, m: total count × m per count (a function of
    /// the integer count; its error is the two roundings of this product, never accumulated).
    pub fn paid_out_m(&self) -> f32 {
        self.total_counts as f32 * self.m_per_count
    }

    /// Drum surface speed at the last accepted reading, m/s (pay-out positive): the total's
    /// change over the `speed_window_ticks` ticks up to it × m per count / their time, held
    /// through the ticks without an accepted reading since. 0 until the window has the second
    /// reading's tick in it (the drum starts braked, at rest).
    pub fn speed_mps(&self) -> f32 {
        self.last.change as f32 * self.mps_per_window_count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn odo(bits: u32) -> Odometer {
        let mut cfg = DriveConfig::example();
        cfg.geometry.encoder_bits = bits;
        if bits > 16 {
            cfg.faults.encoder_trip_ticks = 100;
        }
        cfg.validate().unwrap();
        Odometer::new(&cfg)
    }

    #[test]
    fn a_16_bit_counter_wraps_both_ways_without_losing_a_count() {
        let mut o = odo(16);
        let mut raw: u32 = 65_000;
        o.update(0, Some(raw)).unwrap();
        // 1000 counts a tick forward through the wrap, 200 ticks, then back.
        for t in 1..=200 {
            raw = (raw + 1000) & 0xFFFF;
            o.update(t, Some(raw)).unwrap();
        }
        assert_eq!(o.total_counts(), 200_000);
        for t in 201..=400 {
            raw = raw.wrapping_sub(1000) & 0xFFFF;
            o.update(t, Some(raw)).unwrap();
        }
        assert_eq!(o.total_counts(), 0);
        assert_eq!(o.paid_out_m(), 0.0);
    }

    #[test]
    fn a_32_bit_counter_wraps_too() {
        let mut o = odo(32);
        o.update(0, Some(u32::MAX - 10)).unwrap();
        o.update(1, Some(20)).unwrap();
        assert_eq!(o.total_counts(), 31);
        o.update(2, Some(u32::MAX - 10)).unwrap();
        assert_eq!(o.total_counts(), 0);
    }

    #[test]
    fn speed_is_the_window_difference() {
        let mut o = odo(16);
        let cfg = DriveConfig::example();
        let mut raw = 0_u32;
        for t in 0..20 {
            o.update(t, Some(raw & 0xFFFF)).unwrap();
            raw += 650; // 650 counts/ms = 9.97 m/s
        }
        let expect = 650.0 * cfg.geometry.m_per_count() * 1000.0;
        assert!((o.speed_mps() - expect).abs() < 1e-4 * expect);
    }

    #[test]
    fn a_jump_is_rejected_and_the_next_good_reading_accepted() {
        let mut o = odo(16);
        o.update(0, Some(100)).unwrap();
        o.update(1, Some(200)).unwrap();
        assert_eq!(o.update(2, Some(30_000)), Err(CountFault::Jump));
        assert_eq!(o.total_counts(), 100);
        assert_eq!(o.ticks_since_accepted(3), Some(2));
        o.update(3, Some(400)).unwrap();
        assert_eq!(o.total_counts(), 300);
    }

    #[test]
    fn the_speed_holds_through_rejected_readings_and_the_total_comes_back() {
        let mut o = odo(16);
        let mut raw = 0_u32;
        for t in 0..20 {
            o.update(t, Some(raw)).unwrap();
            raw += 100;
        }
        let v = o.speed_mps();
        assert!(v > 0.0);
        for t in 20..25 {
            assert_eq!(o.update(t, None), Err(CountFault::Missing));
            assert_eq!(o.speed_mps(), v, "tick {t}");
            raw += 100;
        }
        assert_eq!(
            o.update(25, Some((raw + 30_000) & 0xFFFF)),
            Err(CountFault::Jump)
        );
        assert_eq!(o.speed_mps(), v);
        raw += 100;
        // The next good reading: the true total, and the window's speed from it (the
        // predicted totals were exact at a constant speed).
        o.update(26, Some(raw & 0xFFFF)).unwrap();
        assert_eq!(o.total_counts(), i64::from(raw));
        assert_eq!(o.speed_mps(), v);
        for t in 27..40 {
            raw += 100;
            o.update(t, Some(raw & 0xFFFF)).unwrap();
            assert_eq!(o.speed_mps(), v, "tick {t}");
        }
    }

    #[test]
    fn bits_above_the_counter_width_are_ignored() {
        let mut o = odo(16);
        o.update(0, Some(0xABCD_0005)).unwrap();
        o.update(1, Some(0x1234_0009)).unwrap();
        assert_eq!(o.total_counts(), 4);
    }
}
