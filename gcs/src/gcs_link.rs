//! The GCS end of the two links: the sans-IO GCS logic (`missionlink_ground::ground_station::GroundStation`) driven
//! over UDP, every uplink frame sent on both links, the downlink voted with the same voting code
//! the FCC uses (paper §2.4). Optionally logs every message with its time, direction and
//! acknowledgement, as the paper's Figure 15 shows a transfer.

use std::time::Duration;

use missionlink_ground::ground_station::outcome::UploadReport;
use missionlink_ground::ground_station::{
    GcsConfig, GcsError, GcsEvent, GroundStation, SafetyGateway, ValidatedPlan,
};
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::MissionReport;
use missionlink_interfaces::wire::{self, MAX_FRAME_LEN, Message, Timestamp};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::voting::Voter;

use missionlink_platform::clock::DriverClock;
use missionlink_platform::config::LinkConfig;
use missionlink_platform::files::LineFile;
use missionlink_platform::keys::LinkSigning;
use std::os::fd::AsFd;

use missionlink_platform::udp::{LinkError, LinkPair, MAX_DATAGRAM, MAX_READS_PER_RECEIVE};
use missionlink_protocol::link::signing::{Policy, Signer};

/// The GCS logic that talks to the FCC `config` describes (its IDs and timeouts), its instant
/// zero at `utc_at_zero`: for the GCS link and the tests that play the ground.
pub fn gcs_core(config: &LinkConfig, utc_at_zero: Timestamp) -> GcsConfig {
    GcsConfig {
        endpoint: config.ids.gcs_endpoint(utc_at_zero),
        ack_timeout: config.timing.ack_timeout(),
        transfer_timeout: config.timing.transfer_timeout(),
        transfer_window: config.timing.transfer_window(),
        upload_attempts: config.timing.upload_attempts.max(1),
    }
}

/// How far ahead of the last stamp used [`GcsLink::with_stamp_lease`] reserves.
const STAMP_LEASE: Duration = Duration::from_secs(1);
/// How far ahead of the highest stamp admitted [`GcsLink::with_replay_lease`] keeps its floor;
/// renewed when less than half of it is left (at most some 8 writes a second while the FCC's
/// stamps advance). A GCS started within this of the last one waits until its clock passes
/// the floor before it sends, so that the FCC's answers to it come after the floor.
const REPLAY_LEASE: Duration = Duration::from_millis(250);

/// The downlink's replay window kept across processes ([`GcsLink::with_replay_lease`]): the
/// floor written in its file, and a renewal due but not yet written.
///
/// The file stays open and each renewal overwrites its one line in place
/// ([`LineFile`]): with a position report every half second a renewal is due at almost every
/// one. The next GCS reads the file once this one has stopped; should a crash leave a line
/// that does not read, it counts as none (the window starts at that GCS's start: nothing
/// before it is taken).
#[derive(Debug)]
struct ReplayLease {
    path: std::path::PathBuf,
    /// Open for writing; `None` when it could not be opened (warned about once).
    file: Option<LineFile>,
    floor: wire::Timestamp,
    /// The highest stamp admitted, when it came within half a lease of the floor.
    due: Option<wire::Timestamp>,
}

impl ReplayLease {
    /// The highest stamp admitted so far is `highest`: a renewal is due when less than half a
    /// lease is left above it.
    fn admitted(&mut self, highest: wire::Timestamp) {
        let half = REPLAY_LEASE.as_millis() as u64 / 2;
        if highest.millis().saturating_add(half) >= self.floor.millis() {
            self.due = Some(highest);
        }
    }

