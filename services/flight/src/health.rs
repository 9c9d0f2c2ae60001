//! Liveness of a partition from its heartbeats (docs/design.md "Health"): the one rule by which the
//! launcher decides that a partition it started hangs, and system automation that guidance is
//! alive.
//!
//! A partition beats on a fixed period from its event loop (`HeartbeatPayload` on
//! `fcc/health/<partition>`), so a process that is stopped (SIGSTOP), stuck in a step or dead
//! sends nothing. The watcher takes the time a beat arrives, never the time in it (the sender's
//! clock is not trusted to be ours), and the period of the FCC's configuration, never the period
//! a beat claims: a partition that claimed an hour would otherwise never be found hung. A
//! replacement partition (another language, a HIL rig) must therefore beat at least at the
//! configured period.
//!
//! The limit: a partition is silent when no beat came for [`silence_limit`] = 2.5 periods. A
//! partition stopped at any moment has sent its last beat at most one period before, so it is
//! found silent at most 2.5 periods after the stop plus the watcher's own polling interval:
//! within the three periods the launcher must find it in (docs/deployment.md "Health"), with one
//! and a half periods of slack for a healthy partition that is scheduled late on a loaded machine.

use core::time::Duration;

use missionlink_interfaces::contracts::HeartbeatPayload;

use missionlink_protocol::link::time::Instant;

/// How long a partition beating on `period` may stay silent before it counts as hung (or, for
/// guidance, not alive): two and a half periods.
pub fn silence_limit(period: Duration) -> Duration {
    let nanos = period.as_nanos().saturating_mul(5).div_ceil(2);
    Duration::from_nanos(u64::try_from(nanos).unwrap_or(u64::MAX))
}

/// What a [`Liveness`] found at its deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Silence {
    /// The process started and never beat within the start timeout.
    NeverBeat {
        /// Since it was started.
        since_start: Duration,
    },
    /// It beat, then fell silent for longer than the [`silence_limit`].
    Stopped {
        /// Since its last beat.
        since_beat: Duration,
        /// Beats received from this process.
        beats: u64,
    },
}

impl core::fmt::Display for Silence {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NeverBeat { since_start } => write!(
                f,
                "no heartbeat in the {} ms since it started",
                since_start.as_millis()
            ),
            Self::Stopped { since_beat, beats } => write!(
                f,
                "no heartbeat for {} ms after {beats} beats",
                since_beat.as_millis()
            ),
        }
    }
}

/// The watch over one partition's heartbeats: alive while beats come within the
/// [`silence_limit`], silent once they do not.
///
/// With [`Liveness::expect`] it watches one process (the launcher's child): beats of any other
/// process ID (a predecessor's last sample, another instance) do not count, and the first beat
/// must come within the start timeout. Without, any beat counts (system automation watching
/// whatever fills the guidance role).
#[derive(Debug, Clone)]
pub struct Liveness {
    limit: Duration,
    /// The process watched, if one.
    pid: Option<u32>,
    /// When the watch began (a start) or the last beat arrived, and how many beats came.
    last_beat: Option<Instant>,
    beats: u64,
    started: Option<Instant>,
    start_timeout: Duration,
    /// The silence found at the deadline is reported once.
    reported: bool,
}

impl Liveness {
    /// A watch over partitions beating on `period`, none seen yet (so not alive).
    pub fn new(period: Duration) -> Self {
        Self {
            limit: silence_limit(period),
            pid: None,
            last_beat: None,
            beats: 0,
            started: None,
            start_timeout: Duration::ZERO,
            reported: false,
        }
    }

    /// The silence after which it is no longer alive.
    pub fn limit(&self) -> Duration {
        self.limit
    }

    /// Watches process `pid`, started at `now`: its first beat is due within `start_timeout`.
    pub fn expect(&mut self, now: Instant, pid: u32, start_timeout: Duration) {
        self.pid = Some(pid);
        self.last_beat = None;
        self.beats = 0;
        self.started = Some(now);
        self.start_timeout = start_timeout;
        self.reported = false;
    }

    /// Stops watching a process (it ended); not alive until the next start or beat.
    pub fn forget(&mut self) {
        *self = Self {
            limit: self.limit,
            ..Self::new(Duration::ZERO)
        };
    }

    /// A beat arrived at `now`; `false` when it is of another process than the one expected
    /// (and is ignored).
    pub fn handle_beat(&mut self, now: Instant, beat: &HeartbeatPayload) -> bool {
        if self.pid.is_some_and(|pid| pid != beat.pid) {
            return false;
        }
        self.last_beat = Some(now);
        self.beats = self.beats.saturating_add(1);
        self.reported = false;
        true
    }

