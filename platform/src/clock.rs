//! Clocks of the drivers. Latency is measured across processes, so frames carry
//! CLOCK_MONOTONIC nanoseconds, which every process on the host reads alike; the sans-IO core
//! gets its own [`Instant`] from the process start, and UTC once for its time stamps.

use std::time::SystemTime;

use missionlink_interfaces::wire::Timestamp;
use missionlink_protocol::link::time::Instant;

/// CLOCK_MONOTONIC in nanoseconds: comparable between the partitions of one host.
pub fn monotonic_ns() -> u64 {
    let t = rustix::time::clock_gettime(rustix::time::ClockId::Monotonic);
    (t.tv_sec as u64)
        .saturating_mul(1_000_000_000)
        .saturating_add(t.tv_nsec as u64)
}

/// The driver's clock for the sans-IO core.
#[derive(Debug, Clone, Copy)]
pub struct DriverClock {
    start_ns: u64,
    utc_at_start: Timestamp,
}

impl Default for DriverClock {
    fn default() -> Self {
        Self::start()
    }
}

impl DriverClock {
    /// A clock whose zero is now.
    pub fn start() -> Self {
        let unix_ms = SystemTime::now()
            .duration_since(SystemTime::UNIX_EPOCH)
            .map_or(0, |d| d.as_millis() as u64);
        Self {
            start_ns: monotonic_ns(),
            utc_at_start: Timestamp::from_unix_millis(unix_ms).unwrap_or_default(),
        }
    }

    /// The UTC time of instant zero, for the core's time stamps.
    pub fn utc_at_zero(&self) -> Timestamp {
        self.utc_at_start
    }

    /// Now, for the core.
    pub fn now(&self) -> Instant {
        self.at(monotonic_ns())
    }

    /// The core's instant of a CLOCK_MONOTONIC reading.
    pub fn at(&self, monotonic_ns: u64) -> Instant {
        Instant::from_micros(monotonic_ns.saturating_sub(self.start_ns) / 1000)
    }

    /// The CLOCK_MONOTONIC reading of a core instant.
    pub fn monotonic_ns(&self, instant: Instant) -> u64 {
        self.start_ns
            .saturating_add(instant.micros().saturating_mul(1000))
    }
}