    /// Writes the renewal due, if one is: a lease ahead of the highest stamp admitted.
    fn write_due(&mut self) {
        let Some(highest) = self.due.take() else {
            return;
        };
        let ahead = highest
            .millis()
            .saturating_add(REPLAY_LEASE.as_millis() as u64);
        let Some(file) = &mut self.file else {
            return;
        };
        match file.write(&lease_line(ahead)) {
            Ok(()) => self.floor = wire::Timestamp::from_millis(ahead).unwrap_or(highest),
            Err(e) => {
                tracing::warn!(
                    file = %self.path.display(),
                    %e,
                    "cannot keep the replay window: a GCS started next refuses what the FCC \
                     sent before it as sent before its start"
                );
                self.file = None;
            }
        }
    }
}

/// A lease's line: 20 digits hold any u64, so every line is as long as the one it overwrites.
fn lease_line(millis: u64) -> String {
    format!("{millis:020}")
}

/// What a lease's file holds: the time stamp it reserved, `None` when there is none or it does
/// not read.
fn read_lease(file: &std::path::Path) -> Option<wire::Timestamp> {
    LineFile::read(file)
        .and_then(|t| t.trim().parse::<u64>().ok())
        .and_then(wire::Timestamp::from_millis)
}

impl Drop for ReplayLease {
    fn drop(&mut self) {
        self.write_due();
    }
}

/// How a request ended well.
#[derive(Debug, Clone, PartialEq)]
pub enum Finished {
    /// A command was accepted (or nothing was in progress).
    Done,
    /// An upload completed: both lists are active.
    Uploaded(Box<UploadReport>),
    /// The lists downloaded.
    Downloaded(Box<ValidatedPlan>),
    /// The FCC's report (ICD §8), the active lists first.
    Reported(Vec<MissionReport>),
}

impl Finished {
    /// The downloaded lists, if the request was a download.
    pub fn into_plan(self) -> Option<ValidatedPlan> {
        match self {
            Self::Downloaded(plan) => Some(*plan),
            _ => None,
        }
    }
}

/// Which way a logged message went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// GCS to FCC.
    Up,
    /// FCC to GCS (as voted: one entry per message, whatever the links duplicated).
    Down,
}

/// One logged message.
#[derive(Debug, Clone)]
pub struct Logged {
    /// Since the link was opened.
    pub at: Duration,
    /// Up or down.
    pub direction: Direction,
    /// The message.
    pub message: Message,
}

/// What one link brought from the FCC's side, for the ground service's status.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkActivity {
    /// Datagrams received.
    pub datagrams: u64,
    /// When the last one came.
    pub last: Option<std::time::Instant>,
}

/// The GCS over UDP.
#[derive(Debug)]
pub struct GcsLink<G: SafetyGateway> {
    links: LinkPair,
    /// The Key ID the uplink is signed with.
    signing: Option<u8>,
    voter: Voter,
    /// Boxed: the GCS logic holds its transfers inline (over 100 KB), and a link moves by value
    /// through the tool's commands (in a debug build each move is a copy on the stack).
    station: Box<GroundStation<G>>,
    clock: DriverClock,
    started: std::time::Instant,
    /// One pump's datagrams, copied out of the socket buffer: as many slots as
    /// [`LinkPair::receive`] reads, so every datagram it reads reaches the voter (the voter
    /// counts what a step cannot hold). Allocated once.
    slots: Vec<[u8; MAX_DATAGRAM]>,
    /// The file that reserves time stamps across processes, and how far it reserves.
    stamp_lease: Option<(LineFile, wire::Timestamp)>,
    /// The file that keeps the replay window's floor across processes.
    replay_lease: Option<ReplayLease>,
    /// What each link (direct, LTE) brought: datagrams and when the last one came.
    activity: [LinkActivity; 2],
    /// Every message sent and every voted message received, when logging is on, but the
    /// periodic position downlink (#101).
    pub log: Vec<Logged>,
    logging: bool,
}

impl<G: SafetyGateway> GcsLink<G> {
    /// Binds the GCS's ends of both links as `config` says.
    pub fn open(config: &LinkConfig, gateway: G) -> Result<Self, LinkError> {
        let links = LinkPair::bind(
            config.links.gcs_direct,
            config.links.gcs_lte,
            config.links.fcc_direct,
            config.links.fcc_lte,
        )?;
        Self::with_links(config, links, gateway)
    }

