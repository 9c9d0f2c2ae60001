//! Mission data handling: the FCC partition of paper §3.1, a thin driver around
//! `missionlink_flight::mission_data_handling::MissionDataHandling`. It consumes voted uplink frames, the
//! automation state and guidance progress; it publishes the frames the core transmits on the
//! downlink, the active waypoint and area lists (history 1: late joiners get them) and accepted
//! #50000 commands. Whenever either list changes it saves and publishes both, under the one
//! activation the core gave them, the waypoint list first (docs/design.md "Activation is atomic").
//! After a restart it resumes with the lists it published last, so guidance never sees them
//! change, and with the record of a mission upload it cut.
//!
//! Everything the core asks to record (an activated list, an open mission upload) is written
//! before the answers it queued go out: an FCC that answered "valid and active" must still hold
//! that list after a `kill -9` that follows the answer.

use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use missionlink_flight::health::Liveness;
use missionlink_flight::mission_data_handling::{FccEvent, MissionDataHandling, Resumed};
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationCommandPayload, AutomationStatePayload, FccService, FramePayload,
    GuidanceProgressPayload, Link, Partition, WaypointListPayload,
};
use missionlink_interfaces::wire::MAX_FRAME_LEN;
use missionlink_protocol::transfer::staged::StagedMissions;

use crate::config::Config;
use crate::health::Watch;
use crate::ipc::{Ipc, Publisher};
use crate::latency::Recorder;
use crate::runtime::{self, Control, Inputs, PartitionError};
use crate::state;
use missionlink_platform::clock::{DriverClock, monotonic_ns};

/// The partition it is (its binary, node and summary are named `Partition::binary`, its
/// heartbeat `fcc/health/<role>`).
pub const PARTITION: Partition = Partition::MissionDataHandling;

/// How often late subscribers are connected to the list histories.
const CONNECT_INTERVAL: Duration = Duration::from_millis(100);

