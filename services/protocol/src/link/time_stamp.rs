//! The time stamps a sender puts on the messages it originates (ICD §3, "Time stamps are
//! identities"): strictly increasing, from the sender's clock, bumped by 1 ms where the clock has
//! not moved on since the previous message. The receiver's message sampling relies on it: a
//! (Source ID, Message Type, Time Stamp) triple names exactly one message.

use missionlink_interfaces::wire::Timestamp;

/// The clock has passed the last time stamp a U5 holds (2034-11-01).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("no time stamp left: the U5 millisecond count of ICD §3 is exhausted")]
pub struct TimeStampsExhausted;

/// Issues strictly increasing time stamps for one sender.
#[derive(Debug, Clone, Default)]
pub struct TimeStamper {
    last: Option<Timestamp>,
}

impl TimeStamper {
    /// A stamper that has issued nothing yet.
    pub const fn new() -> Self {
        Self { last: None }
    }

    /// Stamps from now on are strictly greater than `floor` (and than every stamp issued): how
    /// a sender that restarts continues after what an earlier process of it may have sent.
    pub fn resume_after(&mut self, floor: Timestamp) {
        self.last = Some(self.last.map_or(floor, |last| last.max(floor)));
    }

    /// The last stamp issued.
    pub fn last(&self) -> Option<Timestamp> {
        self.last
    }

    /// The time stamp for a message originated at `now`: `now`, or 1 ms after the previous
    /// stamp when the clock has not moved past it (same millisecond, or a clock step back).
    pub fn stamp(&mut self, now: Timestamp) -> Result<Timestamp, TimeStampsExhausted> {
        let stamp = match self.last {
            Some(last) if now <= last => last.next().ok_or(TimeStampsExhausted)?,
            _ => now,
        };
        self.last = Some(stamp);
        Ok(stamp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ts(ms: u64) -> Timestamp {
        Timestamp::from_millis(ms).unwrap()
    }

    #[test]
    fn resumes_strictly_after_a_floor() {
        let mut s = TimeStamper::new();
        s.resume_after(ts(500));
        assert_eq!(s.stamp(ts(100)), Ok(ts(501)));
        s.resume_after(ts(200));
        assert_eq!(
            s.stamp(ts(100)),
            Ok(ts(502)),
            "a lower floor changes nothing"
        );
        assert_eq!(s.last(), Some(ts(502)));
    }

    #[test]
    fn follows_the_clock_when_it_advances() {
        let mut s = TimeStamper::new();
        assert_eq!(s.stamp(ts(100)), Ok(ts(100)));
        assert_eq!(s.stamp(ts(250)), Ok(ts(250)));
    }

    #[test]
    fn bumps_by_one_millisecond_within_the_same_millisecond() {
        let mut s = TimeStamper::new();
        assert_eq!(s.stamp(ts(100)), Ok(ts(100)));
        assert_eq!(s.stamp(ts(100)), Ok(ts(101)));
        assert_eq!(s.stamp(ts(100)), Ok(ts(102)));
        // The clock catches up: stamps follow it again once it is ahead.
        assert_eq!(s.stamp(ts(102)), Ok(ts(103)));
        assert_eq!(s.stamp(ts(110)), Ok(ts(110)));
    }

    #[test]
    fn never_goes_back_when_the_clock_steps_back() {
        let mut s = TimeStamper::new();
        assert_eq!(s.stamp(ts(1_000)), Ok(ts(1_000)));
        assert_eq!(s.stamp(ts(10)), Ok(ts(1_001)));
    }

    #[test]
    fn reports_exhaustion_instead_of_wrapping() {
        let mut s = TimeStamper::new();
        let max = ts(Timestamp::MAX_MILLIS);
        assert_eq!(s.stamp(max), Ok(max));
        assert_eq!(s.stamp(max), Err(TimeStampsExhausted));
    }
}