    /// When it falls silent if no beat comes first, or `None` when nothing is watched.
    pub fn deadline(&self) -> Option<Instant> {
        match (self.last_beat, self.started) {
            (Some(beat), _) => Some(beat + self.limit),
            (None, Some(start)) => Some(start + self.start_timeout),
            (None, None) => None,
        }
    }

    /// Whether it beat within the limit (a process just started is not alive until it beats).
    pub fn is_alive(&self, now: Instant) -> bool {
        self.last_beat.is_some_and(|beat| now < beat + self.limit)
    }

    /// The silence found once `now` passed the [`Liveness::deadline`], reported once per
    /// silence (a beat afterwards starts a new one).
    pub fn poll(&mut self, now: Instant) -> Option<Silence> {
        let deadline = self.deadline()?;
        if self.reported || now < deadline {
            return None;
        }
        self.reported = true;
        Some(match (self.last_beat, self.started) {
            (Some(beat), _) => Silence::Stopped {
                since_beat: now.saturating_since(beat),
                beats: self.beats,
            },
            (None, start) => Silence::NeverBeat {
                since_start: now.saturating_since(start.unwrap_or(now)),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PERIOD: Duration = Duration::from_millis(100);

    fn beat(pid: u32) -> HeartbeatPayload {
        HeartbeatPayload {
            sequence: 1,
            time_ns: 0,
            period_ns: 100_000_000,
            pid,
            reserved: [0; 4],
        }
    }

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    #[test]
    fn silent_at_two_and_a_half_periods_not_a_microsecond_before() {
        let mut live = Liveness::new(PERIOD);
        assert_eq!(live.limit(), Duration::from_millis(250));
        assert!(!live.is_alive(at(0)), "nothing seen: not alive");
        assert_eq!(live.poll(at(10_000)), None, "nothing watched: no deadline");
        assert!(live.handle_beat(at(1000), &beat(7)));
        assert!(live.is_alive(at(1000)));
        assert_eq!(live.deadline(), Some(at(1250)));
        let just_before = Instant::from_micros(1_249_999);
        assert!(live.is_alive(just_before));
        assert_eq!(live.poll(just_before), None);
        assert!(!live.is_alive(at(1250)));
        assert_eq!(
            live.poll(at(1250)),
            Some(Silence::Stopped {
                since_beat: Duration::from_millis(250),
                beats: 1
            })
        );
        assert_eq!(live.poll(at(1300)), None, "reported once");
        // It beats again: alive, and a new silence is reported again.
        assert!(live.handle_beat(at(2000), &beat(7)));
        assert!(live.is_alive(at(2000)));
        assert!(live.poll(at(2250)).is_some());
    }

    #[test]
    fn a_partition_stopped_right_after_a_beat_is_found_within_three_periods() {
        // The worst case: stopped just after its beat at t, found at t + limit (+ the watcher's
        // poll interval, 20 ms in the launcher).
        let mut live = Liveness::new(PERIOD);
        live.handle_beat(at(0), &beat(1));
        let found = (0..).map(at).find(|&t| live.poll(t).is_some()).unwrap();
        assert!(found + Duration::from_millis(20) <= at(0) + PERIOD * 3);
    }

    #[test]
    fn a_started_process_must_beat_within_the_start_timeout_and_only_its_beats_count() {
        let mut live = Liveness::new(PERIOD);
        live.expect(at(0), 42, Duration::from_secs(5));
        assert_eq!(live.deadline(), Some(at(5000)));
        assert!(
            !live.handle_beat(at(100), &beat(41)),
            "a predecessor's beat"
        );
        assert!(!live.is_alive(at(100)));
        assert_eq!(live.poll(at(4999)), None);
        assert_eq!(
            live.poll(at(5000)),
            Some(Silence::NeverBeat {
                since_start: Duration::from_secs(5)
            })
        );
        live.expect(at(6000), 43, Duration::from_secs(5));
        assert!(live.handle_beat(at(6500), &beat(43)));
        assert_eq!(live.deadline(), Some(at(6750)));
        live.forget();
        assert_eq!(live.deadline(), None);
        assert!(!live.is_alive(at(6600)));
        assert_eq!(live.limit(), Duration::from_millis(250));
    }

    #[test]
    fn the_limit_rounds_up() {
        assert_eq!(
            silence_limit(Duration::from_nanos(3)),
            Duration::from_nanos(8)
        );
        assert_eq!(silence_limit(Duration::ZERO), Duration::ZERO);
    }
}
