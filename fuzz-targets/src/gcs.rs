//! Target `fuzz_gcs`: the GCS logic (paper §3.2, Figure 11) fed frames while it is in the
//! middle of uploads, downloads, reports and commands, sans-IO in simulated time.
//!
//! The GCS talks to a real FCC (mission data handling) through two queues that the input pumps
//! and loses frames from, and the input puts frames of its own in front of the GCS as the FCC
//! would send them. The input is a sequence of [records](crate::input); the tag modulo 8 says
//! what a record does:
//!
//! | tag | body | step |
//! |---|---|---|
//! | 0 raw | any bytes | to the GCS's `handle_frame` as they are |
//! | 1 wrap | [`MessageBody`] | its data in an FCC frame with a correct checksum ([`wrap`]) |
//! | 2 send | [`MessageBody`] | its data decoded, sent by an FCC endpoint with a fresh time stamp |
//! | 3 time | ms (2 bytes) | the clock moves on; both sides' deadlines fire in order |
//! | 4 request | see [`Rig::request`] | the operator asks the GCS for something |
//! | 5 pump | rounds, loss bits | frames move between the GCS and the FCC; a set bit loses one |
//! | 6 answer | reason (1 byte) | a forged answer to the GCS's last request: 0 accepted, else that reason |
//! | 7 state | 1 byte | the FCC's aircraft flies (odd) or stands on the ground (even) |
//!
//! Every record but `time` moves the clock 1 ms. After every record:
//! - every frame the GCS sends decodes and is addressed to the FCC;
//! - a download the GCS reports complete holds whole valid lists (ICD §7, §11);
//! - the FCC's lists keep the invariants of [`crate::fcc`];
//! - a deadline that fires does not stay due.
//!
//! At the end neither side hears anything for a minute: the GCS is back in standby (Figure 11:
//! every failure returns to standby) and neither side has a deadline left.

use core::time::Duration;
use std::collections::VecDeque;
use std::sync::OnceLock;

use missionlink_ground::ground_station::{
    GcsEvent, GroundStation, MissionPlan, Sequence, WithoutGateway,
};
use missionlink_ground::testkit;
use missionlink_interfaces::contracts::{
    AutomationStatePayload, FlightPhase, GuidanceProgressPayload,
};
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
use missionlink_interfaces::wire::{ExecuteCommand, MAX_FRAME_LEN};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::staged::MissionId;

use crate::fcc::{check_areas, check_mission};
use crate::session::{self, Core, Session};

/// Record tags of this target (the tag byte modulo [`TAGS`]).
pub mod tag {
    pub use crate::session::tag::{RAW, SEND, TIME, WRAP};
    /// An operator request.
    pub const REQUEST: u8 = 4;
    /// Frames move between the GCS and the FCC.
    pub const PUMP: u8 = 5;
    /// A forged answer to the GCS's last request.
    pub const ANSWER: u8 = 6;
    /// The FCC's aircraft flies or stands.
    pub const STATE: u8 = 7;
}

/// Kinds of records.
pub const TAGS: u8 = 8;

/// Operator requests of [`tag::REQUEST`] (its first byte modulo this).
pub const REQUESTS: u8 = 14;

/// Frames a queue holds; the oldest is lost beyond (a socket buffer).
const QUEUE: usize = 256;

/// The entry point: panics only when an invariant of the module documentation is broken.
pub fn gcs(input: &[u8]) {
    let mut rig = Rig::new();
    session::run(&mut rig, input);
    rig.advance(Duration::from_secs(60));
    assert!(
        rig.gcs.is_standby(),
        "the GCS is not back in standby after a minute of silence"
    );
    assert_eq!(rig.gcs.poll_timeout(), None, "a GCS deadline left");
    assert_eq!(rig.core.fcc.poll_timeout(), None, "an FCC deadline left");
}

/// The plans the requests upload: the demo missions and the largest (256 waypoints, 11 areas).
fn plans() -> &'static [MissionPlan; 3] {
    static PLANS: OnceLock<[MissionPlan; 3]> = OnceLock::new();
    PLANS.get_or_init(|| {
        [
            testkit::mission_1(),
            testkit::mission_2(),
            testkit::generated_plan(256),
        ]
    })
}

struct Rig {
    gcs: GroundStation<WithoutGateway>,
    /// The FCC, the endpoint that forges its frames (the peer), the clock, the GCS's last
    /// request.
    core: Core,
    up: VecDeque<Vec<u8>>,
    down: VecDeque<Vec<u8>>,
}

impl Rig {
    fn new() -> Self {
        let mut rig = Self {
            gcs: GroundStation::new(testkit::gcs_config(), WithoutGateway),
            core: Core::new(<Self as Session>::PEER),
            up: VecDeque::new(),
            down: VecDeque::new(),
        };
        rig.state(0);
        rig
    }

