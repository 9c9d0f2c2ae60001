//! The driver of `gcs mavlink`: one UDP socket for the MAVLink clients and the GCS link to the
//! FCC. It only moves bytes and carries out the vehicle's events: every datagram from a client
//! goes to [`Vehicle::handle_datagram`], every datagram of [`Vehicle::poll_transmit`] goes to
//! `--to` (where QGroundControl listens) and to the client that spoke last, if another; the
//! downlink's #101 and #4001 go to the vehicle; a [`VehicleEvent::Commit`] is validated by the
//! safety gateway and uploaded atomically (ICD §8), a [`VehicleEvent::Execute`] is #50000
//! execute, a [`VehicleEvent::Clear`] the FCC's clear of the mission or the areas; each outcome
//! is reported back to the vehicle.

use std::fs::File;
use std::io::{BufWriter, Write as _};
use std::net::{SocketAddr, UdpSocket};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use missionlink_ground::ground_station::{
    GcsError, GcsEvent, MissionPlan, SafetyGateway, Sequence,
};

use super::vehicle::{Vehicle, VehicleEvent};
use missionlink_interfaces::wire::GeoPoint;
use missionlink_protocol::transfer::integrity::{areas_checksum, mission_checksum};
use missionlink_protocol::transfer::mission::Mission;

use super::memory::Memory;
use super::plan::{List, from_plan};
use crate::gcs_link::{Finished, GcsLink};
use crate::qgc::ExportOptions;

/// The ground service's own check of a plan to commit, after the safety gateway's: its mission
/// as validated and its take-off position; why not, in the operator's words.
pub type CommitCheck<'a> = dyn FnMut(&Mission, Option<GeoPoint>) -> Result<(), String> + 'a;

/// Largest MAVLink 2 datagram (280 bytes a frame; a datagram may hold several).
const DATAGRAM: usize = 2048;

/// The MAVLink side's socket: bound where the operator says, sending to `to` and to the client
/// that spoke last. Shared by reference: the ground service's vehicles send on one endpoint
/// from their threads while one thread receives.
#[derive(Debug)]
pub struct MavlinkSocket {
    socket: UdpSocket,
    to: SocketAddr,
    /// The client that spoke last.
    peer: Mutex<Option<SocketAddr>>,
    /// The session's capture, if asked for.
    tlog: Mutex<Option<BufWriter<File>>>,
}

impl MavlinkSocket {
    /// Binds `bind` (port 0: the system chooses) and sends to `to`.
    pub fn bind(bind: SocketAddr, to: SocketAddr) -> std::io::Result<Self> {
        let socket = UdpSocket::bind(bind)?;
        Ok(Self {
            socket,
            to,
            peer: Mutex::new(None),
            tlog: Mutex::new(None),
        })
    }

    /// The same socket capturing every MAVLink message it sends and receives into `path`, a
    /// telemetry log as QGroundControl and MAVProxy write them (`.tlog`: each message after its
    /// time, microseconds since 1970 as 8 bytes big-endian), which pymavlink reads (the
    /// pymavlink test reads its session's capture back with it).
    pub fn with_tlog(self, path: &Path) -> std::io::Result<Self> {
        let tlog = BufWriter::new(File::create(path)?);
        Ok(Self {
            tlog: Mutex::new(Some(tlog)),
            ..self
        })
    }

    /// The bound address.
    pub fn local_addr(&self) -> std::io::Result<SocketAddr> {
        self.socket.local_addr()
    }

    /// Where it sends.
    pub fn to(&self) -> SocketAddr {
        self.to
    }

    /// Sends `datagram` to `to` and to the client that spoke last, if another.
    pub fn send(&self, datagram: &[u8]) {
        self.capture(datagram);
        let peer = self.peer.lock().map_or(None, |p| *p);
        let mut targets = [Some(self.to), peer.filter(|p| *p != self.to)];
        for target in targets.iter_mut().flatten() {
            if let Err(e) = self.socket.send_to(datagram, *target) {
                tracing::debug!(%e, %target, "MAVLink datagram not sent");
            }
        }
    }

