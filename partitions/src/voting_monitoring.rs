//! Voting-monitoring: the FCC partition that owns the two data links (paper §2.4). It votes
//! every step's datagrams from the direct and the LTE link (integrity and validity checks of ICD
//! §2, the signature check of §9, newest by time stamp, the direct link on a tie, never waiting
//! for the other link), publishes the voted uplink frames on `fcc/link/uplink`, and sends every
//! frame of `fcc/link/downlink` on both links, signed per link when it has a key. It is the
//! only FCC partition that holds the link keys.
//!
//! It binds the FCC's ends of the links itself (port 0 in the configuration: the system chooses)
//! and announces where in the state directory ([`state::BoundLinks`]); after a restart it binds
//! the announced ports again, so the GCS keeps talking to the same ones.

use std::net::{SocketAddr, UdpSocket};
use std::path::Path;
use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use missionlink_interfaces::contracts::{FccService, FramePayload, Link, Partition};
use missionlink_protocol::voting::{VOTING_STEP_MESSAGES, Voter};

use crate::config::{Config, SigningPolicy};
use crate::ipc::Ipc;
use crate::latency::Recorder;
use crate::runtime::{self, Control, Inputs, PartitionError};
use crate::state::{self, BoundLinks};
use missionlink_platform::clock::{DriverClock, monotonic_ns};
use missionlink_platform::keys::LinkSigning;
use missionlink_platform::udp::{LinkError, LinkPair, MAX_DATAGRAM, MAX_READS_PER_RECEIVE};

// Every datagram one receive hands over is a candidate of the vote: none is read and dropped.
const _: () = assert!(MAX_READS_PER_RECEIVE <= VOTING_STEP_MESSAGES);

/// The partition it is (its binary, node and summary are named `Partition::binary`, its
/// heartbeat `fcc/health/<role>`).
pub const PARTITION: Partition = Partition::VotingMonitoring;

/// The longest sleep without data (nothing else is due).
const IDLE_WAIT: Duration = Duration::from_secs(1);

/// Binds `configured`, or with port 0 the port announced before (a restart), else one the
/// system chooses.
fn bind(
    configured: SocketAddr,
    announced: Option<SocketAddr>,
    link: &str,
) -> Result<UdpSocket, LinkError> {
    if configured.port() == 0 {
        if let Some(previous) = announced.filter(|a| a.ip() == configured.ip()) {
            match UdpSocket::bind(previous) {
                Ok(socket) => return Ok(socket),
                Err(e) => {
                    tracing::warn!(%previous, %e, "{link} link: the announced port is taken; choosing another")
                }
            }
        }
    }
    UdpSocket::bind(configured)
        .map_err(|e| LinkError(format!("cannot bind the {link} link to {configured}: {e}")))
}

/// What voting-monitoring needs of `config` that resolving it does not check: the GCS's ports
/// (the FCC sends to them, so they cannot be the system's choice). The launcher checks it before
/// it starts any partition; the partition again before it binds.
pub fn check_config(config: &Config) -> Result<(), PartitionError> {
    // The key files are read here too, so that an FCC without the key its policy needs stops
    // at once with the line that says how to make one, before any partition starts.
    LinkSigning::load(&config.signing).map_err(|e| PartitionError::Config(e.to_string()))?;
    let l = &config.links;
    for (peer, name) in [(l.gcs_direct, "gcs_direct"), (l.gcs_lte, "gcs_lte")] {
        if peer.port() == 0 {
            return Err(PartitionError::Config(format!(
                "links.{name} = {peer}: the FCC must know the port the GCS receives on"
            )));
        }
    }
    Ok(())
}

/// Binds the FCC's ends as `config` says and announces them in `state_dir`.
fn open_links(config: &Config, state_dir: &Path) -> Result<LinkPair, PartitionError> {
    check_config(config)?;
    let l = &config.links;
    let announced = state::load_links(state_dir);
    let links = LinkPair::from_sockets(
        bind(l.fcc_direct, announced.map(|a| a.fcc_direct), "direct")?,
        bind(l.fcc_lte, announced.map(|a| a.fcc_lte), "LTE")?,
        l.gcs_direct,
        l.gcs_lte,
    )?;
    let [fcc_direct, fcc_lte] = links.local_addrs()?;
    let bound = BoundLinks {
        fcc_direct,
        fcc_lte,
    };
    if announced != Some(bound) {
        state::save_links(state_dir, &bound).map_err(|e| {
            PartitionError::Config(format!(
                "cannot announce the links in {}: {e}",
                state_dir.display()
            ))
        })?;
    }
    Ok(links)
}