    /// Over links the caller bound already (the demo and the tests bind port 0 themselves and
    /// hand the FCC the ports they got); `config` gives the IDs, timeouts and link signing
    /// (ICD §9: an unusable key file is the error).
    pub fn with_links(config: &LinkConfig, links: LinkPair, gateway: G) -> Result<Self, LinkError> {
        let signing = LinkSigning::load(&config.signing).map_err(|e| LinkError(e.to_string()))?;
        let clock = DriverClock::start();
        let mut station = Box::new(GroundStation::new(
            gcs_core(config, clock.utc_at_zero()),
            gateway,
        ));
        station.set_link_rate(config.timing.uplink_rate());
        tracing::debug!(signing = %signing.summary(), "link signing (ICD §9)");
        // Said at every start, as the FCC says it: a link anyone on the path can write to must
        // not pass unnoticed.
        match signing.policy {
            Policy::Off => tracing::warn!(
                "the links are not authenticated: signing is off ([signing] policy = \"off\"), \
                 so this ground takes any FCC's answers for its vehicle's (ICD §9)"
            ),
            Policy::Accept => tracing::warn!(
                "unsigned frames are accepted ([signing] policy = \"accept\"): only \"require\" \
                 authenticates the links (ICD §9)"
            ),
            Policy::Require => {}
        }
        Ok(Self {
            signing: signing.signer.as_ref().map(Signer::key_id),
            links: links.with_signer(signing.signer.clone()),
            voter: Voter::new(
                config.ids.gcs,
                config.ids.fcc,
                config.timing.transfer_timeout(),
            )
            .with_signatures(signing.check(clock.utc_at_zero(), clock.now())),
            station,
            clock,
            started: std::time::Instant::now(),
            slots: vec![[0u8; MAX_DATAGRAM]; MAX_READS_PER_RECEIVE],
            stamp_lease: None,
            replay_lease: None,
            activity: [LinkActivity::default(); 2],
            log: Vec::new(),
            logging: false,
        })
    }

    /// Reserves this GCS's time stamps in `file` (see the module documentation): every stamp is
    /// above what the file reserved for earlier processes, and the file is moved ahead before a
    /// stamp beyond it is sent. A file that cannot be read counts as empty; one that cannot be
    /// written is the error.
    pub fn with_stamp_lease(mut self, file: &std::path::Path) -> Result<Self, LinkError> {
        let reserved = read_lease(file);
        if let Some(floor) = reserved {
            self.station.resume_stamps_after(floor);
        }
        let now = self.clock.utc_at_zero();
        let start = reserved.map_or(now, |r| r.max(now));
        let lease =
            LineFile::open(file).map_err(|e| LinkError(format!("{}: {e}", file.display())))?;
        self.stamp_lease = Some((lease, start));
        self.reserve_stamps(start)?;
        Ok(self)
    }

    /// Keeps the downlink's replay window (ICD §9 "Replay") across processes in `file`: a stamp
    /// at or above every FCC stamp this GCS admitted, renewed ahead of them. A GCS started
    /// again reads it, refuses what is at or below it as sent before its start, and takes what
    /// the FCC sent after it as new, though it was sent before this start (the signature
    /// check's [`resume_after`](missionlink_protocol::link::signing::SignatureCheck::resume_after)).
    /// A file that cannot be read counts as none (the window starts at this start); one that
    /// cannot be written is warned about.
    pub fn with_replay_lease(mut self, file: &std::path::Path) -> Self {
        let floor = read_lease(file);
        if let Some(floor) = floor {
            self.voter.signatures_mut().resume_after(floor);
            // The FCC's answers to this GCS must come after the floor to be taken: a GCS
            // started right after another waits the rest of the lease (the FCC's clock agrees
            // with this one's within what ICD §9 asks).
            let now = DriverClock::start().utc_at_zero();
            // Past the floor: one millisecond beyond it.
            let wait = (floor.millis() + 1)
                .saturating_sub(now.millis())
                .min(REPLAY_LEASE.as_millis() as u64 + 1);
            std::thread::sleep(Duration::from_millis(wait));
        }
        let open = match LineFile::open(file) {
            Ok(f) => Some(f),
            Err(e) => {
                tracing::warn!(
                    file = %file.display(),
                    %e,
                    "cannot keep the replay window: a GCS started next refuses what the FCC \
                     sent before it as sent before its start"
                );
                None
            }
        };
        self.replay_lease = Some(ReplayLease {
            path: file.to_owned(),
            file: open,
            floor: floor.unwrap_or_default(),
            due: None,
        });
        self
    }

