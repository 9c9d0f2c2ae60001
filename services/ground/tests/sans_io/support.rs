//! A GCS and an FCC stepped through simulated time over two simulated links (after quinn-proto's
//! `tests/util.rs` `Pair`): the pair takes each side's frames from its `poll_transmit` and only
//! moves the bytes; every frame goes out on the direct and the LTE link, each link with
//! its own loss, duplication and latency (random latency reorders), drawn from a seeded RNG. The
//! receiving side votes each step's arrivals (paper §2.4) before its logic sees them, as the
//! partitions do.
//!
//! Beside the pair, [`FccRig`]: the FCC alone, driven by hand one message at a time, for the
//! tests that check its every answer (reject reasons, ICD §11).

use std::time::Duration;

use missionlink_flight::mission_data_handling::{DataKind, FccEvent, MissionDataHandling};
use missionlink_ground::ground_station::{
    GcsEvent, GroundStation, MissionPlan, ValidatedPlan, WithoutGateway,
};
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{
    AckType, AreaDownloadStatus, AreaListStatus, AreaTransferMode, AreaTransmissionCommand,
    Checksum, Envelope, MAX_FRAME_LEN, Message, MissionPlanMode, MissionTransferCommand, Reason,
    SafetyOffset, SpecificData, Text, Timestamp, TransferWindow, WindowOrChecksum,
};
use missionlink_protocol::link::endpoint::Endpoint;
use missionlink_protocol::link::signing::{Keyring, LinkKey, Policy, SignatureCheck, Signer};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::{mission_command, transfer_command};
use missionlink_protocol::voting::Voter;

// The fixtures (messages, areas, the demo missions) come from the testkit every test and bench
// shares, the configurations of ICD §1 from each side's; the links' fault model and the seeded
// RNG from the link simulation the link emulator uses too.
pub use missionlink_flight::testkit::fcc_config;
pub use missionlink_ground::testkit::*;
pub use missionlink_linksim::Rng;
pub use missionlink_linksim::channel::{Channel, Impairments};
pub use missionlink_linksim::round_trips::{RoundTrips, Way};

/// Datagrams a driver reads per link per step (`missionlink_platform::udp::MAX_READS_PER_WAKE`).
const READS_PER_LINK: usize = 32;

/// How long a sender waits for an answer (ICD §1).
pub const ACK_TIMEOUT: Duration = defaults::ACK_TIMEOUT;
/// How long a transfer waits for its peer (ICD §1).
pub const TRANSFER_TIMEOUT: Duration = defaults::TRANSFER_TIMEOUT;

/// A link of the pair that works: 2 ms one way, nothing else (the testkit's one fault model,
/// [`Impairments`]).
pub const CLEAN: Impairments = Impairments {
    delay: Duration::from_millis(2),
    ..Impairments::NONE
};

/// A link of the pair that is cut.
pub const DOWN: Impairments = CLEAN.cut();

