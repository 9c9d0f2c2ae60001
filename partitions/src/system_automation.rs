//! System automation: the FCC partition of paper §2.5, a thin driver around
//! `missionlink_flight::automation::SystemAutomation`. It follows the active lists (taken only as a pair
//! of one activation, `ipc::ListPairing`), guidance's progress and guidance's heartbeat
//! (guidance alive or not, docs/design.md "Health"), carries out the #50000 commands mission data
//! handling accepted, and publishes the flight phase and which functions
//! are active (`fcc/automation/state`, history 1). A restarted automation adopts the phase
//! guidance's progress shows, so it never drops an aircraft in the air back to "on ground".

use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use missionlink_flight::automation::SystemAutomation;
use missionlink_interfaces::contracts::{
    AutomationCommandPayload, AutomationStatePayload, FccService, GuidanceProgressPayload,
    Partition,
};
use missionlink_protocol::link::time::Instant;

use crate::config::Config;
use crate::health::Watch;
use crate::ipc::{Ipc, ListPairing};
use crate::latency::Recorder;
use crate::runtime::{self, Control, Inputs, PartitionError};
use missionlink_platform::clock::{DriverClock, monotonic_ns};

/// The partition it is (its binary, node and summary are named `Partition::binary`, its
/// heartbeat `fcc/health/<role>`).
pub const PARTITION: Partition = Partition::SystemAutomation;

/// How often late subscribers are connected to the state's history.
const CONNECT_INTERVAL: Duration = Duration::from_millis(100);

/// Runs system automation on the service type `S` until `control` or a termination request
/// stops it.
pub fn run<S: Service>(config: &Config, control: &Control) -> Result<(), PartitionError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let ipc = Ipc::<S>::for_partition(PARTITION, &config.ipc)?;
    let lists = ipc.active_lists()?;
    let progress = ipc.subscriber::<GuidanceProgressPayload>(FccService::GuidanceProgress)?;
    let commands = ipc.subscriber::<AutomationCommandPayload>(FccService::AutomationCommand)?;
    let state = ipc.publisher::<AutomationStatePayload>(FccService::AutomationState)?;
    let health = Watch::open(&ipc, &[Partition::Guidance])?;

    let clock = DriverClock::start();
    // A restarted automation resumes from guidance's progress (see `handle_progress`); it
    // takes guidance as not alive until guidance's next beat.
    let mut automation = SystemAutomation::with_heartbeat_period(config.health.period());
    let mut command_latency = Recorder::new("command: accepted to carried out");
    let mut pairing = ListPairing::new();

    let guidance_beats = health
        .subscriber(Partition::Guidance)
        .ok_or_else(|| PartitionError::Config("no watch of guidance".to_owned()))?;
    let inputs = Inputs::new(CONNECT_INTERVAL)
        .every(CONNECT_INTERVAL)
        .lists(&lists)
        .subscriber(&progress)
        .subscriber(&commands)
        // Not spun for: guidance's heartbeat is not urgent and comes every period.
        .waking(guidance_beats);
    let report = runtime::run_loop::<S>(PARTITION, &ipc, config, control, inputs, |report| {
        progress.drain_notifications();
        commands.drain_notifications();
        // Only whole pairs of one activation: a command is never checked against the new
        // waypoint list with the old areas or the reverse.
        if let Some((waypoint_list, area_list)) = lists.receive(&mut pairing) {
            automation.handle_waypoint_list(waypoint_list);
            automation.handle_area_list(area_list);
        }
        let now = clock.now();
        health.receive(|_, beat| automation.handle_guidance_heartbeat(now, beat));
        automation.handle_timeout(now);
        commands.for_each(|c| match c.command() {
            Some(command) => match automation.handle_command(now, command) {
                Ok(()) => command_latency.record_between(c.accepted_ns, monotonic_ns()),
                // Mission data handling checked the same rule; the state changed in between.
                Err(reason) => tracing::warn!(?command, %reason, "command refused"),
            },
            None => tracing::warn!(command = c.command, "unknown command"),
        });
        if let Some(p) = progress.latest() {
            automation.handle_progress(now, &p);
        }
        if automation.take_changed() {
            // The core counts time from the driver's start; the contract says CLOCK_MONOTONIC.
            let s = automation.state();
            let changed = Instant::from_micros(s.changed_ns / 1000);
            state.send(&AutomationStatePayload {
                changed_ns: clock.monotonic_ns(changed),
                ..*s
            })?;
        }
        state.update_connections();
        report.log_if_due(&[&command_latency]);
        // Awake when guidance would fall silent, so the state says so at once.
        let until_silent = automation
            .poll_timeout()
            .map_or(CONNECT_INTERVAL, |t| t.saturating_since(now));
        Ok(CONNECT_INTERVAL.min(until_silent))
    })?;
    report.finish(&[&command_latency], &[]);
    Ok(())
}
