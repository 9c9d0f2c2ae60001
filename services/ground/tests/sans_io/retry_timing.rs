//! Timeout and retry (paper §3.1.4, ICD §5) in scripted time: nothing before the ack timeout, the
//! resend exactly at it with a new time stamp, the abort after the second timeout; the same for
//! rejections; and the receiver's transfer timeout.

use std::time::Duration;

use crate::support::*;
use missionlink_flight::mission_data_handling::{DataKind, FccEvent, MissionDataHandling};
use missionlink_ground::ground_station::outcome::UploadOutcome;
use missionlink_ground::ground_station::{
    GcsError, GcsEvent, GroundStation, Phase, Sequence, WithoutGateway,
};
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    AckType, AreaTransferMode, AreaTransmissionCommand, AreaType, ExecuteCommand, MAX_FRAME_LEN,
    Message, MessageAcknowledgement, MessageType, Reason, SafetyOffset, Timestamp,
};
use missionlink_protocol::link::endpoint::Endpoint;
use missionlink_protocol::link::retry::{AttemptFailure, Subject};
use missionlink_protocol::link::time::Instant;

fn at(ms: u64) -> Instant {
    Instant::from_millis(ms)
}

#[test]
fn resend_at_the_ack_timeout_with_a_new_time_stamp_then_abort() {
    let mut gcs = GroundStation::new(gcs_config(), WithoutGateway);
    gcs.execute(at(0), ExecuteCommand::Execute).unwrap();
    let first = gcs.messages();
    assert_eq!(first.len(), 1);
    assert_eq!(gcs.poll_timeout(), Some(at(500)));

    gcs.handle_timeout(at(499));
    assert!(gcs.messages().is_empty(), "no resend at timeout - 1 ms");

    gcs.handle_timeout(at(500));
    let second = gcs.messages();
    assert_eq!(second.len(), 1, "resend at the timeout");
    assert_eq!(second[0].message_type(), MessageType::MissionExecuteCommand);
    assert!(
        second[0].time_stamp() > first[0].time_stamp(),
        "a retry gets a new time stamp"
    );
    assert_eq!(
        second[0].time_stamp().millis() - first[0].time_stamp().millis(),
        500
    );
    assert_eq!(gcs.poll_timeout(), Some(at(1000)));

    gcs.handle_timeout(at(999));
    assert!(gcs.messages().is_empty());
    assert!(gcs.poll_event().is_none());

    gcs.handle_timeout(at(1000));
    assert!(gcs.messages().is_empty(), "no third attempt");
    let Some(GcsEvent::Failed(GcsError::Transfer { error, .. })) = gcs.poll_event() else {
        panic!("no abort after the second timeout");
    };
    assert_eq!(error.message_type, MessageType::MissionExecuteCommand);
    assert_eq!(error.first, AttemptFailure::Timeout);
    assert_eq!(error.second, Some(AttemptFailure::Timeout));
    assert_eq!(
        error.to_string(),
        "#50000 Mission Execute Command: no answer within the ack timeout; retried: no answer \
         within the ack timeout"
    );
    assert!(gcs.is_standby());
    assert_eq!(gcs.poll_timeout(), None);
}

/// The FCC's answer to `original`, as bytes from the FCC.
fn answer(original: &Message, ack_type: AckType, reason: Reason, at_ms: u64) -> Vec<u8> {
    let mut fcc = Endpoint::new(endpoint(defaults::FCC_ID, defaults::GCS_ID));
    let ack = MessageAcknowledgement {
        time_stamp: Timestamp::default(),
        original_time_stamp: original.time_stamp(),
        original_message_type: original.message_type() as u16,
        ack_type,
        reject_reason: Some(reason),
    };
    fcc.send(at(at_ms), ack.into(), false);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = fcc.poll_transmit(&mut buf).unwrap().unwrap();
    buf[..len].to_vec()
}

