//! What an edition-2 GCS sends without waiting for an answer (ICD §10.3), and the FCC that
//! accepts it: the report left out when the GCS holds a fresh one, the opener with the first
//! window, the area upload beside the mission data, the closer behind its data, the activation
//! behind the area closer.
//! Every case of loss ends as today: the exact lists, or for each list the one before, and the
//! GCS says which (ICD §11).
//!
//! | rule (ICD §10.3) | tests |
//! |---|---|
//! | what goes behind what; the report held | `the_atomic_upload_sends_each_step_behind_the_one_before`, `the_paper_sequence_sends_the_areas_beside_the_mission_data` |
//! | the opener lost, its answer lost, the first data lost, the area opener lost | `a_lost_opener_or_answer_sends_the_opener_alone_then_its_data_again`, `a_lost_data_message_is_retried_alone`, `area_data_refused_before_their_opener_go_again_after_it` |
//! | the closer's answer lost, once and twice | `a_lost_answer_to_the_closer_is_given_again_behind_the_area_opener`, `a_lost_answer_to_the_area_closer_is_given_again_after_the_activation_behind_it`, `a_closer_whose_answers_are_lost_is_confirmed_by_the_report`, `an_activation_sent_behind_a_closer_whose_answers_are_lost_is_not_sent_again` |
//! | a refused opener | `a_refused_opener_leaves_the_lists_and_the_data_sent_behind_it_are_dropped` |
//! | the FCC in stamp order | `the_fcc_keeps_the_data_that_overtook_their_opener`, `a_late_copy_of_an_opener_changes_nothing` |
//! | loss, duplication, reordering over many seeds | `pipelined_uploads_under_faults_end_with_the_exact_lists_or_the_previous_ones` |
//! | edition 1 | `an_edition_1_fcc_still_gets_the_papers_sequence_stop_and_wait` |
//! | the window sized to the link (ICD §10.4) | `with_the_rate_known_the_window_keeps_what_the_link_carries` |
//! | the area upload beside the mission data, one window for both | `the_area_upload_beside_the_mission_data_shares_the_window` |
//! | the closer behind its data, refused and sent again | `a_lost_data_message_is_retried_alone`; the FCC's side in `integrity.rs`, `a_closer_that_overtook_its_data_is_refused_and_closes_after_them` |

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::time::Duration;

use crate::support::*;
use missionlink_flight::mission_data_handling::{FccConfig, MissionDataHandling};
use missionlink_ground::ground_station::outcome::{UploadOutcome, UploadReport};
use missionlink_ground::ground_station::{
    GcsConfig, GcsError, GcsEvent, GroundStation, MissionPlan, Phase, Sequence, WithoutGateway,
};
use missionlink_interfaces::wire::{
    AckType, AreaTransferMode, Message, MissionPlanMode, Reason, Text, TransferWindow,
};
use missionlink_linksim::channel::Bandwidth;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::sender::mission_command;

type Event = GcsEvent<core::convert::Infallible>;

const LIMIT: Duration = Duration::from_secs(120);

/// The GCS configuration of ICD §1 with the shared contract's window of 32 (ICD §10.2; this
/// GCS's default is 128).
fn config() -> GcsConfig {
    GcsConfig {
        transfer_window: TransferWindow::MAX,
        ..gcs_config()
    }
}

/// The GCS logic with a window of 32 against `rig`'s FCC.
fn station(rig: FccRig) -> StationRig {
    let mut s = StationRig::new(rig);
    s.gcs = GroundStation::new(config(), WithoutGateway);
    s
}

/// Uploads `plan` by `sequence`; the report.
fn upload(s: &mut StationRig, plan: &MissionPlan, sequence: Sequence) -> UploadReport {
    let now = s.rig.now;
    s.gcs.upload_with(now, plan, sequence).unwrap();
    report(&s.run(LIMIT))
}

