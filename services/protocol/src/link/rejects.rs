//! Rejected input counted by cause, and logged at most once a second per cause.
//!
//! ICD §2 says a receiver counts and logs the frames it rejects, and a message that breaks a
//! rule of ICD §3 or §4 is rejected with its reason (§6). On a link anyone can send to, logging
//! each one is a denial of service on the log: 20,000 bad datagrams on the FCC's ports once gave
//! 19,153 lines. So the counters keep every rejection, by cause ([`ByCause`]), and the log gets
//! at most one line per cause per [`LOG_INTERVAL`] ([`LogLimiter`]), which says how many of that
//! cause were rejected since its last line. Sans-IO: the time comes in with every rejection.

use core::fmt;
use core::marker::PhantomData;
use core::time::Duration;

use missionlink_interfaces::wire::{FrameError, Reason};

use crate::link::time::Instant;

/// At most one log line per cause in this interval.
pub const LOG_INTERVAL: Duration = Duration::from_secs(1);

/// One cause of rejection out of `N`, each with the name its counter is listed under.
pub trait Cause<const N: usize>: Copy + Eq + fmt::Debug + 'static {
    /// Every cause, in [`Cause::index`] order.
    const ALL: [Self; N];

    /// The slot of this cause, below `N`.
    fn index(self) -> usize;

    /// The counter's name in summaries (snake case, unique among the counters of a partition).
    fn counter_name(self) -> &'static str;
}

/// Declares a cause `enum` and its [`Cause`] implementation from one list of variants, each
/// with its counter's name, so the slots, [`Cause::ALL`] and the names cannot disagree: each
/// variant's slot is its position.
#[macro_export]
macro_rules! causes {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident {
            $( $(#[$variant_meta:meta])* $variant:ident => $counter:literal ),+ $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$variant_meta])* $variant ),+
        }

        impl $crate::link::rejects::Cause<{ [$($counter),+].len() }> for $name {
            const ALL: [Self; [$($counter),+].len()] = [$(Self::$variant),+];

            fn index(self) -> usize {
                self as usize
            }

            fn counter_name(self) -> &'static str {
                match self {
                    $(Self::$variant => $counter),+
                }
            }
        }
    };
}

crate::causes! {
    /// The rule of ICD §2 a frame breaks: a [`FrameError`] without the values it reports.
    pub enum FrameCause {
        /// [`FrameError::TooShort`]: fewer bytes than the wrapper header (an empty datagram too).
        TooShort => "too_short",
        /// [`FrameError::LengthOutOfRange`]: Message Length 0 or above 528.
        LengthOutOfRange => "length_out_of_range",
        /// [`FrameError::LengthMismatch`]: Message Length and checksum width disagree with the
        /// datagram.
        LengthMismatch => "length_mismatch",
        /// [`FrameError::InvalidChecksumLength`]: checksum length code 11.
        InvalidChecksumLength => "invalid_checksum_length",
        /// [`FrameError::ChecksumMismatch`]: wrong checksum.
        ChecksumMismatch => "checksum_mismatch",
        /// [`FrameError::UnsupportedVersion`]: IDD version outside 30..=40.
        UnsupportedVersion => "unsupported_version",
        /// [`FrameError::WrongDestination`]: neither this node nor broadcast.
        WrongDestination => "wrong_destination",
        /// [`FrameError::UnknownSource`]: not the configured peer.
        UnknownSource => "unknown_source",
    }
}

impl FrameCause {
    /// The cause of `error`.
    pub const fn of(error: &FrameError) -> Self {
        match error {
            FrameError::TooShort { .. } => Self::TooShort,
            FrameError::LengthOutOfRange { .. } => Self::LengthOutOfRange,
            FrameError::LengthMismatch { .. } => Self::LengthMismatch,
            FrameError::InvalidChecksumLength => Self::InvalidChecksumLength,
            FrameError::ChecksumMismatch { .. } => Self::ChecksumMismatch,
            FrameError::UnsupportedVersion { .. } => Self::UnsupportedVersion,
            FrameError::WrongDestination { .. } => Self::WrongDestination,
            FrameError::UnknownSource { .. } => Self::UnknownSource,
        }
    }
}