/// Runs mission data handling on the service type `S` until `control` or a termination request
/// stops it.
pub fn run<S: Service>(config: &Config, control: &Control) -> Result<(), PartitionError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let ipc = Ipc::<S>::for_partition(PARTITION, &config.ipc)?;
    let uplink = ipc.subscriber::<FramePayload>(FccService::Uplink)?;
    let automation = ipc.subscriber::<AutomationStatePayload>(FccService::AutomationState)?;
    let progress = ipc.subscriber::<GuidanceProgressPayload>(FccService::GuidanceProgress)?;
    let downlink = ipc.publisher::<FramePayload>(FccService::Downlink)?;
    let commands = ipc.publisher::<AutomationCommandPayload>(FccService::AutomationCommand)?;
    let waypoint_list = ipc.publisher::<WaypointListPayload>(FccService::WaypointList)?;
    let area_list = ipc.publisher::<AreaListPayload>(FccService::AreaList)?;
    // System automation carries out the #50000 commands: while its heartbeat is silent (hung,
    // dead, or given up by the launcher: the FCC degraded) they are refused.
    let health = Watch::open(&ipc, &[Partition::SystemAutomation])?;
    let mut automation_liveness = Liveness::new(config.health.period());

    let clock = DriverClock::start();
    let mut core = MissionDataHandling::new(config.fcc_core(clock.utc_at_zero()));
    // Resume with the lists of a previous instance and publish them again, so late joiners
    // find them; their generations are unchanged, so guidance sees no change.
    let state_dir = config.ipc.state_dir();
    let active = state::load_active(&state_dir);
    let mission_upload_open = state::load_mission_upload_open(&state_dir);
    let mut staged = StagedMissions::new();
    for (id, mission, areas) in state::load_staged(&state_dir) {
        // Capacity: the records were made by an FCC that held at most as many.
        let stored = mission
            .map(|m| staged.store_mission(id, m))
            .into_iter()
            .chain(areas.map(|a| staged.store_areas(id, a)))
            .collect::<Result<Vec<_>, _>>();
        if let Err(reason) = stored {
            tracing::error!(%id, %reason, "staged mission record not resumed");
        }
    }
    if active.is_some() || mission_upload_open || !staged.is_empty() {
        let state::ActiveLists {
            mission,
            mission_generation,
            areas,
            area_generation,
        } = active.unwrap_or_default();
        core.resume(
            clock.now(),
            Resumed {
                mission,
                mission_generation,
                areas,
                area_generation,
                mission_upload_open,
                staged,
            },
        );
        publish_active(&core, &waypoint_list, &area_list)?;
        tracing::info!(
            waypoint_list = mission_generation,
            area_list = area_generation,
            mission_upload_open,
            staged = core.staged().len(),
            dir = %state_dir.display(),
            "resumed with the lists active before the restart and the staged missions"
        );
    }

    let mut hop = Recorder::new("uplink: shared-memory hop");
    let mut handled = Recorder::new("uplink: UDP receive to handled");
    let mut processing = Recorder::new("uplink: frame processing");
    let mut outputs = Outputs {
        waypoint_list: &waypoint_list,
        area_list: &area_list,
        commands: &commands,
        state_dir: &state_dir,
        command_sequence: 0,
    };

    let mut frame = [0u8; MAX_FRAME_LEN];
    // Whether system automation was alive at the last step: logged when it changes, from its
    // first beat on (before it, at start, it is refused in silence).
    let mut automation_seen: Option<bool> = None;
    let inputs = Inputs::new(CONNECT_INTERVAL)
        .every(CONNECT_INTERVAL)
        .subscriber(&uplink)
        .subscriber(&automation)
        .subscriber(&progress);
    let report = runtime::run_loop::<S>(PARTITION, &ipc, config, control, inputs, |report| {
        if let Some(state) = automation.latest() {
            core.set_automation_state(&state);
        }
        let now = clock.now();
        health.receive(|_, beat| {
            automation_liveness.handle_beat(now, beat);
        });
        let alive = automation_liveness.is_alive(now);
        match (automation_seen, alive) {
            (Some(true), false) => tracing::warn!(
                "system automation not alive: execute, return to home and land are refused"
            ),
            (seen, true) if seen != Some(true) => tracing::info!("system automation alive"),
            _ => {}
        }
        if alive || automation_seen.is_some() {
            automation_seen = Some(alive);
        }
        core.set_automation_alive(alive);
        let mut failure = None;
        uplink.take_all(|f| {
            let start = monotonic_ns();
            hop.record_between(f.published_ns, start);
            // A rejected frame is counted by the core, by cause; it is never answered (ICD §2).
            let _ = core.handle_frame(clock.at(start), f.frame());
            let end = monotonic_ns();
            processing.record(end.saturating_sub(start));
            handled.record_between(f.origin_ns, end);
            // After every frame, not after the whole batch: the core's event queue holds
            // EVENT_CAPACITY, and an activation or a command must never be dropped. Before the
            // answers: what they confirm is recorded first.
            if let Err(e) = outputs.publish_events(&mut core) {
                failure.get_or_insert(e);
            }
            // The frame whose handling produced the answers: its receive time starts the
            // turnaround that voting-monitoring measures.
            transmit(&mut core, &downlink, &mut frame, f.origin_ns);
        });
        if let Some(e) = failure {
            return Err(e);
        }
        automation.drain_notifications();
        progress.drain_notifications();
        // Once more after the drain: a state published between the first look and the drain
        // woke nobody, and a clear or #50000 must be judged against it.
        if let Some(state) = automation.latest() {
            core.set_automation_state(&state);
        }
        if let Some(p) = progress.latest() {
            core.handle_progress(clock.now(), &p);
        }
        let now = clock.now();
        if core.poll_timeout().is_some_and(|t| t <= now) {
            core.handle_timeout(now);
        }
        outputs.publish_events(&mut core)?;
        transmit(&mut core, &downlink, &mut frame, 0);
        waypoint_list.update_connections();
        area_list.update_connections();
        report.log_if_due(&[&hop, &handled, &processing]);
        Ok(core
            .poll_timeout()
            .map_or(CONNECT_INTERVAL, |t| t.saturating_since(clock.now()))
            .min(CONNECT_INTERVAL))
    })?;
    tracing::info!(stats = ?core.endpoint().stats(), "endpoint at shutdown");
    report.finish(
        &[&hop, &handled, &processing],
        &core.endpoint().stats().counters().collect::<Vec<_>>(),
    );
    Ok(())
}

/// What mission data handling publishes besides the downlink: the active lists (saved to the
/// state directory first) and the accepted #50000 commands.
struct Outputs<'a, S: Service> {
    waypoint_list: &'a Publisher<S, WaypointListPayload>,
    area_list: &'a Publisher<S, AreaListPayload>,
    commands: &'a Publisher<S, AutomationCommandPayload>,
    state_dir: &'a std::path::Path,
    command_sequence: u64,
}

