//! Target `fuzz_datagram`: the datagram walker and the message decoders (ICD §1 to §4).
//!
//! The input is one datagram as it comes off a socket. Checked:
//! - the walker ([`wire::frames`]) yields the frames back to back from the first byte (each
//!   with its signature trailer right after it), stops at the first broken frame, and when no
//!   frame is broken it has used every byte;
//! - every message that decodes encodes again in the same envelope, decodes to the same message,
//!   and encodes then to the same bytes (so an FCC can always send back what it accepted: ICD
//!   §5.2 download);
//! - the same for [`wire::decode`] of the whole datagram as one frame, and for the decoders
//!   alone ([`Message::decode`]) with the first two bytes as the Message Type;
//! - `Display` of messages and errors never fails.

use core::fmt::Write;

use missionlink_interfaces::wire::{self, Envelope, Frame, MAX_FRAME_LEN, Message};

/// The entry point: panics only when an invariant above is broken.
pub fn datagram(input: &[u8]) {
    walk(input);
    match wire::decode(input) {
        Ok((envelope, message)) => round_trip(&envelope, &message),
        Err(error) => shown(&error),
    }
    if let [hi, lo, data @ ..] = input {
        match Message::decode(u16::from_be_bytes([*hi, *lo]), data) {
            Ok(message) => round_trip(&Envelope::new(1, 2), &message),
            Err(error) => shown(&error),
        }
    }
}

fn walk(input: &[u8]) {
    let start = input.as_ptr() as usize;
    let offset = |bytes: &[u8]| bytes.as_ptr() as usize - start;
    let mut next = 0usize;
    let mut broken = false;
    for item in wire::frames(input) {
        assert!(!broken, "the walker went on after a broken frame");
        match item {
            Ok(frame) => {
                let bytes = frame.as_bytes();
                assert_eq!(offset(bytes), next, "frames are not back to back");
                next += bytes.len();
                if let Some(trailer) = frame.trailer() {
                    assert!(
                        frame.properties().signed(),
                        "a trailer on an unsigned frame"
                    );
                    let at = trailer as *const wire::SignatureTrailer as usize - start;
                    assert_eq!(at, next, "the trailer does not follow its frame");
                    next += wire::TRAILER_LEN;
                }
                assert!(next <= input.len(), "a frame beyond the datagram");
                frame_checked(&frame);
            }
            Err(error) => {
                shown(&error);
                broken = true;
            }
        }
    }
    if !broken {
        assert_eq!(next, input.len(), "bytes left over without a broken frame");
    }
}

fn frame_checked(frame: &Frame<'_>) {
    let header_len = usize::from(frame.header().message_length.get());
    assert_eq!(
        frame.data().len(),
        header_len,
        "data length is not the header's"
    );
    match frame.message() {
        Ok(message) => round_trip(&frame.envelope(), &message),
        Err(error) => shown(&error),
    }
}

/// Encode, decode, encode: the message survives and the bytes settle after one round.
fn round_trip(envelope: &Envelope, message: &Message) {
    let mut first = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(envelope, message, &mut first)
        .unwrap_or_else(|e| panic!("a decoded message does not encode: {e} ({message:?})"));
    let first = first.get(..len).unwrap_or_default();
    let (envelope_again, again) = wire::decode(first)
        .unwrap_or_else(|e| panic!("an encoded message does not decode: {e} ({message:?})"));
    assert_eq!(
        &envelope_again, envelope,
        "the envelope changed in a round trip"
    );
    assert_eq!(&again, message, "the message changed in a round trip");
    let mut second = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(envelope, &again, &mut second).unwrap_or(0);
    assert_eq!(
        second.get(..len).unwrap_or_default(),
        first,
        "the bytes changed in a second round"
    );
    shown(message);
}

/// `Display` writes something and never fails.
fn shown(value: &dyn core::fmt::Display) {
    let mut text = String::new();
    assert!(write!(text, "{value}").is_ok(), "Display failed");
    assert!(!text.is_empty(), "Display wrote nothing");
}