/// The upload's report, whether it completed or failed.
fn report(events: &[Event]) -> UploadReport {
    events
        .iter()
        .find_map(|e| match e {
            GcsEvent::Uploaded(r) => Some((**r).clone()),
            GcsEvent::Failed(GcsError::Upload(r)) => Some((**r).clone()),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no upload report: {events:?}"))
}

/// The FCC holds `plan`'s lists.
fn holds(s: &StationRig, plan: &MissionPlan) -> bool {
    let valid = validated(plan);
    s.rig.fcc.active_mission() == Some(&valid.mission)
        && s.rig.fcc.active_areas() == Some(&valid.areas)
}

/// Whether the message at `index` of the log went out before the answer to the one at
/// `before` came back: sent behind it, without waiting.
fn sent_behind(sent: &[Sent], before: usize, index: usize) -> bool {
    let b = &sent[before].message;
    let answered = sent.iter().position(|s| {
        s.direction == Direction::Down
            && match &s.message {
                Message::MessageAcknowledgement(a) => {
                    a.original_message_type == b.message_type() as u16
                        && a.original_time_stamp == b.time_stamp()
                }
                Message::AreaStatusAlert(_) => b.message_type() as u16 == 2011,
                _ => false,
            }
    });
    answered.is_none_or(|a| index < a)
}

/// The index in the log of the first request described as `what`, from `from`.
fn first(s: &StationRig, from: usize, what: &str) -> usize {
    s.sent
        .iter()
        .enumerate()
        .skip(from)
        .find(|(_, m)| m.direction == Direction::Up && describe(&m.message) == what)
        .map(|(i, _)| i)
        .unwrap_or_else(|| panic!("no {what}"))
}

/// Loses the `n`-th message (from 1) going `direction` that `which` picks.
fn lose_nth(direction: Direction, n: usize, which: impl Fn(&Message) -> bool + 'static) -> Loss {
    let mut seen = 0;
    Box::new(move |d, m| {
        if d == direction && which(m) {
            seen += 1;
            return seen == n;
        }
        false
    })
}

fn is(what: &'static str) -> impl Fn(&Message) -> bool {
    move |m| describe(m) == what
}

/// The #17000 answering a message described as `what`.
fn ack_of(type_: u16) -> impl Fn(&Message) -> bool {
    move |m| matches!(m, Message::MessageAcknowledgement(a) if a.original_message_type == type_)
}

#[test]
fn the_atomic_upload_sends_each_step_behind_the_one_before() {
    let mut s = station(FccRig::new().with_mission_2());
    let r = upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(holds(&s, &mission_1()));
    // The same messages as stop-and-wait sends, the first upload of a session with the report.
    assert_eq!(
        s.requests(0),
        [
            "13000 mode 7",
            "13000 mode 10",
            "13006 take-off",
            "13002 wp 1",
            "13001",
            "2011 mode 1",
            "2012 area 1",
            "13000 mode 8",
            "2011 mode 7",
            "50000",
            "13000 mode 6"
        ]
    );
    let at = |what| first(&s, 0, what);
    assert!(sent_behind(&s.sent, at("13000 mode 10"), at("13001")));
    // The area upload goes beside the mission data, once all of them were sent.
    assert!(sent_behind(&s.sent, at("13001"), at("2011 mode 1")));
    assert!(sent_behind(&s.sent, at("13001"), at("2012 area 1")));
    assert!(
        !sent_behind(&s.sent, at("13000 mode 8"), at("2011 mode 7")),
        "the area closer waits for the mission closer's answer"
    );
    assert!(sent_behind(&s.sent, at("2011 mode 7"), at("50000")));
    assert!(
        !sent_behind(&s.sent, at("50000"), at("13000 mode 6")),
        "the delete waits"
    );
    assert!(
        !sent_behind(&s.sent, at("2012 area 1"), at("2011 mode 7")),
        "the closer waits"
    );

    // The next upload within the transfer timeout holds the report this one brought up to date:
    // it does not ask for it.
    let from = s.sent.len();
    let r = upload(&mut s, &mission_2(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(holds(&s, &mission_2()));
    assert_eq!(s.requests(from)[0], "13000 mode 10");
    assert_eq!(r.messages.sent, r.messages.full);
    // After the transfer timeout without the FCC it asks again.
    s.rig.now = s.rig.now + TRANSFER_TIMEOUT;
    let from = s.sent.len();
    upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(s.requests(from)[0], "13000 mode 7");
}

#[test]
fn the_paper_sequence_sends_the_areas_beside_the_mission_data() {
    let mut s = station(FccRig::new().with_mission_2());
    let r = upload(&mut s, &mission_1(), Sequence::Paper { clear: true });
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(holds(&s, &mission_1()));
    let at = |what| first(&s, 0, what);
    assert!(sent_behind(&s.sent, at("13000 mode 1"), at("13001")));
    assert!(sent_behind(&s.sent, at("13001"), at("2011 mode 1")));
    assert!(sent_behind(&s.sent, at("13001"), at("2012 area 1")));
    assert!(at("2012 area 1") < at("13000 mode 2"));
    assert!(
        !sent_behind(&s.sent, at("13000 mode 2"), at("2011 mode 2")),
        "the area closer waits for the transmit's answer"
    );
}

/// The opener lost, or its answer: the data sent behind it are not known to be where the
/// opener puts them. The opener goes again alone, then every data message again.
#[test]
fn a_lost_opener_or_answer_sends_the_opener_alone_then_its_data_again() {
    for (case, direction, which) in [
        (
            "the opener",
            Direction::Up,
            Box::new(is("13000 mode 10")) as Box<dyn Fn(&Message) -> bool>,
        ),
        ("its answer", Direction::Down, Box::new(ack_of(13000))),
    ] {
        let mut s = station(FccRig::new().with_mission_2());
        // The report first (the answer lost is the one to mode 10, not to mode 7).
        let r = upload(&mut s, &mission_2(), Sequence::Atomic);
        assert!(r.is_complete());
        let from = s.sent.len();
        s.lose = lose_nth(direction, 1, which);
        let r = upload(&mut s, &mission_1(), Sequence::Atomic);
        assert_eq!(r.outcome(), UploadOutcome::Complete, "{case}: {r}");
        assert!(holds(&s, &mission_1()), "{case}");
        assert_eq!(
            s.requests(from),
            [
                "13000 mode 10",
                "13006 take-off",
                "13002 wp 1",
                "13001",
                "2011 mode 1",
                "2012 area 1",
                "13000 mode 10",
                "13006 take-off",
                "13002 wp 1",
                "13001",
                "13000 mode 8",
                "2011 mode 7",
                "50000",
                "13000 mode 6"
            ],
            "{case}"
        );
        let retry = s
            .sent
            .iter()
            .enumerate()
            .skip(from)
            .filter(|(_, m)| describe(&m.message) == "13000 mode 10")
            .map(|(i, _)| i)
            .nth(1)
            .unwrap();
        let again = first(&s, retry, "13006 take-off");
        assert!(
            !sent_behind(&s.sent, retry, again),
            "{case}: the retry goes alone"
        );
    }
}

/// The take-off height lost: it alone goes again; the mission closer (mode 8), sent behind the
/// data, found it missing, was refused and goes again after it (ICD §10.3).
#[test]
fn a_lost_data_message_is_retried_alone() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    let from = s.sent.len();
    s.lose = lose_nth(Direction::Up, 1, is("13006 take-off"));
    let r = upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(holds(&s, &mission_1()));
    assert_eq!(
        s.requests(from)[..9],
        [
            "13000 mode 10",
            "13006 take-off",
            "13002 wp 1",
            "13001",
            "2011 mode 1",
            "2012 area 1",
            "13000 mode 8",
            "13006 take-off",
            "13000 mode 8"
        ]
    );
}

/// The area opener lost: the FCC refuses the areas sent behind it (no area transfer open); they
/// wait for the opener, which goes again alone.
#[test]
fn area_data_refused_before_their_opener_go_again_after_it() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    let from = s.sent.len();
    s.lose = lose_nth(Direction::Up, 1, is("2011 mode 1"));
    let r = upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert!(holds(&s, &mission_1()));
    let requests = s.requests(from);
    assert_eq!(
        requests[4..],
        [
            "2011 mode 1",
            "2012 area 1",
            "13000 mode 8",
            "2011 mode 1",
            "2012 area 1",
            "2011 mode 7",
            "50000",
            "13000 mode 6"
        ]
    );
}

/// The answer to the mission closer lost once: its retry is answered from the FCC's memory
/// although the area opener and its data, sent behind the closer, were accepted since (the
/// memory is kept per kind of list, ICD §11).
#[test]
fn a_lost_answer_to_the_closer_is_given_again_behind_the_area_opener() {
    for (sequence, closer) in [
        (Sequence::Atomic, "13000 mode 8"),
        (Sequence::Paper { clear: true }, "13000 mode 2"),
    ] {
        let mut s = station(FccRig::new().with_mission_2());
        upload(&mut s, &mission_2(), sequence);
        let sent_closer = Rc::new(RefCell::new(false));
        let seen = Rc::clone(&sent_closer);
        let mut lost = false;
        s.lose = Box::new(move |d, m| {
            if d == Direction::Up && describe(m) == closer {
                *seen.borrow_mut() = true;
            }
            let answer = d == Direction::Down && ack_of(13000)(m) && *seen.borrow();
            if answer && !lost {
                lost = true;
                return true;
            }
            false
        });
        s.rig.events();
        let r = upload(&mut s, &mission_1(), sequence);
        assert_eq!(r.outcome(), UploadOutcome::Complete, "{closer}: {r}");
        assert_eq!(r.failure, None, "{closer}");
        assert!(holds(&s, &mission_1()));
        assert!(*sent_closer.borrow());
    }
}

/// Both answers to the closer lost: the transfer fails, the report says the FCC holds what it
/// closed, and the upload goes on from there (ICD §11), as before ICD §10.3. The area upload
/// sent behind the closer was cancelled and is sent again.
#[test]
fn a_closer_whose_answers_are_lost_is_confirmed_by_the_report() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    let from = s.sent.len();
    let mut n = 0;
    let mut closer_sent = false;
    s.lose = Box::new(move |d, m| {
        if d == Direction::Up && describe(m) == "13000 mode 8" {
            closer_sent = true;
        }
        if d == Direction::Down && closer_sent && ack_of(13000)(m) && n < 2 {
            n += 1;
            return true;
        }
        false
    });
    let r = upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::CompleteAfterLostAnswer, "{r}");
    assert!(matches!(r.failure, Some((Phase::MissionUpload, _))));
    assert!(holds(&s, &mission_1()));
    let requests = s.requests(from);
    let cancel = s.sent[from..].iter().any(|m| {
        matches!(&m.message, Message::AreaTransmissionCommand(c) if c.mode == AreaTransferMode::Cancel)
    });
    assert!(cancel, "the area upload sent behind is cancelled");
    assert!(requests.contains(&"13000 mode 7".to_owned()), "the truth");
    assert_eq!(
        requests.iter().filter(|r| *r == "2011 mode 1").count(),
        2,
        "{requests:?}"
    );
}