    /// Moves the reservation to one second past `stamp` and writes it whole (one line of fixed
    /// width overwritten in place: [`LineFile`]).
    fn reserve_stamps(&mut self, stamp: wire::Timestamp) -> Result<(), LinkError> {
        let Some((file, reserved)) = self.stamp_lease.as_mut() else {
            return Ok(());
        };
        let ahead = stamp
            .millis()
            .saturating_add(STAMP_LEASE.as_millis() as u64);
        file.write(&lease_line(ahead))
            .map_err(|e| LinkError(format!("{}: {e}", file.path().display())))?;
        *reserved = wire::Timestamp::from_millis(ahead).unwrap_or(stamp);
        Ok(())
    }

    /// The Key ID this GCS signs with, if it signs (ICD §9).
    pub fn signing_key_id(&self) -> Option<u8> {
        self.signing
    }

    /// When this GCS has heard nothing from the FCC, what the silence may mean as far as link
    /// signing goes (ICD §9): a GCS with a key never falls back to unsigned frames, so it says
    /// that the FCC's frames fail its check, or that the FCC does not verify its key (or does
    /// not run); a GCS without one says that an FCC that requires signing, the default, drops
    /// its frames. `None` when the GCS has heard the FCC.
    pub fn unheard(&self) -> Option<String> {
        let stats = self.voter.stats();
        if stats.forwarded.iter().any(|n| *n > 0) {
            return None;
        }
        let rejected = stats.rejected_signatures;
        let Some(key_id) = self.signing else {
            return Some(
                "nothing was heard from the FCC. This GCS sends unsigned frames: an FCC that \
                 requires signing (the default, ICD §9) drops them, or the FCC does not run"
                    .to_owned(),
            );
        };
        Some(if rejected.total() > 0 {
            format!(
                "the FCC sends, but its frames fail this GCS's signature check ({rejected:?}): \
                 this GCS signs with key {key_id}, and the two sides hold different keys or \
                 policies. The GCS does not fall back to unsigned frames (ICD §9)"
            )
        } else {
            format!(
                "nothing was heard from the FCC. This GCS signs with key {key_id}: an FCC that does \
                 not hold that key, or does not run, stays silent. The GCS does not fall back to \
                 unsigned frames (ICD §9)"
            )
        })
    }

    /// Where this GCS receives the direct link and the LTE link (the ports bound, when port 0
    /// was asked for); the unspecified address when the system cannot say.
    pub fn local_addrs(&self) -> [std::net::SocketAddr; 2] {
        self.links
            .local_addrs()
            .unwrap_or([std::net::SocketAddr::from(([0, 0, 0, 0], 0)); 2])
    }

    /// What the direct link and the LTE link brought, in that order.
    pub fn activity(&self) -> [LinkActivity; 2] {
        self.activity
    }

    /// The voter of the downlink (its counters, the signature check's among them).
    pub fn voter(&self) -> &Voter {
        &self.voter
    }

    /// Ends this GCS as a crash would (nothing more is sent, answered or retried) and hands back
    /// its sockets, for a GCS started again on the same ports (the FCC answers to them).
    pub fn into_links(self) -> LinkPair {
        self.links
    }

    /// Logs every message from now on.
    pub fn enable_log(&mut self) {
        self.logging = true;
    }

