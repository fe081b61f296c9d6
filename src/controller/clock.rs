//! The controller's time base: the caller's tick count, compared wrap-aware.
//!
//! A tick is a u32 count of control periods, and it wraps (after 136 years at 1 s, 49.7 days
//! at the shortest period, [`crate::config::MIN_PERIOD_S`]). Each sample's tick is compared
//! with the last accepted one modulo 2³²: a difference in [1, 2³¹) is time moving forward by
//! that many ticks, through a wrap as well; a difference of 0 is a repeated tick and one in
//! [2³¹, 2³²) a tick from the past (stale). Both are rejected ([`Sensor::Tick`]): the
//! controller's time does not move, and neither does its command (see
//! [`Controller::step`](super::Controller::step)). Every other tick difference in the
//! controller (the blend's age, the slew's, the stage-2 start, the α-jump allowance) is taken
//! modulo 2³² from an accepted tick, so it is right across a wrap.

use crate::monitor::Sensor;

/// Half the tick range: forward differences are below it.
const HALF_RANGE: u32 = 1 << 31;

/// How far time moved at an accepted tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Elapsed {
    /// The first step: there is no earlier tick.
    First,
    /// This many ticks (≥ 1) since the last accepted tick.
    Ticks(u32),
}

/// The last accepted tick.
#[derive(Clone, Copy, Debug)]
pub(super) struct Clock {
    last_tick: Option<u32>,
}

impl Clock {
    pub(super) const fn new() -> Self {
        Self { last_tick: None }
    }

    /// The last accepted tick (`None` before the first step).
    pub(super) fn last_tick(&self) -> Option<u32> {
        self.last_tick
    }

    /// Accepts `tick` if time moved forward to it, and says by how much.
    pub(super) fn advance(&mut self, tick: u32) -> Result<Elapsed, Sensor> {
        let elapsed = match self.last_tick {
            None => Elapsed::First,
            Some(last) => match tick.wrapping_sub(last) {
                n @ 1..HALF_RANGE => Elapsed::Ticks(n),
                // 0: repeated; HALF_RANGE and above: from the past.
                _ => return Err(Sensor::Tick),
            },
        };
        self.last_tick = Some(tick);
        Ok(elapsed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forward_repeated_stale_and_through_the_wrap() {
        let mut c = Clock::new();
        assert_eq!(c.advance(u32::MAX - 1), Ok(Elapsed::First));
        assert_eq!(c.advance(u32::MAX - 1), Err(Sensor::Tick));
        assert_eq!(c.advance(u32::MAX - 3), Err(Sensor::Tick));
        assert_eq!(c.advance(u32::MAX), Ok(Elapsed::Ticks(1)));
        // Through the wrap: u32::MAX → 2 is three ticks.
        assert_eq!(c.advance(2), Ok(Elapsed::Ticks(3)));
        assert_eq!(c.advance(u32::MAX), Err(Sensor::Tick));
        assert_eq!(c.last_tick(), Some(2));
        // The largest forward step, and the smallest backward one.
        assert_eq!(
            c.advance(2 + (HALF_RANGE - 1)),
            Ok(Elapsed::Ticks(HALF_RANGE - 1))
        );
        let last = 2 + (HALF_RANGE - 1);
        assert_eq!(c.advance(last.wrapping_add(HALF_RANGE)), Err(Sensor::Tick));
    }
}
