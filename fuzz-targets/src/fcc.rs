//! Target `fuzz_fcc`: mission data handling (the FCC's frame handler, paper §3.1) fed sequences
//! of frames, answers and clock steps, sans-IO in simulated time as the tests of `services/ground/tests/sans_io` drive it.
//!
//! The input is a sequence of [records](crate::input); the tag modulo 7 says what a record does:
//!
//! | tag | body | step |
//! |---|---|---|
//! | 0 raw | any bytes | handed to `handle_frame` as they are |
//! | 1 wrap | [`MessageBody`] | its data in a GCS frame with a correct checksum ([`wrap`]) |
//! | 2 send | [`MessageBody`] | its data decoded, sent by a GCS endpoint with a fresh time stamp |
//! | 3 time | ms (2 bytes) | the clock moves on; the FCC's deadlines fire in order |
//! | 4 answer | reason (1 byte) | the GCS answers the FCC's last request: 0 accepted, else rejected with that reason |
//! | 5 state | see [`Rig::state`] | system automation's state or guidance's progress changes |
//! | 6 restart | 1 byte | the partition restarts and resumes with what its driver recorded |
//!
//! Every record but `time` moves the clock 1 ms. After every record:
//! - **the active lists are unchanged, or each is a whole valid list** (paper §3.1; ICD §7): a
//!   changed waypoint list assembles again from its own messages into itself, with the same
//!   checksum (ICD §11); a changed area list assembles again with the same checksum; the staged
//!   missions likewise (ICD §8); a changed list has a newer generation, generations never go
//!   back, and both published lists carry the activation of the pair (docs/design.md "Activation
//!   is atomic") and show the active lists;
//! - every frame the FCC sends decodes and is addressed to the GCS;
//! - a deadline that fires does not stay due.
//!
//! At the end the FCC hears nothing for a minute: every deadline fires and none is left.

use core::time::Duration;

use missionlink_flight::mission_data_handling::{FccEvent, MissionDataHandling, Resumed};
use missionlink_flight::testkit;
use missionlink_interfaces::contracts::{AutomationStatePayload, GuidanceProgressPayload};
use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::transfer::areas::{AreaBuffer, AreaList};
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::{Mission, MissionBuffer};
use missionlink_protocol::transfer::staged::StagedMissions;

use crate::input::u16_at;
use crate::session::{self, Core, Session};

/// Record tags of this target (the tag byte modulo [`TAGS`]).
pub mod tag {
    pub use crate::session::tag::{RAW, SEND, TIME, WRAP};
    /// The GCS answers the FCC's last request.
    pub const ANSWER: u8 = 4;
    /// Automation state or guidance progress.
    pub const STATE: u8 = 5;
    /// The partition restarts.
    pub const RESTART: u8 = 6;
}

/// Kinds of records.
pub const TAGS: u8 = 7;

/// The entry point: panics only when an invariant of the module documentation is broken.
pub fn fcc(input: &[u8]) {
    let mut rig = Rig::new();
    session::run(&mut rig, input);
    let before = Lists::of(&rig.core.fcc);
    rig.advance(Duration::from_secs(60));
    before.check_against(&rig.core.fcc);
    assert_eq!(
        rig.core.fcc.poll_timeout(),
        None,
        "a deadline left after a minute of silence"
    );
}

/// The FCC, the GCS endpoint that talks to it, and what a driver keeps.
struct Rig {
    /// The FCC, the GCS endpoint (the peer), the clock, the FCC's last request.
    core: Core,
    /// Whether the driver holds the record "a mission upload is open" (restart safety, see
    /// `services/flight/src/mission_data_handling/`).
    upload_open: bool,
    progress: u64,
}

impl Rig {
    fn new() -> Self {
        let mut rig = Self {
            core: Core::new(<Self as Session>::PEER),
            upload_open: false,
            progress: 0,
        };
        // Navigation has the aircraft on the ground at TROL: the onboard geofence check of an
        // execute or an activation starts there.
        rig.state(&[1, 0, 1]);
        rig
    }