/// The reject reasons of ICD §6, each a cause of its own.
pub const REASONS: usize = 16;

// A reason added to the ICD needs a slot and a name below.
const _: () = assert!(Reason::ALL.len() == REASONS);

impl Cause<REASONS> for Reason {
    const ALL: [Self; REASONS] = [
        Self::None,
        Self::Malformed,
        Self::MissingField,
        Self::UnknownField,
        Self::Unsupported,
        Self::Capacity,
        Self::WrongState,
        Self::GuidanceActive,
        Self::CountMismatch,
        Self::BrokenChain,
        Self::MissingInitial,
        Self::MissingRfCentre,
        Self::BadGeometry,
        Self::Busy,
        Self::GeofenceViolation,
        Self::IntegrityMismatch,
    ];

    /// The wire value (ICD §6 numbers the reasons from 0).
    fn index(self) -> usize {
        self as usize
    }

    fn counter_name(self) -> &'static str {
        match self {
            Self::None => "reason_none",
            Self::Malformed => "reason_malformed",
            Self::MissingField => "reason_missing_field",
            Self::UnknownField => "reason_unknown_field",
            Self::Unsupported => "reason_unsupported",
            Self::Capacity => "reason_capacity",
            Self::WrongState => "reason_wrong_state",
            Self::GuidanceActive => "reason_guidance_active",
            Self::CountMismatch => "reason_count_mismatch",
            Self::BrokenChain => "reason_broken_chain",
            Self::MissingInitial => "reason_missing_initial",
            Self::MissingRfCentre => "reason_missing_rf_centre",
            Self::BadGeometry => "reason_bad_geometry",
            Self::Busy => "reason_busy",
            Self::GeofenceViolation => "reason_geofence_violation",
            Self::IntegrityMismatch => "reason_integrity_mismatch",
        }
    }
}

/// A counter per cause.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct ByCause<C: Cause<N>, const N: usize> {
    counts: [u64; N],
    causes: PhantomData<C>,
}

impl<C: Cause<N>, const N: usize> ByCause<C, N> {
    /// Every counter at zero.
    pub const fn new() -> Self {
        Self {
            counts: [0; N],
            causes: PhantomData,
        }
    }

    /// Counts one more of `cause`.
    pub fn add(&mut self, cause: C) {
        if let Some(count) = self.counts.get_mut(cause.index()) {
            *count = count.saturating_add(1);
        }
    }

    /// How many of `cause`.
    pub fn get(&self, cause: C) -> u64 {
        self.counts.get(cause.index()).copied().unwrap_or(0)
    }

    /// How many of all causes.
    pub fn total(&self) -> u64 {
        self.counts.iter().fold(0, |sum, c| sum.saturating_add(*c))
    }

    /// Every cause with its count, in [`Cause::ALL`] order (zeros included).
    pub fn iter(&self) -> impl Iterator<Item = (C, u64)> + '_ {
        C::ALL.into_iter().map(|cause| (cause, self.get(cause)))
    }

    /// Every counter by its [`Cause::counter_name`], for a summary.
    pub fn counters(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        self.iter()
            .map(|(cause, count)| (cause.counter_name(), count))
    }
}

impl<C: Cause<N>, const N: usize> Default for ByCause<C, N> {
    fn default() -> Self {
        Self::new()
    }
}

/// The causes that occurred, with their counts.
impl<C: Cause<N>, const N: usize> fmt::Debug for ByCause<C, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries(self.counters().filter(|(_, count)| *count > 0))
            .finish()
    }
}

/// Decides, per cause, whether a rejection gets a log line: the first does, then none until
/// [`LOG_INTERVAL`] has passed since the cause's last line.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct LogLimiter<C: Cause<N>, const N: usize> {
    last_line: [Option<Instant>; N],
    since_line: [u64; N],
    lines: u64,
    causes: PhantomData<C>,
}