    /// The GCS logic, to start requests.
    pub fn station(&mut self) -> &mut GroundStation<G> {
        &mut self.station
    }

    /// The clock of the GCS logic (for a state machine beside it that must keep the same time).
    pub fn clock(&self) -> DriverClock {
        self.clock
    }

    /// Now, for requests to the GCS logic.
    pub fn now(&self) -> Instant {
        self.clock.now()
    }

    fn record(&mut self, direction: Direction, message: Message) {
        // The log is of the exchanges of ICD §5: the periodic position downlink (#101, §5.8)
        // would only grow it by two entries a second and shift the counts of transfers; the
        // driver hands each position on as `GcsEvent::Position` instead.
        if self.logging && !matches!(message, Message::InertialStates(_)) {
            self.log.push(Logged {
                at: self.started.elapsed(),
                direction,
                message,
            });
        }
    }

    /// Sends the frames the GCS logic encoded, on both links: the driver only moves bytes (it
    /// decodes a frame again only to log it, when asked to).
    fn flush(&mut self) {
        // The stamps of the frames about to leave were issued already: reserve past them first.
        let last = self.station.endpoint().last_stamp();
        if let (Some(last), Some((_, reserved))) = (last, &self.stamp_lease)
            && last >= *reserved
            && let Err(e) = self.reserve_stamps(last)
        {
            tracing::warn!(%e, "cannot reserve time stamps: a GCS started next may reuse them");
        }
        let mut buf = [0u8; MAX_FRAME_LEN];
        while let Some(encoded) = self.station.poll_transmit(&mut buf) {
            let frame = match encoded {
                Ok(len) => buf.get(..len).unwrap_or_default(),
                Err(e) => {
                    tracing::error!(%e, "cannot encode");
                    continue;
                }
            };
            if self.links.send_both(frame) == 0 {
                tracing::warn!("no link could send");
            }
            if self.logging {
                match wire::decode(frame) {
                    Ok((_, message)) => self.record(Direction::Up, message),
                    Err(e) => tracing::error!(%e, "a frame the GCS logic encoded does not decode"),
                }
            }
        }
    }

    /// Runs the links for at most `wait`: sends, sleeps until a datagram or the next timer,
    /// votes and handles what arrived, fires due timers.
    pub fn pump(&mut self, wait: Duration) {
        self.pump_or_bell(wait, None);
    }