    /// Body `[kind, a, b, c, d, e, f, g]`: an even `kind` publishes automation's state (flight
    /// phase `a`, any value; `b` bit 0 trajectory generation active, bit 1 route reversed, bit
    /// 2 flying the active list, bit 3 guidance not alive; land at `c, d`); an odd one
    /// guidance's progress (near TROL, CCP or 0/0 by `a`, `b` bit 0 on ground, bit 1 trajectory
    /// generation active, offsets `c`, `d` in millidegrees, FROM `e`, TO `f`, NEXT `g`).
    fn state(&mut self, body: &[u8]) {
        let byte = |i: usize| body.get(i).copied().unwrap_or(0);
        let (kind, a, b) = (byte(0), byte(1), byte(2));
        let (list, _) = self.core.fcc.generations();
        if kind % 2 == 0 {
            self.core.fcc.set_automation_state(&AutomationStatePayload {
                flight_phase: a,
                trajectory_generation_active: b & 1 != 0,
                route_reversed: b & 2 != 0,
                flown_waypoint_list: if b & 4 != 0 { list } else { 0 },
                land_at: u16_at(body, 3),
                guidance_alive: b & 8 == 0,
                ..AutomationStatePayload::ON_GROUND
            });
        } else {
            let (lat, lon) = match a % 3 {
                0 => testkit::TROL,
                1 => testkit::CCP,
                _ => (0.0, 0.0),
            };
            self.progress += 1;
            let offset = |i: usize| f64::from(byte(i) as i8) * 1e-3;
            self.core.fcc.handle_progress(
                self.core.now,
                &GuidanceProgressPayload {
                    sequence: self.progress,
                    waypoint_list: list,
                    latitude_deg: lat + offset(3),
                    longitude_deg: lon + offset(4),
                    on_ground: b & 1 != 0,
                    trajectory_generation_active: b & 2 != 0,
                    from: u16::from(byte(5)),
                    to: u16::from(byte(6)),
                    next: u16::from(byte(7)),
                    ..GuidanceProgressPayload::IDLE
                },
            );
        }
        self.drain();
    }

    /// The partition restarts: a new mission data handling resumes with the lists, generations
    /// and staged missions its driver recorded, and the open-upload record (partitions'
    /// `state.rs`). `flags` bit 0: automation's and navigation's state are published again.
    fn restart(&mut self, flags: u8) {
        let resumed = Resumed {
            mission: self.core.fcc.active_mission().cloned(),
            mission_generation: self.core.fcc.generations().0,
            areas: self.core.fcc.active_areas().cloned(),
            area_generation: self.core.fcc.generations().1,
            mission_upload_open: self.upload_open,
            staged: self.core.fcc.staged().clone(),
        };
        self.core.fcc = MissionDataHandling::new(testkit::fcc_config());
        self.core.fcc.resume(self.core.now, resumed);
        self.core.request = None;
        if flags & 1 != 0 {
            self.state(&[1, 0, 1]);
        }
        self.drain();
    }
}

impl Session for Rig {
    const TAGS: u8 = TAGS;
    const ANSWER: u8 = tag::ANSWER;
    const PEER: (u32, u32) = (GCS_ID, FCC_ID);

    fn core(&self) -> &Core {
        &self.core
    }

    fn core_mut(&mut self) -> &mut Core {
        &mut self.core
    }

    fn next_deadline(&self) -> Option<Instant> {
        self.core.fcc.poll_timeout()
    }

    fn handle_timeout(&mut self) {
        self.core.fcc.handle_timeout(self.core.now);
    }

    /// Takes what the FCC sends and its events, as a driver does.
    fn drain(&mut self) {
        session::checked_frames(
            &mut self.core.fcc,
            ("FCC", "GCS"),
            (FCC_ID, GCS_ID),
            |_, envelope, message| {
                if envelope.ack_requested {
                    self.core.request = Some(message);
                }
            },
        );
        while let Some(event) = self.core.fcc.poll_event() {
            match event {
                FccEvent::MissionUploadOpened => self.upload_open = true,
                FccEvent::MissionUploadClosed => self.upload_open = false,
                FccEvent::MissionActivated { generation } => assert!(
                    generation <= self.core.fcc.generations().0,
                    "an activation announced under a generation not reached"
                ),
                FccEvent::AreasActivated { generation } => assert!(
                    generation <= self.core.fcc.generations().1,
                    "an activation announced under a generation not reached"
                ),
                _ => {}
            }
        }
    }

    fn hand(&mut self, frame: &[u8]) {
        // A frame error is the driver's to count; nothing else to check here.
        let _ = self.core.fcc.handle_frame(self.core.now, frame);
        self.drain();
    }

    fn other(&mut self, record: u8, body: &[u8]) {
        match record {
            tag::STATE => self.state(body),
            _ => self.restart(body.first().copied().unwrap_or(0)),
        }
    }
}

/// The lists of mission data handling at one moment.
pub(crate) struct Lists {
    mission: Option<Mission>,
    areas: Option<AreaList>,
    generations: (u64, u64),
    staged: StagedMissions,
}