/// The answer to the area closer lost once, the activation sent behind it carried out: the
/// closer's retry is answered from the FCC's memory, which an activation leaves for a staged
/// closer (ICD §11), and the upload completes without a failure.
#[test]
fn a_lost_answer_to_the_area_closer_is_given_again_after_the_activation_behind_it() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    s.lose = lose_nth(Direction::Down, 1, |m| {
        matches!(m, Message::AreaStatusAlert(_))
    });
    let from = s.sent.len();
    let r = upload(&mut s, &mission_1(), Sequence::Atomic);
    assert_eq!(r.outcome(), UploadOutcome::Complete, "{r}");
    assert_eq!(r.failure, None);
    assert!(holds(&s, &mission_1()));
    let requests = s.requests(from);
    assert_eq!(
        requests[requests.len() - 4..],
        ["2011 mode 7", "50000", "2011 mode 7", "13000 mode 6"]
    );
}

/// Both answers to the area closer lost, the activation sent behind it accepted: the report
/// shows the new lists active, and the upload goes on after the activation, not with it again.
#[test]
fn an_activation_sent_behind_a_closer_whose_answers_are_lost_is_not_sent_again() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    let mut n = 0;
    s.lose = Box::new(move |d, m| {
        if d == Direction::Down && matches!(m, Message::AreaStatusAlert(_)) && n < 2 {
            n += 1;
            return true;
        }
        false
    });
    let from = s.sent.len();
    s.rig.events();
    let now = s.rig.now;
    s.gcs
        .upload_with(now, &mission_1(), Sequence::Atomic)
        .unwrap();
    // The FCC's events as they come: StationRig drops them, so watch its activations here.
    let r = report(&s.run(LIMIT));
    assert_eq!(r.outcome(), UploadOutcome::CompleteAfterLostAnswer, "{r}");
    assert!(matches!(r.failure, Some((Phase::AreaUpload, _))));
    assert!(holds(&s, &mission_1()));
    let requests = s.requests(from);
    assert_eq!(
        requests.iter().filter(|r| *r == "50000").count(),
        1,
        "{requests:?}"
    );
    assert_eq!(requests.last().map(String::as_str), Some("13000 mode 6"));
}

