//! A GCS and an FCC stepped through simulated time over two simulated links (after quinn-proto's
//! `tests/util.rs` `Pair`): the pair takes each side's frames from its `poll_transmit` and only
//! moves the bytes; every frame goes out on the direct and the LTE link, each link with
//! its own loss, duplication and latency (random latency reorders), drawn from a seeded RNG. The
//! receiving side votes each step's arrivals (paper §2.4) before its logic sees them, as the
//! partitions do.
#![allow(dead_code)]

use std::time::Duration;

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{AckType, Message, SpecificData};
use missionlink_services::ground_station::{GcsEvent, GroundStation, WithoutGateway};
use missionlink_services::link::time::Instant;
use missionlink_services::mission_data_handling::{FccEvent, MissionDataHandling};
use missionlink_services::voting::Voter;

// The fixtures (configurations, messages, areas, the demo missions, the seeded RNG) come from
// the testkit that every test and bench shares.
pub use missionlink_services::testkit::*;

/// How long a sender waits for an answer (ICD §1).
pub const ACK_TIMEOUT: Duration = defaults::ACK_TIMEOUT;
/// How long a transfer waits for its peer (ICD §1).
pub const TRANSFER_TIMEOUT: Duration = defaults::TRANSFER_TIMEOUT;

/// The faults of one link in one direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Faults {
    /// Probability that a frame is lost.
    pub loss: f64,
    /// Probability that a frame arrives twice.
    pub duplicate: f64,
    /// Latency, uniform in this range (ms); a wide range reorders frames.
    pub latency_ms: (u64, u64),
}

impl Faults {
    pub const NONE: Self = Self {
        loss: 0.0,
        duplicate: 0.0,
        latency_ms: (2, 2),
    };
    pub const DOWN: Self = Self {
        loss: 1.0,
        duplicate: 0.0,
        latency_ms: (2, 2),
    };
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
}

/// The pair.
pub struct Pair {
    pub now: Instant,
    pub gcs: GroundStation<WithoutGateway>,
    pub fcc: MissionDataHandling,
    gcs_voter: Voter,
    fcc_voter: Voter,
    /// Faults of [direct, LTE], per direction.
    pub uplink: [Faults; 2],
    pub downlink: [Faults; 2],
    to_fcc: Vec<InFlight>,
    to_gcs: Vec<InFlight>,
    order: u64,
    rng: Rng,
    pub sent: Vec<Sent>,
    pub gcs_events: Vec<GcsEvent<core::convert::Infallible>>,
    pub fcc_events: Vec<FccEvent>,
}

impl Pair {
    pub fn new(seed: u64) -> Self {
        Self {
            now: Instant::ZERO,
            gcs: GroundStation::new(gcs_config(), WithoutGateway),
            fcc: MissionDataHandling::new(fcc_config()),
            gcs_voter: Voter::new(defaults::GCS_ID, defaults::FCC_ID, TRANSFER_TIMEOUT),
            fcc_voter: Voter::new(defaults::FCC_ID, defaults::GCS_ID, TRANSFER_TIMEOUT),
            uplink: [Faults::NONE; 2],
            downlink: [Faults::NONE; 2],
            to_fcc: Vec::new(),
            to_gcs: Vec::new(),
            order: 0,
            rng: Rng::new(seed),
            sent: Vec::new(),
            gcs_events: Vec::new(),
            fcc_events: Vec::new(),
        }
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

    fn transmit(&mut self, direction: Direction, link: Link, faults: Faults, bytes: &[u8]) {
        let copies = if self.rng.chance(faults.loss) {
            0
        } else if self.rng.chance(faults.duplicate) {
            2
        } else {
            1
        };
        for _ in 0..copies {
            let latency = self.rng.range(faults.latency_ms.0, faults.latency_ms.1);
            self.order += 1;
            let f = InFlight {
                deliver_at: self.now + Duration::from_millis(latency),
                order: self.order,
                link,
                bytes: bytes.to_vec(),
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

    /// Votes the frames of `queue` due at `now` (paper §2.4) and hands each winner to `handle`.
    fn deliver(
        queue: &mut Vec<InFlight>,
        voter: &mut Voter,
        now: Instant,
        mut handle: impl FnMut(&[u8]),
    ) {
        let due = Self::take_due(queue, now);
        let arrivals: Vec<(Link, &[u8])> =
            due.iter().map(|f| (f.link, f.bytes.as_slice())).collect();
        voter.vote_step(now, &arrivals, |_, frame| handle(frame));
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
        Self::deliver(&mut self.to_fcc, &mut self.fcc_voter, now, |frame| {
            let _ = fcc.handle_frame(now, frame);
        });
        let gcs = &mut self.gcs;
        Self::deliver(&mut self.to_gcs, &mut self.gcs_voter, now, |frame| {
            let _ = gcs.handle_frame(now, frame);
        });

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

/// System automation's state while the aircraft flies (trajectory generation active).
pub fn flying() -> missionlink_interfaces::contracts::AutomationStatePayload {
    use missionlink_interfaces::contracts::{AutomationStatePayload, FlightPhase};
    AutomationStatePayload {
        flight_phase: FlightPhase::Cruise as u8,
        trajectory_generation_active: true,
        ..AutomationStatePayload::ON_GROUND
    }
}

/// System automation's state on the ground.
pub fn on_ground() -> missionlink_interfaces::contracts::AutomationStatePayload {
    missionlink_interfaces::contracts::AutomationStatePayload::ON_GROUND
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