impl<S: Service> Outputs<'_, S> {
    /// Carries out every event the core queued.
    fn publish_events(&mut self, core: &mut MissionDataHandling) -> Result<(), PartitionError> {
        while let Some(event) = core.poll_event() {
            match event {
                // Either list changed: both are saved in one file and both published, under the
                // one activation the core gave them (docs/design.md "Activation is atomic").
                FccEvent::MissionActivated { .. }
                | FccEvent::MissionCleared
                | FccEvent::AreasActivated { .. }
                | FccEvent::AreasCleared
                | FccEvent::StagedActivated { .. } => {
                    if let FccEvent::StagedActivated { id, .. } = &event {
                        tracing::info!(%id, "staged mission activated: both lists replaced");
                    }
                    self.save_active(core);
                    publish_active(core, self.waypoint_list, self.area_list)?;
                }
                // A staged mission is kept across a restart like the active lists (ICD §8).
                FccEvent::StagedStored { id, kind } => {
                    let entry = core.staged().get(&id);
                    if let Err(e) = state::save_staged(
                        self.state_dir,
                        &id,
                        entry.and_then(|s| s.mission.as_ref()),
                        entry.and_then(|s| s.areas.as_ref()),
                    ) {
                        tracing::error!(%e, %id, "cannot save the staged mission");
                    }
                    tracing::info!(%id, ?kind, "staged");
                }
                FccEvent::StagedDeleted { id } => {
                    if let Err(e) = state::delete_staged(self.state_dir, &id) {
                        tracing::error!(%e, %id, "cannot remove the staged mission's record");
                    }
                    tracing::info!(%id, "staged mission deleted");
                }
                FccEvent::Execute(command) => {
                    self.command_sequence += 1;
                    self.commands.send(&AutomationCommandPayload {
                        sequence: self.command_sequence,
                        accepted_ns: monotonic_ns(),
                        command: command as u8,
                        reserved: [0; 7],
                    })?;
                    tracing::info!(?command, "command for system automation");
                }
                FccEvent::MissionUploadOpened | FccEvent::MissionUploadClosed => {
                    let open = matches!(event, FccEvent::MissionUploadOpened);
                    if let Err(e) = state::save_mission_upload_open(self.state_dir, open) {
                        tracing::error!(%e, "cannot record the mission upload");
                    }
                }
                other => tracing::info!(event = ?other, "mission data handling"),
            }
        }
        Ok(())
    }
}

impl<S: Service> Outputs<'_, S> {
    /// Saves both active lists and their generations (one file, replaced atomically): an
    /// activation is recorded whole before anything is published or answered.
    fn save_active(&self, core: &MissionDataHandling) {
        let (mission_generation, area_generation) = core.generations();
        if let Err(e) = state::save_active(
            self.state_dir,
            core.active_mission(),
            mission_generation,
            core.active_areas(),
            area_generation,
        ) {
            tracing::error!(%e, "cannot save the active lists");
        }
    }
}

/// Publishes both active lists, the waypoint list first. They carry the same activation, so a
/// subscriber takes them only together (`ipc::ListPairing`).
fn publish_active<S: Service>(
    core: &MissionDataHandling,
    waypoint_list: &Publisher<S, WaypointListPayload>,
    area_list: &Publisher<S, AreaListPayload>,
) -> Result<(), PartitionError> {
    let (w, a) = (core.waypoint_list(), core.area_list());
    waypoint_list.send(w)?;
    area_list.send(a)?;
    tracing::info!(
        activation = w.activation,
        waypoint_list = w.generation,
        waypoints = w.count,
        area_list = a.generation,
        areas = a.area_count(),
        "active lists published"
    );
    Ok(())
}

/// Publishes on the downlink every frame the core transmits (the driver moves bytes only: the
/// core encodes). `origin_ns` is the receive time of the frame being answered, 0 for none.
fn transmit<S: Service>(
    core: &mut MissionDataHandling,
    downlink: &Publisher<S, FramePayload>,
    buf: &mut [u8; MAX_FRAME_LEN],
    origin_ns: u64,
) {
    while let Some(encoded) = core.poll_transmit(buf) {
        let len = match encoded {
            Ok(len) => len,
            Err(e) => {
                tracing::error!(%e, "the core could not encode a downlink message");
                continue;
            }
        };
        let origin = if origin_ns == 0 {
            monotonic_ns()
        } else {
            origin_ns
        };
        let Some(mut payload) =
            FramePayload::new(Link::Both, buf.get(..len).unwrap_or_default(), origin)
        else {
            continue;
        };
        payload.published_ns = monotonic_ns();
        if let Err(e) = downlink.send(&payload) {
            tracing::error!(%e, "downlink frame lost");
        }
    }
}