/// A clear refused (the aircraft flies): the data sent behind it were taken as an edit of the
/// active mission, and the cancel ends it; nothing changed.
#[test]
fn a_refused_opener_leaves_the_lists_and_the_data_sent_behind_it_are_dropped() {
    let mut s = station(FccRig::new().with_mission_2());
    upload(&mut s, &mission_2(), Sequence::Atomic);
    s.rig.fcc.set_automation_state(&flying());
    let r = upload(&mut s, &mission_1(), Sequence::Paper { clear: true });
    assert_eq!(r.outcome(), UploadOutcome::PreviousActive, "{r}");
    assert!(holds(&s, &mission_2()));
    // Nothing of the upload is left open on the FCC: a download is served.
    s.rig.fcc.set_automation_state(&on_ground());
    let now = s.rig.now;
    s.gcs.download(now).unwrap();
    let events = s.run(LIMIT);
    assert!(
        events
            .iter()
            .any(|e| matches!(e, GcsEvent::DownloadComplete(_))),
        "{events:?}"
    );
}

#[test]
fn an_edition_1_fcc_still_gets_the_papers_sequence_stop_and_wait() {
    let mut s = StationRig::edition_1(FccRig::new().with_mission_2());
    s.gcs = GroundStation::new(config(), WithoutGateway);
    for _ in 0..2 {
        let from = s.sent.len();
        let r = upload(&mut s, &mission_1(), Sequence::Atomic);
        assert!(r.is_complete(), "{r}");
        let requests = s.requests(from);
        // The report request only while the edition is not known (ICD §10.1).
        let expected = [
            "13000 mode 1",
            "13006 take-off",
            "13002 wp 1",
            "13001",
            "13000 mode 2",
            "2011 mode 1",
            "2012 area 1",
            "2011 mode 2",
        ];
        assert_eq!(requests[requests.len() - 8..], expected);
        // Each request after the answer to the one before.
        let up: Vec<usize> = s
            .sent
            .iter()
            .enumerate()
            .skip(from)
            .filter(|(_, m)| m.direction == Direction::Up && m.ack_requested)
            .map(|(i, _)| i)
            .collect();
        for pair in up.windows(2) {
            assert!(
                !sent_behind(&s.sent, pair[0], pair[1]),
                "{:?}",
                s.sent[pair[1]].message
            );
        }
    }
}