    /// [`GcsLink::pump`], woken too when `bell` becomes readable (the owner's queue of work: an
    /// eventfd another thread writes).
    pub fn pump_or_bell(&mut self, wait: Duration, bell: Option<std::os::fd::BorrowedFd<'_>>) {
        // The replay window's floor follows what the last pump admitted. Written here, once its
        // caller has handed on what arrived, not between the arrival and the caller: the write
        // of a file (about a millisecond here) would otherwise delay every position report on
        // its way to the MAVLink side and the monitors. A link dropped writes it too.
        if let Some(lease) = &mut self.replay_lease {
            lease.write_due();
        }
        self.flush();
        let now = self.clock.now();
        let until_timer = self
            .station
            .poll_timeout()
            .map_or(wait, |t| t.saturating_since(now))
            .min(wait);
        let timeout = rustix::time::Timespec {
            tv_sec: until_timer.as_secs() as _,
            tv_nsec: until_timer.subsec_nanos() as _,
        };
        {
            let [direct, lte] = self.links.sockets();
            let mut fds: heapless::Vec<rustix::event::PollFd<'_>, 3> = heapless::Vec::new();
            for fd in [direct.as_fd(), lte.as_fd()].into_iter().chain(bell) {
                let _ = fds.push(rustix::event::PollFd::from_borrowed_fd(
                    fd,
                    rustix::event::PollFlags::IN,
                ));
            }
            if let Err(e) = rustix::event::poll(&mut fds, Some(&timeout)) {
                if e != rustix::io::Errno::INTR {
                    tracing::warn!(%e, "poll failed");
                }
            }
        }
        let slots = &mut self.slots;
        let mut lens: heapless::Vec<(Link, usize), MAX_READS_PER_RECEIVE> = heapless::Vec::new();
        let mut buf = [0u8; MAX_DATAGRAM];
        self.links.receive(&mut buf, |link, datagram, _| {
            let slot = slots
                .get_mut(lens.len())
                .and_then(|s| s.get_mut(..datagram.len()));
            // `receive` reads at most MAX_READS_PER_RECEIVE datagrams of at most MAX_DATAGRAM
            // bytes, so there is always a slot; should there not be, say so.
            match slot {
                Some(slot) if lens.push((link, datagram.len())).is_ok() => {
                    slot.copy_from_slice(datagram)
                }
                _ => tracing::error!(?link, "no slot for a received datagram: dropped"),
            }
        });
        let now = self.clock.now();
        let arrived = std::time::Instant::now();
        for (link, _) in &lens {
            // A datagram comes on one socket; `Both` names no socket.
            let activity = match link {
                Link::Lte => &mut self.activity[1],
                Link::Direct | Link::Both => &mut self.activity[0],
            };
            activity.datagrams += 1;
            activity.last = Some(arrived);
        }
        if !lens.is_empty() {
            let mut arrivals: heapless::Vec<(Link, &[u8]), MAX_READS_PER_RECEIVE> =
                heapless::Vec::new();
            for (slot, (link, len)) in self.slots.iter().zip(&lens) {
                let _ = arrivals.push((*link, slot.get(..*len).unwrap_or_default()));
            }
            let station = &mut self.station;
            let mut received = Vec::new();
            self.voter.vote_step(now, &arrivals, |_, _, frame| {
                // Counted by cause and logged at most once a second by the endpoint.
                let _ = station.handle_frame(now, frame);
                if let Ok((_, m)) = wire::decode(frame) {
                    received.push(m);
                }
            });
            // The arrivals borrow the slots; recording needs all of `self`.
            drop(arrivals);
            if let (Some(lease), Some(highest)) = (
                &mut self.replay_lease,
                self.voter.signatures().admitted_up_to(),
            ) {
                lease.admitted(highest);
            }
            for m in received {
                self.record(Direction::Down, m);
            }
        }
        if self.station.poll_timeout().is_some_and(|t| t <= now) {
            self.station.handle_timeout(now);
        }
        self.flush();
    }

    /// Runs the links until the request in progress ends, and gives its outcome. The GCS logic
    /// ends every request by itself (2 x ack timeout per message, the transfer timeout for a
    /// download). The other events (progress, FROM-TO-NEXT) go to `on_event`. Without a
    /// request in progress it returns at once.
    pub fn finish(
        &mut self,
        mut on_event: impl FnMut(&GcsEvent<G::Report>),
    ) -> Result<Finished, GcsError<G::Report>> {
        self.finish_ticking(|event, _| {
            if let Some(event) = event {
                on_event(event);
            }
        })
    }

    /// [`GcsLink::finish`], with `on` also called with `None` and the GCS logic after every pump
    /// of the links (for what must follow the request as it runs: the copies it stages).
    pub fn finish_ticking(
        &mut self,
        mut on: impl FnMut(Option<&GcsEvent<G::Report>>, &GroundStation<G>),
    ) -> Result<Finished, GcsError<G::Report>> {
        loop {
            while let Some(event) = self.station.poll_event() {
                match event {
                    GcsEvent::CommandAccepted(_) => return Ok(Finished::Done),
                    GcsEvent::Uploaded(report) => return Ok(Finished::Uploaded(report)),
                    GcsEvent::DownloadComplete(plan) => return Ok(Finished::Downloaded(plan)),
                    GcsEvent::Reported(entries) => {
                        return Ok(Finished::Reported(entries.into_iter().collect()));
                    }
                    GcsEvent::Failed(e) => return Err(e),
                    other => on(Some(&other), &self.station),
                }
            }
            if self.station.is_standby() {
                return Ok(Finished::Done);
            }
            self.pump(Duration::from_millis(20));
            on(None, &self.station);
        }
    }

