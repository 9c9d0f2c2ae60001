//! Target `fuzz_voting`: voting and monitoring of the direct and the LTE link (paper §2.4), on
//! the FCC's side, with each signing policy of ICD §9.
//!
//! The first byte of the input picks the policy (modulo 3: off, accept, require); the rest is a
//! sequence of [records](crate::input) that build the datagrams of a step and vote it. The tag
//! modulo 4 says what a record does; bit 3 of the tag puts the datagram on the LTE link instead
//! of the direct one:
//!
//! | tag | body | step |
//! |---|---|---|
//! | 0 raw | any bytes | a datagram as it is |
//! | 1 frame | `[stamp offset (2)]` then a [`MessageBody`] | a GCS frame of that data, see below |
//! | 2 copy | nothing | the step's last datagram again (the other link's copy, a repeat) |
//! | 3 vote | ms (2 bytes) | the voter votes the step; then the clock moves on |
//!
//! A frame record encodes the message the data decodes to with its time stamp set to the UTC
//! clock plus the offset (a signed number of 10 ms), or, when the data does not decode, wraps
//! the data as it is ([`wrap`]). Tag bit 4 signs it (the trailer names the tag's link, or with
//! bit 5 the other link; bit 6 signs with a key the FCC does not hold); bit 7 appends it to the
//! step's last datagram instead of making a new one (several messages per datagram, ICD §1).
//!
//! Checked after every vote:
//! - every message of every datagram is accounted for exactly once in the voter's counters
//!   (forwarded, duplicate, stale, rejected frame, rejected signature, unreadable, overflow);
//! - every forwarded message is one whole frame of an input datagram that passes the wrapper and
//!   addressing rules of ICD §2 and has a readable time stamp, and under `require` it is signed;
//! - no message identity (source, type, time stamp; ICD §3) is forwarded twice within the
//!   sampling window (paper §3.1.1).

use core::time::Duration;
use std::collections::HashMap;

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID, TRANSFER_TIMEOUT};
use missionlink_interfaces::wire::{
    self, Envelope, Frame, MAX_FRAME_LEN, MAX_SIGNED_FRAME_LEN, Message, Timestamp,
};
use missionlink_protocol::link::signing::{Keyring, LinkKey, Policy, SignatureCheck, Signer};
use missionlink_protocol::link::time::{Instant, UtcClock};
use missionlink_protocol::testkit;
use missionlink_protocol::voting::{Voter, VotingStats};

use crate::input::{MessageBody, records, u16_at, wrap};

/// Record tags of this target (the tag byte modulo [`TAGS`]).
pub mod tag {
    /// A datagram as it is.
    pub const RAW: u8 = 0;
    /// A GCS frame of message data.
    pub const FRAME: u8 = 1;
    /// The step's last datagram again.
    pub const COPY: u8 = 2;
    /// Vote the step.
    pub const VOTE: u8 = 3;
    /// Tag bit: the datagram arrives on the LTE link.
    pub const LTE: u8 = 1 << 3;
    /// Tag bit: sign the frame.
    pub const SIGN: u8 = 1 << 4;
    /// Tag bit: the trailer names the other link.
    pub const OTHER_LINK: u8 = 1 << 5;
    /// Tag bit: sign with a key the receiver does not hold.
    pub const UNKNOWN_KEY: u8 = 1 << 6;
    /// Tag bit: append to the step's last datagram.
    pub const APPEND: u8 = 1 << 7;
}

/// Kinds of records.
pub const TAGS: u8 = 4;

/// The key both sides hold (Key ID 1), and one only a stranger holds (Key ID 2).
pub fn keys() -> (LinkKey, LinkKey) {
    (LinkKey::new(1, &[0x5a; 32]), LinkKey::new(2, &[0xa5; 32]))
}

/// The signing policy the first byte of an input picks.
pub fn policy(byte: u8) -> Policy {
    match byte % 3 {
        0 => Policy::Off,
        1 => Policy::Accept,
        _ => Policy::Require,
    }
}

/// A signature check with `policy` holding Key ID 1 of [`keys`], on the testkit's clock,
/// started at instant zero.
pub fn check(policy: Policy) -> SignatureCheck {
    let mut ring = Keyring::new();
    // One key never fills a keyring.
    let _ = ring.insert(keys().0);
    SignatureCheck::new(policy, ring, testkit::utc_at_zero(), Instant::ZERO)
}

/// A frame record's message, stamped at the UTC time of `now` plus `offset` (10 ms each),
/// encoded in a GCS frame; `None` when the stamp or the message does not encode.
pub fn stamped_frame(body: &MessageBody<'_>, offset: i16, now: Instant) -> Option<Vec<u8>> {
    let mut message: Message = body.message()?;
    let utc = UtcClock::new(testkit::utc_at_zero()).utc(now).millis();
    let stamp = utc.checked_add_signed(i64::from(offset) * 10)?;
    message.set_time_stamp(Timestamp::from_millis(stamp)?);
    let envelope = Envelope::new(GCS_ID, FCC_ID).with_ack(body.ack_requested());
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, &message, &mut buf).ok()?;
    Some(buf.get(..len)?.to_vec())
}