// ---- The FCC in stamp order ----

/// Stamps `messages` in order (1 ms apart, as the GCS sends them) and returns their frames.
fn stamped(rig: &mut FccRig, messages: Vec<Message>) -> Vec<Vec<u8>> {
    for m in messages {
        rig.now = rig.now + Duration::from_millis(1);
        rig.gcs.send(rig.now, m, true);
    }
    use missionlink_protocol::testkit::Transmit;
    rig.gcs.frames()
}

fn accepted(answers: &[Message]) -> bool {
    matches!(answers, [Message::MessageAcknowledgement(a)] if a.ack_type == AckType::Completed)
}

fn refused(answers: &[Message]) -> Option<Reason> {
    match answers {
        [Message::MessageAcknowledgement(a)] if a.ack_type == AckType::Rejected => a.reject_reason,
        _ => None,
    }
}

/// ICD §10.3: the opener and the data behind it arrive in any order; the FCC assembles what it
/// would have in the order they were sent.
#[test]
fn the_fcc_keeps_the_data_that_overtook_their_opener() {
    let new = validated(&generated_plan(6));
    let checksum = mission_checksum(&new.mission);
    for opener in [
        mission_command(MissionPlanMode::ClearMission, None, None),
        mission_command(
            MissionPlanMode::LoadWaypointBuffer,
            None,
            Text::new("no-such-mission").ok(),
        ),
    ] {
        let mut rig = FccRig::new().with_mission_2();
        let mut messages = vec![opener.clone()];
        messages.extend(new.mission.messages());
        let frames = stamped(&mut rig, messages);
        // The data first, in reverse; the opener last.
        for frame in frames[1..].iter().rev() {
            assert!(accepted(&rig.send_raw(frame)));
        }
        assert!(accepted(&rig.send_raw(&frames[0])), "{opener}");
        let answers = rig.send(transmit(&new.mission, Some(checksum)));
        assert!(accepted(&answers), "{opener}: {answers:?}");
        assert_eq!(rig.fcc.active_mission(), Some(&new.mission), "{opener}");
    }
}