#[test]
fn resend_at_once_after_a_rejection_then_abort_after_the_second() {
    let mut gcs = GroundStation::new(gcs_config(), WithoutGateway);
    gcs.execute(at(0), ExecuteCommand::Execute).unwrap();
    let first = gcs.messages().remove(0);

    gcs.handle_frame(
        at(10),
        &answer(&first, AckType::Rejected, Reason::WrongState, 10),
    )
    .unwrap();
    let second = gcs.messages();
    assert_eq!(second.len(), 1, "resend at once after a rejection");
    assert!(second[0].time_stamp() > first.time_stamp());
    assert_eq!(gcs.poll_timeout(), Some(at(510)), "a fresh ack timeout");

    // A late rejection of the first attempt says nothing about the retry.
    gcs.handle_frame(
        at(20),
        &answer(&first, AckType::Rejected, Reason::WrongState, 11),
    )
    .unwrap();
    assert!(gcs.messages().is_empty());
    assert!(gcs.poll_event().is_none());

    gcs.handle_frame(
        at(30),
        &answer(&second[0], AckType::Rejected, Reason::WrongState, 30),
    )
    .unwrap();
    assert!(gcs.messages().is_empty(), "no third attempt");
    let Some(GcsEvent::Failed(GcsError::Transfer { error, .. })) = gcs.poll_event() else {
        panic!("no abort after the second rejection");
    };
    assert_eq!(error.first, AttemptFailure::Rejected(Reason::WrongState));
    assert_eq!(
        error.second,
        Some(AttemptFailure::Rejected(Reason::WrongState))
    );
    assert_eq!(error.reason(), Some(Reason::WrongState));
}

#[test]
fn a_timeout_then_an_acceptance_of_either_attempt_succeeds() {
    let mut gcs = GroundStation::new(gcs_config(), WithoutGateway);
    gcs.execute(at(0), ExecuteCommand::Execute).unwrap();
    let first = gcs.messages().remove(0);
    gcs.handle_timeout(at(500));
    assert_eq!(gcs.messages().len(), 1);
    // The acceptance of the first attempt arrives late: the command was carried out.
    gcs.handle_frame(
        at(600),
        &answer(&first, AckType::Completed, Reason::None, 600),
    )
    .unwrap();
    assert_eq!(
        gcs.poll_event(),
        Some(GcsEvent::CommandAccepted(
            MessageType::MissionExecuteCommand
        ))
    );
    assert!(gcs.is_standby());
}

#[test]
fn an_upload_that_loses_its_link_names_the_message_after_the_retry() {
    let mut pair = Pair::new(7);
    pair.uplink = [CLEAN; 2];
    let plan = mission_2();
    let now = pair.now;
    pair.gcs.upload(now, &plan, true).unwrap();
    // Let the report (its request and the acknowledgement of its entry), the clear, the
    // take-off height and waypoint 1 through, then cut both uplinks.
    while pair
        .sent
        .iter()
        .filter(|s| s.direction == Direction::Up)
        .count()
        < 5
    {
        pair.step();
    }
    pair.uplink = [DOWN; 2];
    let cut = pair.now;
    let before = pair.sent.len();
    pair.run_until_standby(Duration::from_secs(30));
    let events = pair.take_gcs_events();
    let Some(GcsEvent::Failed(GcsError::Upload(report))) = events.last() else {
        panic!("{events:?}");
    };
    let Some((Phase::MissionUpload, error)) = report.failure else {
        panic!("{report}");
    };
    assert_eq!(error.message_type, MessageType::UaPositionWaypoint);
    assert_eq!(error.subject, Some(Subject::Waypoint(2)));
    // Worst case for one message: 2 x ack timeout; then the GCS asks what is active (ICD §11),
    // and with the uplink dead it cannot know.
    let asked = pair.sent[before..]
        .iter()
        .find(|s| describe(&s.message) == "13000 mode 7")
        .expect("the GCS asks what is active");
    assert!(asked.at.saturating_since(cut) <= 2 * ACK_TIMEOUT + Duration::from_millis(10));
    assert_eq!(report.outcome(), UploadOutcome::Unknown, "{report}");
    // The FCC abandons the upload after the transfer timeout; nothing was activated.
    let deadline = pair.now + TRANSFER_TIMEOUT;
    pair.run_until(deadline);
    assert_eq!(pair.fcc.active_mission(), None);
    assert!(pair.fcc_events.iter().any(|e| matches!(
        e,
        missionlink_flight::mission_data_handling::FccEvent::UploadAbandoned { .. }
    )));
}

#[test]
fn a_download_abandoned_when_the_fcc_falls_silent() {
    let mut pair = Pair::new(8);
    let now = pair.now;
    pair.gcs.upload(now, &mission_1(), true).unwrap();
    pair.run_until_standby(Duration::from_secs(10));
    pair.take_gcs_events();
    let now = pair.now;
    pair.gcs.download(now).unwrap();
    // The FCC accepts the request and sends the take-off height, then its downlinks die.
    while !pair
        .sent
        .iter()
        .any(|s| s.direction == Direction::Down && describe(&s.message) == "13006 take-off")
    {
        pair.step();
    }
    pair.downlink = [DOWN; 2];
    pair.run_until_standby(Duration::from_secs(30));
    let events = pair.take_gcs_events();
    assert!(
        matches!(
            events.last(),
            Some(GcsEvent::Failed(GcsError::Timeout { .. }))
        ),
        "{events:?}"
    );
}

