//! Voting and monitoring of the two data links (paper §2.4; ICD §1, §2).
//!
//! The direct and the LTE link carry the same traffic (ICD §1), so every message normally
//! arrives twice. The voter sits between the sockets and mission data handling and passes each
//! message on exactly once:
//!
//! - **Integrity (ICD §2, §9).** Every message of every datagram (a datagram may hold several,
//!   back to back) goes through the wrapper rules ([`wire::frames`]), the addressing rules
//!   ([`Frame::check_addressing`]) and, where links are signed, the signature check. A frame
//!   that breaks one is dropped and counted by cause: it is never processed and never
//!   acknowledged. The log hears of it at most once a second per cause
//!   ([`crate::link::rejects`]), so a flood of bad datagrams cannot flood the log. Of the
//!   message data the voter reads only the time stamp ([`Frame::time_stamp`]): a message
//!   without a readable one is dropped (nobody could answer it); a message that breaks a rule
//!   of ICD §3 or §4 otherwise is forwarded, and the endpoint behind the voter rejects it with
//!   #17000 type 3 and the reason.
//! - **Each message once (paper §2.4; ICD §3 "Time stamps are identities", §10.2).** Message
//!   sampling ([`MessageSampler`], keyed by source, message type and time stamp) drops the
//!   redundant copy from the other link (or a repeated frame); it keeps the identities it
//!   forwarded, so a message that arrives after a newer one of its type (a window of data
//!   messages in flight, reordering) is still forwarded. The voter never waits for the other
//!   link: a message that arrives alone is forwarded at once, so a dead link costs no latency.
//! - **Tie goes to the direct link.** The driver hands over a *step*: every datagram received
//!   since its last wake-up. Within a step the messages are handled in order of (time stamp,
//!   direct before LTE), so when both copies arrive in the same step the direct copy is the one
//!   forwarded; across steps the first copy to arrive wins, because waiting would cost latency.
//!
//! **Who owns what.** The voter owns the link-level checks (wrapper, addressing, signature) and
//! message sampling across both links, with their counters ([`VotingStats`]). The endpoint
//! ([`crate::link::endpoint`]) owns decoding, the message rules and the acknowledgement, with
//! theirs. Nothing is checked or counted twice.
//!
//! Sans-IO (docs/design.md, "The sans-IO core"): the driver passes the time and the bytes in and
//! gets the forwarded frames back through a callback, as sub-slices of the datagrams it passed
//! in, each with the index of its datagram in the step.
//! Nothing is allocated: a step holds at most [`VOTING_STEP_MESSAGES`] candidates on the stack.

use core::time::Duration;

use heapless::Vec;
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::{self, Frame, FrameError, Timestamp};

use crate::link::rejects::{ByCause, Cause, FrameCause, LogLimiter};
use crate::link::sampling::{MessageSampler, Sample};
use crate::link::signing::{Authenticity, NotAdmitted, SignatureCause, SignatureCheck};
use crate::link::time::Instant;

/// Messages one step considers at most; the rest of the step is dropped and counted as
/// [`VotingStats::overflow`]. As deep as the frame queues between the partitions
/// (`fcc/link/uplink` buffers 64 frames), and far more than a transfer has in flight: one message
/// per acknowledgement round trip, twice (both links).
pub const VOTING_STEP_MESSAGES: usize = 64;

/// What the voter did since it was created. Every message of every datagram lands in exactly
/// one of: `forwarded`, `duplicates`, `stale`, `rejected_frames` (by cause),
/// `rejected_signatures` (by cause), `before_start`, `unreadable_messages`, `overflow`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VotingStats {
    /// Messages forwarded, per link: `[direct, LTE]` (a message that breaks a rule of ICD §3 or
    /// §4 too: the endpoint rejects it with #17000 and the reason).
    pub forwarded: [u64; 2],
    /// Redundant copies dropped: the same (source, type, time stamp) was already forwarded.
    pub duplicates: u64,
    /// Copies dropped as stale: at or below a stamp of the same source and type that sampling
    /// forgot to make room (see [`crate::link::sampling`]), so possibly a delayed duplicate.
    pub stale: u64,
    /// Frames dropped by a rule of ICD §2, by cause (as [`crate::link::endpoint::EndpointStats`]
    /// counts them).
    pub rejected_frames: ByCause<FrameCause, 8>,
    /// Frames that fail the signature check of ICD §9, by cause: dropped like a frame with a
    /// bad checksum.
    pub rejected_signatures: ByCause<SignatureCause, 4>,
    /// Signed frames stamped before this receiver started (ICD §9 "Replay"): sent while it
    /// was down or starting, dropped since a lost memory cannot prove them new, and no sign of
    /// an attack, so not among the rejections.
    pub before_start: u64,
    /// Messages whose time stamp cannot be read (or whose type the ICD does not define):
    /// dropped, since sampling cannot identify them and no acknowledgement can refer to them.
    pub unreadable_messages: u64,
    /// Messages beyond [`VOTING_STEP_MESSAGES`] in one step: dropped unexamined.
    pub overflow: u64,
}