/// ICD §10.3: the first attempt of an opener arriving after its retry and the data sent again
/// behind it (late on the link) changes nothing, for missions and areas.
#[test]
fn a_late_copy_of_an_opener_changes_nothing() {
    let new = validated(&generated_plan(6));
    let mut rig = FccRig::new().with_mission_2();
    let load = || {
        mission_command(
            MissionPlanMode::LoadWaypointBuffer,
            None,
            Text::new("no-such-mission").ok(),
        )
    };
    let late = stamped(&mut rig, vec![load()]);
    let mut messages = vec![load()];
    messages.extend(new.mission.messages());
    for frame in stamped(&mut rig, messages) {
        assert!(accepted(&rig.send_raw(&frame)));
    }
    assert_eq!(refused(&rig.send_raw(&late[0])), Some(Reason::WrongState));
    let answers = rig.send(transmit(&new.mission, Some(mission_checksum(&new.mission))));
    assert!(accepted(&answers), "{answers:?}");

    let opener = || {
        let mut c = area_command(
            AreaTransferMode::InitiateUpload,
            Some(new.areas.areas.len() as u8),
        );
        c.safety_offset = Some(new.areas.safety_offset);
        Message::from(c)
    };
    let late = stamped(&mut rig, vec![opener()]);
    let mut messages = vec![opener()];
    messages.extend(new.areas.areas.iter().cloned().map(Message::from));
    for frame in stamped(&mut rig, messages) {
        assert!(accepted(&rig.send_raw(&frame)));
    }
    assert_eq!(refused(&rig.send_raw(&late[0])), Some(Reason::WrongState));
    let answers = rig.send(area_closer(&new.areas, Some(areas_checksum(&new.areas))));
    assert_eq!(area_status(&answers), (new.areas.areas.len() as u8, Ok(())));
    assert_eq!(rig.fcc.active_areas(), Some(&new.areas));
}

// ---- Over the simulated links ----

/// A pair 100 ms apart with a window of 32, the FCC on the ground at TROL.
fn pair(seed: u64) -> Pair {
    let mut p = Pair::new(seed);
    p.gcs = GroundStation::new(config(), WithoutGateway);
    p.fcc.set_automation_state(&on_ground());
    p.fcc.handle_progress(p.now, &on_ground_at(TROL));
    p
}

fn pair_upload(p: &mut Pair, plan: &MissionPlan, sequence: Sequence) -> UploadReport {
    let now = p.now;
    p.gcs.upload_with(now, plan, sequence).unwrap();
    p.run_until_standby(LIMIT);
    report(&p.take_gcs_events())
}