impl<C: Cause<N>, const N: usize> LogLimiter<C, N> {
    /// A limiter that has let no line through.
    pub const fn new() -> Self {
        Self {
            last_line: [None; N],
            since_line: [0; N],
            lines: 0,
            causes: PhantomData,
        }
    }

    /// One rejection of `cause` at `now`. `Some(n)` when it gets a log line: `n` rejections of
    /// the cause since its last line, this one included; `None` when it is only counted.
    pub fn admit(&mut self, cause: C, now: Instant) -> Option<u64> {
        let i = cause.index();
        let (Some(last_line), Some(since_line)) =
            (self.last_line.get_mut(i), self.since_line.get_mut(i))
        else {
            return None;
        };
        *since_line = since_line.saturating_add(1);
        if last_line.is_some_and(|at| now.saturating_since(at) < LOG_INTERVAL) {
            return None;
        }
        *last_line = Some(now);
        self.lines = self.lines.saturating_add(1);
        Some(core::mem::take(since_line))
    }

    /// Log lines let through so far, all causes.
    pub fn lines(&self) -> u64 {
        self.lines
    }
}

impl<C: Cause<N>, const N: usize> Default for LogLimiter<C, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<C: Cause<N>, const N: usize> fmt::Debug for LogLimiter<C, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LogLimiter")
            .field("lines", &self.lines)
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_indices<C: Cause<N>, const N: usize>() {
        let mut names = std::collections::HashSet::new();
        for (i, cause) in C::ALL.into_iter().enumerate() {
            assert_eq!(cause.index(), i, "{cause:?}");
            assert!(names.insert(cause.counter_name()), "{cause:?}: name twice");
        }
    }

    #[test]
    fn every_cause_has_its_own_slot_and_name() {
        check_indices::<FrameCause, 8>();
        check_indices::<Reason, REASONS>();
        assert_eq!(<Reason as Cause<REASONS>>::ALL.as_slice(), Reason::ALL);
    }

    #[test]
    fn counts_by_cause() {
        let mut counts = ByCause::<FrameCause, 8>::new();
        counts.add(FrameCause::ChecksumMismatch);
        counts.add(FrameCause::ChecksumMismatch);
        counts.add(FrameCause::of(&FrameError::UnknownSource { source: 7 }));
        assert_eq!(counts.get(FrameCause::ChecksumMismatch), 2);
        assert_eq!(counts.get(FrameCause::UnknownSource), 1);
        assert_eq!(counts.get(FrameCause::TooShort), 0);
        assert_eq!(counts.total(), 3);
        assert_eq!(counts.counters().count(), 8, "zeros are listed too");
        assert!(counts.counters().any(|c| c == ("checksum_mismatch", 2)));
        assert_eq!(
            format!("{counts:?}"),
            r#"{"checksum_mismatch": 2, "unknown_source": 1}"#
        );
    }

    fn at(ms: u64) -> Instant {
        Instant::from_millis(ms)
    }

    #[test]
    fn one_line_per_cause_per_interval_saying_how_many_since_the_last() {
        let mut log = LogLimiter::<FrameCause, 8>::new();
        assert_eq!(log.admit(FrameCause::TooShort, at(0)), Some(1), "the first");
        assert_eq!(log.admit(FrameCause::TooShort, at(1)), None);
        assert_eq!(log.admit(FrameCause::TooShort, at(999)), None);
        // Another cause has its own line.
        assert_eq!(log.admit(FrameCause::ChecksumMismatch, at(999)), Some(1));
        // Nothing at t - 1, the line at t: the two suppressed and this one.
        assert_eq!(log.admit(FrameCause::TooShort, at(1000)), Some(3));
        assert_eq!(log.admit(FrameCause::TooShort, at(1999)), None);
        assert_eq!(log.admit(FrameCause::TooShort, at(60_000)), Some(2));
        assert_eq!(log.lines(), 4);
    }
}
