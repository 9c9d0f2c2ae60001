//! `system-automation`: the FCC partition of paper §2.5, a thin driver around
//! `services::automation::SystemAutomation`. It follows the active lists and guidance's
//! progress, carries out the #50000 commands mission data handling accepted, and publishes the
//! flight phase and which functions are active (`fcc/automation/state`, history 1). A restarted
//! automation adopts the phase guidance's progress shows, so it never drops an aircraft in the
//! air back to "on ground".

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationCommandPayload, AutomationStatePayload, FccService,
    GuidanceProgressPayload, WaypointListPayload,
};
use missionlink_partitions::clock::{DriverClock, monotonic_ns};
use missionlink_partitions::config::{Config, ConfigArgs};
use missionlink_partitions::ipc::Ipc;
use missionlink_partitions::latency::{self, Recorder};
use missionlink_partitions::runtime::{Report, Shutdown, partition_main, wait};
use missionlink_services::automation::SystemAutomation;

/// System automation of the FCC.
#[derive(Debug, Parser)]
#[command(name = "system-automation", version, about)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

const NAME: &str = "system-automation";
const CONNECT_INTERVAL: Duration = Duration::from_millis(100);

fn run(config: &Config) -> Result<(), Box<dyn std::error::Error>> {
    type S = ipc::Service;
    let ipc = Ipc::<S>::open(NAME, &config.ipc.service_prefix)?;
    let waypoints = ipc.subscriber::<WaypointListPayload>(FccService::WaypointList)?;
    let areas = ipc.subscriber::<AreaListPayload>(FccService::AreaList)?;
    let progress = ipc.subscriber::<GuidanceProgressPayload>(FccService::GuidanceProgress)?;
    let commands = ipc.subscriber::<AutomationCommandPayload>(FccService::AutomationCommand)?;
    let state = ipc.publisher::<AutomationStatePayload>(FccService::AutomationState)?;

    let clock = DriverClock::start();
    // A restarted automation resumes from guidance's progress (see `handle_progress`).
    let mut automation = SystemAutomation::new();
    let mut command_latency = Recorder::new("command: accepted to carried out");

    let waitset = WaitSetBuilder::new().create::<S>()?;
    let _g1 = waitset.attach_notification(waypoints.listener())?;
    let _g2 = waitset.attach_notification(areas.listener())?;
    let _g3 = waitset.attach_notification(progress.listener())?;
    let _g4 = waitset.attach_notification(commands.listener())?;
    let _tick = waitset.attach_interval(CONNECT_INTERVAL)?;
    let mut report = Report::new(config, NAME);
    let signals = Shutdown::install()?;
    tracing::info!(prefix = %config.ipc.service_prefix, "system-automation up");

    while wait(&waitset, config.ipc.poll, CONNECT_INTERVAL)? {
        for s in [
            waypoints.listener(),
            areas.listener(),
            progress.listener(),
            commands.listener(),
        ] {
            if let Err(e) = s.try_wait(|_| {}) {
                tracing::warn!(?e, "listener failed");
            }
        }
        if let Some(list) = waypoints.latest() {
            automation.handle_waypoint_list(&list);
        }
        if let Some(list) = areas.latest() {
            automation.handle_area_list(&list);
        }
        let now = clock.now();
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
            state.send(automation.state())?;
        }
        state.update_connections();
        if report.due() || signals.report_requested() {
            latency::log(NAME, &[&command_latency]);
        }
    }
    report.finish(&[&command_latency], &[]);
    Ok(())
}

fn main() -> ExitCode {
    partition_main(NAME, &Args::parse().config, run)
}