impl VotingStats {
    /// Every counter by name, for a summary: the total of rejected frames, then each cause
    /// under its [`Cause::counter_name`].
    pub fn counters(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        let [direct, lte] = self.forwarded;
        [
            ("forwarded_direct", direct),
            ("forwarded_lte", lte),
            ("duplicates", self.duplicates),
            ("stale", self.stale),
            ("rejected_frames", self.rejected_frames.total()),
        ]
        .into_iter()
        .chain(self.rejected_frames.counters())
        .chain([("rejected_signatures", self.rejected_signatures.total())])
        .chain(self.rejected_signatures.counters())
        .chain([
            ("before_start", self.before_start),
            ("unreadable_messages", self.unreadable_messages),
            ("overflow", self.overflow),
        ])
    }

    /// Counts a forwarded message on its link.
    fn count_forwarded(&mut self, link: Link) {
        let [direct, lte] = &mut self.forwarded;
        match link {
            Link::Direct => *direct += 1,
            // `Both` is no receive link; a driver that passes it gets LTE's treatment (see
            // `tie_rank`).
            Link::Lte | Link::Both => *lte += 1,
        }
    }
}

/// Rank of a link on equal time stamps: lower wins. The direct link is preferred (paper §2.4):
/// it is the link with the shorter, more predictable delay.
const fn tie_rank(link: Link) -> u8 {
    match link {
        Link::Direct => 0,
        Link::Lte | Link::Both => 1,
    }
}

/// A message of the step that passed the wrapper and addressing rules and has a time stamp.
#[derive(Debug, Clone, Copy)]
struct Candidate<'a> {
    link: Link,
    /// The one message, wrapper to checksum.
    bytes: &'a [u8],
    source: u32,
    message_type: u16,
    time_stamp: Timestamp,
    /// The index of its datagram in the step.
    datagram: usize,
    /// Position in the step, so that the order is total and deterministic.
    arrival: usize,
}

impl Candidate<'_> {
    /// Handling order within a step: time stamp, then direct before LTE, then arrival. Sorting
    /// by time stamp also restores the sender's order (ICD §3: stamps strictly increase), so a
    /// newer copy never hides an older message of the same source and type as stale.
    fn order(&self) -> (Timestamp, u8, usize) {
        (self.time_stamp, tie_rank(self.link), self.arrival)
    }
}

/// The voter of one node: integrity checks, message sampling and the direct-link tie-break.
#[derive(Debug, Clone)]
pub struct Voter {
    local_id: u32,
    peer_id: u32,
    sampler: MessageSampler,
    signatures: SignatureCheck,
    stats: VotingStats,
    frame_log: LogLimiter<FrameCause, 8>,
    signature_log: LogLimiter<SignatureCause, 4>,
    unreadable_log: LogLimiter<Unreadable, 1>,
    overflow_log: LogLimiter<StepFull, 1>,
}

crate::causes! {
    /// The cause of [`VotingStats::unreadable_messages`], logged like a rejection.
    enum Unreadable {
        NoTimeStamp => "unreadable_messages",
    }
}

crate::causes! {
    /// The cause of [`VotingStats::overflow`], logged like a rejection.
    enum StepFull {
        Overflow => "overflow",
    }
}

