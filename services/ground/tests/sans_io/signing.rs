//! Link signing (ICD §9) between the GCS and the FCC stepped through simulated time: what an
//! attacker on the link can no longer do, and what a signed link still does as before.
//!
//! | rule (ICD §9) | tests |
//! |---|---|
//! | forged frames change nothing under `require` | `a_forged_clear_and_transmit_change_nothing_under_require` |
//! | replay | `a_captured_upload_replayed_later_is_refused` |
//! | out of order is not a replay | `a_signed_upload_completes_through_reordering_and_duplication` |
//! | both links, processed once | `both_links_carry_each_signed_message_and_it_is_processed_once` |
//! | `off` is edition 1, byte for byte | `with_signing_off_the_bytes_on_the_wire_are_edition_1` |
//! | `accept` | `accept_takes_unsigned_frames_and_refuses_bad_signatures` |

use std::time::Duration;

use crate::support::*;
use missionlink_ground::ground_station::GcsEvent;
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
use missionlink_interfaces::wire::{
    Envelope, Frame, MAX_SIGNED_FRAME_LEN, Message, MissionPlanMode, Timestamp,
};
use missionlink_protocol::link::signing::{LinkKey, Policy, SignatureCause, Signer};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::sender::transfer_command;

fn upload(pair: &mut Pair, plan: &missionlink_ground::ground_station::MissionPlan) {
    let now = pair.now;
    pair.gcs.upload(now, plan, true).unwrap();
    pair.run_until_standby(Duration::from_secs(60));
    let events = pair.take_gcs_events();
    assert!(
        events.iter().any(|e| matches!(e, GcsEvent::Uploaded(_))),
        "upload did not complete: {events:?}"
    );
}

/// The attack that link signing (ICD §9) stops: a well-formed #13000 clear, then a #13000 transmit
/// with Waypoint Number 0, with the GCS's ID, stamped now, right checksum; from a foreign sender.
fn attack(pair: &Pair) -> Vec<Vec<u8>> {
    let utc = pair.now.micros() / 1000 + UTC_AT_ZERO_MS;
    [
        (MissionPlanMode::ClearMission, None, 1),
        (MissionPlanMode::TransmitMission, Some(0), 2),
    ]
    .into_iter()
    .map(|(mode, waypoint_number, after)| {
        let command = missionlink_interfaces::wire::MissionTransferCommand {
            time_stamp: Timestamp::from_millis(utc + after).unwrap(),
            ..transfer_command(mode, waypoint_number, None)
        };
        frame(
            &Envelope::new(GCS_ID, FCC_ID).with_ack(true),
            &Message::from(command),
        )
    })
    .collect()
}

fn signed_with(key: &LinkKey, link: Link, frame: &[u8]) -> Vec<u8> {
    let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
    let len = Signer::new(key.clone())
        .sign(link, frame, &mut out)
        .unwrap();
    out[..len].to_vec()
}

/// Sends the attack's frames on both links, as `disguise` makes them, and lets them arrive.
fn send_attack(pair: &mut Pair, disguise: impl Fn(Link, &[u8]) -> Vec<u8>) {
    for frame in attack(pair) {
        for link in [Link::Direct, Link::Lte] {
            pair.inject_uplink(link, &disguise(link, &frame), Duration::from_millis(1));
        }
        pair.run_until(pair.now + Duration::from_millis(20));
    }
}