/// A link of the pair with `loss`, `duplicate`, and a one-way delay uniform in
/// `latency_ms.0..=latency_ms.1` (a wide range reorders frames).
pub fn faulty(loss: f64, duplicate: f64, latency_ms: (u64, u64)) -> Impairments {
    Impairments {
        delay: Duration::from_millis(latency_ms.0),
        jitter: Duration::from_millis(latency_ms.1 - latency_ms.0),
        loss,
        duplicate,
        ..Impairments::NONE
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// GCS to FCC.
    Up,
    /// FCC to GCS.
    Down,
}

/// One message as it left its sender.
#[derive(Debug, Clone)]
pub struct Sent {
    pub at: Instant,
    pub direction: Direction,
    pub message: Message,
    pub ack_requested: bool,
}

#[derive(Debug)]
struct InFlight {
    deliver_at: Instant,
    order: u64,
    link: Link,
    bytes: Vec<u8>,
    /// The round of the conversation it belongs to (`linksim/src/round_trips.rs`).
    round: u64,
}

/// The pair.
pub struct Pair {
    pub now: Instant,
    pub gcs: GroundStation<WithoutGateway>,
    pub fcc: MissionDataHandling,
    gcs_voter: Voter,
    fcc_voter: Voter,
    /// The impairments of [direct, LTE], per direction (the testkit's one fault model).
    pub uplink: [Impairments; 2],
    pub downlink: [Impairments; 2],
    to_fcc: Vec<InFlight>,
    to_gcs: Vec<InFlight>,
    order: u64,
    /// The channels [up direct, up LTE, down direct, down LTE], each drawing from its own
    /// seed; their impairments are `uplink` and `downlink` as they are at each send.
    channels: [Channel; 4],
    /// The signer of each direction's frames, `[up, down]` (ICD §9); none: unsigned.
    signers: [Option<Signer>; 2],
    pub sent: Vec<Sent>,
    /// Every datagram put on a link, as it went: direction, link, bytes (signed where a signer
    /// is set), for the tests that replay captures or compare bytes.
    pub wire: Vec<(Direction, Link, Vec<u8>)>,
    pub gcs_events: Vec<GcsEvent<core::convert::Infallible>>,
    pub fcc_events: Vec<FccEvent>,
    /// The round trips between the GCS (the asking end) and the FCC, counted from the times of
    /// the datagrams as the link emulator counts them (`linksim/src/round_trips.rs`).
    pub round_trips: RoundTrips,
}

impl Pair {
    pub fn new(seed: u64) -> Self {
        Self {
            now: Instant::ZERO,
            gcs: GroundStation::new(gcs_config(), WithoutGateway),
            fcc: MissionDataHandling::new(fcc_config()),
            gcs_voter: Voter::new(defaults::GCS_ID, defaults::FCC_ID, TRANSFER_TIMEOUT),
            fcc_voter: Voter::new(defaults::FCC_ID, defaults::GCS_ID, TRANSFER_TIMEOUT),
            uplink: [CLEAN; 2],
            downlink: [CLEAN; 2],
            to_fcc: Vec::new(),
            to_gcs: Vec::new(),
            order: 0,
            channels: core::array::from_fn(|i| {
                Channel::new(CLEAN, seed.wrapping_mul(4).wrapping_add(i as u64))
            }),
            signers: [None, None],
            sent: Vec::new(),
            wire: Vec::new(),
            gcs_events: Vec::new(),
            fcc_events: Vec::new(),
            round_trips: RoundTrips::new(),
        }
    }

    /// A pair whose both sides hold [`link_key`] as Key ID 1, sign every frame with it and check
    /// received frames with `gcs_policy` and `fcc_policy` (ICD §9).
    pub fn signed(seed: u64, gcs_policy: Policy, fcc_policy: Policy) -> Self {
        let mut pair = Self::new(seed);
        pair.signers = [Some(Signer::new(link_key())), Some(Signer::new(link_key()))];
        pair.gcs_voter = pair.gcs_voter.with_signatures(signature_check(gcs_policy));
        pair.fcc_voter = pair.fcc_voter.with_signatures(signature_check(fcc_policy));
        pair
    }

    /// Sets the receivers' signature checks (the GCS's, the FCC's) as they are now.
    pub fn set_signature_checks(&mut self, gcs: SignatureCheck, fcc: SignatureCheck) {
        let fresh = || Voter::new(0, 0, TRANSFER_TIMEOUT);
        self.gcs_voter = std::mem::replace(&mut self.gcs_voter, fresh()).with_signatures(gcs);
        self.fcc_voter = std::mem::replace(&mut self.fcc_voter, fresh()).with_signatures(fcc);
    }

    /// The FCC's voter (its counters).
    pub fn fcc_voter(&self) -> &Voter {
        &self.fcc_voter
    }

    /// What became of the datagrams of each channel: [up direct, up LTE, down direct, down
    /// LTE].
    pub fn channel_stats(&self) -> [missionlink_linksim::channel::ChannelStats; 4] {
        core::array::from_fn(|i| self.channels[i].stats())
    }

    /// Puts `bytes` on `link` toward the FCC as they are (a foreign sender, a replay), arriving
    /// after `latency`.
    pub fn inject_uplink(&mut self, link: Link, bytes: &[u8], latency: Duration) {
        self.order += 1;
        self.to_fcc.push(InFlight {
            deliver_at: self.now + latency,
            order: self.order,
            link,
            bytes: bytes.to_vec(),
            round: self.round_trips.sent(Way::Up),
        });
    }

    /// Puts the frames both sides have to send (from their `poll_transmit`) on both links of
    /// their direction.
    fn drain_outgoing(&mut self) {
        for bytes in self.gcs.frames() {
            self.send(Direction::Up, bytes);
        }
        for bytes in self.fcc.frames() {
            self.send(Direction::Down, bytes);
        }
    }

    /// Records one frame's message and puts the frame on the direct and the LTE link of
    /// `direction`.
    fn send(&mut self, direction: Direction, bytes: Vec<u8>) {
        let (envelope, message) = decoded(&bytes);
        self.sent.push(Sent {
            at: self.now,
            direction,
            message,
            ack_requested: envelope.ack_requested,
        });
        let faults = match direction {
            Direction::Up => self.uplink,
            Direction::Down => self.downlink,
        };
        for (link, faults) in [Link::Direct, Link::Lte].into_iter().zip(faults) {
            self.transmit(direction, link, faults, &bytes);
        }
    }

    fn transmit(&mut self, direction: Direction, link: Link, faults: Impairments, bytes: &[u8]) {
        let signer = match direction {
            Direction::Up => &self.signers[0],
            Direction::Down => &self.signers[1],
        };
        let mut signed = [0u8; missionlink_interfaces::wire::MAX_SIGNED_FRAME_LEN];
        let bytes = match signer {
            Some(signer) => {
                let len = signer
                    .sign(link, bytes, &mut signed)
                    .expect("a frame to sign");
                &signed[..len]
            }
            None => bytes,
        };
        self.wire.push((direction, link, bytes.to_vec()));
        let index = match (direction, link) {
            (Direction::Up, Link::Direct) => 0,
            (Direction::Up, _) => 1,
            (Direction::Down, Link::Direct) => 2,
            (Direction::Down, _) => 3,
        };
        let round = self.round_trips.sent(match direction {
            Direction::Up => Way::Up,
            Direction::Down => Way::Down,
        });
        let channel = &mut self.channels[index];
        channel.impairments = faults;
        // The time of the send: a link with a rate queues the frames behind each other.
        let sent_at = self.now.saturating_since(Instant::ZERO);
        for (after, bytes) in channel.transmit_at(sent_at, bytes) {
            self.order += 1;
            let f = InFlight {
                deliver_at: self.now + after,
                order: self.order,
                link,
                bytes,
                round,
            };
            match direction {
                Direction::Up => self.to_fcc.push(f),
                Direction::Down => self.to_gcs.push(f),
            }
        }
    }

    fn drain_events(&mut self) {
        while let Some(e) = self.gcs.poll_event() {
            self.gcs_events.push(e);
        }
        while let Some(e) = self.fcc.poll_event() {
            self.fcc_events.push(e);
        }
    }

    /// When something happens next: a delivery or a timer.
    pub fn next_time(&self) -> Option<Instant> {
        self.to_fcc
            .iter()
            .chain(&self.to_gcs)
            .map(|f| f.deliver_at)
            .chain(self.gcs.poll_timeout())
            .chain(self.fcc.poll_timeout())
            .min()
    }

    fn take_due(queue: &mut Vec<InFlight>, now: Instant) -> Vec<InFlight> {
        let (mut due, rest): (Vec<_>, Vec<_>) = queue.drain(..).partition(|f| f.deliver_at <= now);
        *queue = rest;
        due.sort_by_key(|f| (f.deliver_at, f.order));
        due
    }

    /// Votes the frames of `queue` due at `now` (paper §2.4) and hands each winner to `handle`;
    /// each datagram's arrival counts for the round trips (`way`).
    fn deliver(
        queue: &mut Vec<InFlight>,
        voter: &mut Voter,
        now: Instant,
        (rounds, way): (&mut RoundTrips, Way),
        mut handle: impl FnMut(&[u8]),
    ) {
        let due = Self::take_due(queue, now);
        for f in &due {
            rounds.arrived(way, f.round);
        }
        // As the drivers read them: at most `READS_PER_LINK` datagrams per link per step (the
        // partitions' `MAX_READS_PER_WAKE`), the rest in the next step.
        let mut rest: Vec<&InFlight> = due.iter().collect();
        while !rest.is_empty() {
            let mut taken = [0usize; 2];
            let (step, later): (Vec<&InFlight>, Vec<&InFlight>) = rest.into_iter().partition(|f| {
                let n = &mut taken[usize::from(f.link != Link::Direct)];
                *n += 1;
                *n <= READS_PER_LINK
            });
            let arrivals: Vec<(Link, &[u8])> =
                step.iter().map(|f| (f.link, f.bytes.as_slice())).collect();
            voter.vote_step(now, &arrivals, |_, _, frame| handle(frame));
            rest = later;
        }
    }

    /// Advances to the next event and handles it. `false` when nothing is left to happen.
    pub fn step(&mut self) -> bool {
        self.drain_outgoing();
        let Some(next) = self.next_time() else {
            return false;
        };
        self.now = self.now.max(next);
        let now = self.now;

        let fcc = &mut self.fcc;
        let rounds = &mut self.round_trips;
        Self::deliver(
            &mut self.to_fcc,
            &mut self.fcc_voter,
            now,
            (rounds, Way::Up),
            |frame| {
                let _ = fcc.handle_frame(now, frame);
            },
        );
        let gcs = &mut self.gcs;
        Self::deliver(
            &mut self.to_gcs,
            &mut self.gcs_voter,
            now,
            (&mut self.round_trips, Way::Down),
            |frame| {
                let _ = gcs.handle_frame(now, frame);
            },
        );

        if self.fcc.poll_timeout().is_some_and(|t| t <= now) {
            self.fcc.handle_timeout(now);
        }
        if self.gcs.poll_timeout().is_some_and(|t| t <= now) {
            self.gcs.handle_timeout(now);
        }
        self.drain_events();
        self.drain_outgoing();
        true
    }

    /// Steps until the GCS is back in standby and nothing is in flight, or `limit` of
    /// simulated time has passed.
    pub fn run_until_standby(&mut self, limit: Duration) {
        let end = self.now + limit;
        while self.now < end {
            self.drain_outgoing();
            if self.gcs.is_standby() && self.to_fcc.is_empty() && self.to_gcs.is_empty() {
                return;
            }
            if !self.step() {
                return;
            }
        }
    }

    /// Steps until simulated time reaches `until` (or nothing is left to happen before it).
    pub fn run_until(&mut self, until: Instant) {
        self.drain_outgoing();
        while self.next_time().is_some_and(|t| t <= until) {
            self.step();
        }
        self.now = self.now.max(until);
        self.fcc.handle_timeout(self.now);
        self.gcs.handle_timeout(self.now);
        self.drain_events();
    }

    /// The GCS events since the last call.
    pub fn take_gcs_events(&mut self) -> Vec<GcsEvent<core::convert::Infallible>> {
        std::mem::take(&mut self.gcs_events)
    }
}

/// The key of the signed pairs: Key ID 1.
pub fn link_key() -> LinkKey {
    LinkKey::new(1, &[0x5a; 32])
}

/// A signature check with `policy` holding [`link_key`], on the testkit's clock.
pub fn signature_check(policy: Policy) -> SignatureCheck {
    let mut keys = Keyring::new();
    keys.insert(link_key()).expect("one key");
    SignatureCheck::new(policy, keys, utc_at_zero(), Instant::ZERO)
}

/// System automation's state while the aircraft flies (trajectory generation active).
pub fn flying() -> missionlink_interfaces::contracts::AutomationStatePayload {
    use missionlink_interfaces::contracts::{AutomationStatePayload, FlightPhase};
    AutomationStatePayload {
        flight_phase: FlightPhase::Cruise as u8,
        trajectory_generation_active: true,
        guidance_alive: true,
        ..AutomationStatePayload::ON_GROUND
    }
}

/// Navigation's report of the aircraft on the ground at `(lat, lon)`: where the onboard
/// geofence check starts from (ICD §7).
pub fn on_ground_at(
    (lat, lon): (f64, f64),
) -> missionlink_interfaces::contracts::GuidanceProgressPayload {
    missionlink_interfaces::contracts::GuidanceProgressPayload {
        sequence: 1,
        latitude_deg: lat,
        longitude_deg: lon,
        ..missionlink_interfaces::contracts::GuidanceProgressPayload::IDLE
    }
}

/// System automation's state on the ground, guidance alive.
pub fn on_ground() -> missionlink_interfaces::contracts::AutomationStatePayload {
    missionlink_interfaces::contracts::AutomationStatePayload {
        guidance_alive: true,
        ..missionlink_interfaces::contracts::AutomationStatePayload::ON_GROUND
    }
}

/// A compact description of a message for sequence checks: type, then mode, ack type and the
/// acknowledged type where they matter.
pub fn describe(m: &Message) -> String {
    match m {
        Message::MessageAcknowledgement(a) => format!(
            "17000 {} {}",
            match a.ack_type {
                AckType::Completed => "completed",
                AckType::Rejected => "rejected",
                other => return format!("17000 {other:?}"),
            },
            a.original_message_type
        ),
        Message::MissionTransferCommand(c) => format!("13000 mode {}", c.mode as u8),
        Message::AreaTransmissionCommand(c) => format!("2011 mode {}", c.mode as u8),
        Message::VehicleSpecificWaypoint(v) => match v.data {
            SpecificData::TakeOffHeight { .. } => "13006 take-off".to_owned(),
            SpecificData::RfCentre {
                waypoint_number, ..
            } => format!("13006 rf {waypoint_number}"),
        },
        Message::UaPositionWaypoint(w) => format!("13002 wp {}", w.waypoint_number),
        Message::AreaPolygonLoopSegment(a) => format!("2012 area {}", a.area_id),
        Message::AreaStatusAlert(a) => format!("3012 {:?}", a.status),
        Message::AreaTransmissionStatus(s) => format!("3013 {:?}", s.status),
        Message::MissionUploadDownloadStatus(s) => format!("14000 {:?}", s.status),
        other => format!("{}", other.message_type() as u16),
    }
}

// ---- The FCC driven by hand ----

/// The FCC driven by hand: a GCS endpoint stamps and encodes each message (every one with a new
/// time stamp, as a retry has), the FCC answers, and the test reads the answers off the wire.
/// Simulated time moves 1 ms per message and otherwise only when the test says so.
pub struct FccRig {
    pub fcc: MissionDataHandling,
    pub gcs: Endpoint,
    pub now: Instant,
}

impl Default for FccRig {
    fn default() -> Self {
        Self::new()
    }
}

impl FccRig {
    /// An FCC with no active lists.
    pub fn new() -> Self {
        let mut fcc = MissionDataHandling::new(fcc_config());
        // System automation on the ground with guidance alive, as on a running FCC.
        fcc.set_automation_state(&on_ground());
        Self {
            fcc,
            gcs: Endpoint::new(endpoint(defaults::GCS_ID, defaults::FCC_ID)),
            now: Instant::from_millis(1),
        }
    }

    /// Sends `message` with "acknowledgement requested"; returns the FCC's answers with their
    /// envelopes (everything it sent since the last call).
    pub fn send_enveloped(&mut self, message: impl Into<Message>) -> Vec<(Envelope, Message)> {
        self.now = self.now + Duration::from_millis(1);
        self.gcs.send(self.now, message.into(), true);
        self.gcs_frame()
    }

    /// Sends `message` with "acknowledgement requested"; returns the FCC's answers.
    pub fn send(&mut self, message: impl Into<Message>) -> Vec<Message> {
        self.send_enveloped(message)
            .into_iter()
            .map(|(_, m)| m)
            .collect()
    }

    /// The frame the GCS endpoint has queued goes to the FCC; the FCC's answers.
    fn gcs_frame(&mut self) -> Vec<(Envelope, Message)> {
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = self.gcs.poll_transmit(&mut buf).unwrap().unwrap();
        self.fcc.handle_frame(self.now, &buf[..len]).unwrap();
        self.out()
    }

    /// Hands `frame` to the FCC as it is; returns the FCC's answers.
    pub fn send_raw(&mut self, frame: &[u8]) -> Vec<Message> {
        self.fcc.handle_frame(self.now, frame).unwrap();
        self.fcc.messages()
    }

    /// What the FCC sent since the last call, with the envelopes.
    pub fn out(&mut self) -> Vec<(Envelope, Message)> {
        self.fcc.frames().iter().map(|f| decoded(f)).collect()
    }

    /// The GCS answers `message` (which the FCC sent, acknowledgement requested) with #17000:
    /// type 2, or type 3 with the reason. Returns the FCC's next messages.
    pub fn acknowledge(
        &mut self,
        message: &Message,
        outcome: Result<(), Reason>,
    ) -> Vec<(Envelope, Message)> {
        self.now = self.now + Duration::from_millis(1);
        self.gcs.answer(self.now, message, true, outcome);
        self.gcs_frame()
    }

    /// Simulated time moves to `at` and the FCC's due timers fire; returns what it sent.
    pub fn advance_to(&mut self, at: Instant) -> Vec<(Envelope, Message)> {
        self.now = at;
        self.fcc.handle_timeout(at);
        self.out()
    }

    /// The FCC's events since the last call.
    pub fn events(&mut self) -> Vec<FccEvent> {
        std::iter::from_fn(|| self.fcc.poll_event()).collect()
    }

    /// Checks that the FCC's one event since the last look is the completed download of `kind`.
    pub fn assert_download_complete(&mut self, kind: DataKind) {
        assert_eq!(self.events(), [FccEvent::DownloadComplete { kind }]);
    }

    /// The reason of the FCC's answer to `message` (None when accepted).
    pub fn reason(&mut self, message: impl Into<Message>) -> Option<Reason> {
        reason_of(&self.send(message))
    }

    /// Sends `message` and checks that the FCC accepts it.
    pub fn accepted(&mut self, message: impl Into<Message>) {
        let m = message.into();
        let what = describe(&m);
        assert_eq!(self.reason(m), None, "{what} refused");
    }

    /// Uploads `mission` as ICD §5.1 (clear first, each message accepted); returns the answers
    /// to the closer, which carries `checksum` (edition 2) or none (edition 1).
    pub fn upload_mission(
        &mut self,
        mission: &Mission,
        checksum: Option<Checksum>,
    ) -> Vec<Message> {
        self.accepted(mission_command(MissionPlanMode::ClearMission, None, None));
        for m in mission.messages() {
            self.accepted(m);
        }
        self.send(transmit(mission, checksum))
    }

    /// Uploads `mission` into a buffer emptied by #13000 mode 10 with a Mission ID that holds
    /// nothing (ICD §8), as the GCS opens a full upload toward edition 2: unlike the clear, the
    /// opener leaves the active list alone until the closer. Returns the answers to the closer.
    pub fn upload_mission_into_empty_buffer(
        &mut self,
        mission: &Mission,
        checksum: Option<Checksum>,
    ) -> Vec<Message> {
        let unused = Text::new("no-such-mission").ok();
        self.accepted(mission_command(
            MissionPlanMode::LoadWaypointBuffer,
            None,
            unused,
        ));
        for m in mission.messages() {
            self.accepted(m);
        }
        self.send(transmit(mission, checksum))
    }

    /// Uploads `list` as ICD §5.3 (each message accepted); returns the answers to the closer,
    /// which carries `checksum` (edition 2) or none (edition 1).
    pub fn upload_areas(&mut self, list: &AreaList, checksum: Option<Checksum>) -> Vec<Message> {
        let count = list.areas.len() as u8;
        self.accepted(area_command(AreaTransferMode::InitiateUpload, Some(count)));
        for a in &list.areas {
            self.accepted(a.clone());
        }
        self.send(area_closer(list, checksum))
    }

    /// Uploads demo mission 2 and its areas (edition 1: no checksums).
    pub fn with_mission_2(mut self) -> Self {
        let valid = validated(&mission_2());
        assert_eq!(reason_of(&self.upload_mission(&valid.mission, None)), None);
        assert_eq!(reason_of(&self.upload_areas(&valid.areas, None)), None);
        assert!(self.fcc.active_mission().is_some());
        assert!(self.fcc.active_areas().is_some());
        self
    }
}

/// The GCS's own assembly of `plan` (what it uploads and what it checksums).
pub fn validated(plan: &MissionPlan) -> ValidatedPlan {
    GroundStation::new(gcs_config(), WithoutGateway)
        .validate(plan)
        .unwrap()
}

/// #13000 mode 2 that closes the upload of `mission`, with `checksum` or none.
pub fn transmit(mission: &Mission, checksum: Option<Checksum>) -> MissionTransferCommand {
    MissionTransferCommand {
        mission_checksum: checksum,
        ..transfer_command(
            MissionPlanMode::TransmitMission,
            Some(mission.waypoints.len() as u16),
            mission.mission_id,
        )
    }
}

/// #2011 mode 2 that closes the upload of `list`, with `checksum` or none.
pub fn area_closer(list: &AreaList, checksum: Option<Checksum>) -> AreaTransmissionCommand {
    AreaTransmissionCommand {
        safety_offset: Some(list.safety_offset),
        window_or_checksum: checksum.map(WindowOrChecksum::AreaChecksum),
        ..area_command(
            AreaTransferMode::UploadComplete,
            Some(list.areas.len() as u8),
        )
    }
}

/// The reason of the first answer: #17000 type 3 or #3012 status 0 (None when accepted).
pub fn reason_of(answers: &[Message]) -> Option<Reason> {
    match answers.first() {
        Some(Message::MessageAcknowledgement(a)) => match a.ack_type {
            AckType::Rejected => Some(a.reject_reason.unwrap_or(Reason::None)),
            _ => None,
        },
        Some(Message::AreaStatusAlert(a)) => match a.status {
            AreaListStatus::Invalid => Some(a.reason.unwrap_or(Reason::None)),
            AreaListStatus::Valid => None,
        },
        other => panic!("no answer: {other:?}"),
    }
}

/// A #2011 of `mode` with the demo safety offset (25 m).
pub fn area_command(mode: AreaTransferMode, loop_count: Option<u8>) -> AreaTransmissionCommand {
    AreaTransmissionCommand {
        time_stamp: Timestamp::default(),
        mode,
        loop_count,
        area_id: None,
        safety_offset: Some(SafetyOffset::from_metres(25.0).unwrap()),
        activity_id: None,
        mission_id: None,
        window_or_checksum: None,
    }
}

/// Time stamp bytes of 2026-11-21T12:00:10Z (ms since 2000).
pub const TS: [u8; 5] = [0xc5, 0x93, 0x2a, 0xc1, 0x10];

/// The transfer window the windowed downloads of the tests ask for (ICD §10).
pub fn window() -> Option<TransferWindow> {
    TransferWindow::new(4)
}

// ---- The GCS logic against the FCC of a rig ----

/// Which messages a [`StationRig`] loses: `true` drops the message going `Direction`.
pub type Loss = Box<dyn FnMut(Direction, &Message) -> bool>;

/// The GCS logic against the FCC of an [`FccRig`]: every frame moved at once, 1 ms of simulated
/// time per message, no links and no voting, so that a test sees exactly the messages of each
/// request. `lose` decides for each message whether it is lost on its way (to inject the loss
/// of one answer); `edition_1` makes the FCC an edition-1 FCC as ICD §10.1 sees it: its
/// endpoint refuses #13000 mode 7 with `Unsupported` before the FCC sees it, and the FCC never
/// hears an edition-2 request (the GCS sends none after that refusal).
pub struct StationRig {
    pub rig: FccRig,
    pub gcs: GroundStation<WithoutGateway>,
    /// The FCC's refusing endpoint when it plays edition 1.
    pub edition_1: Option<Endpoint>,
    /// Every message, in the order it was sent (lost ones included).
    pub sent: Vec<Sent>,
    pub events: Vec<GcsEvent<core::convert::Infallible>>,
    pub lose: Loss,
}

impl StationRig {
    /// The GCS logic against `rig`'s FCC, nothing lost.
    pub fn new(mut rig: FccRig) -> Self {
        // Navigation reports the aircraft on the ground at TROL: the onboard geofence check of
        // an activation (ICD §8) and of execute starts from there.
        rig.fcc.handle_progress(rig.now, &on_ground_at(TROL));
        let _ = rig.fcc.messages();
        Self {
            rig,
            gcs: GroundStation::new(gcs_config(), WithoutGateway),
            edition_1: None,
            sent: Vec::new(),
            events: Vec::new(),
            lose: Box::new(|_, _| false),
        }
    }

    /// The same with `rig`'s FCC playing an edition-1 FCC.
    pub fn edition_1(rig: FccRig) -> Self {
        Self {
            edition_1: Some(Endpoint::new(endpoint(defaults::FCC_ID, defaults::GCS_ID))),
            ..Self::new(rig)
        }
    }

    fn tick(&mut self) -> Instant {
        self.rig.now = self.rig.now + Duration::from_millis(1);
        self.rig.now
    }

    fn record(&mut self, direction: Direction, frame: &[u8]) -> Option<Message> {
        let (envelope, message) = decoded(frame);
        self.sent.push(Sent {
            at: self.rig.now,
            direction,
            message: message.clone(),
            ack_requested: envelope.ack_requested,
        });
        (!(self.lose)(direction, &message)).then_some(message)
    }

    /// Moves frames and fires timers until the GCS is back in standby (at most `limit` of
    /// simulated time); returns the GCS's events of the request.
    pub fn run(&mut self, limit: Duration) -> Vec<GcsEvent<core::convert::Infallible>> {
        let end = self.rig.now + limit;
        while self.rig.now < end {
            let mut moved = false;
            for frame in self.gcs.frames() {
                moved = true;
                let Some(message) = self.record(Direction::Up, &frame) else {
                    continue;
                };
                let now = self.tick();
                let report_request = matches!(&message, Message::MissionTransferCommand(c)
                    if c.mode == MissionPlanMode::ReportMissions);
                match self.edition_1.as_mut() {
                    Some(e1) if report_request => {
                        e1.answer(now, &message, true, Err(Reason::Unsupported));
                    }
                    _ => {
                        let _ = self.rig.fcc.handle_frame(now, &frame);
                    }
                }
            }
            let mut down = self.rig.fcc.frames();
            if let Some(e1) = self.edition_1.as_mut() {
                down.extend(e1.frames());
            }
            for frame in down {
                moved = true;
                if self.record(Direction::Down, &frame).is_some() {
                    let now = self.tick();
                    let _ = self.gcs.handle_frame(now, &frame);
                }
            }
            while let Some(e) = self.gcs.poll_event() {
                self.events.push(e);
            }
            let _ = self.rig.events();
            if moved {
                continue;
            }
            if self.gcs.is_standby() {
                break;
            }
            let Some(next) = [self.gcs.poll_timeout(), self.rig.fcc.poll_timeout()]
                .into_iter()
                .flatten()
                .min()
            else {
                break;
            };
            self.rig.now = self.rig.now.max(next);
            let now = self.rig.now;
            self.rig.fcc.handle_timeout(now);
            self.gcs.handle_timeout(now);
        }
        std::mem::take(&mut self.events)
    }

    /// The GCS's requests (messages that ask for an answer) since `from`, described.
    pub fn requests(&self, from: usize) -> Vec<String> {
        self.sent
            .iter()
            .skip(from)
            .filter(|s| s.direction == Direction::Up && s.ack_requested)
            .map(|s| describe(&s.message))
            .collect()
    }
}

// ---- Reading the FCC's answers (integrity.rs, staged.rs) ----

/// The FCC's only answer, a #17000: accepted, or the reason.
pub fn one_ack(answers: &[Message]) -> Result<(), Reason> {
    let [Message::MessageAcknowledgement(a)] = answers else {
        panic!("one #17000 expected: {answers:?}");
    };
    match a.ack_type {
        AckType::Completed => Ok(()),
        AckType::Rejected => Err(a.reject_reason.expect("a rejection names its reason")),
        other => panic!("ack type {other:?}"),
    }
}

/// The FCC's one answer by #3012 to #2011 mode 2: the loop count, and valid or the reason.
pub fn area_status(answers: &[Message]) -> (u8, Result<(), Reason>) {
    let [Message::AreaStatusAlert(a)] = answers else {
        panic!("one #3012 expected: {answers:?}");
    };
    match a.status {
        AreaListStatus::Valid => {
            assert_eq!(a.reason, Some(Reason::None));
            (a.loop_count, Ok(()))
        }
        AreaListStatus::Invalid => (
            a.loop_count,
            Err(a.reason.expect("an invalid list names its reason")),
        ),
    }
}

/// Acknowledges (type 2) every message the FCC sends, starting with `pending`, until it sends
/// no more; returns what it sent, in order. Every message of a download or a report is sent with
/// "acknowledgement requested" (ICD §5, §8).
pub fn follow(rig: &mut FccRig, mut pending: Vec<(Envelope, Message)>) -> Vec<Message> {
    let mut sent = Vec::new();
    while !pending.is_empty() {
        let mut next = Vec::new();
        for (envelope, message) in pending {
            assert!(envelope.ack_requested, "{message:?} without ack request");
            next.extend(rig.acknowledge(&message, Ok(())));
            sent.push(message);
        }
        pending = next;
    }
    sent
}

/// Follows an area download the FCC answered `request` with ([`follow`]): it completes, and
/// opens with #3013 "ready" for `loop_count` areas, not with #17000 (ICD §5.4). Returns what
/// the FCC sent, the #3013 first.
pub fn follow_area_download(
    rig: &mut FccRig,
    request: Vec<(Envelope, Message)>,
    loop_count: u8,
) -> Vec<Message> {
    let sent = follow(rig, request);
    rig.assert_download_complete(DataKind::Areas);
    let Some(Message::AreaTransmissionStatus(ready)) = sent.first() else {
        panic!("the download starts with #3013: {sent:?}");
    };
    assert_eq!(
        (ready.status, ready.loop_count),
        (AreaDownloadStatus::Ready, loop_count)
    );
    sent
}