/// Uploads by both sequences over links that lose `loss` of the datagrams each, duplicate 10 %
/// and reorder 5 % (and more by their jitter), 40 seeds each: every upload ends with the exact
/// lists or, for each list, the one before (the mission none after the paper's clear), and the
/// GCS says which (ICD §11). The uploads that completed, per sequence.
fn under_faults(loss: f64) -> HashMap<&'static str, usize> {
    let mut completed: HashMap<&str, usize> = HashMap::new();
    let mut runs: HashMap<&str, usize> = HashMap::new();
    for (name, sequence) in [
        ("atomic", Sequence::Atomic),
        ("paper", Sequence::Paper { clear: true }),
    ] {
        for seed in 0..40u64 {
            let old_plan = mission_1();
            // The generated plan's legs cross its no-fly-zones: the onboard check of an
            // activation (ICD §8) refuses it, the paper's sequence does not check.
            let new_plan = if seed % 2 == 0 || sequence == Sequence::Atomic {
                mission_2()
            } else {
                generated_plan(40)
            };
            let mut p = pair(seed);
            assert!(pair_upload(&mut p, &old_plan, sequence).is_complete());
            let old = validated(&old_plan);
            let new = validated(&new_plan);
            let mut rng = Rng::new(seed ^ 0x9e11);
            for f in p.uplink.iter_mut().chain(p.downlink.iter_mut()) {
                let lo = rng.range(1, 20);
                *f = Impairments {
                    reorder: 0.05,
                    ..faulty(loss, 0.1, (lo, lo + rng.range(10, 60)))
                };
            }
            let r = pair_upload(&mut p, &new_plan, sequence);
            p.run_until(p.now + Duration::from_secs(10));
            let lists = (
                p.fcc.active_mission().cloned(),
                p.fcc.active_areas().cloned(),
            );
            *runs.entry(name).or_default() += 1;
            if r.is_complete() {
                assert_eq!(
                    lists,
                    (Some(new.mission.clone()), Some(new.areas.clone())),
                    "{name} seed {seed}: reported complete"
                );
                *completed.entry(name).or_default() += 1;
                continue;
            }
            let mission = lists.0.as_ref();
            let areas = lists.1.as_ref();
            if sequence == Sequence::Atomic {
                // Both new or both as before (ICD §8).
                assert!(
                    (mission, areas) == (Some(&new.mission), Some(&new.areas))
                        || (mission, areas) == (Some(&old.mission), Some(&old.areas)),
                    "{name} seed {seed}: {r}"
                );
            } else {
                // Each list new or as before; the mission none after the clear (ICD §5.1).
                assert!(
                    [Some(&new.mission), Some(&old.mission), None].contains(&mission),
                    "{name} seed {seed}: {r}"
                );
                assert!(
                    [Some(&new.areas), Some(&old.areas)].contains(&areas),
                    "{name} seed {seed}: {r}"
                );
            }
            // What the GCS says is active, when it could find out (ICD §11).
            if r.outcome() != UploadOutcome::Unknown {
                assert_eq!(
                    (r.mission.checksum, r.areas.checksum),
                    (mission.map(mission_checksum), areas.map(areas_checksum)),
                    "{name} seed {seed}: {r}"
                );
            }
        }
    }
    println!(
        "pipelined uploads under {} % loss, 10 % duplication and 5 % reordering per link: \
         {completed:?} of {runs:?}",
        loss * 100.0
    );
    completed
}

#[test]
fn pipelined_uploads_under_faults_end_with_the_exact_lists_or_the_previous_ones() {
    // Each message has a retry, and a datagram goes on both links: most complete.
    let completed = under_faults(0.1);
    for name in ["atomic", "paper"] {
        assert!(
            completed.get(name).copied().unwrap_or(0) >= 36,
            "{completed:?}"
        );
    }
    // A third lost per link: many fail, at every step, and each failure ends as above.
    let completed = under_faults(0.3);
    for name in ["atomic", "paper"] {
        assert!(
            completed.get(name).copied().unwrap_or(0) < 30,
            "{completed:?}"
        );
    }
}

/// ICD §10.4: over a link of 2.4 kbit/s and 750 ms one way, a GCS that knows the rate keeps in
/// flight what the link carries in the shortest round trip it measured (1.71 s: both ways and
/// the serialisation of the shortest exchange; 512 bytes: the take-off height and seven
/// waypoints, 48 + 7 x 65); one that does not fills the window of 32, and its frames wait in the
/// link's queue behind each other.
#[test]
fn with_the_rate_known_the_window_keeps_what_the_link_carries() {
    let plan = generated_plan(40);
    let mut most = Vec::new();
    for rate in [Some(2_400), None] {
        let mut p = Pair::new(1);
        p.gcs = GroundStation::new(
            GcsConfig {
                // Above the round trip and the queue a window of 32 builds at the rate.
                ack_timeout: Duration::from_secs(20),
                transfer_timeout: Duration::from_secs(60),
                ..config()
            },
            WithoutGateway,
        );
        p.gcs.set_link_rate(rate);
        p.fcc = MissionDataHandling::new(FccConfig {
            transfer_timeout: Duration::from_secs(60),
            ..fcc_config()
        });
        p.fcc.set_automation_state(&on_ground());
        let narrow = Impairments {
            delay: Duration::from_millis(750),
            bandwidth: Some(Bandwidth::new(2_400).unwrap()),
            ..Impairments::NONE
        };
        p.uplink = [narrow; 2];
        p.downlink = [narrow; 2];
        let r = pair_upload(&mut p, &plan, Sequence::Paper { clear: true });
        assert!(r.is_complete(), "{rate:?}: {r}");
        // The most data messages unanswered at once.
        let mut open = std::collections::HashSet::new();
        let mut peak = 0;
        for s in &p.sent {
            let data = matches!(
                s.message,
                Message::UaPositionWaypoint(_)
                    | Message::VehicleSpecificWaypoint(_)
                    | Message::UaRoute(_)
                    | Message::AreaPolygonLoopSegment(_)
            );
            match (&s.direction, &s.message) {
                (Direction::Up, m) if data && s.ack_requested => {
                    open.insert((m.message_type() as u16, m.time_stamp()));
                }
                (Direction::Down, Message::MessageAcknowledgement(a)) => {
                    open.remove(&(a.original_message_type, a.original_time_stamp));
                }
                _ => {}
            }
            peak = peak.max(open.len());
        }
        let overflowed: u64 = p.channel_stats().iter().map(|c| c.overflowed).sum();
        assert_eq!(overflowed, 0);
        most.push((rate, peak, p.gcs.link_window().min_rtt()));
    }
    println!("{most:?}");
    assert_eq!(most[0].1, 8, "{most:?}");
    assert_eq!(most[1].1, 32, "{most:?}");
}

