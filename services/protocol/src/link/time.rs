//! Time as the sans-IO core sees it: a monotonic instant the driver passes in with every call.
//! The core never reads a clock; UTC time stamps are derived from the instant and the UTC time of
//! instant zero, which the driver gives once (so a wall-clock step never breaks a timeout).

use core::ops::{Add, Sub};
use core::time::Duration;

use missionlink_interfaces::wire::Timestamp;

/// A point on the driver's monotonic clock, in microseconds since the driver started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Instant(u64);

impl Instant {
    /// The driver's start.
    pub const ZERO: Self = Self(0);

    /// `micros` microseconds after the start.
    pub const fn from_micros(micros: u64) -> Self {
        Self(micros)
    }

    /// `millis` milliseconds after the start.
    pub const fn from_millis(millis: u64) -> Self {
        Self(millis.saturating_mul(1000))
    }

    /// Microseconds since the start.
    pub const fn micros(self) -> u64 {
        self.0
    }

    /// Time since `earlier`, zero if `earlier` is later.
    pub fn saturating_since(self, earlier: Instant) -> Duration {
        Duration::from_micros(self.0.saturating_sub(earlier.0))
    }
}

impl Add<Duration> for Instant {
    type Output = Instant;
    fn add(self, d: Duration) -> Instant {
        Instant(
            self.0
                .saturating_add(u64::try_from(d.as_micros()).unwrap_or(u64::MAX)),
        )
    }
}

impl Sub<Instant> for Instant {
    type Output = Duration;
    fn sub(self, earlier: Instant) -> Duration {
        self.saturating_since(earlier)
    }
}

/// Maps instants to UTC time stamps: the UTC time of instant zero plus the elapsed time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UtcClock {
    at_zero: Timestamp,
}

impl UtcClock {
    /// A clock on which [`Instant::ZERO`] is `at_zero`.
    pub const fn new(at_zero: Timestamp) -> Self {
        Self { at_zero }
    }

    /// The UTC time stamp of `now` (saturating at the last U5 value).
    pub fn utc(&self, now: Instant) -> Timestamp {
        let ms = self.at_zero.millis().saturating_add(now.micros() / 1000);
        Timestamp::from_millis(ms.min(Timestamp::MAX_MILLIS)).unwrap_or(self.at_zero)
    }
}
