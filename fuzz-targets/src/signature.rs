//! Target `fuzz_signature`: the signature check of ICD §9 ([`check_signature`],
//! [`SignatureCheck::verify`] and [`SignatureCheck::admit`]) against a model of what it must
//! decide.
//!
//! The first byte of the input picks the policy (modulo 3: off, accept, require); the receiver
//! holds Key ID 1 and starts at instant zero. The rest is a sequence of [records](crate::input);
//! the tag modulo 6 says what a record does, bit 3 of the tag names the LTE link instead of the
//! direct one:
//!
//! | tag | body | step |
//! |---|---|---|
//! | 0 raw | any bytes | every frame of the datagram is checked on the tag's link (and a verified one for replay) |
//! | 1 sign | `[stamp offset (2)]` then a [`MessageBody`] | the message, stamped at the clock plus the offset (10 ms each), signed for the tag's link (bit 4: with a key the receiver does not hold), becomes the datagram at hand |
//! | 2 mutate | pairs `[position (2), xor]` | bytes of the datagram at hand change |
//! | 3 verify | nothing | the datagram at hand is checked on the tag's link |
//! | 4 admit | `[stamp offset (2), type (2)]` | a replay check of that identity on the tag's link, without a frame |
//! | 5 time | ms (2 bytes) | the clock moves on, by 10 ms per unit |
//!
//! Checked:
//! - a frame verifies only if it is, byte for byte with its trailer, what the key's holder
//!   makes of it when signing for the link the trailer names ([`Signer::sign`]): no trailer,
//!   key or link the signer would not write passes. A captured frame replayed does verify, and
//!   then the replay check must stop it; the fuzzer learns signed frames (libFuzzer takes the
//!   bytes the harness compares into its dictionary), so replays are fuzzed too;
//! - a signed datagram as signed verifies exactly when the policy checks signatures, the
//!   receiver holds the key and it arrived on the link its trailer names, and fails with the
//!   cause ICD §9 gives otherwise (unknown key, bad signature);
//! - a replay check passes exactly when the time stamp is within the replay window of the clock,
//!   not older than the receiver's start, and the identity was not admitted on that link before
//!   (as long as the replay memory is not full), and never passes for an identity admitted
//!   before.

use core::time::Duration;
use std::collections::HashSet;

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
use missionlink_interfaces::wire::{self, Timestamp};
use missionlink_protocol::link::signing::{
    Authenticity, Keyring, Policy, REPLAY_MEMORY, REPLAY_WINDOW, SignatureCause, SignatureCheck,
    check_signature,
};
use missionlink_protocol::link::time::{Instant, UtcClock};
use missionlink_protocol::testkit;

use crate::input::{MessageBody, records, u16_at};
use crate::voting::{check, keys, policy, signed, stamped_frame};

/// Record tags of this target (the tag byte modulo [`TAGS`]).
pub mod tag {
    /// Check raw bytes.
    pub const RAW: u8 = 0;
    /// Sign a message: the datagram at hand.
    pub const SIGN: u8 = 1;
    /// Change bytes of the datagram at hand.
    pub const MUTATE: u8 = 2;
    /// Check the datagram at hand.
    pub const VERIFY: u8 = 3;
    /// A replay check without a frame.
    pub const ADMIT: u8 = 4;
    /// The clock moves on.
    pub const TIME: u8 = 5;
    /// Tag bit: the LTE link.
    pub const LTE: u8 = 1 << 3;
    /// Tag bit: sign with a key the receiver does not hold.
    pub const UNKNOWN_KEY: u8 = 1 << 4;
}

/// Kinds of records.
pub const TAGS: u8 = 6;

/// A signed datagram and what it was when signed.
struct AtHand {
    bytes: Vec<u8>,
    pristine: Vec<u8>,
    link: Link,
    known_key: bool,
}

/// What the receiver admitted, per link: the model of its replay memory.
struct Model {
    policy: Policy,
    clock: UtcClock,
    start: Timestamp,
    admitted: [HashSet<(u32, u16, Timestamp)>; 2],
}

impl Model {
    /// Checks the replay decision `passed` on the identity against the model, and remembers it.
    fn admit(&mut self, now: Instant, link: Link, identity: (u32, u16, Timestamp), passed: bool) {
        let [direct, lte] = &mut self.admitted;
        let seen = if link == Link::Direct { direct } else { lte };
        let utc = self.clock.utc(now).millis();
        let window = REPLAY_WINDOW.as_millis() as u64;
        let fresh = identity.2.millis().abs_diff(utc) <= window
            && identity.2 >= self.start
            && !seen.contains(&identity);
        if passed {
            assert!(fresh, "a replay admitted: {identity:?} at {utc} ms");
            seen.insert(identity);
        } else if self.policy != Policy::Off && seen.len() < REPLAY_MEMORY {
            assert!(
                !fresh,
                "a fresh identity refused as a replay: {identity:?} at {utc} ms"
            );
        }
    }
}