    /// Body `[which, argument]`: `which` modulo [`REQUESTS`] picks the request (uploads of the
    /// demo missions and of 256 waypoints by each sequence, downloads of the active and of the
    /// staged lists, report, clears, #50000 with command `argument`, staged activate, delete
    /// and store, the transfer window `argument`). A request refused as busy changes nothing.
    fn request(&mut self, body: &[u8]) {
        let (which, argument) = (
            body.first().copied().unwrap_or(0),
            body.get(1).copied().unwrap_or(0),
        );
        let [mission_1, mission_2, largest] = plans();
        let staged = MissionId::new("MEDEVAC-2").ok();
        let now = self.core.now;
        // A refusal (busy, an edition-1 FCC for a staged request) is an answer, not a fault.
        let _ = match which % REQUESTS {
            0 => self
                .gcs
                .upload_with(now, mission_1, Sequence::Paper { clear: true }),
            1 => self.gcs.upload_with(now, mission_2, Sequence::Atomic),
            2 => self
                .gcs
                .upload_with(now, mission_2, Sequence::Paper { clear: false }),
            3 => self.gcs.upload_with(now, largest, Sequence::Atomic),
            4 => self.gcs.download(now),
            5 => self.gcs.download_of(now, staged),
            6 => self.gcs.report(now),
            7 => self.gcs.clear_mission(now),
            8 => self.gcs.clear_areas(now),
            9 => {
                let commands = ExecuteCommand::ALL;
                let command = commands
                    .get(usize::from(argument) % commands.len())
                    .copied()
                    .unwrap_or(ExecuteCommand::Execute);
                self.gcs.execute(now, command)
            }
            10 => match staged {
                Some(id) => self.gcs.activate(now, id),
                None => Ok(()),
            },
            11 => match staged {
                Some(id) => self.gcs.delete(now, id),
                None => Ok(()),
            },
            12 => match staged {
                Some(id) => self.gcs.stage(now, id, mission_2),
                None => Ok(()),
            },
            _ => {
                // Any count: the GCS clamps it to 1..=128 (ICD §10.2).
                self.gcs.set_transfer_window(argument);
                Ok(())
            }
        };
        self.drain();
    }

    /// Body `[rounds, loss bits ...]`: up to 16 rounds, each moving every queued frame, the
    /// GCS's to the FCC, then the FCC's to the GCS; the next loss bit set loses the frame.
    fn pump(&mut self, body: &[u8]) {
        let rounds = usize::from(body.first().copied().unwrap_or(0) % 16) + 1;
        let mut bit = 0usize;
        let lost = |bit: &mut usize| {
            let b = *bit;
            *bit += 1;
            body.get(1 + b / 8)
                .is_some_and(|byte| byte & (1 << (b % 8)) != 0)
        };
        for _ in 0..rounds {
            self.drain();
            while let Some(frame) = self.up.pop_front() {
                if !lost(&mut bit) {
                    let _ = self.core.fcc.handle_frame(self.core.now, &frame);
                }
            }
            self.drain();
            while let Some(frame) = self.down.pop_front() {
                if !lost(&mut bit) {
                    let _ = self.gcs.handle_frame(self.core.now, &frame);
                }
            }
            self.drain();
        }
    }

    /// Even: on the ground at TROL; odd: flying (system automation in cruise).
    fn state(&mut self, flags: u8) {
        let flying = flags % 2 == 1;
        self.core.fcc.set_automation_state(&AutomationStatePayload {
            flight_phase: if flying {
                FlightPhase::Cruise as u8
            } else {
                FlightPhase::OnGround as u8
            },
            trajectory_generation_active: flying,
            guidance_alive: true,
            ..AutomationStatePayload::ON_GROUND
        });
        let (lat, lon) = testkit::TROL;
        self.core.fcc.handle_progress(
            self.core.now,
            &GuidanceProgressPayload {
                sequence: u64::from(flags) + 1,
                latitude_deg: lat,
                longitude_deg: lon,
                on_ground: !flying,
                trajectory_generation_active: flying,
                ..GuidanceProgressPayload::IDLE
            },
        );
        self.drain();
    }
}

impl Session for Rig {
    const TAGS: u8 = TAGS;
    const ANSWER: u8 = tag::ANSWER;
    const PEER: (u32, u32) = (FCC_ID, GCS_ID);

    fn core(&self) -> &Core {
        &self.core
    }

    fn core_mut(&mut self) -> &mut Core {
        &mut self.core
    }

    fn next_deadline(&self) -> Option<Instant> {
        [self.gcs.poll_timeout(), self.core.fcc.poll_timeout()]
            .into_iter()
            .flatten()
            .min()
    }

    fn handle_timeout(&mut self) {
        self.gcs.handle_timeout(self.core.now);
        self.core.fcc.handle_timeout(self.core.now);
    }

    /// Takes what both sides send into the queues, and the GCS's events.
    fn drain(&mut self) {
        session::checked_frames(
            &mut self.gcs,
            ("GCS", "FCC"),
            (GCS_ID, FCC_ID),
            |frame, envelope, message| {
                if envelope.ack_requested {
                    self.core.request = Some(message);
                }
                queue(&mut self.up, frame);
            },
        );
        let mut buf = [0u8; MAX_FRAME_LEN];
        while let Some(sent) = self.core.fcc.poll_transmit(&mut buf) {
            let len = sent.unwrap_or_else(|e| panic!("the FCC cannot encode its message: {e}"));
            queue(&mut self.down, buf.get(..len).unwrap_or_default());
        }
        while self.core.fcc.poll_event().is_some() {}
        while let Some(event) = self.gcs.poll_event() {
            if let GcsEvent::DownloadComplete(plan) = event {
                check_mission(&plan.mission);
                check_areas(&plan.areas);
            }
        }
    }

    fn hand(&mut self, frame: &[u8]) {
        // A frame error is the driver's to count.
        let _ = self.gcs.handle_frame(self.core.now, frame);
        self.drain();
    }

    fn other(&mut self, record: u8, body: &[u8]) {
        match record {
            tag::REQUEST => self.request(body),
            tag::PUMP => self.pump(body),
            _ => self.state(body.first().copied().unwrap_or(0)),
        }
    }
}

fn queue(queue: &mut VecDeque<Vec<u8>>, frame: &[u8]) {
    if queue.len() == QUEUE {
        queue.pop_front();
    }
    queue.push_back(frame.to_vec());
}
