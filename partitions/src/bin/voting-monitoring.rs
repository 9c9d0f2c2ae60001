//! `voting-monitoring`: the FCC partition that owns the two data links (paper §2.4). It votes
//! every step's datagrams from the direct and the LTE link (integrity and validity checks of ICD
//! §2, newest by time stamp, the direct link on a tie, never waiting for the other link),
//! publishes the voted uplink frames on `fcc/link/uplink`, and sends every frame of
//! `fcc/link/downlink` on both links.

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{FccService, FramePayload, Link};
use missionlink_partitions::clock::{DriverClock, monotonic_ns};
use missionlink_partitions::config::{Config, ConfigArgs};
use missionlink_partitions::ipc::Ipc;
use missionlink_partitions::latency::{self, Recorder};
use missionlink_partitions::runtime::{Report, Shutdown, partition_main, wait};
use missionlink_partitions::udp::{LinkPair, MAX_DATAGRAM};
use missionlink_services::voting::{VOTING_STEP_MESSAGES, Voter};

/// Voting and monitoring of the direct and LTE links.
#[derive(Debug, Parser)]
#[command(name = "voting-monitoring", version, about)]
struct Args {
    #[command(flatten)]
    config: ConfigArgs,
}

const NAME: &str = "voting-monitoring";

fn run(config: &Config) -> Result<(), Box<dyn std::error::Error>> {
    type S = ipc::Service;
    let ipc = Ipc::<S>::open(NAME, &config.ipc.service_prefix)?;
    let uplink = ipc.publisher::<FramePayload>(FccService::Uplink)?;
    let downlink = ipc.subscriber::<FramePayload>(FccService::Downlink)?;
    let links = LinkPair::bind(
        config.links.fcc_direct,
        config.links.fcc_lte,
        config.links.gcs_direct,
        config.links.gcs_lte,
    )?;
    let clock = DriverClock::start();
    let mut voter = Voter::new(
        config.ids.fcc,
        config.ids.gcs,
        config.timing.transfer_timeout(),
    );
    let mut received = Recorder::new("uplink: UDP receive to published");
    let mut downlink_hop = Recorder::new("downlink: shared-memory hop");
    let mut turnaround = Recorder::new("FCC turnaround: UDP receive to answer sent");
    let mut sequence = 0u64;

    let waitset = WaitSetBuilder::new().create::<S>()?;
    let [direct_fd, lte_fd] = links.attachments();
    let _g1 = waitset.attach_notification(direct_fd)?;
    let _g2 = waitset.attach_notification(lte_fd)?;
    let _g3 = waitset.attach_notification(downlink.listener())?;
    let mut report = Report::new(config, NAME);
    let shutdown = Shutdown::install()?;
    tracing::info!(
        direct = %config.links.fcc_direct,
        lte = %config.links.fcc_lte,
        prefix = %config.ipc.service_prefix,
        "voting-monitoring up"
    );

    // One step's datagrams, copied out of the socket buffer into slots allocated once.
    let mut slots = vec![[0u8; MAX_DATAGRAM]; VOTING_STEP_MESSAGES];
    let mut step: heapless::Vec<(Link, usize, u64), VOTING_STEP_MESSAGES> = heapless::Vec::new();
    let mut buf = [0u8; MAX_DATAGRAM];
    while wait(&waitset, config.ipc.poll, Duration::from_secs(1))? {
        // The answers first (the turnaround's path), then drain the notifications, then look
        // once more, so the drain's system calls stay off the frame's path and nothing
        // published meanwhile waits for the next wake-up (benches/latency.rs).
        for pass in 0..2 {
            downlink.for_each(|frame| {
                let at = monotonic_ns();
                downlink_hop.record_between(frame.published_ns, at);
                links.send_both(frame.frame());
                turnaround.record_between(frame.origin_ns, monotonic_ns());
            });
            if pass == 0 {
                downlink.drain_notifications();
            }
        }
        step.clear();
        links.receive(&mut buf, |link, datagram, at| {
            let slot = slots
                .get_mut(step.len())
                .and_then(|s| s.get_mut(..datagram.len()));
            if let Some(slot) = slot {
                slot.copy_from_slice(datagram);
                let _ = step.push((link, datagram.len(), at));
            }
        });
        if !step.is_empty() {
            let mut arrivals: heapless::Vec<(Link, &[u8]), VOTING_STEP_MESSAGES> =
                heapless::Vec::new();
            for (slot, (link, len, _)) in slots.iter().zip(&step) {
                let _ = arrivals.push((*link, slot.get(..*len).unwrap_or_default()));
            }
            voter.vote_step(clock.now(), &arrivals, |link, frame| {
                // The datagram the frame lies in gives its receive time.
                let origin = arrivals
                    .iter()
                    .zip(&step)
                    .find(|((_, d), _)| d.as_ptr_range().contains(&frame.as_ptr()))
                    .map_or(0, |(_, (_, _, at))| *at);
                let Some(mut payload) = FramePayload::new(link, frame, origin) else {
                    return;
                };
                sequence += 1;
                payload.sequence = sequence;
                payload.published_ns = monotonic_ns();
                match uplink.send(&payload) {
                    Ok(()) => received.record_between(origin, monotonic_ns()),
                    Err(e) => tracing::error!(%e, "uplink frame lost"),
                }
            });
        }
        if report.due() || shutdown.report_requested() {
            latency::log(NAME, &[&received, &downlink_hop, &turnaround]);
            tracing::info!(stats = ?voter.stats(), "voting");
        }
    }
    tracing::info!(stats = ?voter.stats(), "voting at shutdown");
    let counters: Vec<_> = voter.stats().counters().collect();
    report.finish(&[&received, &downlink_hop, &turnaround], &counters);
    Ok(())
}

fn main() -> ExitCode {
    partition_main(NAME, &Args::parse().config, run)
}
