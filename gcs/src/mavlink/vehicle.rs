//! The MAVLink side of `gcs mavlink`, sans-IO: a state machine that reads the client's MAVLink 2
//! messages, writes the vehicle's, and owns its deadlines in a timer table (heartbeat, the item
//! request of an upload in progress, the commit of a mission that waits for its fence). Time is
//! injected; the driver moves datagrams, hands over the downlink's positions and FROM-TO-NEXT,
//! and carries out the [`VehicleEvent`]s on the GCS link (the safety gateway, the atomic upload,
//! execute), reporting each outcome back.
//!
//! # The vehicle it presents
//!
//! System 1, component 1 (MAV_COMP_ID_AUTOPILOT1), HEARTBEAT once a second as MAV_TYPE 22 (VTOL
//! with separate lift and cruise rotors, the demo eVTOL) and MAV_AUTOPILOT_PX4 with PX4's custom
//! mode (AUTO.MISSION while the mission flies, AUTO.LOITER otherwise): the encoding MAVSDK,
//! MAVProxy and QGroundControl all name, where a generic autopilot's mode has no name;
//! EXTENDED_SYS_STATE with it;
//! AUTOPILOT_VERSION with MISSION_INT, MISSION_FENCE and MAVLINK2; a parameter list that holds
//! nothing of the FCC's (it has no MAVLink parameters) but one read-only `MLNK_VERSION`: a
//! client reads a list until it holds `param_count` values, and a list of none cannot be told
//! from a lost answer;
//! GLOBAL_POSITION_INT from each #101 of the downlink; MISSION_CURRENT and MISSION_ITEM_REACHED
//! from each #4001; STATUSTEXT for what the operator must read.
//!
//! # Addressing
//!
//! MAVLink's routing rules: every reply (MISSION_REQUEST_INT, MISSION_ACK, MISSION_COUNT,
//! MISSION_ITEM_INT, COMMAND_ACK) is addressed to the system and component of the message that
//! asked; the vehicle's own messages are broadcast; commands and mission traffic addressed to
//! another system or component are ignored (counted in [`Vehicle::elsewhere`]).
//!
//! # Mission and fence, committed as one
//!
//! QGroundControl uploads the mission, then the fence, then rally points, each after the
//! previous MISSION_ACK. The FCC takes mission and areas as one atomic upload, so the vehicle
//! answers in time and commits once:
//!
//! 1. A complete **mission** upload is converted with the fence the vehicle holds ([`plan`]'s
//!    rules, those of a `.plan` import). Refused: MISSION_ACK with an error and a STATUSTEXT
//!    naming the item and the violation; nothing changes. Accepted as the pending half of a
//!    plan: MISSION_ACK ACCEPTED at once, and the commit waits [`VehicleConfig::fence_wait`] for
//!    a fence upload.
//! 2. A complete **fence** upload (within the wait, or alone) makes the pair (the pending
//!    mission, else the mission held) a plan and commits it ([`VehicleEvent::Commit`]); its
//!    MISSION_ACK is held until the FCC confirmed both lists: ACCEPTED, or an error with a
//!    STATUSTEXT naming the violation or the failure (the FCC's lists stay as they were).
//! 3. No fence within the wait: the pending mission is committed with the fence held (the
//!    areas the FCC holds); a failure is a STATUSTEXT (the MISSION_ACK was sent).
//!    Without a mission held or pending, a fence is held (ACCEPTED, and a STATUSTEXT says so)
//!    and goes to the FCC with the next mission.
//! 4. **Rally points**: an empty list is accepted; points are refused (MAV_MISSION_UNSUPPORTED
//!    and a STATUSTEXT: the ICD has none).
//!
//! MAV_CMD_MISSION_START is execute (#50000 command 1), and so is MAV_CMD_DO_SET_MODE to the
//! mission mode (PX4's AUTO.MISSION, main mode 4, sub mode 4); a pending mission is committed
//! first. Hold (AUTO.LOITER) on the ground is accepted (it is the mode); other modes are
//! unsupported. MISSION_CLEAR_ALL is the FCC's clear of the mission (#13000 mode 1) or of the
//! areas (#2011 mode 6), refused as the FCC refuses it, with the reason in a STATUSTEXT.

use std::collections::VecDeque;

use core::time::Duration;

use mavlink::dialects::common::{
    ATTITUDE_DATA, AUTOPILOT_VERSION_DATA, COMMAND_ACK_DATA, EXTENDED_SYS_STATE_DATA,
    GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA, HOME_POSITION_DATA, MISSION_ACK_DATA,
    MISSION_COUNT_DATA, MISSION_CURRENT_DATA, MISSION_ITEM_INT_DATA, MISSION_ITEM_REACHED_DATA,
    MISSION_REQUEST_INT_DATA, MavAutopilot, MavCmd, MavFrame, MavLandedState, MavMessage,
    MavMissionResult, MavMissionType, MavModeFlag, MavParamType, MavProtocolCapability, MavResult,
    MavSeverity, MavState, MavSysStatusSensor, MavSysStatusSensorExtended, MavType, MavVtolState,
    MissionState, PARAM_VALUE_DATA, STATUSTEXT_DATA, SYS_STATUS_DATA, VFR_HUD_DATA,
};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use missionlink_interfaces::wire::{AltitudeType, FromToNext, InertialStates};
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::link::timer::TimerTable;
use num_traits::FromPrimitive;

use super::home::{Home, amsl_m};
use super::memory::Memory;
use super::plan::{Item, List, PlanContext, to_plan};
use crate::qgc::QgcImport;

/// The system ID of the one vehicle of `gcs mavlink` (the ground service gives each vehicle of a
/// fleet its own, [`VehicleConfig::system_id`]).
pub const SYSTEM_ID: u8 = 1;
/// MAV_COMP_ID_AUTOPILOT1.
pub const COMPONENT_ID: u8 = 1;
/// PX4's custom main mode AUTO (px4_custom_mode.h): the family of modes the FCC flies in.
const PX4_MAIN_AUTO: u32 = 4;
/// PX4's AUTO sub mode LOITER: "Hold", the vehicle waits (on the ground, or after the mission).
const PX4_SUB_LOITER: u32 = 3;
/// PX4's AUTO sub mode MISSION: the vehicle flies its mission.
const PX4_SUB_MISSION: u32 = 4;

/// PX4's custom_mode: the main mode in bits 16..24, the sub mode in bits 24..32.
const fn px4_mode(main: u32, sub: u32) -> u32 {
    (main << 16) | (sub << 24)
}

/// The message IDs REQUEST_MESSAGE asks for that the vehicle sends.
const HEARTBEAT_ID: u32 = 0;
const SYS_STATUS_ID: u32 = 1;
const MISSION_CURRENT_ID: u32 = 42;
const AUTOPILOT_VERSION_ID: u32 = 148;
const HOME_POSITION_ID: u32 = 242;
const EXTENDED_SYS_STATE_ID: u32 = 245;

/// Items the vehicle holds per list (the FCC holds 256 waypoints; a mission item list has a
/// take-off, speed changes and a land besides).
pub const MAX_ITEMS: u16 = 1024;