    /// Waits at most `wait` for a client's datagram; its length in `buf` (the sender becomes
    /// the client that spoke last), `None` when none came.
    pub fn receive(&self, buf: &mut [u8], wait: Duration) -> std::io::Result<Option<usize>> {
        self.socket
            .set_read_timeout(Some(wait.max(Duration::from_millis(1))))?;
        match self.socket.recv_from(buf) {
            Ok((len, from)) => {
                if let Ok(mut peer) = self.peer.lock() {
                    *peer = Some(from);
                }
                if let Some(d) = buf.get(..len) {
                    self.capture(d);
                }
                Ok(Some(len))
            }
            // Interrupted: a signal came (the debugger's, say); nothing was read.
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock
                        | std::io::ErrorKind::TimedOut
                        | std::io::ErrorKind::Interrupted
                ) =>
            {
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// Each message of `datagram` into the capture, if one is kept. A write that fails ends
    /// the capture, said once.
    fn capture(&self, datagram: &[u8]) {
        let Ok(mut guard) = self.tlog.lock() else {
            return;
        };
        let Some(tlog) = guard.as_mut() else {
            return;
        };
        let micros = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| u64::try_from(d.as_micros()).unwrap_or(u64::MAX));
        let mut written = Ok(());
        for message in messages(datagram) {
            written = written
                .and_then(|()| tlog.write_all(&micros.to_be_bytes()))
                .and_then(|()| tlog.write_all(message));
        }
        if let Err(e) = written.and_then(|()| tlog.flush()) {
            tracing::warn!(%e, "the MAVLink capture ends: it cannot be written");
            *guard = None;
        }
    }
}

/// The MAVLink messages of a datagram, by their framing (MAVLink 1: 0xFE, length, 6 header
/// bytes with the start, 2 of checksum; MAVLink 2: 0xFD, length, 10 header bytes, 2 of
/// checksum, 13 of signature when its incompatibility flag 1 says so). Bytes that are not a
/// whole message end the list.
fn messages(datagram: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = datagram;
    core::iter::from_fn(move || {
        let (&magic, tail) = rest.split_first()?;
        let &payload = tail.first()?;
        let payload = usize::from(payload);
        let len = match magic {
            0xFE => 6 + payload + 2,
            0xFD => 10 + payload + 2 + if tail.get(1)? & 1 != 0 { 13 } else { 0 },
            _ => return None,
        };
        let message = rest.get(..len)?;
        rest = rest.get(len..).unwrap_or_default();
        Some(message)
    })
}

/// What a previous run remembered in `path` ([`Memory`]), if it is there and reads; a file
/// that does not read is said once and left for the next memory to replace.
fn recall(path: &Path) -> Option<Memory> {
    let text = std::fs::read_to_string(path).ok()?;
    match Memory::from_text(&text) {
        Ok(memory) => Some(memory),
        Err(e) => {
            tracing::warn!(
                path = %path.display(),
                %e,
                "the MAVLink memory is not read: downloads give the lists as the FCC holds them"
            );
            None
        }
    }
}

/// Writes `memory` to `path` whole, so a crash leaves the old memory or the new one.
fn remember(path: &Path, memory: &Memory) {
    if let Err(e) = missionlink_platform::files::replace(path, memory.to_text().as_bytes()) {
        tracing::warn!(path = %path.display(), %e, "the MAVLink memory is not written");
    }
}

/// The lists the FCC holds, as MAVLink items, for the vehicle to answer downloads with; none
/// when the FCC holds none (or does not answer). Then what a previous run remembered in
/// `memory`, if given ([`Vehicle::recall`]).
pub fn read_lists<G: SafetyGateway>(
    link: &mut GcsLink<G>,
    vehicle: &mut Vehicle,
    memory: Option<&Path>,
) {
    read_fcc_lists(link, vehicle);
    if let Some(m) = memory.and_then(recall) {
        vehicle.recall(m);
    }
}

fn read_fcc_lists<G: SafetyGateway>(link: &mut GcsLink<G>, vehicle: &mut Vehicle) {
    let now = link.now();
    if link.station().download(now).is_err() {
        return;
    }
    if let Ok(Finished::Downloaded(plan)) = link.finish(|_| {}) {
        let (mission, fence) = from_plan(&plan, &ExportOptions::default());
        vehicle.set_lists(mission, fence);
        vehicle.set_ids(
            mission_checksum(&plan.mission).value(),
            areas_checksum(&plan.areas).value(),
        );
    }
}

/// Validates and uploads `plan` atomically: the checksums of the lists the FCC confirmed
/// (ICD §11), or why not, in the operator's words.
fn commit<G: SafetyGateway>(
    link: &mut GcsLink<G>,
    plan: &MissionPlan,
    check: &mut CommitCheck<'_>,
) -> Result<(u32, u32), String> {
    let lists = link.station().validate(plan).map_err(|e| e.to_string())?;
    check(&lists.mission, plan.take_off_position)?;
    let now = link.now();
    link.station()
        .upload_with(now, plan, Sequence::Atomic)
        .map_err(|e| e.to_string())?;
    match link.finish(|_| {}).map_err(|e| e.to_string())? {
        Finished::Uploaded(report) => Ok((report.uploaded.0.value(), report.uploaded.1.value())),
        // Confirmed, without checksums to show: MAVLink's "unknown".
        _ => Ok((0, 0)),
    }
}

/// A failure in the operator's words with the FCC's reason first, when it gave one: a ground
/// station shows the first 50 characters of a STATUSTEXT, and "command failed: #13000 Mission
/// Transfer Command" would fill them.
fn in_words<R: core::fmt::Display>(e: &GcsError<R>) -> String {
    match e {
        GcsError::Transfer { error, .. } => match error.reason() {
            Some(reason) => format!("{} ({reason}); {e}", reason.meaning()),
            None => e.to_string(),
        },
        _ => e.to_string(),
    }
}

/// The FCC's clear of `list`: the mission (#13000 mode 1 alone, which deletes the active
/// mission) or the areas (#2011 mode 6); why not, in the operator's words.
fn clear<G: SafetyGateway>(link: &mut GcsLink<G>, list: List) -> Result<(), String> {
    let now = link.now();
    let station = link.station();
    match list {
        List::Mission => station.clear_mission(now),
        List::Fence => station.clear_areas(now),
    }
    .map_err(|e| in_words(&e))?;
    link.finish(|_| {}).map(|_| ()).map_err(|e| in_words(&e))
}

fn execute<G: SafetyGateway>(link: &mut GcsLink<G>) -> Result<(), String> {
    let now = link.now();
    link.station()
        .execute(now, missionlink_interfaces::wire::ExecuteCommand::Execute)
        .map_err(|e| in_words(&e))?;
    link.finish(|_| {}).map(|_| ()).map_err(|e| in_words(&e))
}

/// Runs the vehicle until `stop` is set, keeping what it must remember across a restart in
/// `memory`, if given.
pub fn run<G: SafetyGateway>(
    link: &mut GcsLink<G>,
    vehicle: &mut Vehicle,
    socket: &MavlinkSocket,
    memory: Option<&Path>,
    stop: &AtomicBool,
) -> std::io::Result<()> {
    vehicle.start(link.now());
    while !stop.load(Ordering::Relaxed) {
        carry_out_events(link, vehicle, memory, &mut |_, _| Ok(()));
        tick(link.now(), vehicle, socket);
        // The downlink: positions and FROM-TO-NEXT.
        let mut downlink = Vec::new();
        link.run_until(Duration::from_millis(5), |event| {
            if matches!(event, GcsEvent::Position(_) | GcsEvent::FromToNext(_)) {
                downlink.push(event.clone());
            }
            false
        });
        let now = link.now();
        for event in &downlink {
            hear(now, vehicle, event);
        }
        // The clients: wait at most until the vehicle's next deadline.
        let wait = vehicle
            .poll_timeout()
            .map_or(Duration::from_millis(20), |t| t.saturating_since(now))
            .clamp(Duration::from_millis(1), Duration::from_millis(20));
        let mut datagram = [0u8; DATAGRAM];
        if let Some(len) = socket.receive(&mut datagram, wait)?
            && let Some(d) = datagram.get(..len)
        {
            vehicle.handle_datagram(link.now(), d);
        }
    }
    Ok(())
}

/// What the vehicle asked of the GCS link (a commit, execute, a clear), carried out and
/// reported back; what it must remember written to `memory`; the links' counts handed over. A
/// plan to commit passes the safety gateway, then `check` of its mission as validated, with its
/// take-off position (the ground service's separation from the fleet), before it goes. Whether
/// a list may have changed on the FCC.
pub fn carry_out_events<G: SafetyGateway>(
    link: &mut GcsLink<G>,
    vehicle: &mut Vehicle,
    memory: Option<&Path>,
    check: &mut CommitCheck<'_>,
) -> bool {
    let mut changed = false;
    while let Some(event) = vehicle.poll_event() {
        match event {
            VehicleEvent::Commit { plan } => {
                changed = true;
                let outcome = commit(link, &plan.plan, check);
                match &outcome {
                    Ok((mission_id, fence_id)) => vehicle.set_ids(*mission_id, *fence_id),
                    Err(why) => {
                        tracing::warn!(%why, "the MAVLink client's plan was not committed");
                    }
                }
                vehicle.committed(outcome.map(|_| ()));
            }
            VehicleEvent::Execute => vehicle.executed(execute(link)),
            VehicleEvent::Clear { list } => {
                changed = true;
                let outcome = clear(link, list);
                if let Err(why) = &outcome {
                    tracing::warn!(%why, %list, "the MAVLink client's clear was refused");
                }
                vehicle.cleared(list, outcome);
            }
        }
    }
    if let (Some(path), Some(m)) = (memory, vehicle.memory()) {
        remember(path, &m);
    }
    let stats = link.voter().stats();
    let rejected = stats.rejected_frames.total()
        + stats.rejected_signatures.total()
        + stats.unreadable_messages;
    let [direct, lte] = stats.forwarded;
    let all = direct
        + lte
        + stats.duplicates
        + stats.stale
        + stats.before_start
        + stats.overflow
        + rejected;
    vehicle.set_link_counts(all, rejected);
    changed
}

/// The vehicle's deadlines that passed at `now`, and every datagram it has to send, sent: what
/// keeps its heartbeat going while the GCS link is busy with a request.
pub fn tick(
    now: missionlink_protocol::link::time::Instant,
    vehicle: &mut Vehicle,
    socket: &MavlinkSocket,
) {
    if vehicle.poll_timeout().is_some_and(|t| t <= now) {
        vehicle.handle_timeout(now);
    }
    let mut buf = [0u8; DATAGRAM];
    while let Some(len) = vehicle.poll_transmit(&mut buf) {
        if let Some(datagram) = buf.get(..len) {
            socket.send(datagram);
        }
    }
}

/// A downlink report for the vehicle: a position (#101) or FROM-TO-NEXT (#4001).
pub fn hear<R>(
    now: missionlink_protocol::link::time::Instant,
    vehicle: &mut Vehicle,
    event: &GcsEvent<R>,
) {
    match event {
        GcsEvent::Position(p) => vehicle.handle_position(now, p),
        GcsEvent::FromToNext(f) => vehicle.handle_from_to_next(f),
        _ => {}
    }
}