/// The entry point: panics only when an invariant of the module documentation is broken.
pub fn signature(input: &[u8]) {
    let Some((&first, rest)) = input.split_first() else {
        return;
    };
    let policy = policy(first);
    let mut receiver = check(policy);
    let mut ring = Keyring::new();
    let _ = ring.insert(keys().0);
    let clock = UtcClock::new(testkit::utc_at_zero());
    let mut model = Model {
        policy,
        clock,
        start: clock.utc(Instant::ZERO),
        admitted: [HashSet::new(), HashSet::new()],
    };
    let mut now = Instant::from_millis(1);
    let mut at_hand: Option<AtHand> = None;
    for (tag, body) in records(rest) {
        let link = if tag & tag::LTE != 0 {
            Link::Lte
        } else {
            Link::Direct
        };
        match tag % TAGS {
            tag::RAW => {
                for frame in wire::frames(body).flatten() {
                    let authentic = check_signature(&ring, &frame).is_ok();
                    let verdict = receiver.verify(link, &frame);
                    if authentic || verdict == Ok(Authenticity::Verified) {
                        assert!(
                            genuine(&frame),
                            "a frame the key's holder did not sign verifies"
                        );
                    }
                    if verdict == Ok(Authenticity::Verified) {
                        replay_check(&mut receiver, &mut model, now, link, &frame);
                    }
                }
            }
            tag::SIGN => {
                let Some(message) = MessageBody::parse(body.get(2..).unwrap_or_default()) else {
                    continue;
                };
                let offset = u16_at(body, 0) as i16;
                let (known, stranger) = keys();
                let known_key = tag & tag::UNKNOWN_KEY == 0;
                let key = if known_key { known } else { stranger };
                at_hand = stamped_frame(&message, offset, now)
                    .and_then(|frame| signed(&key, link, &frame))
                    .map(|bytes| AtHand {
                        pristine: bytes.clone(),
                        bytes,
                        link,
                        known_key,
                    });
            }
            tag::MUTATE => {
                if let Some(hand) = at_hand.as_mut() {
                    for change in body.chunks_exact(3) {
                        let len = hand.bytes.len();
                        if let [hi, lo, xor] = change
                            && let Some(b) = hand
                                .bytes
                                .get_mut(usize::from(u16::from_be_bytes([*hi, *lo])) % len.max(1))
                        {
                            *b ^= xor;
                        }
                    }
                }
            }
            tag::VERIFY => {
                if let Some(hand) = &at_hand {
                    verify(&mut receiver, &mut model, now, link, hand);
                }
            }
            tag::ADMIT => {
                let utc = clock.utc(now).millis();
                let offset = i64::from(u16_at(body, 0) as i16) * 10;
                let Some(stamp) = utc
                    .checked_add_signed(offset)
                    .and_then(Timestamp::from_millis)
                else {
                    continue;
                };
                let identity = (GCS_ID, u16_at(body, 2), stamp);
                let passed = receiver
                    .admit(now, link, identity.0, identity.1, Some(identity.2))
                    .is_ok();
                model.admit(now, link, identity, passed);
            }
            _ => now = now + Duration::from_millis(u64::from(u16_at(body, 0)) * 10),
        }
    }
}

/// Whether `frame` with its trailer is what the signer with the receiver's key makes of it for
/// the link its trailer names.
fn genuine(frame: &wire::Frame<'_>) -> bool {
    let (known, _) = keys();
    let Some(trailer) = frame.trailer() else {
        return false;
    };
    let link = match trailer.link_id {
        0 => Link::Direct,
        1 => Link::Lte,
        _ => return false,
    };
    trailer.key_id == known.id()
        && signed(&known, link, frame.as_bytes()).as_deref() == Some(&with_trailer(frame)[..])
}

/// The bytes a signature covers and carries: the frame and its trailer.
fn with_trailer(frame: &wire::Frame<'_>) -> Vec<u8> {
    let mut bytes = frame.as_bytes().to_vec();
    if let Some(trailer) = frame.trailer() {
        bytes.extend_from_slice(zerocopy::IntoBytes::as_bytes(trailer));
    }
    bytes
}

/// Checks the datagram at hand on `link` against what the model says.
fn verify(
    receiver: &mut SignatureCheck,
    model: &mut Model,
    now: Instant,
    link: Link,
    hand: &AtHand,
) {
    let Some(Ok(frame)) = wire::frames(&hand.bytes).next() else {
        assert_ne!(
            hand.bytes, hand.pristine,
            "a signed frame the walker refuses"
        );
        return;
    };
    let verdict = receiver.verify(link, &frame);
    if hand.bytes != hand.pristine {
        if verdict == Ok(Authenticity::Verified) {
            assert!(
                genuine(&frame),
                "a signed frame verifies after its bytes changed into what the key's holder did not sign"
            );
            replay_check(receiver, model, now, link, &frame);
        }
        return;
    }
    let expected = match model.policy {
        Policy::Off => Ok(Authenticity::Unchecked),
        _ if !hand.known_key => Err(SignatureCause::UnknownKey),
        _ if link != hand.link => Err(SignatureCause::BadSignature),
        _ => Ok(Authenticity::Verified),
    };
    assert_eq!(verdict, expected, "the signature check of a signed frame");
    if verdict == Ok(Authenticity::Verified) {
        replay_check(receiver, model, now, link, &frame);
    }
}

/// The replay check of a verified frame, against the model.
fn replay_check(
    receiver: &mut SignatureCheck,
    model: &mut Model,
    now: Instant,
    link: Link,
    frame: &wire::Frame<'_>,
) {
    let stamp = frame
        .message()
        .map(|m| m.time_stamp())
        .unwrap_or_else(|e| panic!("a frame signed from a decoded message: {e}"));
    assert_eq!(frame.destination_id(), FCC_ID);
    let identity = (frame.source_id(), frame.message_type(), stamp);
    let passed = receiver
        .admit(now, link, identity.0, identity.1, Some(stamp))
        .is_ok();
    model.admit(now, link, identity, passed);
}