/// `message` from the GCS, stamped and encoded with "acknowledgement requested".
fn from_gcs(gcs: &mut Endpoint, now: Instant, message: impl Into<Message>) -> Vec<u8> {
    gcs.send(now, message.into(), true);
    let mut buf = [0u8; MAX_FRAME_LEN];
    let len = gcs.poll_transmit(&mut buf).unwrap().unwrap();
    buf[..len].to_vec()
}

fn initiate_area_upload(loop_count: u8) -> AreaTransmissionCommand {
    AreaTransmissionCommand {
        time_stamp: Timestamp::default(),
        mode: AreaTransferMode::InitiateUpload,
        loop_count: Some(loop_count),
        area_id: None,
        safety_offset: Some(SafetyOffset::from_metres(25.0).unwrap()),
        activity_id: None,
        mission_id: None,
        window_or_checksum: None,
    }
}

#[test]
fn the_fcc_abandons_an_upload_at_the_transfer_timeout_not_before() {
    let mut fcc = MissionDataHandling::new(fcc_config());
    let mut gcs = Endpoint::new(endpoint(defaults::GCS_ID, defaults::FCC_ID));
    assert_eq!(fcc.poll_timeout(), None, "no transfer, no timer");

    fcc.handle_frame(at(10), &from_gcs(&mut gcs, at(10), initiate_area_upload(2)))
        .unwrap();
    assert_eq!(fcc.poll_timeout(), Some(at(3010)));
    // Every message of the transfer restarts the transfer timeout.
    let fly_zone = polygon(1, AreaType::FlyZone, &FLY_ZONE);
    fcc.handle_frame(at(1000), &from_gcs(&mut gcs, at(1000), fly_zone))
        .unwrap();
    assert_eq!(fcc.poll_timeout(), Some(at(4000)));
    assert_eq!(fcc.messages().len(), 2, "one answer per message");

    fcc.handle_timeout(at(3999));
    assert_eq!(fcc.poll_event(), None, "nothing at the timeout - 1 ms");
    assert_eq!(fcc.poll_timeout(), Some(at(4000)));

    fcc.handle_timeout(at(4000));
    assert_eq!(
        fcc.poll_event(),
        Some(FccEvent::UploadAbandoned {
            kind: DataKind::Areas,
            reason: None
        }),
        "abandoned at the timeout"
    );
    assert_eq!(fcc.poll_timeout(), None);
    assert!(fcc.frames().is_empty(), "the FCC sends nothing for it");
    assert_eq!(fcc.active_areas(), None);
}

#[test]
fn a_stray_area_outside_a_transfer_starts_no_timer() {
    let mut fcc = MissionDataHandling::new(fcc_config());
    let mut gcs = Endpoint::new(endpoint(defaults::GCS_ID, defaults::FCC_ID));
    let fly_zone = polygon(1, AreaType::FlyZone, &FLY_ZONE);
    fcc.handle_frame(at(10), &from_gcs(&mut gcs, at(10), fly_zone))
        .unwrap();
    let [Message::MessageAcknowledgement(ack)] = fcc.messages()[..] else {
        panic!("no answer");
    };
    assert_eq!(ack.reject_reason, Some(Reason::WrongState));
    assert_eq!(fcc.poll_timeout(), None);
    fcc.handle_timeout(at(10) + TRANSFER_TIMEOUT);
    assert_eq!(fcc.poll_event(), None, "no upload to abandon");
}

/// ICD §5: the ack timer of an upload's first message starts when the message goes out, after
/// the validation (which takes up to a second for a large plan in a debug build), not when the
/// operator asked: validated first, the request at the time it is sent.
#[test]
fn an_uploads_first_ack_timer_starts_after_the_validation() {
    let mut gcs = GroundStation::new(gcs_config(), WithoutGateway);
    let plan = generated_plan(256);
    let validated = gcs.validate(&plan).unwrap();
    // The validation took 900 ms of the driver's clock.
    gcs.upload_validated(at(900), validated, Sequence::Atomic)
        .unwrap();
    assert_eq!(gcs.messages().len(), 1, "the report request");
    assert_eq!(gcs.poll_timeout(), Some(at(1400)));
    gcs.handle_timeout(at(1399));
    assert!(
        gcs.messages().is_empty(),
        "no resend before its own ack timeout"
    );
}