/// ICD §10.3, §10.4: the area upload goes beside the mission upload's data, and the window
/// counts both: over 64 kbit/s and 300 ms each way (what the link carries in a round trip holds
/// about 75 waypoints and 8 areas), area data leave while waypoints are unanswered, and the
/// bytes of the data messages unanswered of both uploads never exceed what the link carries in
/// the shortest round trip measured, or one frame.
#[test]
fn the_area_upload_beside_the_mission_data_shares_the_window() {
    use missionlink_interfaces::wire::{self, Envelope, TRAILER_LEN};
    let plan = generated_plan(100);
    let rate = 64_000;
    let mut p = Pair::new(1);
    p.gcs = GroundStation::new(
        GcsConfig {
            transfer_window: 128,
            ack_timeout: Duration::from_secs(5),
            ..config()
        },
        WithoutGateway,
    );
    p.gcs.set_link_rate(Some(rate));
    p.fcc.set_automation_state(&on_ground());
    let satellite = Impairments {
        delay: Duration::from_millis(300),
        bandwidth: Some(Bandwidth::new(rate).unwrap()),
        ..Impairments::NONE
    };
    p.uplink = [satellite; 2];
    p.downlink = [satellite; 2];
    let r = pair_upload(&mut p, &plan, Sequence::Paper { clear: true });
    assert!(r.is_complete(), "{r}");
    let bytes = |m: &Message| {
        let mut buf = [0u8; wire::MAX_FRAME_LEN];
        (wire::encode(&Envelope::new(0, 0), m, &mut buf).unwrap() + TRAILER_LEN) as u64
    };
    let mut open = HashMap::new();
    let (mut peak, mut beside) = (0, false);
    for s in &p.sent {
        match (&s.direction, &s.message) {
            (Direction::Up, m @ Message::AreaPolygonLoopSegment(_)) => {
                beside |= open.values().any(|(area, _)| !area);
                open.insert((m.message_type() as u16, m.time_stamp()), (true, bytes(m)));
            }
            (
                Direction::Up,
                m @ (Message::UaPositionWaypoint(_)
                | Message::VehicleSpecificWaypoint(_)
                | Message::UaRoute(_)),
            ) => {
                open.insert((m.message_type() as u16, m.time_stamp()), (false, bytes(m)));
            }
            (Direction::Down, Message::MessageAcknowledgement(a)) => {
                open.remove(&(a.original_message_type, a.original_time_stamp));
            }
            _ => {}
        }
        peak = peak.max(open.values().map(|(_, b)| b).sum::<u64>());
    }
    let rtt = p.gcs.link_window().min_rtt().unwrap();
    let carried = (u128::from(rate) * rtt.as_nanos() / 8_000_000_000) as u64;
    assert!(beside, "area data left while waypoints were unanswered");
    assert!(
        peak <= carried.max(wire::MAX_SIGNED_FRAME_LEN as u64),
        "{peak} bytes in flight, {carried} carried in {rtt:?}"
    );
    assert!(
        peak > carried / 2,
        "{peak} of {carried}: the window is used"
    );
}
