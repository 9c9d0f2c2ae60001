//! `guidance-stub`: the FCC partition that stands in for flight guidance in the rig, a thin
//! driver around `services::guidance::Guidance`. It flies the active waypoint and area lists
//! with a simple kinematic model when system automation says so, time-scaled for demos, and
//! publishes FROM / TO / NEXT and the position on `fcc/guidance/progress`. It reports when the
//! position leaves the fly-zone or enters a no-fly-zone.

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationStatePayload, FccService, GuidanceProgressPayload,
    WaypointListPayload,
};
use missionlink_partitions::clock::DriverClock;
use missionlink_partitions::config::{Config, ConfigArgs};
use missionlink_partitions::ipc::Ipc;
use missionlink_partitions::runtime::{Report, Shutdown, partition_main, wait};
use missionlink_services::guidance::{Guidance, GuidanceConfig};

/// Guidance stub of the FCC.
#[derive(Debug, Parser)]
#[command(name = "guidance-stub", version, about)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

const NAME: &str = "guidance-stub";

fn run(config: &Config) -> Result<(), Box<dyn std::error::Error>> {
    type S = ipc::Service;
    let ipc = Ipc::<S>::open(NAME, &config.ipc.service_prefix)?;
    let waypoints = ipc.subscriber::<WaypointListPayload>(FccService::WaypointList)?;
    let areas = ipc.subscriber::<AreaListPayload>(FccService::AreaList)?;
    let automation = ipc.subscriber::<AutomationStatePayload>(FccService::AutomationState)?;
    let progress = ipc.publisher::<GuidanceProgressPayload>(FccService::GuidanceProgress)?;

    let g = &config.guidance;
    let mut guidance = Guidance::new(GuidanceConfig {
        start_latitude_deg: g.start_latitude_deg,
        start_longitude_deg: g.start_longitude_deg,
        climb_rate_mps: g.climb_rate_mps,
        descent_rate_mps: g.descent_rate_mps,
        time_scale: g.time_scale,
        ..GuidanceConfig::default()
    });
    let clock = DriverClock::start();
    let interval = Duration::from_millis(g.update_interval_ms.max(1));

    let waitset = WaitSetBuilder::new().create::<S>()?;
    let _g1 = waitset.attach_notification(waypoints.listener())?;
    let _g2 = waitset.attach_notification(areas.listener())?;
    let _g3 = waitset.attach_notification(automation.listener())?;
    let _tick = waitset.attach_interval(interval)?;
    let mut report = Report::new(config, NAME);
    let signals = Shutdown::install()?;
    tracing::info!(
        prefix = %config.ipc.service_prefix,
        time_scale = g.time_scale,
        "guidance-stub up"
    );

    let mut last_published: Option<GuidanceProgressPayload> = None;
    let mut last_sent = std::time::Instant::now();
    while wait(&waitset, config.ipc.poll, interval)? {
        for l in [
            waypoints.listener(),
            areas.listener(),
            automation.listener(),
        ] {
            if let Err(e) = l.try_wait(|_| {}) {
                tracing::warn!(?e, "listener failed");
            }
        }
        waypoints.for_each(|list| {
            tracing::info!(
                generation = list.generation,
                waypoints = list.count,
                "waypoint list received"
            );
            guidance.set_waypoint_list(list);
        });
        areas.for_each(|list| {
            tracing::info!(
                generation = list.generation,
                areas = list.area_count(),
                "area list received"
            );
            guidance.set_area_list(list);
        });
        if let Some(state) = automation.latest() {
            guidance.set_automation(&state);
        }
        let p = guidance.step(clock.now());
        // Publish on change of anything but the counters, and at least once a second.
        let changed = last_published.is_none_or(|last| {
            GuidanceProgressPayload {
                sequence: 0,
                time_ns: 0,
                ..last
            } != GuidanceProgressPayload {
                sequence: 0,
                time_ns: 0,
                ..p
            }
        });
        if changed || last_sent.elapsed() >= Duration::from_secs(1) {
            progress.send(&p)?;
            last_published = Some(p);
            last_sent = std::time::Instant::now();
        }
        progress.update_connections();
        if report.due() || signals.report_requested() {
            tracing::info!(
                latitude = p.latitude_deg,
                longitude = p.longitude_deg,
                altitude = p.altitude_m,
                from = p.from,
                to = p.to,
                next = p.next,
                "position"
            );
        }
    }
    report.finish(&[], &[]);
    Ok(())
}

fn main() -> ExitCode {
    partition_main(NAME, &Args::parse().config, run)
}