#[test]
fn a_forged_clear_and_transmit_change_nothing_under_require() {
    let mut pair = Pair::signed(14, Policy::Require, Policy::Require);
    let plan = mission_1();
    upload(&mut pair, &plan);
    let mission = pair.fcc.active_mission().cloned();
    let areas = pair.fcc.active_areas().cloned();
    assert!(mission.is_some() && areas.is_some());
    let wrong_key = LinkKey::new(1, &[0xa5; 32]);
    let unknown_key = LinkKey::new(2, &[0x5a; 32]);
    let sent_before = pair.sent.len();

    // Unsigned; signed with the right Key ID and a wrong key; with a key the FCC does not hold;
    // with the right key but the trailer for the other link.
    send_attack(&mut pair, |_, f| f.to_vec());
    send_attack(&mut pair, |link, f| signed_with(&wrong_key, link, f));
    send_attack(&mut pair, |link, f| signed_with(&unknown_key, link, f));
    send_attack(&mut pair, |link, f| {
        let other = match link {
            Link::Direct => Link::Lte,
            _ => Link::Direct,
        };
        signed_with(&link_key(), other, f)
    });

    assert_eq!(pair.fcc.active_mission().cloned(), mission);
    assert_eq!(pair.fcc.active_areas().cloned(), areas);
    assert!(
        pair.sent[sent_before..].is_empty(),
        "the FCC answered a forged frame: {:?}",
        &pair.sent[sent_before..]
    );
    let rejected = pair.fcc_voter().stats().rejected_signatures;
    // Two frames per attack, each on both links.
    assert_eq!(rejected.get(SignatureCause::NoTrailer), 4);
    assert_eq!(rejected.get(SignatureCause::BadSignature), 8);
    assert_eq!(rejected.get(SignatureCause::UnknownKey), 4);
    assert_eq!(rejected.get(SignatureCause::Replay), 0);
    // Counted, not logged per frame: one line per cause at most in this second.
    assert!(pair.fcc_voter().reject_log_lines() <= 3);
}

#[test]
fn a_captured_upload_replayed_later_is_refused() {
    let mut pair = Pair::signed(15, Policy::Require, Policy::Require);
    upload(&mut pair, &mission_1());
    // What an attacker captured on both links: every signed uplink datagram of mission 1.
    let captured: Vec<(Link, Vec<u8>)> = pair
        .wire
        .iter()
        .filter(|(d, _, _)| *d == Direction::Up)
        .map(|(_, link, bytes)| (*link, bytes.clone()))
        .collect();
    assert!(captured.len() >= 10, "{} datagrams", captured.len());
    upload(&mut pair, &mission_2());
    let mission_2_active = pair.fcc.active_mission().cloned();
    let areas_2_active = pair.fcc.active_areas().cloned();

    // Within the 60 s window (the identities are remembered), then 73 s later (the stamps are
    // out of the window), as an attacker replaying a capture would.
    for delay in [Duration::from_secs(5), Duration::from_secs(73)] {
        pair.run_until(pair.now + delay);
        let before = pair
            .fcc_voter()
            .stats()
            .rejected_signatures
            .get(SignatureCause::Replay);
        let sent_before = pair.sent.len();
        for (link, bytes) in &captured {
            pair.inject_uplink(*link, bytes, Duration::from_millis(1));
            pair.run_until(pair.now + Duration::from_millis(2));
        }
        pair.run_until(pair.now + Duration::from_secs(1));
        let replays = pair
            .fcc_voter()
            .stats()
            .rejected_signatures
            .get(SignatureCause::Replay);
        assert_eq!(replays - before, captured.len() as u64, "after {delay:?}");
        assert_eq!(pair.fcc.active_mission().cloned(), mission_2_active);
        assert_eq!(pair.fcc.active_areas().cloned(), areas_2_active);
        assert_eq!(pair.sent.len(), sent_before, "a replay was answered");
    }
}

#[test]
fn a_signed_upload_completes_through_reordering_and_duplication() {
    for seed in 0..8 {
        let mut pair = Pair::signed(seed, Policy::Require, Policy::Require);
        for faults in pair.uplink.iter_mut().chain(pair.downlink.iter_mut()) {
            *faults = faulty(0.0, 0.3, (1, 60));
        }
        let plan = mission_2();
        upload(&mut pair, &plan);
        assert_eq!(
            pair.fcc.active_mission(),
            Some(&pair.gcs.validate(&plan).unwrap().mission),
            "seed {seed}"
        );
        let stats = pair.fcc_voter().stats();
        // Duplicates on one link are replays by ICD §9 (and dropped either way); nothing else
        // fails the check, reordered frames included.
        let rejected = stats.rejected_signatures;
        assert_eq!(
            rejected.total(),
            rejected.get(SignatureCause::Replay),
            "seed {seed}"
        );
        assert!(
            rejected.get(SignatureCause::Replay) > 0,
            "seed {seed}: no duplicate drawn"
        );
    }
}

