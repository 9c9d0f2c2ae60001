//! Guidance stub: the FCC partition that stands in for flight guidance in the rig, a thin
//! driver around `missionlink_flight::guidance::Guidance`. It flies the active waypoint and area lists
//! (taken only as a pair of one activation, `ipc::ListPairing`) with a simple kinematic model
//! when system automation says so, time-scaled for demos, and publishes FROM / TO / NEXT and the
//! position on `fcc/guidance/progress`. It reports when the position leaves the fly-zone or
//! enters a no-fly-zone.

use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use missionlink_flight::guidance::Guidance;
use missionlink_interfaces::contracts::{
    AutomationStatePayload, FccService, GuidanceProgressPayload, Partition,
};

use crate::config::Config;
use crate::ipc::{Ipc, ListPairing};
use crate::runtime::{self, Control, Inputs, PartitionError};
use missionlink_platform::clock::DriverClock;

/// The partition it is (its binary, node and summary are named `Partition::binary`, its
/// heartbeat `fcc/health/<role>`).
pub const PARTITION: Partition = Partition::Guidance;

/// Progress is published on every change and at least this often.
const REPUBLISH: Duration = Duration::from_secs(1);

/// Whether `next` differs from `last` in anything but the counters (sequence, time). The bytes
/// are compared: a value guidance does not know is NaN, which `==` never finds equal.
fn changed(last: Option<&GuidanceProgressPayload>, next: &GuidanceProgressPayload) -> bool {
    last.is_none_or(|last| !last.same_report_as(next))
}

/// Runs the guidance stub on the service type `S` until `control` or a termination request
/// stops it.
pub fn run<S: Service>(config: &Config, control: &Control) -> Result<(), PartitionError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let ipc = Ipc::<S>::for_partition(PARTITION, &config.ipc)?;
    let lists = ipc.active_lists()?;
    let automation = ipc.subscriber::<AutomationStatePayload>(FccService::AutomationState)?;
    let progress = ipc.publisher::<GuidanceProgressPayload>(FccService::GuidanceProgress)?;

    let g = &config.guidance;
    let mut guidance = Guidance::new(*g);
    let clock = DriverClock::start();
    let interval = Duration::from_millis(g.update_interval_ms.max(1));

    tracing::info!(time_scale = g.time_scale, "guidance-stub flies time-scaled");
    let mut pairing = ListPairing::new();
    let mut last_published: Option<GuidanceProgressPayload> = None;
    let mut last_sent = std::time::Instant::now();
    let inputs = Inputs::new(interval)
        .every(interval)
        .lists(&lists)
        .subscriber(&automation);
    let report = runtime::run_loop::<S>(PARTITION, &ipc, config, control, inputs, |report| {
        automation.drain_notifications();
        // Only whole pairs of one activation, both set before the next step: guidance never
        // flies the new waypoint list inside the old areas or the reverse.
        if let Some((waypoint_list, area_list)) = lists.receive(&mut pairing) {
            tracing::info!(
                generation = waypoint_list.generation,
                waypoints = waypoint_list.count,
                activation = waypoint_list.activation,
                "waypoint list received"
            );
            tracing::info!(
                generation = area_list.generation,
                areas = area_list.area_count(),
                activation = area_list.activation,
                "area list received"
            );
            guidance.set_waypoint_list(waypoint_list);
            guidance.set_area_list(area_list);
        }
        if let Some(state) = automation.latest() {
            guidance.set_automation(&state);
        }
        let now = clock.now();
        // The core counts time from the driver's start; the contract says CLOCK_MONOTONIC.
        let p = GuidanceProgressPayload {
            time_ns: clock.monotonic_ns(now),
            ..guidance.step(now)
        };
        if changed(last_published.as_ref(), &p) || last_sent.elapsed() >= REPUBLISH {
            progress.send(&p)?;
            last_published = Some(p);
            last_sent = std::time::Instant::now();
        }
        progress.update_connections();
        if report.log_if_due(&[]) {
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
        Ok(interval)
    })?;
    report.finish(&[], &[]);
    Ok(())
}