/// The longest STATUSTEXT sent, in bytes: 20 chunks. Longer texts are cut (the vehicle's texts
/// are its own; only a gateway report that names many violations comes near).
pub const STATUSTEXT_MAX: usize = 1000;

/// Settings of the vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleConfig {
    /// The vehicle's MAVLink system ID, 1..=255.
    pub system_id: u8,
    /// HEARTBEAT period (MAVLink: 1 Hz).
    pub heartbeat: Duration,
    /// How long an upload waits for the item it requested before it asks again (MAVLink's
    /// mission protocol: 1.5 s is the client's own default for its retries).
    pub item_timeout: Duration,
    /// How many times an item is asked for before the upload is abandoned.
    pub item_retries: u8,
    /// How long an accepted mission waits for a fence upload before it is committed alone.
    pub fence_wait: Duration,
    /// What the `.plan` import needs that MAVLink items do not say.
    pub plan: PlanContext,
}

impl VehicleConfig {
    /// The vehicle `gcs mavlink` and the ground service present: system `system_id`, MAVLink's
    /// 1 Hz heartbeat, an item asked for again after 1.5 s and up to 3 times, the mission
    /// waiting `fence_wait` for its fence, waypoints before any speed change at
    /// `cruise_speed_mps`.
    pub fn standard(system_id: u8, fence_wait: Duration, cruise_speed_mps: f64) -> Self {
        Self {
            system_id,
            heartbeat: Duration::from_secs(1),
            item_timeout: Duration::from_millis(1500),
            item_retries: 3,
            fence_wait,
            plan: PlanContext {
                cruise_speed_mps,
                home: None,
                import: crate::qgc::ImportOptions::default(),
            },
        }
    }
}

/// What the driver must carry out on the GCS link, then report back.
#[derive(Debug, Clone)]
pub enum VehicleEvent {
    /// Validate `plan` (the safety gateway) and upload it atomically; report with
    /// [`Vehicle::committed`].
    Commit {
        /// The plan, converted by the `.plan` import's rules.
        plan: Box<QgcImport>,
    },
    /// Send #50000 execute; report with [`Vehicle::executed`].
    Execute,
    /// Carry out the FCC's clear of `list` (the mission: #13000 mode 1, which deletes the
    /// active mission; the fence: #2011 mode 6, which removes the areas); report with
    /// [`Vehicle::cleared`].
    Clear {
        /// Which list.
        list: List,
    },
}

/// A MISSION_CLEAR_ALL being carried out: whom it answers, and how it went so far.
#[derive(Debug, Clone)]
struct Clearing {
    peer: Peer,
    kind: MavMissionType,
    /// Clears not yet reported (two for MAV_MISSION_TYPE_ALL).
    left: u8,
    /// The first refusal, in the operator's words.
    refused: Option<String>,
}

missionlink_protocol::timers! {
    /// The timers of the vehicle.
    pub enum VehicleTimer {
        /// The next HEARTBEAT.
        Heartbeat,
        /// The item an upload requested is overdue.
        Item,
        /// The pending mission is committed without a fence.
        FenceWait,
    }
}

/// A client by its MAVLink address: the system and component of a message that asked, to which
/// its answer goes (MAVLink's routing rules: a reply is addressed to the requester; a client
/// such as MAVProxy drops mission requests and acks addressed to any system but its own).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Peer {
    /// The client's system ID.
    pub system: u8,
    /// The client's component ID.
    pub component: u8,
}

/// Degrees as MAVLink's integer latitude and longitude (degE7).
fn e7(degrees: f64) -> i32 {
    (degrees * 1e7).round() as i32
}

/// Metres as MAVLink's integer millimetres.
fn mm(metres: f64) -> i32 {
    (metres * 1000.0).round() as i32
}

/// The system and component a client's message is addressed to, for the messages that name
/// one (MAVLink's routing rules): commands, parameter requests and the mission protocol.
#[allow(
    deprecated,
    reason = "MISSION_REQUEST and MISSION_SET_CURRENT are superseded; older clients still send them"
)]
pub fn target(message: &MavMessage) -> Option<(u8, u8)> {
    match message {
        MavMessage::COMMAND_LONG(c) => Some((c.target_system, c.target_component)),
        MavMessage::COMMAND_INT(c) => Some((c.target_system, c.target_component)),
        MavMessage::PARAM_REQUEST_LIST(r) => Some((r.target_system, r.target_component)),
        MavMessage::PARAM_REQUEST_READ(r) => Some((r.target_system, r.target_component)),
        MavMessage::MISSION_REQUEST_LIST(r) => Some((r.target_system, r.target_component)),
        MavMessage::MISSION_REQUEST(r) => Some((r.target_system, r.target_component)),
        MavMessage::MISSION_REQUEST_INT(r) => Some((r.target_system, r.target_component)),
        MavMessage::MISSION_COUNT(c) => Some((c.target_system, c.target_component)),
        MavMessage::MISSION_ITEM_INT(i) => Some((i.target_system, i.target_component)),
        MavMessage::MISSION_CLEAR_ALL(c) => Some((c.target_system, c.target_component)),
        MavMessage::MISSION_SET_CURRENT(c) => Some((c.target_system, c.target_component)),
        MavMessage::MISSION_ACK(a) => Some((a.target_system, a.target_component)),
        _ => None,
    }
}

/// An upload from the client in progress.
#[derive(Debug, Clone)]
struct Upload {
    /// Who uploads: items are taken from it alone, requests and the ack go to it.
    peer: Peer,
    kind: MavMissionType,
    count: u16,
    items: Vec<Item>,
    retries: u8,
}

/// What a commit in progress answers when it ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Waiting {
    /// The MISSION_ACK of a fence upload.
    FenceAck,
    /// Nothing: the mission's ACK went out.
    Nothing,
    /// Execute after the commit.
    Execute,
}

/// The MAVLink vehicle of `gcs mavlink`.
#[derive(Debug)]
pub struct Vehicle {
    config: VehicleConfig,
    timers: TimerTable<VehicleTimer, 3>,
    sequence: u8,
    outbox: VecDeque<MavMessage>,
    events: VecDeque<VehicleEvent>,
    /// The lists as the FCC holds them (the last commit, or what the driver read at start).
    mission: Vec<Item>,
    fence: Vec<Item>,
    /// An accepted mission waiting for its fence.
    pending: Option<Vec<Item>>,
    upload: Option<Upload>,
    /// The lists of the commit in progress, what its end answers, and to whom.
    committing: Option<(Vec<Item>, Vec<Item>, Waiting, Peer)>,
    /// Execute asked while nothing was to commit: waiting for its outcome.
    executing: bool,
    /// A clear being carried out.
    clearing: Option<Clearing>,
    /// The command that asked for execute and who sent it, for its COMMAND_ACK.
    start_command: (MavCmd, Peer),
    /// The mission item the aircraft flies to (MISSION_CURRENT).
    current: u16,
    /// The mission items reported reached (MISSION_ITEM_REACHED) in this flight: all below it.
    reached: u16,
    /// The ICD §11 checksums of the lists the FCC holds (MISSION_CURRENT's mission_id and
    /// fence_id; 0, MAVLink's "unknown", for none).
    ids: (u32, u32),
    state: MissionState,
    booted: Option<Instant>,
    /// MAVLink datagrams that did not parse, counted (a flood costs counters, not lines).
    pub unreadable: u64,
    /// Commands and mission messages addressed to another system or component, or from a
    /// system ID MAVLink 2 cannot carry, ignored and counted.
    pub elsewhere: u64,
    /// The id of the last STATUSTEXT sent in chunks (0 is a text of one message).
    statustext_id: u16,
    /// The vehicle's home, once a position told it.
    home: Option<Home>,
    /// The home last sent in HOME_POSITION.
    home_sent: Option<Home>,
    /// Messages of the data links as the ground received them: (all, rejected), for
    /// SYS_STATUS.
    link_counts: (u64, u64),
    /// What the vehicle must remember across a restart changed (see [`Self::memory`]).
    remember: bool,
}