#[test]
fn both_links_carry_each_signed_message_and_it_is_processed_once() {
    let mut pair = Pair::signed(16, Policy::Require, Policy::Require);
    upload(&mut pair, &mission_2());
    let uplink: Vec<_> = pair
        .wire
        .iter()
        .filter(|(d, _, _)| *d == Direction::Up)
        .collect();
    let messages = uplink.len() / 2;
    // Each message went once on each link, signed for that link.
    for (link, id) in [(Link::Direct, 0u8), (Link::Lte, 1)] {
        let on_link: Vec<_> = uplink.iter().filter(|(_, l, _)| *l == link).collect();
        assert_eq!(on_link.len(), messages);
        for (_, _, bytes) in on_link {
            let frame = Frame::new_checked(bytes).unwrap();
            assert!(frame.properties().signed());
            assert_eq!(frame.trailer().unwrap().link_id, id);
        }
    }
    let stats = pair.fcc_voter().stats();
    assert_eq!(stats.forwarded.iter().sum::<u64>(), messages as u64);
    assert_eq!(
        stats.duplicates, messages as u64,
        "the second copy of each is dropped"
    );
    assert_eq!(stats.rejected_signatures.total(), 0);
    assert_eq!(
        pair.fcc_voter().signatures().stats().verified,
        2 * messages as u64
    );
}

#[test]
fn with_signing_off_the_bytes_on_the_wire_are_edition_1() {
    let run = |pair: &mut Pair| {
        upload(pair, &mission_2());
        pair.wire.clone()
    };
    let mut plain = Pair::new(17);
    let mut off = Pair::new(17);
    off = {
        // Both receivers set to `off` explicitly, no sending key.
        let mut p = off;
        p.set_signature_checks(signature_check(Policy::Off), signature_check(Policy::Off));
        p
    };
    let plain_wire = run(&mut plain);
    assert_eq!(run(&mut off), plain_wire);
    for (_, _, bytes) in &plain_wire {
        let frame = Frame::new_checked(bytes).unwrap();
        assert!(!frame.properties().signed());
        assert_eq!(frame.as_bytes().len(), bytes.len(), "no trailer");
        assert_eq!(bytes[15] & 0x3f, 0, "bits 5..0 of Message Properties are 0");
    }
}

#[test]
fn accept_takes_unsigned_frames_and_refuses_bad_signatures() {
    // The FCC accepts; the GCS does not sign (a rollout: the ground not yet keyed).
    let mut pair = Pair::new(18);
    pair.set_signature_checks(
        signature_check(Policy::Off),
        signature_check(Policy::Accept),
    );
    upload(&mut pair, &mission_1());
    let mission = pair.fcc.active_mission().cloned();
    assert!(mission.is_some());
    let wrong_key = LinkKey::new(1, &[0xa5; 32]);
    send_attack(&mut pair, |link, f| signed_with(&wrong_key, link, f));
    assert_eq!(pair.fcc.active_mission().cloned(), mission);
    let stats = pair.fcc_voter().stats();
    assert_eq!(
        stats.rejected_signatures.get(SignatureCause::BadSignature),
        4
    );
    assert!(pair.fcc_voter().signatures().stats().unsigned_accepted > 0);
}

#[test]
fn a_receiver_refuses_stamps_from_before_it_started() {
    // The FCC's voter restarted (its replay memory lost) at 10 s: a frame captured at 5 s and
    // replayed is refused, though 5 s is inside the window. It cannot be told from a frame the
    // GCS sent while the FCC was down, so it is counted as sent before the start, not as a
    // rejection (ICD §9 "Replay").
    let mut pair = Pair::signed(19, Policy::Require, Policy::Require);
    pair.set_signature_checks(
        signature_check(Policy::Require),
        missionlink_protocol::link::signing::SignatureCheck::new(
            Policy::Require,
            {
                let mut k = missionlink_protocol::link::signing::Keyring::new();
                k.insert(link_key()).unwrap();
                k
            },
            utc_at_zero(),
            Instant::from_millis(10_000),
        ),
    );
    let captured = signed_with(&link_key(), Link::Direct, &attack(&pair)[0]);
    pair.run_until(Instant::from_millis(10_000));
    pair.inject_uplink(Link::Direct, &captured, Duration::from_millis(1));
    pair.run_until(pair.now + Duration::from_millis(10));
    let stats = pair.fcc_voter().stats();
    assert_eq!(stats.before_start, 1);
    assert_eq!(stats.rejected_signatures.total(), 0);
    assert_eq!(stats.forwarded, [0, 0], "the frame was not processed");
}