impl Voter {
    /// A voter for the node `local_id` that accepts frames from `peer_id` only (ICD §2).
    /// `sampling_window` is how long the time stamps of a (source, type) are remembered
    /// without traffic (see [`MessageSampler::new`]; the transfer timeout of ICD §1 fits).
    pub fn new(local_id: u32, peer_id: u32, sampling_window: Duration) -> Self {
        Self {
            local_id,
            peer_id,
            sampler: MessageSampler::new(sampling_window),
            signatures: SignatureCheck::off(),
            stats: VotingStats::default(),
            frame_log: LogLimiter::new(),
            signature_log: LogLimiter::new(),
            unreadable_log: LogLimiter::new(),
            overflow_log: LogLimiter::new(),
        }
    }

    /// The same voter checking signatures (ICD §9) as `check` says; without it, policy `off`.
    pub fn with_signatures(mut self, check: SignatureCheck) -> Self {
        self.signatures = check;
        self
    }

    /// The signature check (its policy and counters).
    pub fn signatures(&self) -> &SignatureCheck {
        &self.signatures
    }

    /// The signature check, to resume its replay window ([`SignatureCheck::resume_after`]).
    pub fn signatures_mut(&mut self) -> &mut SignatureCheck {
        &mut self.signatures
    }

    /// Votes one step: `arrivals` are the datagrams received since the last step, each with its
    /// link. Calls `forward(link, datagram, frame_bytes)` for every message to pass on, in
    /// forwarding order (`datagram` = its datagram's index in `arrivals`, `frame_bytes` = the
    /// bytes of that one message, wrapper to checksum). Bounded: at
    /// most [`VOTING_STEP_MESSAGES`] messages per step are considered, in arrival order; the
    /// rest are dropped and counted as [`VotingStats::overflow`].
    pub fn vote_step<'a>(
        &mut self,
        now: Instant,
        arrivals: &[(Link, &'a [u8])],
        mut forward: impl FnMut(Link, usize, &'a [u8]),
    ) {
        let mut candidates: Vec<Candidate<'a>, VOTING_STEP_MESSAGES> = Vec::new();
        let mut considered = 0usize;
        for (index, &(link, datagram)) in arrivals.iter().enumerate() {
            if datagram.is_empty() {
                // The walker yields nothing for no bytes, but ICD §2 still calls an empty
                // datagram shorter than the header: count it, so a peer sending them is seen.
                if self.admit(now, &mut considered, link) {
                    self.reject(now, link, FrameError::TooShort { len: 0 });
                }
                continue;
            }
            for item in wire::frames(datagram) {
                let arrival = considered;
                if !self.admit(now, &mut considered, link) {
                    continue;
                }
                let checked = item.and_then(|frame| {
                    frame
                        .check_addressing(self.local_id, self.peer_id)
                        .map(|()| frame)
                });
                match checked {
                    Err(error) => self.reject(now, link, error),
                    Ok(frame) => {
                        let candidate = self.candidate(now, link, frame, index, arrival);
                        if let Some(candidate) = candidate {
                            // `admit` keeps the count within the capacity, so this never fails;
                            // should it, the message is accounted for rather than lost silently.
                            if candidates.push(candidate).is_err() {
                                self.stats.overflow += 1;
                            }
                        }
                    }
                }
            }
        }
        // Unstable sort: it never allocates, and the arrival index makes the key unique.
        candidates.sort_unstable_by_key(Candidate::order);
        for candidate in &candidates {
            self.sample(now, candidate, &mut forward);
        }
    }

    /// One datagram alone (a step of one).
    pub fn vote<'a>(
        &mut self,
        now: Instant,
        link: Link,
        datagram: &'a [u8],
        mut forward: impl FnMut(Link, &'a [u8]),
    ) {
        self.vote_step(now, &[(link, datagram)], |link, _, frame| {
            forward(link, frame)
        });
    }

    /// What the voter did so far.
    pub fn stats(&self) -> &VotingStats {
        &self.stats
    }

    /// Log lines about rejected frames, unreadable messages and full steps so far (at most one
    /// per cause per [`crate::link::rejects::LOG_INTERVAL`]).
    pub fn reject_log_lines(&self) -> u64 {
        self.frame_log.lines()
            + self.signature_log.lines()
            + self.unreadable_log.lines()
            + self.overflow_log.lines()
    }

    /// Counts one more message of the step; `false` (and counted as overflow) once the step
    /// has had [`VOTING_STEP_MESSAGES`].
    fn admit(&mut self, now: Instant, considered: &mut usize, link: Link) -> bool {
        if *considered >= VOTING_STEP_MESSAGES {
            self.stats.overflow += 1;
            if let Some(dropped) = self.overflow_log.admit(StepFull::Overflow, now) {
                tracing::warn!(
                    ?link,
                    limit = VOTING_STEP_MESSAGES,
                    dropped,
                    "voting steps full: messages dropped since the last line"
                );
            }
            return false;
        }
        *considered += 1;
        true
    }

    /// Drops a frame by a rule of ICD §2: counted, logged at most once a second per cause,
    /// never processed.
    fn reject(&mut self, now: Instant, link: Link, error: FrameError) {
        let cause = FrameCause::of(&error);
        self.stats.rejected_frames.add(cause);
        if let Some(rejected) = self.frame_log.admit(cause, now) {
            tracing::warn!(
                ?link,
                cause = cause.counter_name(),
                rejected,
                last = %error,
                "frames rejected since the last line of this cause"
            );
        }
    }

    /// Drops a frame that fails the signature check (ICD §9): counted, logged at most once a
    /// second per cause, never processed.
    fn reject_signature(
        &mut self,
        now: Instant,
        link: Link,
        cause: SignatureCause,
        message_type: u16,
    ) {
        self.stats.rejected_signatures.add(cause);
        if let Some(rejected) = self.signature_log.admit(cause, now) {
            tracing::warn!(
                ?link,
                cause = cause.counter_name(),
                rejected,
                last_message_type = message_type,
                "frames failing the signature check since the last line of this cause"
            );
        }
    }

    /// Checks the signature of a frame that passed the wrapper and addressing rules and decodes
    /// its message; `None` when it is dropped: its signature fails, or its time stamp cannot be
    /// read. The signature is checked first, so a forger's bytes reach no decoder under
    /// `require`; the replay check needs the time stamp, so it follows decoding.
    fn candidate<'a>(
        &mut self,
        now: Instant,
        link: Link,
        frame: Frame<'a>,
        datagram: usize,
        arrival: usize,
    ) -> Option<Candidate<'a>> {
        let authenticity = match self.signatures.verify(link, &frame) {
            Ok(a) => a,
            Err(cause) => {
                self.reject_signature(now, link, cause, frame.message_type());
                return None;
            }
        };
        // The time stamp alone: the endpoint decodes the message (module documentation).
        let stamp = frame.time_stamp();
        if authenticity == Authenticity::Verified {
            let admitted =
                self.signatures
                    .admit(now, link, frame.source_id(), frame.message_type(), stamp);
            match admitted {
                Ok(()) => {}
                Err(NotAdmitted::Replay) => {
                    let cause = SignatureCause::Replay;
                    self.reject_signature(now, link, cause, frame.message_type());
                    return None;
                }
                Err(NotAdmitted::BeforeStart) => {
                    self.stats.before_start += 1;
                    return None;
                }
            }
        }
        let Some(time_stamp) = stamp else {
            self.stats.unreadable_messages += 1;
            if let Some(dropped) = self.unreadable_log.admit(Unreadable::NoTimeStamp, now) {
                tracing::warn!(
                    ?link,
                    dropped,
                    last_message_type = frame.message_type(),
                    "messages without a readable time stamp (or of a type the ICD does not \
                     define) dropped since the last line"
                );
            }
            return None;
        };
        Some(Candidate {
            link,
            bytes: frame.as_bytes(),
            source: frame.source_id(),
            message_type: frame.message_type(),
            time_stamp,
            datagram,
            arrival,
        })
    }