    /// Runs the links until `done` returns true for an event, or `limit` passes; hands every
    /// event to `done`. Returns whether `done` said so.
    pub fn run_until(
        &mut self,
        limit: Duration,
        mut done: impl FnMut(&GcsEvent<G::Report>) -> bool,
    ) -> bool {
        let end = std::time::Instant::now() + limit;
        while std::time::Instant::now() < end {
            self.pump(Duration::from_millis(20).min(end - std::time::Instant::now()));
            while let Some(event) = self.station.poll_event() {
                if done(&event) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::UdpSocket;

    use missionlink_ground::ground_station::WithoutGateway;
    use missionlink_interfaces::wire::{AckType, Envelope, MessageAcknowledgement, Timestamp};

    /// A #17000 from the FCC stamped `ms`: every one a message of its own to the voter.
    fn ack(config: &LinkConfig, ms: u64) -> Vec<u8> {
        let message = Message::from(MessageAcknowledgement {
            time_stamp: Timestamp::from_millis(ms).unwrap(),
            original_time_stamp: Timestamp::from_millis(1).unwrap(),
            original_message_type: 13002,
            ack_type: AckType::Completed,
            reject_reason: None,
        });
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = wire::encode(
            &Envelope::new(config.ids.fcc, config.ids.gcs),
            &message,
            &mut buf,
        )
        .unwrap();
        buf[..len].to_vec()
    }

    /// A GCS that kept its replay window (a floor 20 s back) takes an FCC frame stamped after
    /// the floor as new, though the FCC sent it before this GCS started, and counts one at or
    /// below the floor as sent before its start; it renews the lease past what it admitted.
    #[test]
    fn a_kept_replay_window_admits_what_came_after_its_floor() {
        use missionlink_platform::keys;
        use missionlink_protocol::link::signing::Signer;
        let dir = tempfile::Builder::new()
            .prefix("replay-lease-")
            .tempdir()
            .unwrap();
        let key_file = dir.path().join("link.key");
        keys::generate_key_files(&[&key_file], 1).unwrap();
        let signer = Signer::new(keys::read_key_file(&key_file).unwrap());
        let fcc_direct = UdpSocket::bind("127.0.0.1:0").unwrap();
        let fcc_lte = UdpSocket::bind("127.0.0.1:0").unwrap();
        let mut config = LinkConfig::default();
        config.links.gcs_direct = "127.0.0.1:0".parse().unwrap();
        config.links.gcs_lte = "127.0.0.1:0".parse().unwrap();
        config.links.fcc_direct = fcc_direct.local_addr().unwrap();
        config.links.fcc_lte = fcc_lte.local_addr().unwrap();
        config.signing.key_files = vec![key_file];
        let now = DriverClock::start().utc_at_zero().millis();
        let lease = dir.path().join("replay-window");
        std::fs::write(&lease, format!("{}\n", now - 20_000)).unwrap();
        let mut link = GcsLink::open(&config, WithoutGateway)
            .unwrap()
            .with_replay_lease(&lease);
        let [gcs_direct, _] = link.links.sockets().map(|s| s.local_addr().unwrap());
        let send = |ms: u64| {
            let mut out = [0u8; wire::MAX_SIGNED_FRAME_LEN];
            let len = signer
                .sign(Link::Direct, &ack(&config, ms), &mut out)
                .unwrap();
            fcc_direct.send_to(&out[..len], gcs_direct).unwrap();
        };
        send(now - 10_000);
        send(now - 30_000);
        for _ in 0..100 {
            let stats = link.voter.stats();
            if stats.forwarded[0] + stats.before_start >= 2 {
                break;
            }
            link.pump(Duration::from_millis(20));
        }
        let stats = link.voter.stats();
        assert_eq!(stats.forwarded, [1, 0], "the frame after the floor is new");
        assert_eq!(
            stats.before_start, 1,
            "the one below it may have been admitted"
        );
        assert_eq!(stats.rejected_signatures.total(), 0);
        // The renewal is written at the next pump, once the caller has handed on what arrived.
        link.pump(Duration::ZERO);
        let renewed: u64 = std::fs::read_to_string(&lease)
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        assert_eq!(renewed, now - 10_000 + REPLAY_LEASE.as_millis() as u64);
        // A GCS started within the lease of the last one waits until its clock passes it.
        let floor = DriverClock::start().utc_at_zero().millis() + 200;
        std::fs::write(&lease, format!("{floor}\n")).unwrap();
        let _next = GcsLink::open(&config, WithoutGateway)
            .unwrap()
            .with_replay_lease(&lease);
        assert!(DriverClock::start().utc_at_zero().millis() > floor);
    }

    /// `[timing] uplink_rate_bps` reaches the window of the GCS logic (ICD §10.4): with a rate,
    /// the window counts bytes in flight (none before a round trip is measured); without, it
    /// does not.
    #[test]
    fn the_uplink_rate_of_the_configuration_limits_the_window() {
        let mut config = LinkConfig::default();
        config.links.gcs_direct = "127.0.0.1:0".parse().unwrap();
        config.links.gcs_lte = "127.0.0.1:0".parse().unwrap();
        config.signing.policy = missionlink_platform::config::SigningPolicy::Off;
        let mut link = GcsLink::open(&config, WithoutGateway).unwrap();
        assert_eq!(link.station().link_window().bytes(), None);
        config.timing.uplink_rate_bps = 64_000;
        let mut link = GcsLink::open(&config, WithoutGateway).unwrap();
        assert_eq!(link.station().link_window().bytes(), Some(0));
    }

    /// A burst of more datagrams than the pump once had slots for (8) all reach the voter and
    /// the GCS logic: none is read and then dropped.
    #[test]
    fn a_burst_of_datagrams_is_handled_whole() {
        let fcc_direct = UdpSocket::bind("127.0.0.1:0").unwrap();
        let fcc_lte = UdpSocket::bind("127.0.0.1:0").unwrap();
        let mut config = LinkConfig::default();
        config.links.gcs_direct = "127.0.0.1:0".parse().unwrap();
        config.links.gcs_lte = "127.0.0.1:0".parse().unwrap();
        config.links.fcc_direct = fcc_direct.local_addr().unwrap();
        config.links.fcc_lte = fcc_lte.local_addr().unwrap();
        // The frames below are unsigned, as from an FCC that cannot sign.
        config.signing.policy = missionlink_platform::config::SigningPolicy::Off;
        let mut link = GcsLink::open(&config, WithoutGateway).unwrap();
        link.enable_log();
        let [gcs_direct, gcs_lte] = link.links.sockets().map(|s| s.local_addr().unwrap());

        // Within what one receive reads from one socket, and three times the old slot count.
        const BURST: u64 = 25;
        for ms in 1000..1000 + BURST {
            let frame = ack(&config, ms);
            fcc_direct.send_to(&frame, gcs_direct).unwrap();
            fcc_lte.send_to(&frame, gcs_lte).unwrap();
        }
        let down = |link: &GcsLink<WithoutGateway>| {
            link.log
                .iter()
                .filter(|l| l.direction == Direction::Down)
                .count() as u64
        };
        // Pumps until every message came down; a datagram read and dropped never comes, so the
        // bound ends the test with the count that arrived.
        for _ in 0..100 {
            if down(&link) == BURST {
                break;
            }
            link.pump(Duration::from_millis(20));
        }
        assert_eq!(down(&link), BURST);
        let stats = link.voter.stats();
        assert_eq!(stats.forwarded[0] + stats.forwarded[1], BURST);
        assert_eq!(stats.duplicates, BURST, "every LTE copy was read and voted");
        assert_eq!(stats.overflow, 0);
    }
}