/// The FCC's voter (paper §2.4): frames from the configured GCS to the configured FCC, the
/// transfer timeout of its timing, and the signature check of `signing` (ICD §9) from `clock`'s
/// now on. One constructor for the partition and for FCCs simulated in a benchmark.
pub fn fcc_voter(config: &Config, signing: &LinkSigning, clock: &DriverClock) -> Voter {
    Voter::new(
        config.ids.fcc,
        config.ids.gcs,
        config.timing.transfer_timeout(),
    )
    .with_signatures(signing.check(clock.utc_at_zero(), clock.now()))
}

/// Runs voting-monitoring on the service type `S` until `control` or a termination request
/// stops it.
pub fn run<S: Service>(config: &Config, control: &Control) -> Result<(), PartitionError>
where
    Listener<S>: SynchronousMultiplexing,
{
    let ipc = Ipc::<S>::for_partition(PARTITION, &config.ipc)?;
    let uplink = ipc.publisher::<FramePayload>(FccService::Uplink)?;
    let downlink = ipc.subscriber::<FramePayload>(FccService::Downlink)?;
    let signing =
        LinkSigning::load(&config.signing).map_err(|e| PartitionError::Config(e.to_string()))?;
    let links = open_links(config, &config.ipc.state_dir())?.with_signer(signing.signer.clone());
    let clock = DriverClock::start();
    let mut voter = fcc_voter(config, &signing, &clock);
    tracing::info!(signing = %signing.summary(), "link signing (ICD §9)");
    // Said at every start: a link anyone on the path can write to must not pass unnoticed.
    match config.signing.policy {
        SigningPolicy::Off => tracing::warn!(
            "the links are not authenticated: signing is off ([signing] policy = \"off\"), so \
             any host that reaches the FCC's ports can upload, clear and execute (ICD §9)"
        ),
        SigningPolicy::Accept => tracing::warn!(
            "unsigned frames are accepted ([signing] policy = \"accept\"): only \"require\" \
             authenticates the links (ICD §9)"
        ),
        SigningPolicy::Require => {}
    }
    let mut received = Recorder::new("uplink: UDP receive to published");
    let mut downlink_hop = Recorder::new("downlink: shared-memory hop");
    let mut turnaround = Recorder::new("FCC turnaround: UDP receive to answer sent");
    let mut sequence = 0u64;

    let [direct, lte] = links.local_addrs()?;
    tracing::info!(%direct, %lte, "links bound");

    // One step's datagrams, copied out of the socket buffer into slots allocated once.
    let mut slots = vec![[0u8; MAX_DATAGRAM]; MAX_READS_PER_RECEIVE];
    let mut step: heapless::Vec<(Link, usize, u64), MAX_READS_PER_RECEIVE> = heapless::Vec::new();
    let mut buf = [0u8; MAX_DATAGRAM];
    let inputs = Inputs::new(IDLE_WAIT).links(&links)?.subscriber(&downlink);
    let report = runtime::run_loop::<S>(PARTITION, &ipc, config, control, inputs, |report| {
        // The answers first: they are the turnaround's path.
        downlink.take_all(|frame| {
            downlink_hop.record_between(frame.published_ns, monotonic_ns());
            links.send_both(frame.frame());
            turnaround.record_between(frame.origin_ns, monotonic_ns());
        });
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
            let mut arrivals: heapless::Vec<(Link, &[u8]), MAX_READS_PER_RECEIVE> =
                heapless::Vec::new();
            for (slot, (link, len, _)) in slots.iter().zip(&step) {
                let _ = arrivals.push((*link, slot.get(..*len).unwrap_or_default()));
            }
            voter.vote_step(clock.now(), &arrivals, |link, datagram, frame| {
                // The datagram the frame lies in gives its receive time.
                let origin = step.get(datagram).map_or(0, |(_, _, at)| *at);
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
        if report.log_if_due(&[&received, &downlink_hop, &turnaround]) {
            tracing::info!(stats = ?voter.stats(), "voting");
        }
        Ok(IDLE_WAIT)
    })?;
    tracing::info!(stats = ?voter.stats(), "voting at shutdown");
    report.finish(
        &[&received, &downlink_hop, &turnaround],
        &voter.stats().counters().collect::<Vec<_>>(),
    );
    Ok(())
}