    /// Message sampling of one candidate: forward it when fresh, else count the drop.
    fn sample<'a>(
        &mut self,
        now: Instant,
        candidate: &Candidate<'a>,
        forward: &mut impl FnMut(Link, usize, &'a [u8]),
    ) {
        let Candidate {
            link,
            bytes,
            source,
            message_type,
            time_stamp,
            datagram,
            ..
        } = *candidate;
        match self.sampler.sample(now, source, message_type, time_stamp) {
            Sample::Fresh => {
                self.stats.count_forwarded(link);
                forward(link, datagram, bytes);
            }
            Sample::Duplicate => {
                self.stats.duplicates += 1;
                tracing::debug!(?link, message_type, %time_stamp, "redundant copy dropped");
            }
            Sample::Stale => {
                self.stats.stale += 1;
                tracing::debug!(?link, message_type, %time_stamp, "stale copy dropped");
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{self, ts};
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::{
        AckType, BROADCAST_ID, Envelope, LegType, Message, MessageAcknowledgement,
        UaPositionWaypoint, frame::checksum,
    };

    const WINDOW: Duration = Duration::from_secs(3);

    /// A valid #13002 (waypoint `number`, the last) stamped `stamp`.
    fn waypoint(stamp: u64, number: u16) -> UaPositionWaypoint {
        UaPositionWaypoint {
            time_stamp: ts(stamp),
            ..testkit::waypoint(number, 0, testkit::CCP, LegType::TrackToFix)
        }
    }

    fn encode(envelope: Envelope, message: impl Into<Message>) -> std::vec::Vec<u8> {
        testkit::frame(&envelope, &message.into())
    }

    /// An uplink #13002 from the GCS to the FCC.
    fn uplink(stamp: u64) -> std::vec::Vec<u8> {
        encode(
            Envelope::new(GCS_ID, FCC_ID).with_ack(true),
            waypoint(stamp, 1),
        )
    }

    /// An uplink #17000 from the GCS to the FCC.
    fn ack(stamp: u64) -> std::vec::Vec<u8> {
        encode(
            Envelope::new(GCS_ID, FCC_ID),
            MessageAcknowledgement {
                time_stamp: ts(stamp),
                original_time_stamp: ts(1),
                original_message_type: 13002,
                ack_type: AckType::Completed,
                reject_reason: None,
            },
        )
    }

    /// A frame built by hand around `data`, with a correct 4-byte checksum.
    fn raw(source: u32, destination: u32, message_type: u16, data: &[u8]) -> std::vec::Vec<u8> {
        testkit::RawFrame {
            source,
            destination,
            ..testkit::RawFrame::uplink(message_type)
        }
        .build(data)
    }

    /// Rewrites the checksum after a test changed header bytes.
    fn fix_checksum(f: &mut [u8]) {
        let end = f.len() - 4;
        let sum = checksum(&f[..end], wire::ChecksumWidth::Four);
        f[end..].copy_from_slice(&sum.to_be_bytes());
    }

    fn fcc() -> Voter {
        Voter::new(FCC_ID, GCS_ID, WINDOW)
    }

    /// Runs one step and collects what was forwarded.
    fn step(
        voter: &mut Voter,
        now: Instant,
        arrivals: &[(Link, &[u8])],
    ) -> std::vec::Vec<(Link, std::vec::Vec<u8>)> {
        let mut out = std::vec::Vec::new();
        voter.vote_step(now, arrivals, |link, _, bytes| {
            out.push((link, bytes.to_vec()))
        });
        out
    }

    /// Rejected-frame counters with `counts` of each cause.
    fn rejected(counts: &[(FrameCause, u64)]) -> ByCause<FrameCause, 8> {
        let mut by_cause = ByCause::new();
        for &(cause, n) in counts {
            for _ in 0..n {
                by_cause.add(cause);
            }
        }
        by_cause
    }

    fn stats(forwarded: [u64; 2]) -> VotingStats {
        VotingStats {
            forwarded,
            ..VotingStats::default()
        }
    }

    #[test]
    fn single_link_is_forwarded_at_once() {
        let mut v = fcc();
        let a = uplink(100);
        let out = step(&mut v, Instant::from_millis(1), &[(Link::Lte, &a)]);
        assert_eq!(out, [(Link::Lte, a.clone())]);
        let b = uplink(200);
        let mut out = std::vec::Vec::new();
        v.vote(Instant::from_millis(2), Link::Direct, &b, |l, f| {
            out.push((l, f.to_vec()))
        });
        assert_eq!(out, [(Link::Direct, b)]);
        assert_eq!(v.stats(), &stats([1, 1]));
    }

    #[test]
    fn same_message_on_both_links_in_one_step_goes_out_once_by_direct() {
        let mut v = fcc();
        let a = uplink(100);
        // LTE listed first: the tie-break, not the arrival order, decides.
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Lte, &a), (Link::Direct, &a)],
        );
        assert_eq!(out, [(Link::Direct, a)]);
        assert_eq!(
            v.stats(),
            &VotingStats {
                duplicates: 1,
                ..stats([1, 0])
            }
        );
    }