/// `frame` signed for `link` with `key`.
pub fn signed(key: &LinkKey, link: Link, frame: &[u8]) -> Option<Vec<u8>> {
    let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
    let len = Signer::new(key.clone()).sign(link, frame, &mut out).ok()?;
    Some(out.get(..len)?.to_vec())
}

/// The entry point: panics only when an invariant of the module documentation is broken.
pub fn voting(input: &[u8]) {
    let Some((&first, rest)) = input.split_first() else {
        return;
    };
    let policy = policy(first);
    let mut voter = Voter::new(FCC_ID, GCS_ID, TRANSFER_TIMEOUT).with_signatures(check(policy));
    let mut now = Instant::from_millis(1);
    let mut step: Vec<(Link, Vec<u8>)> = Vec::new();
    let mut forwarded: HashMap<(u32, u16, Timestamp), Instant> = HashMap::new();
    for (tag, body) in records(rest) {
        let link = if tag & tag::LTE != 0 {
            Link::Lte
        } else {
            Link::Direct
        };
        match tag % TAGS {
            tag::RAW => step.push((link, body.to_vec())),
            tag::FRAME => {
                let Some(message) = MessageBody::parse(body.get(2..).unwrap_or_default()) else {
                    continue;
                };
                let offset = u16_at(body, 0) as i16;
                let Some(mut frame) =
                    stamped_frame(&message, offset, now).or_else(|| wrap(&message, GCS_ID, FCC_ID))
                else {
                    continue;
                };
                if tag & tag::SIGN != 0 {
                    let (known, stranger) = keys();
                    let key = if tag & tag::UNKNOWN_KEY != 0 {
                        stranger
                    } else {
                        known
                    };
                    let named = match (link, tag & tag::OTHER_LINK != 0) {
                        (Link::Direct, true) => Link::Lte,
                        (_, true) => Link::Direct,
                        (l, false) => l,
                    };
                    match signed(&key, named, &frame) {
                        Some(s) => frame = s,
                        None => continue,
                    }
                }
                match step.last_mut() {
                    Some((_, last)) if tag & tag::APPEND != 0 => last.extend_from_slice(&frame),
                    _ => step.push((link, frame)),
                }
            }
            tag::COPY => {
                if let Some((_, last)) = step.last() {
                    let copy = last.clone();
                    step.push((link, copy));
                }
            }
            _ => {
                vote(&mut voter, now, &step, policy, &mut forwarded);
                step.clear();
                now = now + Duration::from_millis(u64::from(u16_at(body, 0)));
            }
        }
    }
    vote(&mut voter, now, &step, policy, &mut forwarded);
}

/// Every counter a message can land in, summed.
fn accounted(stats: &VotingStats) -> u64 {
    let [direct, lte] = stats.forwarded;
    direct
        + lte
        + stats.duplicates
        + stats.stale
        + stats.rejected_frames.total()
        + stats.rejected_signatures.total()
        + stats.before_start
        + stats.unreadable_messages
        + stats.overflow
}

fn vote(
    voter: &mut Voter,
    now: Instant,
    step: &[(Link, Vec<u8>)],
    policy: Policy,
    forwarded: &mut HashMap<(u32, u16, Timestamp), Instant>,
) {
    let messages: u64 = step
        .iter()
        .map(|(_, d)| match d.len() {
            0 => 1,
            _ => wire::frames(d).count() as u64,
        })
        .sum();
    let before = accounted(voter.stats());
    let arrivals: Vec<(Link, &[u8])> = step.iter().map(|(l, d)| (*l, d.as_slice())).collect();
    let mut out: Vec<(Link, &[u8])> = Vec::new();
    voter.vote_step(now, &arrivals, |link, _, frame| out.push((link, frame)));
    assert_eq!(
        accounted(voter.stats()) - before,
        messages,
        "messages not accounted for exactly once: {:?}",
        voter.stats()
    );
    for (link, bytes) in out {
        let within = arrivals.iter().any(|(l, d)| {
            let (start, end) = (d.as_ptr() as usize, d.as_ptr() as usize + d.len());
            let at = bytes.as_ptr() as usize;
            *l == link && at >= start && at + bytes.len() <= end
        });
        assert!(
            within,
            "a forwarded message is not part of a datagram of its link"
        );
        let frame = Frame::new_checked(bytes)
            .unwrap_or_else(|e| panic!("a forwarded message breaks the wrapper rules: {e}"));
        assert!(
            frame.check_addressing(FCC_ID, GCS_ID).is_ok(),
            "a forwarded message is not from the GCS to the FCC"
        );
        let stamp = match frame.message() {
            Ok(m) => m.time_stamp(),
            Err(e) => e
                .time_stamp
                .unwrap_or_else(|| panic!("a forwarded message has no readable time stamp: {e}")),
        };
        if policy == Policy::Require {
            assert!(
                frame.properties().signed(),
                "an unsigned message forwarded under require"
            );
        }
        let identity = (frame.source_id(), frame.message_type(), stamp);
        if let Some(first) = forwarded.get(&identity) {
            assert!(
                now.saturating_since(*first) >= TRANSFER_TIMEOUT,
                "{identity:?} forwarded twice within the sampling window"
            );
        }
        forwarded.insert(identity, now);
    }
}