impl Vehicle {
    /// A vehicle that holds no lists yet.
    pub fn new(config: VehicleConfig) -> Self {
        Self {
            config,
            timers: TimerTable::new(),
            sequence: 0,
            outbox: VecDeque::new(),
            events: VecDeque::new(),
            mission: Vec::new(),
            fence: Vec::new(),
            pending: None,
            upload: None,
            committing: None,
            executing: false,
            clearing: None,
            start_command: (MavCmd::MAV_CMD_MISSION_START, Peer::default()),
            current: 0,
            reached: 0,
            ids: (0, 0),
            state: MissionState::MISSION_STATE_NO_MISSION,
            booted: None,
            unreadable: 0,
            elsewhere: 0,
            statustext_id: 0,
            home: None,
            home_sent: None,
            link_counts: (0, 0),
            remember: false,
        }
    }

    /// The lists the FCC holds, as items (read by the driver at start, from a download).
    pub fn set_lists(&mut self, mission: Vec<Item>, fence: Vec<Item>) {
        self.state = if mission.is_empty() {
            MissionState::MISSION_STATE_NO_MISSION
        } else {
            MissionState::MISSION_STATE_NOT_STARTED
        };
        self.mission = mission;
        self.fence = fence;
    }

    /// The ICD §11 checksums of the lists the FCC holds, mission and areas (what it confirmed
    /// of an upload, or computed from a download), for MISSION_CURRENT's mission_id and
    /// fence_id: a client sees by them that the vehicle's plan changed.
    pub fn set_ids(&mut self, mission_id: u32, fence_id: u32) {
        self.ids = (mission_id, fence_id);
        self.remember = true;
    }

    /// What changed since the last call and must be remembered across a restart, if
    /// anything: the lists as the client uploaded them under the checksums the FCC confirmed,
    /// and the home (the driver writes it to the state directory).
    pub fn memory(&mut self) -> Option<Memory> {
        if !core::mem::take(&mut self.remember) {
            return None;
        }
        Some(Memory {
            ids: self.ids,
            mission: self.mission.clone(),
            fence: self.fence.clone(),
            home: self.home,
        })
    }

    /// What a previous run remembered, after the FCC's lists were read ([`Self::set_lists`],
    /// [`Self::set_ids`]): its items stand for the FCC's lists when the FCC still holds the
    /// lists they were committed as (the same checksums; not for a mission or fence the FCC
    /// does not hold, checksum 0), so a download returns what the client uploaded. Its home
    /// is the vehicle's until a position moves it.
    pub fn recall(&mut self, memory: Memory) {
        if memory.ids == self.ids {
            if self.ids.0 != 0 {
                self.mission = memory.mission;
            }
            if self.ids.1 != 0 {
                self.fence = memory.fence;
            }
        }
        if let Some(home) = memory.home {
            self.set_home(home);
        }
        self.remember = false;
    }

    /// The lists as held: (mission, fence).
    pub fn lists(&self) -> (&[Item], &[Item]) {
        (&self.mission, &self.fence)
    }

    fn list(&self, kind: MavMissionType) -> Option<&[Item]> {
        match kind {
            MavMissionType::MAV_MISSION_TYPE_MISSION => Some(&self.mission),
            MavMissionType::MAV_MISSION_TYPE_FENCE => Some(&self.fence),
            _ => None,
        }
    }

    /// Starts the heartbeat at `now`.
    pub fn start(&mut self, now: Instant) {
        self.booted = Some(now);
        self.timers.set(VehicleTimer::Heartbeat, now);
    }

    /// One datagram from the client, at `now`: every MAVLink message in it.
    pub fn handle_datagram(&mut self, now: Instant, datagram: &[u8]) {
        let messages = read_datagram(datagram);
        if messages.is_empty() {
            self.unreadable += 1;
        }
        for (header, message) in &messages {
            self.handle(now, *header, message);
        }
    }

