//! What link signing (ICD §9) costs per frame: signing and verifying the largest frame (#2012
//! with 60 vertices, 548 bytes) and the most frequent one (#17000), and the voter's work per
//! frame with policy `require` beside `off` in the same run (the ratio is the price of signing
//! on the receive path: MAC, replay memory, the bigger datagram). Percentiles per call (p50,
//! p99, p99.9, max): each sample times a batch of `BATCH` calls and records the mean per call.
//! Run with `cargo bench --bench signing`.
// A benchmark stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::hint::black_box;
use std::time::{Duration, Instant as Clock};

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
use missionlink_interfaces::wire::{
    self, AckType, Envelope, Frame, MAX_FRAME_LEN, MAX_SIGNED_FRAME_LEN, Message,
    MessageAcknowledgement, Timestamp,
};
use missionlink_protocol::link::signing::{self, Keyring, LinkKey, Policy, SignatureCheck, Signer};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::testkit::{RawFrame, UTC_AT_ZERO_MS, full_polygon, utc_at_zero};
use missionlink_protocol::voting::Voter;

const BATCH: usize = 8;
const SAMPLES: usize = 20_000;

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i]
}

/// Percentiles of `f(i)` per call, `i` counting calls from 0; returns the median.
fn measure(name: &str, mut f: impl FnMut(usize)) -> f64 {
    for i in 0..1000 {
        f(i);
    }
    let mut ns = Vec::with_capacity(SAMPLES);
    let mut i = 1000;
    for _ in 0..SAMPLES {
        let start = Clock::now();
        for _ in 0..BATCH {
            f(i);
            i += 1;
        }
        ns.push(start.elapsed().as_nanos() as f64 / BATCH as f64);
    }
    ns.sort_by(f64::total_cmp);
    let p50 = percentile(&ns, 0.5);
    println!(
        "{name:<48} {p50:>9.1} {:>9.1} {:>9.1} {:>9.1}",
        percentile(&ns, 0.99),
        percentile(&ns, 0.999),
        ns[ns.len() - 1]
    );
    p50
}

fn encode(message: &Message) -> Vec<u8> {
    let envelope = Envelope::new(GCS_ID, FCC_ID).with_ack(true);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = wire::encode(&envelope, message, &mut buf).unwrap();
    buf[..len].to_vec()
}

fn key() -> LinkKey {
    LinkKey::new(1, &[0x5a; 32])
}

fn keyring() -> Keyring {
    let mut ring = Keyring::new();
    ring.insert(key()).unwrap();
    ring
}

/// The largest frame ICD §2 allows: 528 bytes of data (no message of the ICD fills them all;
/// signing looks at the bytes, not the message).
fn largest_frame() -> Vec<u8> {
    let data: Vec<u8> = (0..wire::MAX_DATA_LEN).map(|i| i as u8).collect();
    let f = RawFrame::uplink(2012).with_ack().build(&data);
    assert_eq!(f.len(), MAX_FRAME_LEN);
    f
}

fn sign_and_verify(name: &str, frame: &[u8]) {
    let frame = frame.to_vec();
    let signer = Signer::new(key());
    let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
    measure(&format!("sign {name} ({} B)", frame.len()), |_| {
        black_box(signer.sign(Link::Direct, black_box(&frame), &mut out)).ok();
    });
    let len = signer.sign(Link::Direct, &frame, &mut out).unwrap();
    let signed = out[..len].to_vec();
    let keys = keyring();
    measure(&format!("verify {name} ({} B)", frame.len()), |_| {
        let parsed = Frame::new_checked(black_box(&signed)).unwrap();
        black_box(signing::check_signature(&keys, &parsed)).ok();
    });
}

/// The voter per frame: a #2012 of 60 vertices stamped `i` ms after instant zero arrives at
/// `i` ms, so each is fresh (sampling) and inside the replay window (signing).
fn voter_per_frame(policy: Policy) -> f64 {
    let calls = 1000 + SAMPLES * BATCH;
    let signer = Signer::new(key());
    let frames: Vec<Vec<u8>> = (0..calls)
        .map(|i| {
            let mut message: Message = full_polygon().into();
            message.set_time_stamp(Timestamp::from_millis(UTC_AT_ZERO_MS + i as u64).unwrap());
            let frame = encode(&message);
            match policy {
                Policy::Off => frame,
                _ => {
                    let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
                    let len = signer.sign(Link::Direct, &frame, &mut out).unwrap();
                    out[..len].to_vec()
                }
            }
        })
        .collect();
    let mut voter = Voter::new(FCC_ID, GCS_ID, Duration::from_secs(3)).with_signatures(
        SignatureCheck::new(policy, keyring(), utc_at_zero(), Instant::ZERO),
    );
    let mut forwarded = 0u64;
    let name = format!("voter, #2012 60 vertices, policy {policy}");
    let p50 = measure(&name, |i| {
        let now = Instant::from_millis(i as u64);
        voter.vote(now, Link::Direct, &frames[i], |_, f| {
            forwarded += black_box(f.len()) as u64
        });
    });
    let stats = voter.stats();
    assert_eq!(
        stats.forwarded[0], calls as u64,
        "every frame forwarded: {stats:?}"
    );
    p50
}

fn main() {
    println!(
        "ns per call, {SAMPLES} samples of {BATCH} calls\n{:<48} {:>9} {:>9} {:>9} {:>9}",
        "", "p50", "p99", "p99.9", "max"
    );
    sign_and_verify("largest frame", &largest_frame());
    sign_and_verify("#2012 60 vertices", &encode(&full_polygon().into()));
    let ack = Message::from(MessageAcknowledgement {
        time_stamp: utc_at_zero(),
        original_time_stamp: utc_at_zero(),
        original_message_type: 13002,
        ack_type: AckType::Completed,
        reject_reason: None,
    });
    sign_and_verify("#17000", &encode(&ack));
    let mut check = SignatureCheck::new(Policy::Require, keyring(), utc_at_zero(), Instant::ZERO);
    measure("replay check alone", |i| {
        let now = Instant::from_millis(i as u64);
        let stamp = Timestamp::from_millis(UTC_AT_ZERO_MS + i as u64);
        black_box(check.admit(now, Link::Direct, GCS_ID, 2012, stamp)).ok();
    });
    let off = voter_per_frame(Policy::Off);
    let require = voter_per_frame(Policy::Require);
    println!(
        "voter require / off (medians): {:.2} ({:.0} ns more per frame)",
        require / off,
        require - off
    );
}