    #[test]
    fn first_copy_across_steps_wins_without_waiting() {
        let mut v = fcc();
        let a = uplink(100);
        let out = step(&mut v, Instant::from_millis(1), &[(Link::Lte, &a)]);
        assert_eq!(out, [(Link::Lte, a.clone())]);
        let out = step(&mut v, Instant::from_millis(2), &[(Link::Direct, &a)]);
        assert!(out.is_empty());
        assert_eq!(
            v.stats(),
            &VotingStats {
                duplicates: 1,
                ..stats([0, 1])
            }
        );
    }

    #[test]
    fn repeated_frame_on_one_link_is_a_duplicate() {
        let mut v = fcc();
        let a = uplink(100);
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Direct, &a), (Link::Direct, &a)],
        );
        assert_eq!(out.len(), 1);
        assert_eq!(v.stats().duplicates, 1);
    }

    /// ICD §10.2: an older message that arrives after a newer one is forwarded (it was never
    /// processed); its copy on the other link is then a duplicate.
    #[test]
    fn an_older_message_after_a_newer_one_is_forwarded_once() {
        let mut v = fcc();
        let new = uplink(200);
        let old = uplink(100);
        assert_eq!(
            step(&mut v, Instant::from_millis(1), &[(Link::Direct, &new)]).len(),
            1
        );
        assert_eq!(
            step(&mut v, Instant::from_millis(2), &[(Link::Lte, &old)]).len(),
            1
        );
        assert!(step(&mut v, Instant::from_millis(3), &[(Link::Direct, &old)]).is_empty());
        assert_eq!(
            v.stats(),
            &VotingStats {
                duplicates: 1,
                ..stats([1, 1])
            }
        );
    }

    #[test]
    fn a_copy_below_what_sampling_forgot_is_stale() {
        use crate::link::sampling::HORIZON_MS;
        let mut v = fcc();
        for i in [0, HORIZON_MS] {
            let m = uplink(1000 + i);
            assert_eq!(
                step(&mut v, Instant::from_millis(1), &[(Link::Direct, &m)]).len(),
                1
            );
        }
        let oldest = uplink(1000);
        assert!(step(&mut v, Instant::from_millis(2), &[(Link::Lte, &oldest)]).is_empty());
        assert_eq!(v.stats().stale, 1);
    }

    #[test]
    fn newer_lte_after_older_direct_in_one_step_both_forwarded_in_time_stamp_order() {
        let mut v = fcc();
        let older = uplink(100);
        let newer = uplink(200);
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Lte, &newer), (Link::Direct, &older)],
        );
        assert_eq!(out, [(Link::Direct, older), (Link::Lte, newer)]);
        assert_eq!(v.stats(), &stats([1, 1]));
    }

    #[test]
    fn interleaved_copies_of_a_sequence_go_out_once_in_order() {
        let mut v = fcc();
        let (a, b, c) = (uplink(100), ack(101), uplink(102));
        // Direct lost b; LTE delivers everything in reverse.
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[
                (Link::Lte, &c),
                (Link::Lte, &b),
                (Link::Lte, &a),
                (Link::Direct, &a),
                (Link::Direct, &c),
            ],
        );
        assert_eq!(out, [(Link::Direct, a), (Link::Lte, b), (Link::Direct, c)]);
        assert_eq!(v.stats().duplicates, 2);
    }

    #[test]
    fn frame_errors_are_dropped_and_counted_by_cause() {
        let good = uplink(100);

        let too_short = good[..10].to_vec();
        let mut length_zero = good.clone();
        length_zero[2..4].copy_from_slice(&0u16.to_be_bytes());
        let mut length_big = good.clone();
        length_big[2..4].copy_from_slice(&529u16.to_be_bytes());
        let truncated = good[..good.len() - 1].to_vec();
        let mut checksum_code_11 = good.clone();
        checksum_code_11[15] |= 0xc0;
        let mut corrupted = good.clone();
        corrupted[20] ^= 0x01;
        let foreign_version = encode(
            Envelope {
                idd_version: 41,
                ..Envelope::new(GCS_ID, FCC_ID)
            },
            waypoint(100, 1),
        );
        let other_destination = encode(Envelope::new(GCS_ID, 0x0B00_0002), waypoint(100, 1));
        let other_source = encode(Envelope::new(0x0A00_0002, FCC_ID), waypoint(100, 1));

        let mut v = fcc();
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[
                (Link::Direct, &too_short),
                (Link::Direct, &[]),
                (Link::Direct, &length_zero),
                (Link::Lte, &length_big),
                (Link::Direct, &truncated),
                (Link::Lte, &checksum_code_11),
                (Link::Direct, &corrupted),
                (Link::Lte, &foreign_version),
                (Link::Direct, &other_destination),
                (Link::Lte, &other_source),
            ],
        );
        assert!(out.is_empty());
        assert_eq!(
            v.stats(),
            &VotingStats {
                rejected_frames: rejected(&[
                    (FrameCause::TooShort, 2),
                    (FrameCause::LengthOutOfRange, 2),
                    (FrameCause::LengthMismatch, 1),
                    (FrameCause::InvalidChecksumLength, 1),
                    (FrameCause::ChecksumMismatch, 1),
                    (FrameCause::UnsupportedVersion, 1),
                    (FrameCause::WrongDestination, 1),
                    (FrameCause::UnknownSource, 1),
                ]),
                ..VotingStats::default()
            }
        );
        assert_eq!(v.stats().rejected_frames.total(), 10);
        // A rejected frame does not occupy its key: the sound copy still goes through.
        assert_eq!(
            step(&mut v, Instant::from_millis(2), &[(Link::Lte, &good)]),
            [(Link::Lte, good)]
        );
    }

    #[test]
    fn counters_list_every_counter_under_its_summary_name() {
        let mut v = fcc();
        let good = uplink(100);
        step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Direct, &good), (Link::Lte, &good), (Link::Lte, &[])],
        );
        let counters: std::vec::Vec<_> = v.stats().counters().collect();
        assert_eq!(
            counters,
            [
                ("forwarded_direct", 1),
                ("forwarded_lte", 0),
                ("duplicates", 1),
                ("stale", 0),
                ("rejected_frames", 1),
                ("too_short", 1),
                ("length_out_of_range", 0),
                ("length_mismatch", 0),
                ("invalid_checksum_length", 0),
                ("checksum_mismatch", 0),
                ("unsupported_version", 0),
                ("wrong_destination", 0),
                ("unknown_source", 0),
                ("rejected_signatures", 0),
                ("signature_no_trailer", 0),
                ("signature_unknown_key", 0),
                ("signature_bad", 0),
                ("signature_replay", 0),
                ("before_start", 0),
                ("unreadable_messages", 0),
                ("overflow", 0),
            ]
        );
    }

    #[test]
    fn broadcast_destination_is_accepted() {
        let mut v = fcc();
        let a = encode(Envelope::new(GCS_ID, BROADCAST_ID), waypoint(100, 1));
        assert_eq!(
            step(&mut v, Instant::from_millis(1), &[(Link::Direct, &a)]),
            [(Link::Direct, a)]
        );
    }

    #[test]
    fn voter_on_the_gcs_accepts_the_fcc_only() {
        let mut v = Voter::new(GCS_ID, FCC_ID, WINDOW);
        let down = encode(Envelope::new(FCC_ID, GCS_ID), waypoint(100, 1));
        let up = uplink(100);
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Direct, &down), (Link::Direct, &up)],
        );
        assert_eq!(out, [(Link::Direct, down)]);
        assert_eq!(
            v.stats().rejected_frames.get(FrameCause::WrongDestination),
            1
        );
    }

    #[test]
    fn message_with_a_bad_field_is_forwarded_with_its_time_stamp() {
        let mut v = fcc();
        // Waypoint number 0 breaks ICD §4 (1..=65534): mission data handling must reject it.
        let bad = encode(Envelope::new(GCS_ID, FCC_ID), waypoint(100, 0));
        let err = Frame::new_checked(&bad).unwrap().message().unwrap_err();
        assert_eq!(err.time_stamp, Some(ts(100)));
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Direct, &bad), (Link::Lte, &bad)],
        );
        assert_eq!(out, [(Link::Direct, bad)]);
        assert_eq!(
            v.stats(),
            &VotingStats {
                duplicates: 1,
                ..stats([1, 0])
            }
        );
    }

    #[test]
    fn message_without_readable_time_stamp_is_dropped() {
        let mut v = fcc();
        // #17000 with an empty presence vector: no time stamp.
        let no_stamp = raw(GCS_ID, FCC_ID, 17000, &[0x00]);
        // A type the ICD does not define: nothing can be read.
        let unknown_type = raw(GCS_ID, FCC_ID, 9999, &[0x01, 0, 0, 0, 0, 100]);
        // A sound header with a rewritten type: the time stamp bytes are there, but unknown.
        let mut retyped = uplink(100);
        retyped[12..14].copy_from_slice(&13003u16.to_be_bytes());
        fix_checksum(&mut retyped);
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[
                (Link::Direct, &no_stamp),
                (Link::Lte, &unknown_type),
                (Link::Direct, &retyped),
            ],
        );
        assert!(out.is_empty());
        assert_eq!(
            v.stats(),
            &VotingStats {
                unreadable_messages: 3,
                ..VotingStats::default()
            }
        );
    }

    #[test]
    fn every_message_of_a_datagram_is_considered() {
        let mut v = fcc();
        let (a, b) = (uplink(100), ack(101));
        let datagram = [a.as_slice(), b.as_slice()].concat();
        let out = step(&mut v, Instant::from_millis(1), &[(Link::Lte, &datagram)]);
        assert_eq!(out, [(Link::Lte, a.clone()), (Link::Lte, b.clone())]);
        // The direct copies of the same pair are duplicates.
        let out = step(
            &mut v,
            Instant::from_millis(2),
            &[(Link::Direct, &a), (Link::Direct, &b)],
        );
        assert!(out.is_empty());
        assert_eq!(v.stats().duplicates, 2);
    }

    #[test]
    fn broken_tail_of_a_datagram_is_counted_the_messages_before_it_pass() {
        let mut v = fcc();
        let a = uplink(100);
        let datagram = [a.as_slice(), &[0xff, 0xff, 0x00]].concat();
        let out = step(
            &mut v,
            Instant::from_millis(1),
            &[(Link::Direct, &datagram)],
        );
        assert_eq!(out, [(Link::Direct, a)]);
        assert_eq!(v.stats().rejected_frames.get(FrameCause::TooShort), 1);
        assert_eq!(v.stats().rejected_frames.total(), 1);
    }

    #[test]
    fn a_step_considers_at_most_its_capacity() {
        let mut v = fcc();
        let extra = 6;
        let frames: std::vec::Vec<_> = (0..(VOTING_STEP_MESSAGES + extra) as u64)
            .map(|i| uplink(100 + i))
            .collect();
        let arrivals: std::vec::Vec<_> = frames
            .iter()
            .map(|f| (Link::Direct, f.as_slice()))
            .collect();
        let out = step(&mut v, Instant::from_millis(1), &arrivals);
        assert_eq!(out.len(), VOTING_STEP_MESSAGES);
        // The first messages of the step are the ones considered.
        assert_eq!(out.last().unwrap().1, frames[VOTING_STEP_MESSAGES - 1]);
        assert_eq!(
            v.stats(),
            &VotingStats {
                overflow: extra as u64,
                ..stats([VOTING_STEP_MESSAGES as u64, 0])
            }
        );
        // Rejected frames count towards the limit too: every message costs a check.
        let mut v = fcc();
        let junk = [0u8; 4];
        let mut arrivals: std::vec::Vec<(Link, &[u8])> =
            vec![(Link::Lte, &junk[..]); VOTING_STEP_MESSAGES];
        arrivals.push((Link::Direct, &frames[0]));
        assert!(step(&mut v, Instant::from_millis(1), &arrivals).is_empty());
        assert_eq!(
            v.stats().rejected_frames.get(FrameCause::TooShort),
            VOTING_STEP_MESSAGES as u64
        );
        assert_eq!(v.stats().overflow, 1);
        // The next step starts empty.
        assert_eq!(
            step(
                &mut v,
                Instant::from_millis(2),
                &[(Link::Direct, &frames[0])]
            )
            .len(),
            1
        );
    }
}
