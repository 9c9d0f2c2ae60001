//! The GCS end of the two links: the sans-IO GCS logic (`services::gcs::GroundStation`) driven
//! over UDP, every uplink frame sent on both links, the downlink voted with the same voting code
//! the FCC uses (paper §2.4). Optionally logs every message with its time, direction and
//! acknowledgement, as the paper's Figure 15 shows a transfer.

use std::time::Duration;

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::{self, MAX_FRAME_LEN, Message};
use missionlink_services::ground_station::{
    GcsConfig, GcsError, GcsEvent, GroundStation, SafetyGateway, ValidatedPlan,
};
use missionlink_services::link::endpoint::EndpointConfig;
use missionlink_services::link::time::Instant;
use missionlink_services::voting::{VOTING_STEP_MESSAGES, Voter};

use missionlink_partitions::clock::DriverClock;
use missionlink_partitions::config::Config;
use missionlink_partitions::udp::{LinkError, LinkPair, MAX_DATAGRAM};

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

/// The GCS over UDP.
#[derive(Debug)]
pub struct GcsLink<G: SafetyGateway> {
    links: LinkPair,
    voter: Voter,
    station: GroundStation<G>,
    clock: DriverClock,
    started: std::time::Instant,
    /// Every message sent and every voted message received, when logging is on.
    pub log: Vec<Logged>,
    logging: bool,
}

impl<G: SafetyGateway> GcsLink<G> {
    /// Binds the GCS's ends of both links as `config` says.
    pub fn open(config: &Config, gateway: G) -> Result<Self, LinkError> {
        let links = LinkPair::bind(
            config.links.gcs_direct,
            config.links.gcs_lte,
            config.links.fcc_direct,
            config.links.fcc_lte,
        )?;
        let clock = DriverClock::start();
        let station = GroundStation::new(
            GcsConfig {
                endpoint: EndpointConfig {
                    local_id: config.ids.gcs,
                    peer_id: config.ids.fcc,
                    utc_at_zero: clock.utc_at_zero(),
                    sampling_window: config.timing.transfer_timeout(),
                },
                ack_timeout: config.timing.ack_timeout(),
                transfer_timeout: config.timing.transfer_timeout(),
            },
            gateway,
        );
        Ok(Self {
            links,
            voter: Voter::new(
                config.ids.gcs,
                config.ids.fcc,
                config.timing.transfer_timeout(),
            ),
            station,
            clock,
            started: std::time::Instant::now(),
            log: Vec::new(),
            logging: false,
        })
    }

    /// Logs every message from now on.
    pub fn enable_log(&mut self) {
        self.logging = true;
    }

    /// The GCS logic, to start requests.
    pub fn station(&mut self) -> &mut GroundStation<G> {
        &mut self.station
    }

    /// Now, for requests to the GCS logic.
    pub fn now(&self) -> Instant {
        self.clock.now()
    }

    fn record(&mut self, direction: Direction, message: Message) {
        if self.logging {
            self.log.push(Logged {
                at: self.started.elapsed(),
                direction,
                message,
            });
        }
    }

    /// Sends what the GCS logic queued, on both links.
    fn flush(&mut self) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        while let Some((envelope, message)) = self.station.poll_outgoing() {
            match wire::encode(&envelope, &message, &mut buf) {
                Ok(len) => {
                    if self.links.send_both(buf.get(..len).unwrap_or_default()) == 0 {
                        tracing::warn!("no link could send");
                    }
                    self.record(Direction::Up, message);
                }
                Err(e) => tracing::error!(%e, "cannot encode"),
            }
        }
    }

    /// Runs the links for at most `wait`: sends, sleeps until a datagram or the next timer,
    /// votes and handles what arrived, fires due timers.
    pub fn pump(&mut self, wait: Duration) {
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
            let mut fds = [
                rustix::event::PollFd::new(direct, rustix::event::PollFlags::IN),
                rustix::event::PollFd::new(lte, rustix::event::PollFlags::IN),
            ];
            if let Err(e) = rustix::event::poll(&mut fds, Some(&timeout)) {
                if e != rustix::io::Errno::INTR {
                    tracing::warn!(%e, "poll failed");
                }
            }
        }
        let mut slots = [[0u8; MAX_DATAGRAM]; 8];
        let mut lens: heapless::Vec<(Link, usize), 8> = heapless::Vec::new();
        let mut buf = [0u8; MAX_DATAGRAM];
        self.links.receive(&mut buf, |link, datagram, _| {
            let slot = slots
                .get_mut(lens.len())
                .and_then(|s| s.get_mut(..datagram.len()));
            if let Some(slot) = slot {
                slot.copy_from_slice(datagram);
                let _ = lens.push((link, datagram.len()));
            }
        });
        let now = self.clock.now();
        if !lens.is_empty() {
            let mut arrivals: heapless::Vec<(Link, &[u8]), VOTING_STEP_MESSAGES> =
                heapless::Vec::new();
            for (slot, (link, len)) in slots.iter().zip(&lens) {
                let _ = arrivals.push((*link, slot.get(..*len).unwrap_or_default()));
            }
            let station = &mut self.station;
            let mut received = Vec::new();
            self.voter.vote_step(now, &arrivals, |_, frame| {
                if let Err(e) = station.handle_frame(now, frame) {
                    tracing::warn!(%e, "downlink frame rejected");
                }
                if let Ok((_, m)) = wire::decode(frame) {
                    received.push(m);
                }
            });
            for m in received {
                self.record(Direction::Down, m);
            }
        }
        if self.station.poll_timeout().is_some_and(|t| t <= now) {
            self.station.handle_timeout(now);
        }
        self.flush();
    }

    /// Runs the links until the request in progress ends, and gives its outcome (the downloaded
    /// lists for a download). The GCS logic ends every request by itself (2 x ack timeout per
    /// message, the transfer timeout for a download). The other events (progress,
    /// FROM-TO-NEXT) go to `on_event`. Without a request in progress it returns at once.
    pub fn finish(
        &mut self,
        mut on_event: impl FnMut(&GcsEvent<G::Report>),
    ) -> Result<Option<ValidatedPlan>, GcsError<G::Report>> {
        loop {
            while let Some(event) = self.station.poll_event() {
                match event {
                    GcsEvent::UploadComplete | GcsEvent::CommandAccepted(_) => return Ok(None),
                    GcsEvent::DownloadComplete(plan) => return Ok(Some(*plan)),
                    GcsEvent::Failed(e) => return Err(e),
                    other => on_event(&other),
                }
            }
            if self.station.is_standby() {
                return Ok(None);
            }
            self.pump(Duration::from_millis(20));
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