impl Lists {
    pub(crate) fn of(fcc: &MissionDataHandling) -> Self {
        Self {
            mission: fcc.active_mission().cloned(),
            areas: fcc.active_areas().cloned(),
            generations: fcc.generations(),
            staged: fcc.staged().clone(),
        }
    }

    /// The invariants of the module documentation, `self` being the lists before the step.
    pub(crate) fn check_against(&self, fcc: &MissionDataHandling) {
        let after = Self::of(fcc);
        let (mission_gen, area_gen) = after.generations;
        assert!(
            mission_gen >= self.generations.0 && area_gen >= self.generations.1,
            "a generation went back: {:?} -> {:?}",
            self.generations,
            after.generations
        );
        if after.mission != self.mission {
            assert!(
                mission_gen > self.generations.0,
                "a new waypoint list under an old generation"
            );
            if let Some(m) = &after.mission {
                check_mission(m);
            }
        }
        if after.areas != self.areas {
            assert!(
                area_gen > self.generations.1,
                "a new area list under an old generation"
            );
            if let Some(a) = &after.areas {
                check_areas(a);
            }
        }
        if after.staged != self.staged {
            for staged in after.staged.iter() {
                if let Some(m) = &staged.mission {
                    check_mission(m);
                }
                if let Some(a) = &staged.areas {
                    check_areas(a);
                }
            }
        }
        check_published(fcc);
    }
}

/// A waypoint list is whole and valid: its own messages assemble into it (ICD §7), and the
/// checksum of ICD §11 agrees.
pub fn check_mission(mission: &Mission) {
    let count = u16::try_from(mission.waypoints.len()).unwrap_or(u16::MAX);
    let again = MissionBuffer::from_mission(mission)
        .assemble(Some(count), mission.mission_id)
        .unwrap_or_else(|r| panic!("an active or staged mission does not assemble: {r}"));
    assert_eq!(
        &again, mission,
        "a mission that is not the list its messages make"
    );
    assert_eq!(mission_checksum(&again), mission_checksum(mission));
}

/// An area list is whole and valid: its areas, stored again, assemble (ICD §7) to a list with
/// the same checksum (ICD §11).
pub fn check_areas(list: &AreaList) {
    let mut buffer = AreaBuffer::new();
    for area in &list.areas {
        assert!(buffer.store(area).is_ok(), "more areas than a list holds");
    }
    assert_eq!(buffer.len(), list.areas.len(), "an Area ID twice in a list");
    let count = u8::try_from(list.areas.len()).unwrap_or(u8::MAX);
    let again = buffer
        .assemble(count, list.safety_offset)
        .unwrap_or_else(|r| panic!("an active or staged area list does not assemble: {r}"));
    assert_eq!(areas_checksum(&again), areas_checksum(list));
}

/// The published lists show the active ones, under their generations and one activation.
fn check_published(fcc: &MissionDataHandling) {
    let (mission_gen, area_gen) = fcc.generations();
    let (waypoints, areas) = (fcc.waypoint_list(), fcc.area_list());
    assert_eq!(
        waypoints.generation, mission_gen,
        "waypoint list generation"
    );
    assert_eq!(areas.generation, area_gen, "area list generation");
    assert_eq!(
        (waypoints.activation, areas.activation),
        (mission_gen + area_gen, mission_gen + area_gen),
        "the published lists carry different activations"
    );
    match fcc.active_mission() {
        Some(m) => {
            let expected = m.to_payload(mission_gen);
            assert_eq!(
                waypoints.waypoints(),
                expected.waypoints(),
                "published waypoints"
            );
            assert_eq!(
                (
                    waypoints.take_off_height,
                    waypoints.initial_waypoint,
                    waypoints.bidirectional
                ),
                (
                    expected.take_off_height,
                    expected.initial_waypoint,
                    expected.bidirectional
                ),
                "published route"
            );
        }
        None => assert_eq!(
            waypoints.count, 0,
            "a waypoint list published without a mission"
        ),
    }
    match fcc.active_areas() {
        Some(a) => {
            let expected = a.to_payload(area_gen);
            assert!(
                areas.safety_offset == expected.safety_offset
                    && areas.fly_zone == expected.fly_zone
                    && areas.no_fly_polygon_count == expected.no_fly_polygon_count
                    && areas.no_fly_circle_count == expected.no_fly_circle_count
                    && areas.no_fly_polygons == expected.no_fly_polygons
                    && areas.no_fly_circles == expected.no_fly_circles,
                "the published area list is not the active one"
            );
        }
        None => assert!(
            areas.no_fly_polygon_count == 0 && areas.no_fly_circle_count == 0,
            "an area list published without areas"
        ),
    }
}