    /// One message from the client.
    #[allow(
        deprecated,
        reason = "MISSION_REQUEST is answered as MISSION_REQUEST_INT, as MAVLink asks of a \
                  vehicle that gets one; older clients still send it"
    )]
    pub fn handle(&mut self, now: Instant, header: MavHeader, message: &MavMessage) {
        let Ok(system) = u8::try_from(header.system_id) else {
            self.elsewhere += 1;
            return;
        };
        let from = Peer {
            system,
            component: header.component_id,
        };
        // The message's own target, for those that have one: traffic for another system or
        // component is not ours to answer (MAVLink's routing rules); 0 is everyone's.
        let system_id = self.config.system_id;
        let for_us = |(system, component): (u8, u8)| {
            (system == 0 || system == system_id) && (component == 0 || component == COMPONENT_ID)
        };
        if target(message).is_some_and(|t| !for_us(t)) {
            self.elsewhere += 1;
            return;
        }
        match message {
            MavMessage::HEARTBEAT(_) => {}
            MavMessage::COMMAND_LONG(c) => {
                self.command(now, from, c.command, [c.param1, c.param2, c.param3])
            }
            MavMessage::COMMAND_INT(c) => {
                self.command(now, from, c.command, [c.param1, c.param2, c.param3])
            }
            MavMessage::PARAM_REQUEST_LIST(_) | MavMessage::PARAM_REQUEST_READ(_) => {
                // PARAM_VALUE is broadcast: MAVLink's parameter protocol sends it to all.
                self.send(MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
                    param_value: 1.0,
                    param_count: 1,
                    param_index: 0,
                    param_id: "MLNK_VERSION".into(),
                    param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
                }));
            }
            MavMessage::MISSION_REQUEST_LIST(r) => self.request_list(from, r.mission_type),
            MavMessage::MISSION_REQUEST_INT(r) => self.send_item(from, r.mission_type, r.seq),
            MavMessage::MISSION_REQUEST(r) => self.send_item(from, r.mission_type, r.seq),
            MavMessage::MISSION_COUNT(c) => self.count(now, from, c),
            MavMessage::MISSION_ITEM_INT(i) => self.item(now, from, i),
            MavMessage::MISSION_CLEAR_ALL(c) => self.clear(from, c.mission_type),
            // The end of a download, or anything else a client sends: nothing to do.
            _ => {}
        }
    }

    #[allow(
        deprecated,
        reason = "REQUEST_AUTOPILOT_CAPABILITIES is superseded, not gone: clients still send it"
    )]
    fn command(&mut self, now: Instant, from: Peer, command: MavCmd, params: [f32; 3]) {
        let [param1, param2, param3] = params;
        let result = match command {
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                self.autopilot_version();
                MavResult::MAV_RESULT_ACCEPTED
            }
            MavCmd::MAV_CMD_REQUEST_MESSAGE => {
                self.request_message((command, from), param1 as u32);
                return;
            }
            // The superseded form of REQUEST_MESSAGE(HOME_POSITION) that MAVProxy sends.
            MavCmd::MAV_CMD_GET_HOME_POSITION => {
                self.request_message((command, from), HOME_POSITION_ID);
                return;
            }
            MavCmd::MAV_CMD_MISSION_START => {
                self.execute_for(now, (MavCmd::MAV_CMD_MISSION_START, from));
                return;
            }
            // The mission mode (PX4's AUTO.MISSION, what MAVSDK sends to start a mission and
            // MAVProxy's `mode MISSION`) is execute too.
            MavCmd::MAV_CMD_DO_SET_MODE
                if param2 as u32 == PX4_MAIN_AUTO && param3 as u32 == PX4_SUB_MISSION =>
            {
                self.execute_for(now, (MavCmd::MAV_CMD_DO_SET_MODE, from));
                return;
            }
            // Hold is what the vehicle does when no mission flies: nothing to change.
            MavCmd::MAV_CMD_DO_SET_MODE
                if param2 as u32 == PX4_MAIN_AUTO
                    && param3 as u32 == PX4_SUB_LOITER
                    && self.state != MissionState::MISSION_STATE_ACTIVE =>
            {
                MavResult::MAV_RESULT_ACCEPTED
            }
            // The FCC has no other mode to switch to (return and land are its #50000 commands).
            MavCmd::MAV_CMD_DO_SET_MODE => MavResult::MAV_RESULT_UNSUPPORTED,
            _ => MavResult::MAV_RESULT_UNSUPPORTED,
        };
        self.command_ack((command, from), result);
    }

    /// MAV_CMD_REQUEST_MESSAGE: COMMAND_ACK, then the message, for the messages the vehicle
    /// sends; HOME_POSITION is temporarily rejected until a position with an altitude above
    /// mean sea level told the home (a client asks again); any other message is unsupported.
    fn request_message(&mut self, command: (MavCmd, Peer), id: u32) {
        let send: fn(&mut Self) = match id {
            HEARTBEAT_ID => Self::heartbeat,
            SYS_STATUS_ID => Self::sys_status,
            MISSION_CURRENT_ID => Self::mission_current,
            AUTOPILOT_VERSION_ID => Self::autopilot_version,
            HOME_POSITION_ID if self.home.and_then(|h| h.amsl_m()).is_some() => Self::home_position,
            HOME_POSITION_ID => {
                self.command_ack(command, MavResult::MAV_RESULT_TEMPORARILY_REJECTED);
                return;
            }
            EXTENDED_SYS_STATE_ID => Self::extended_sys_state,
            _ => {
                self.command_ack(command, MavResult::MAV_RESULT_UNSUPPORTED);
                return;
            }
        };
        self.command_ack(command, MavResult::MAV_RESULT_ACCEPTED);
        send(self);
    }

    fn command_ack(&mut self, (command, to): (MavCmd, Peer), result: MavResult) {
        self.send(MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command,
            result,
            progress: 0,
            result_param2: 0,
            target_system: to.system,
            target_component: to.component,
        }));
    }

    fn autopilot_version(&mut self) {
        self.send(MavMessage::AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA {
            capabilities: MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MISSION_INT
                | MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MISSION_FENCE
                | MavProtocolCapability::MAV_PROTOCOL_CAPABILITY_MAVLINK2,
            uid: 0,
            flight_sw_version: 0,
            middleware_sw_version: 0,
            os_sw_version: 0,
            board_version: 0,
            vendor_id: 0,
            product_id: 0,
            flight_custom_version: [0; 8],
            middleware_custom_version: [0; 8],
            os_custom_version: [0; 8],
            uid2: [0; 18],
        }));
    }

    fn execute_for(&mut self, now: Instant, command: (MavCmd, Peer)) {
        self.start_command = command;
        if let Some(mission) = self.pending.take() {
            self.timers.stop(VehicleTimer::FenceWait);
            let fence = self.fence.clone();
            self.commit(now, mission, fence, Waiting::Execute, command.1);
        } else if self.committing.is_some() {
            if let Some((_, _, waiting, _)) = &mut self.committing {
                *waiting = Waiting::Execute;
            }
        } else {
            self.executing = true;
            self.events.push_back(VehicleEvent::Execute);
        }
    }

    /// The outcome of [`VehicleEvent::Execute`]: COMMAND_ACK, and a STATUSTEXT why not.
    pub fn executed(&mut self, outcome: Result<(), String>) {
        self.executing = false;
        match outcome {
            Ok(()) => {
                self.state = MissionState::MISSION_STATE_ACTIVE;
                self.current = 0;
                self.reached = 0;
                self.command_ack(self.start_command, MavResult::MAV_RESULT_ACCEPTED);
            }
            Err(why) => {
                self.command_ack(self.start_command, MavResult::MAV_RESULT_DENIED);
                self.statustext(
                    MavSeverity::MAV_SEVERITY_ERROR,
                    &format!("execute refused: {why}"),
                );
            }
        }
    }

    /// MISSION_CLEAR_ALL: the FCC's own clears, which it refuses as it refuses them to any GCS
    /// (while the aircraft flies, during a transfer); rally points are none already.
    fn clear(&mut self, from: Peer, kind: MavMissionType) {
        let lists: &[List] = match kind {
            MavMissionType::MAV_MISSION_TYPE_MISSION => &[List::Mission],
            MavMissionType::MAV_MISSION_TYPE_FENCE => &[List::Fence],
            MavMissionType::MAV_MISSION_TYPE_ALL => &[List::Mission, List::Fence],
            _ => {
                self.ack(from, kind, MavMissionResult::MAV_MISSION_ACCEPTED);
                return;
            }
        };
        if self.busy() || self.clearing.is_some() {
            self.refuse(
                from,
                kind,
                "the clear waits for the upload, execute or clear in progress: try again",
            );
            return;
        }
        self.clearing = Some(Clearing {
            peer: from,
            kind,
            left: u8::try_from(lists.len()).unwrap_or(u8::MAX),
            refused: None,
        });
        for list in lists {
            self.events.push_back(VehicleEvent::Clear { list: *list });
        }
    }

    /// The outcome of [`VehicleEvent::Clear`] of `list`: the FCC cleared it, or why not. The
    /// MISSION_ACK goes out when every list of the MISSION_CLEAR_ALL is reported.
    pub fn cleared(&mut self, list: List, outcome: Result<(), String>) {
        let Some(clearing) = &mut self.clearing else {
            return;
        };
        clearing.left = clearing.left.saturating_sub(1);
        if outcome.is_ok() {
            self.remember = true;
        }
        match outcome {
            Ok(()) => match list {
                List::Mission => {
                    self.mission.clear();
                    self.ids.0 = 0;
                    self.pending = None;
                    self.timers.stop(VehicleTimer::FenceWait);
                    self.current = 0;
                    self.state = MissionState::MISSION_STATE_NO_MISSION;
                }
                List::Fence => {
                    self.fence.clear();
                    self.ids.1 = 0;
                }
            },
            Err(why) => {
                if clearing.refused.is_none() {
                    clearing.refused = Some(format!("{list} not cleared: {why}"));
                }
            }
        }
        if clearing.left > 0 {
            return;
        }
        let Some(done) = self.clearing.take() else {
            return;
        };
        match done.refused {
            None => {
                self.statustext(MavSeverity::MAV_SEVERITY_INFO, "cleared on the FCC");
                self.ack(done.peer, done.kind, MavMissionResult::MAV_MISSION_ACCEPTED);
            }
            Some(why) => {
                self.statustext(MavSeverity::MAV_SEVERITY_ERROR, &why);
                self.ack(done.peer, done.kind, MavMissionResult::MAV_MISSION_DENIED);
            }
        }
    }

    fn request_list(&mut self, to: Peer, kind: MavMissionType) {
        let count = self.list(kind).map_or(0, |l| l.len());
        self.send(MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: u16::try_from(count).unwrap_or(u16::MAX),
            target_system: to.system,
            target_component: to.component,
            mission_type: kind,
            opaque_id: 0,
        }));
    }

    fn send_item(&mut self, to: Peer, kind: MavMissionType, seq: u16) {
        let item = self
            .list(kind)
            .and_then(|l| l.get(usize::from(seq)))
            .copied();
        match item {
            Some(item) => self.send(MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA {
                param1: item.params[0],
                param2: item.params[1],
                param3: item.params[2],
                param4: item.params[3],
                x: item.x,
                y: item.y,
                z: item.z,
                seq,
                command: MavCmd::from_u16(item.command).unwrap_or_default(),
                target_system: to.system,
                target_component: to.component,
                frame: MavFrame::from_u8(item.frame).unwrap_or_default(),
                current: u8::from(seq == 0),
                autocontinue: 1,
                mission_type: kind,
            })),
            None => self.ack(to, kind, MavMissionResult::MAV_MISSION_INVALID_SEQUENCE),
        }
    }

    fn ack(&mut self, to: Peer, kind: MavMissionType, result: MavMissionResult) {
        self.send(MavMessage::MISSION_ACK(MISSION_ACK_DATA {
            target_system: to.system,
            target_component: to.component,
            mavtype: result,
            mission_type: kind,
            opaque_id: 0,
        }));
    }

    fn count(&mut self, now: Instant, from: Peer, c: &MISSION_COUNT_DATA) {
        match c.mission_type {
            MavMissionType::MAV_MISSION_TYPE_MISSION | MavMissionType::MAV_MISSION_TYPE_FENCE => {}
            MavMissionType::MAV_MISSION_TYPE_RALLY if c.count == 0 => {
                self.ack(from, c.mission_type, MavMissionResult::MAV_MISSION_ACCEPTED);
                return;
            }
            other => {
                self.ack(from, other, MavMissionResult::MAV_MISSION_UNSUPPORTED);
                self.statustext(
                    MavSeverity::MAV_SEVERITY_WARNING,
                    "rally points are not supported (the ICD has none)",
                );
                return;
            }
        }
        if c.count > MAX_ITEMS {
            self.ack(from, c.mission_type, MavMissionResult::MAV_MISSION_NO_SPACE);
            return;
        }
        self.upload = Some(Upload {
            peer: from,
            kind: c.mission_type,
            count: c.count,
            items: Vec::with_capacity(usize::from(c.count)),
            retries: 0,
        });
        if c.count == 0 {
            self.upload_complete(now);
        } else {
            self.request_next(now);
        }
    }

    fn request_next(&mut self, now: Instant) {
        let Some(u) = &self.upload else {
            return;
        };
        let seq = u16::try_from(u.items.len()).unwrap_or(u16::MAX);
        let kind = u.kind;
        let to = u.peer;
        self.send(MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq,
            target_system: to.system,
            target_component: to.component,
            mission_type: kind,
        }));
        self.timers
            .set(VehicleTimer::Item, now + self.config.item_timeout);
    }

    fn item(&mut self, now: Instant, from: Peer, i: &MISSION_ITEM_INT_DATA) {
        let Some(u) = &mut self.upload else {
            return;
        };
        if from != u.peer {
            // Another client's item is not part of this upload.
            return;
        }
        if i.mission_type != u.kind || usize::from(i.seq) != u.items.len() {
            // A repeat of an item already taken, or one out of order: ask for the right one.
            return;
        }
        u.items.push(Item {
            command: i.command as u16,
            frame: i.frame as u8,
            params: [i.param1, i.param2, i.param3, i.param4],
            x: i.x,
            y: i.y,
            z: i.z,
        });
        u.retries = 0;
        if u.items.len() == usize::from(u.count) {
            self.timers.stop(VehicleTimer::Item);
            self.upload_complete(now);
        } else {
            self.request_next(now);
        }
    }

    fn upload_complete(&mut self, now: Instant) {
        let Some(u) = self.upload.take() else {
            return;
        };
        match u.kind {
            MavMissionType::MAV_MISSION_TYPE_MISSION => {
                match to_plan(&u.items, &self.fence, &self.config.plan) {
                    Err(refusal) => self.refuse(u.peer, u.kind, &refusal.reason),
                    Ok(_) => {
                        self.ack(u.peer, u.kind, MavMissionResult::MAV_MISSION_ACCEPTED);
                        self.pending = Some(u.items);
                        self.timers
                            .set(VehicleTimer::FenceWait, now + self.config.fence_wait);
                    }
                }
            }
            _ => {
                let mission = match self.pending.take() {
                    Some(m) => {
                        self.timers.stop(VehicleTimer::FenceWait);
                        m
                    }
                    None => self.mission.clone(),
                };
                if mission.is_empty() {
                    // No mission to pair it with: the ICD's upload is mission and areas
                    // together, so the fence is held for the next mission.
                    self.fence = u.items;
                    self.ack(u.peer, u.kind, MavMissionResult::MAV_MISSION_ACCEPTED);
                    self.statustext(
                        MavSeverity::MAV_SEVERITY_INFO,
                        "fence held: it goes to the FCC with the next mission",
                    );
                    return;
                }
                self.commit(now, mission, u.items, Waiting::FenceAck, u.peer);
            }
        }
    }

    /// The reason as STATUSTEXT, then MISSION_ACK with an error: a client that stops listening
    /// at the ACK has read why.
    fn refuse(&mut self, to: Peer, kind: MavMissionType, reason: &str) {
        self.statustext(
            MavSeverity::MAV_SEVERITY_ERROR,
            &format!("refused: {reason}"),
        );
        self.ack(to, kind, MavMissionResult::MAV_MISSION_DENIED);
    }

    /// `peer`: who is answered when the commit ends (the fence's uploader, the commander of
    /// execute).
    fn commit(
        &mut self,
        _now: Instant,
        mission: Vec<Item>,
        fence: Vec<Item>,
        waiting: Waiting,
        peer: Peer,
    ) {
        match to_plan(&mission, &fence, &self.config.plan) {
            Err(refusal) => match waiting {
                Waiting::FenceAck => {
                    self.refuse(
                        peer,
                        MavMissionType::MAV_MISSION_TYPE_FENCE,
                        &refusal.reason,
                    );
                }
                Waiting::Nothing => self.statustext(
                    MavSeverity::MAV_SEVERITY_ERROR,
                    &format!("refused: {}", refusal.reason),
                ),
                Waiting::Execute => {
                    self.statustext(
                        MavSeverity::MAV_SEVERITY_ERROR,
                        &format!("refused: {}", refusal.reason),
                    );
                    self.command_ack(self.start_command, MavResult::MAV_RESULT_DENIED);
                }
            },
            Ok(plan) => {
                self.committing = Some((mission, fence, waiting, peer));
                self.events.push_back(VehicleEvent::Commit {
                    plan: Box::new(plan),
                });
            }
        }
    }

    /// The outcome of [`VehicleEvent::Commit`]: the FCC holds both lists (`Ok`), or not, and
    /// why (the safety gateway's violation, the FCC's refusal, the link's failure).
    pub fn committed(&mut self, outcome: Result<(), String>) {
        let Some((mission, fence, waiting, peer)) = self.committing.take() else {
            return;
        };
        match outcome {
            Ok(()) => {
                self.mission = mission;
                self.fence = fence;
                self.remember = true;
                self.current = 0;
                self.reached = 0;
                self.state = MissionState::MISSION_STATE_NOT_STARTED;
                self.statustext(
                    MavSeverity::MAV_SEVERITY_INFO,
                    "mission and fence active on the FCC",
                );
                match waiting {
                    Waiting::FenceAck => {
                        self.ack(
                            peer,
                            MavMissionType::MAV_MISSION_TYPE_FENCE,
                            MavMissionResult::MAV_MISSION_ACCEPTED,
                        );
                    }
                    Waiting::Nothing => {}
                    Waiting::Execute => {
                        self.executing = true;
                        self.events.push_back(VehicleEvent::Execute);
                    }
                }
            }
            Err(why) => {
                let text = format!("not committed, the FCC's lists are unchanged: {why}");
                match waiting {
                    Waiting::FenceAck => {
                        self.refuse(peer, MavMissionType::MAV_MISSION_TYPE_FENCE, &text)
                    }
                    Waiting::Nothing => self.statustext(MavSeverity::MAV_SEVERITY_ERROR, &text),
                    Waiting::Execute => {
                        self.statustext(MavSeverity::MAV_SEVERITY_ERROR, &text);
                        self.command_ack(self.start_command, MavResult::MAV_RESULT_DENIED);
                    }
                }
            }
        }
    }

    /// A STATUSTEXT, broadcast (it is the vehicle's own message). A text of up to 50 bytes is
    /// one message with id 0; a longer one is MAVLink 2's chunks of 50 bytes under one nonzero
    /// id, `chunk_seq` counting from 0, and ends with a chunk shorter than 50 bytes (an empty
    /// one when the length is a multiple of 50): MAVSDK and MAVProxy join the chunks at that end
    /// marker, and a text without one is dropped or shown late. Texts longer than
    /// [`STATUSTEXT_MAX`] are cut there and end in "...": the essence is in the first 50 bytes.
    pub fn statustext(&mut self, severity: MavSeverity, text: &str) {
        let mut bytes = text.as_bytes();
        let cut = bytes.len() > STATUSTEXT_MAX;
        if cut {
            let mut end = STATUSTEXT_MAX - 3;
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            bytes = bytes.get(..end).unwrap_or_default();
        }
        let mut whole: Vec<u8> = bytes.to_vec();
        if cut {
            whole.extend_from_slice(b"...");
        }
        if whole.len() <= 50 {
            self.statustext_chunk(severity, &whole, 0, 0);
            return;
        }
        self.statustext_id = self.statustext_id.checked_add(1).unwrap_or(1);
        let id = self.statustext_id;
        let chunks = whole.len() / 50 + 1;
        for n in 0..chunks {
            let chunk = whole.get(n * 50..).unwrap_or_default();
            let chunk = chunk.get(..50).unwrap_or(chunk);
            self.statustext_chunk(severity, chunk, id, u8::try_from(n).unwrap_or(u8::MAX));
        }
    }

    fn statustext_chunk(&mut self, severity: MavSeverity, chunk: &[u8], id: u16, chunk_seq: u8) {
        let mut data = [0u8; 50];
        for (d, b) in data.iter_mut().zip(chunk) {
            *d = *b;
        }
        self.send(MavMessage::STATUSTEXT(STATUSTEXT_DATA {
            severity,
            text: data.into(),
            id,
            chunk_seq,
        }));
    }

    /// A position of the downlink (#101): GLOBAL_POSITION_INT, ATTITUDE and VFR_HUD, at the
    /// downlink's rate (2 Hz by default, ICD §5.8). What #101 leaves out is sent as MAVLink's
    /// "unknown" where MAVLink has one (heading UINT16_MAX, a float NaN, throttle UINT16_MAX
    /// like the other unsigned 16-bit unknowns); ATTITUDE needs all three angles and VFR_HUD
    /// the heading, else they are not sent. The home follows the position while no mission
    /// flies and the aircraft stands: HOME_POSITION when it moved.
    pub fn handle_position(&mut self, now: Instant, states: &InertialStates) {
        let Some(position) = states.position() else {
            return;
        };
        let (lat, lon) = (position.latitude.degrees(), position.longitude.degrees());
        let altitude = states.altitude.map(|a| a.metres());
        // Standing: `gcs mavlink` restarted while the aircraft flies learns that the mission flies
        // from the next FROM-TO-NEXT only, and must not take the air for the home meanwhile.
        let standing = states.ground_speed_mps().is_none_or(|v| v < 0.5);
        if self.state != MissionState::MISSION_STATE_ACTIVE
            && standing
            && let Some(altitude_m) = altitude
        {
            self.set_home(Home {
                latitude_deg: lat,
                longitude_deg: lon,
                altitude_m,
                altitude_type: states.altitude_type,
            });
        }
        let amsl = altitude.and_then(|h| amsl_m(h, states.altitude_type, lat, lon));
        // Above home: in the home's altitude type; a height above ground is one above home's
        // ground by itself.
        let relative = altitude.and_then(|h| match self.home {
            Some(home) if home.altitude_type == states.altitude_type => Some(h - home.altitude_m),
            None if states.altitude_type == Some(AltitudeType::Agl) => Some(h),
            _ => None,
        });
        let time_boot_ms = self
            .booted
            .map_or(0, |b| now.saturating_since(b).as_millis() as u32);
        let centi =
            |v: Option<f64>| (v.unwrap_or(0.0) * 100.0).round().clamp(-32768.0, 32767.0) as i16;
        let heading_deg = states.heading_deg();
        self.send(MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
            time_boot_ms,
            lat: e7(lat),
            lon: e7(lon),
            // MAVLink has no "unknown" altitude: without a sea level the height above home
            // stands in (docs/qgroundcontrol.md says when).
            alt: amsl.or(relative).map_or(0, mm),
            relative_alt: relative.map_or(0, mm),
            vx: centi(states.u_speed.map(|v| v.mps())),
            vy: centi(states.v_speed.map(|v| v.mps())),
            vz: centi(states.w_speed.map(|v| v.mps())),
            hdg: heading_deg.map_or(u16::MAX, |h| ((h * 100.0).round() as u16) % 36_000),
        }));
        if let (Some(roll), Some(pitch), Some(yaw)) =
            (states.roll_rad(), states.pitch_rad(), states.heading_rad())
        {
            self.send(MavMessage::ATTITUDE(ATTITUDE_DATA {
                time_boot_ms,
                roll: roll as f32,
                pitch: pitch as f32,
                yaw: yaw as f32,
                rollspeed: f32::NAN,
                pitchspeed: f32::NAN,
                yawspeed: f32::NAN,
            }));
        }
        if let Some(heading) = heading_deg {
            self.send(MavMessage::VFR_HUD(VFR_HUD_DATA {
                // #101 carries no airspeed.
                airspeed: f32::NAN,
                groundspeed: states.ground_speed_mps().map_or(f32::NAN, |v| v as f32),
                alt: amsl.map_or(f32::NAN, |a| a as f32),
                climb: states.climb_rate_mps().map_or(f32::NAN, |c| c as f32),
                heading: (heading.round() as i16) % 360,
                throttle: u16::MAX,
            }));
        }
    }

    /// The home moved to `home`: kept (and remembered), and HOME_POSITION sent at once when it
    /// moved by a metre or more from the home last sent (and with every heartbeat).
    fn set_home(&mut self, home: Home) {
        // The plan's home: the take-off position of a mission whose take-off item gives none,
        // and the reference of AMSL take-off altitudes, so only one whose sea level is known.
        self.config.plan.home = home.amsl_m().map(|altitude_m| crate::qgc::Home {
            latitude_deg: home.latitude_deg,
            longitude_deg: home.longitude_deg,
            altitude_m,
        });
        self.home = Some(home);
        let moved = self.home_sent.is_none_or(|sent| {
            sent.altitude_type != home.altitude_type
                || (sent.altitude_m - home.altitude_m).abs() >= 1.0
                || Site::new(sent.latitude_deg, sent.longitude_deg)
                    .chord_m(&Site::new(home.latitude_deg, home.longitude_deg))
                    >= 1.0
        });
        if moved {
            self.remember = true;
            self.home_position();
        }
    }

    /// HOME_POSITION, when the home and its altitude above mean sea level are known; the local
    /// frame's origin is the home itself.
    fn home_position(&mut self) {
        let Some((home, amsl)) = self.home.and_then(|h| Some((h, h.amsl_m()?))) else {
            return;
        };
        self.home_sent = Some(home);
        self.send(MavMessage::HOME_POSITION(HOME_POSITION_DATA {
            latitude: e7(home.latitude_deg),
            longitude: e7(home.longitude_deg),
            altitude: mm(amsl),
            x: 0.0,
            y: 0.0,
            z: 0.0,
            q: [1.0, 0.0, 0.0, 0.0],
            approach_x: 0.0,
            approach_y: 0.0,
            approach_z: 0.0,
            time_usec: 0,
        }));
    }

    /// The vehicle's home, once known.
    pub fn home(&self) -> Option<Home> {
        self.home
    }

    /// A FROM-TO-NEXT of the downlink (#4001): MISSION_CURRENT, the item of the TO waypoint,
    /// and MISSION_ITEM_REACHED for every item before it not yet reported (the take-off and
    /// speed changes are reached when the aircraft flies past them to the next waypoint). TO 0
    /// while the mission flies is its end: every item reached, MISSION_STATE_COMPLETE with the
    /// last item as seq (an index a client can map, and MAVSDK's `is_mission_finished`).
    pub fn handle_from_to_next(&mut self, ftn: &FromToNext) {
        let to = ftn.to.waypoint_number.unwrap_or(0);
        let last = u16::try_from(self.mission.len().saturating_sub(1)).unwrap_or(u16::MAX);
        match to {
            0 if self.state == MissionState::MISSION_STATE_ACTIVE && !self.mission.is_empty() => {
                self.state = MissionState::MISSION_STATE_COMPLETE;
                self.current = last;
                self.reach_below(last.saturating_add(1));
            }
            0 => {}
            n => {
                // Waypoint n of the FCC is the n-th waypoint or land item of the mission list.
                let seq = self
                    .mission
                    .iter()
                    .enumerate()
                    .filter(|(_, i)| matches!(i.command, 16 | 21 | 85))
                    .nth(usize::from(n) - 1)
                    .and_then(|(k, _)| u16::try_from(k).ok());
                self.state = MissionState::MISSION_STATE_ACTIVE;
                if let Some(seq) = seq {
                    self.current = seq;
                    self.reach_below(seq);
                }
            }
        }
        self.mission_current();
    }

    /// MISSION_ITEM_REACHED for each item below `end` not reported yet, in order.
    fn reach_below(&mut self, end: u16) {
        while self.reached < end {
            self.send(MavMessage::MISSION_ITEM_REACHED(
                MISSION_ITEM_REACHED_DATA { seq: self.reached },
            ));
            self.reached += 1;
        }
    }

    fn mission_current(&mut self) {
        let total = if self.mission.is_empty() {
            // MAVLink: UINT16_MAX when the vehicle holds no mission.
            u16::MAX
        } else {
            u16::try_from(self.mission.len()).unwrap_or(u16::MAX)
        };
        self.send(MavMessage::MISSION_CURRENT(MISSION_CURRENT_DATA {
            seq: self.current,
            total,
            mission_state: self.state,
            // 1: in mission mode; 2: not (holding).
            mission_mode: if self.state == MissionState::MISSION_STATE_ACTIVE {
                1
            } else {
                2
            },
            mission_id: self.ids.0,
            fence_id: self.ids.1,
            rally_points_id: 0,
        }));
    }

    /// When [`Self::handle_timeout`] must be called next.
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.timers.next_timeout()
    }

    /// The timers due at `now` fire.
    pub fn handle_timeout(&mut self, now: Instant) {
        let due: Vec<VehicleTimer> = self.timers.expired(now).collect();
        for timer in due {
            match timer {
                VehicleTimer::Heartbeat => {
                    self.timers
                        .set(VehicleTimer::Heartbeat, now + self.config.heartbeat);
                    self.heartbeat();
                    self.extended_sys_state();
                    self.sys_status();
                    self.mission_current();
                    // As PX4 streams it: a client that subscribes late hears it within a
                    // second, and one that asked too early needs not ask again.
                    self.home_position();
                }
                VehicleTimer::Item => {
                    let again = self.upload.as_mut().map(|u| {
                        u.retries += 1;
                        u.retries <= self.config.item_retries
                    });
                    match again {
                        Some(true) => self.request_next(now),
                        Some(false) => {
                            self.timers.stop(VehicleTimer::Item);
                            if let Some(u) = self.upload.take() {
                                self.ack(
                                    u.peer,
                                    u.kind,
                                    MavMissionResult::MAV_MISSION_OPERATION_CANCELLED,
                                );
                            }
                        }
                        None => self.timers.stop(VehicleTimer::Item),
                    }
                }
                VehicleTimer::FenceWait => {
                    self.timers.stop(VehicleTimer::FenceWait);
                    if let Some(mission) = self.pending.take() {
                        let fence = self.fence.clone();
                        self.commit(now, mission, fence, Waiting::Nothing, Peer::default());
                    }
                }
            }
        }
    }

    /// HEARTBEAT as a PX4 autopilot: MAV_AUTOPILOT_PX4 and PX4's custom mode encoding are what
    /// MAVSDK decodes to a flight mode, what MAVProxy (pymavlink's `mode_string_v10`) prints by
    /// name, and what QGroundControl's PX4 plugin shows; a generic autopilot's custom mode
    /// has no names in any of them. AUTO.MISSION while the mission flies, else AUTO.LOITER
    /// (Hold): the FCC flies nothing else on its own. EXTENDED_SYS_STATE with it.
    fn heartbeat(&mut self) {
        let active = self.state == MissionState::MISSION_STATE_ACTIVE;
        let flags = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
            | MavModeFlag::MAV_MODE_FLAG_AUTO_ENABLED
            | MavModeFlag::MAV_MODE_FLAG_GUIDED_ENABLED
            | MavModeFlag::MAV_MODE_FLAG_STABILIZE_ENABLED;
        self.send(MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: px4_mode(
                PX4_MAIN_AUTO,
                if active {
                    PX4_SUB_MISSION
                } else {
                    PX4_SUB_LOITER
                },
            ),
            mavtype: MavType::MAV_TYPE_VTOL_FIXEDROTOR,
            autopilot: MavAutopilot::MAV_AUTOPILOT_PX4,
            base_mode: if active {
                flags | MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED
            } else {
                flags
            },
            system_status: if active {
                MavState::MAV_STATE_ACTIVE
            } else {
                MavState::MAV_STATE_STANDBY
            },
            mavlink_version: 3,
        }));
    }

    /// EXTENDED_SYS_STATE: the landed state; the VTOL state is not reported by the FCC.
    fn extended_sys_state(&mut self) {
        self.send(MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
            vtol_state: MavVtolState::MAV_VTOL_STATE_UNDEFINED,
            landed_state: self.landed_state(),
        }));
    }

    /// SYS_STATUS, once a second: what the FCC reports of its state is its mission and
    /// position, not its sensors or power, so no sensor but the geofence is claimed present and
    /// the battery is
    /// MAVLink's "unknown" (voltage UINT16_MAX, current and remaining -1); the load is not
    /// reported (0). The communication counters are the data links' as the ground receives
    /// them: `errors_comm` the messages rejected (ICD §2 frame rules, §9 signatures), and
    /// `drop_rate_comm` their share of all received, in 0.01 %.
    fn sys_status(&mut self) {
        let (all, rejected) = self.link_counts;
        let drop = rejected
            .saturating_mul(10_000)
            .checked_div(all)
            .map_or(0, |d| u16::try_from(d).unwrap_or(10_000));
        // The geofence: present and enabled while the FCC holds areas; healthy because the
        // route flown passed the FCC's onboard check against them (ICD §7) and guidance flies
        // no other (a breach of the position is not on the downlink). MAVProxy announces a
        // "fence breach" for a health bit that is clear.
        let fence = if self.ids.1 != 0 {
            MavSysStatusSensor::MAV_SYS_STATUS_GEOFENCE
        } else {
            MavSysStatusSensor::empty()
        };
        self.send(MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            onboard_control_sensors_present: fence,
            onboard_control_sensors_enabled: fence,
            onboard_control_sensors_health: MavSysStatusSensor::MAV_SYS_STATUS_GEOFENCE,
            load: 0,
            voltage_battery: u16::MAX,
            current_battery: -1,
            drop_rate_comm: drop,
            errors_comm: u16::try_from(rejected).unwrap_or(u16::MAX),
            errors_count1: 0,
            errors_count2: 0,
            errors_count3: 0,
            errors_count4: 0,
            battery_remaining: -1,
            onboard_control_sensors_present_extended: MavSysStatusSensorExtended::empty(),
            onboard_control_sensors_enabled_extended: MavSysStatusSensorExtended::empty(),
            onboard_control_sensors_health_extended: MavSysStatusSensorExtended::empty(),
        }));
    }

    /// The data links' messages as the ground received them so far: all, and those rejected
    /// (for SYS_STATUS).
    pub fn set_link_counts(&mut self, all: u64, rejected: u64) {
        self.link_counts = (all, rejected);
    }

    /// What the vehicle knows of the ground: in the air while the mission it started flies; on
    /// the ground at the end of a mission that lands; else unknown (`gcs mavlink` started while the
    /// aircraft flies cannot tell), MAVLink's UNDEFINED, never guessed.
    fn landed_state(&self) -> MavLandedState {
        match self.state {
            MissionState::MISSION_STATE_ACTIVE => MavLandedState::MAV_LANDED_STATE_IN_AIR,
            MissionState::MISSION_STATE_COMPLETE
                if self.mission.last().is_some_and(|i| i.command == 21) =>
            {
                MavLandedState::MAV_LANDED_STATE_ON_GROUND
            }
            _ => MavLandedState::MAV_LANDED_STATE_UNDEFINED,
        }
    }

    fn send(&mut self, message: MavMessage) {
        self.outbox.push_back(message);
    }

    /// The next datagram to send: one MAVLink 2 message in `buf`; its length.
    pub fn poll_transmit(&mut self, buf: &mut [u8]) -> Option<usize> {
        let message = self.outbox.pop_front()?;
        let header = MavHeader {
            system_id: u32::from(self.config.system_id),
            component_id: COMPONENT_ID,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        let mut out: &mut [u8] = buf;
        mavlink::write_v2_msg(&mut out, header, &message).ok()
    }

    /// Whether an event waits for the driver.
    pub fn has_event(&self) -> bool {
        !self.events.is_empty()
    }

    /// The next event for the driver.
    pub fn poll_event(&mut self) -> Option<VehicleEvent> {
        self.events.pop_front()
    }

    /// Whether a commit, an execute or a clear is being carried out.
    pub fn busy(&self) -> bool {
        self.committing.is_some() || self.executing || self.clearing.is_some()
    }
}

/// The MAVLink messages (1 or 2) of a client's datagram with their headers, up to the first that
/// does not read.
pub fn read_datagram(datagram: &[u8]) -> Vec<(MavHeader, MavMessage)> {
    let mut reader = MavlinkReader::new(datagram);
    let mut out = Vec::new();
    while let Ok(m) = reader.read_any_message::<MavMessage>() {
        out.push(m);
    }
    out
}

/// Decodes a datagram the vehicle sent (tests, and a driver that logs).
pub fn decode(datagram: &[u8]) -> Vec<MavMessage> {
    let mut reader = MavlinkReader::new(datagram);
    let mut out = Vec::new();
    while let Ok((_, m)) = reader.read_message::<MavMessage>(MavlinkVersion::V2) {
        out.push(m);
    }
    out
}

#[cfg(test)]
mod tests;
