//! One end of the STANAG link, as the FCC and the GCS both have it: decoding of the messages the
//! voter passed on (paper §3.1.2: the message rules of ICD §3 and §4), acknowledgement (§3.1.3,
//! ICD §4 #17000), and the outgoing queue with the sender's time stamps (ICD §3).
//!
//! **Who owns what.** The voter in front of the endpoint (`missionlink_protocol::voting`) owns the link-level
//! checks (wrapper, addressing, signature) and message sampling across both links (§3.1.1), with
//! their counters; the endpoint owns decoding, the rejection of a message that breaks a message
//! rule, and every answer, with theirs. Nothing is checked or counted twice.
//!
//! Which function handles a fresh message (the moding of §3.1.2) is decided by the owner of the
//! endpoint: `missionlink_flight::mission_data_handling::MissionDataHandling` on the FCC, `missionlink_ground::ground_station::GroundStation` on
//! the GCS.

use heapless::Deque;
use missionlink_interfaces::wire::{
    self, AckType, EncodeError, Envelope, Frame, FrameError, Message, MessageAcknowledgement,
    MessageError, Reason, Timestamp,
};

use crate::link::rejects::{ByCause, Cause, LogLimiter, REASONS};
use crate::link::time::{Instant, UtcClock};
use crate::link::time_stamp::TimeStamper;

/// Messages the outgoing queue holds. A driver drains it after every call into the core; a
/// call queues at most a few answers and cancels ([`OUTBOX_RESERVE`]) and the messages a
/// transfer may have in flight: a window of up to
/// [`MAX_WINDOW`](crate::transfer::window::MAX_WINDOW) data messages (ICD §10.2), all sent
/// again when they timed out together, and its opener.
pub const OUTBOX_CAPACITY: usize = crate::transfer::window::MAX_WINDOW + OUTBOX_RESERVE;

/// Room a sender of data messages leaves in the outgoing queue for answers and cancels
/// ([`Endpoint::outbox_room`]).
pub const OUTBOX_RESERVE: usize = 16;

/// Addresses and clocks of an endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EndpointConfig {
    /// This node's ID (ICD §1: FCC 0x0B000001, GCS 0x0A000001).
    pub local_id: u32,
    /// The configured peer; frames from others are rejected (ICD §2).
    pub peer_id: u32,
    /// UTC time of [`Instant::ZERO`], from which time stamps are derived.
    pub utc_at_zero: Timestamp,
}

/// A message waiting to be sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Outgoing {
    /// The message, stamped.
    pub message: Message,
    /// Ask the peer for an answer.
    pub ack_requested: bool,
}

/// What the endpoint makes of one message the voter passed on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Inbound {
    /// A fresh, valid message for the moding to route.
    Message {
        /// The message.
        message: Message,
        /// The sender asked for an answer.
        ack_requested: bool,
    },
    /// A fresh message that breaks a rule of ICD §3 or §4. It has been answered with #17000
    /// type 3 and the reason where the sender asked and the time stamp was readable.
    Rejected(MessageError),
}

/// Counters of an endpoint, for monitoring.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EndpointStats {
    /// Messages rejected by ICD §3 or §4, by the reason of ICD §6.
    pub rejected_messages: ByCause<Reason, REASONS>,
    /// Valid messages the owner refused in its state (wrong state, busy, guidance active: the
    /// answer is #17000 type 3 with the reason), counted by [`Endpoint::refused`].
    pub refused_messages: u64,
    /// Messages queued for sending.
    pub queued: u64,
    /// Messages lost because the driver did not drain the queue.
    pub outbox_overflow: u64,
}

impl EndpointStats {
    /// Every counter by name, for a summary: the total of rejected messages, then each reason.
    pub fn counters(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        [("rejected_messages", self.rejected_messages.total())]
            .into_iter()
            .chain(self.rejected_messages.counters())
            .chain([
                ("refused_messages", self.refused_messages),
                ("queued", self.queued),
                ("outbox_overflow", self.outbox_overflow),
            ])
    }
}

/// One end of the link.
#[derive(Debug, Clone)]
pub struct Endpoint {
    config: EndpointConfig,
    clock: UtcClock,
    stamper: TimeStamper,
    outbox: Deque<Outgoing, OUTBOX_CAPACITY>,
    stats: EndpointStats,
    message_log: LogLimiter<Reason, REASONS>,
    refusal_log: LogLimiter<Reason, REASONS>,
}

impl Endpoint {
    /// An endpoint that has sent and received nothing.
    pub fn new(config: EndpointConfig) -> Self {
        Self {
            config,
            clock: UtcClock::new(config.utc_at_zero),
            stamper: TimeStamper::new(),
            outbox: Deque::new(),
            stats: EndpointStats::default(),
            message_log: LogLimiter::new(),
            refusal_log: LogLimiter::new(),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &EndpointConfig {
        &self.config
    }

    /// The counters.
    pub fn stats(&self) -> &EndpointStats {
        &self.stats
    }

    /// Log lines about rejected and refused messages so far (at most one per reason per
    /// [`crate::link::rejects::LOG_INTERVAL`]).
    pub fn reject_log_lines(&self) -> u64 {
        self.message_log.lines() + self.refusal_log.lines()
    }

    /// Decodes one message (wrapper to checksum) that the voter passed on at `now`: it checked
    /// the wrapper, the addressing and the signature and sampled the message (module
    /// documentation). A message that breaks a rule of ICD §3 or §4 is counted by reason, logged
    /// at most once a second per reason, answered with #17000 type 3 where its sender asked and
    /// its time stamp is readable, and returned as [`Inbound::Rejected`]. Bytes whose wrapper
    /// does not parse, which a voter never passes on, are returned as the error: neither counted
    /// nor answered (ICD §2).
    pub fn receive(&mut self, now: Instant, bytes: &[u8]) -> Result<Inbound, FrameError> {
        let frame = Frame::new_checked(bytes)?;
        let ack_requested = frame.properties().ack_requested();
        let message_type = frame.message_type();
        match frame.message() {
            Ok(message) => Ok(Inbound::Message {
                message,
                ack_requested,
            }),
            Err(error) => {
                if let (Some(ts), true) = (error.time_stamp, ack_requested) {
                    self.acknowledge(now, message_type, ts, Err(error.reason()));
                }
                let reason = error.reason();
                self.stats.rejected_messages.add(reason);
                if let Some(rejected) = self.message_log.admit(reason, now) {
                    tracing::warn!(
                        reason = reason.counter_name(),
                        rejected,
                        last = %error,
                        "messages rejected since the last line of this reason"
                    );
                }
                Ok(Inbound::Rejected(error))
            }
        }
    }

    /// The owner refused a valid message of `message_type` with `reason` (the moding of paper
    /// §3.1.2): counted, and logged at most once a second per reason, like the rejections, so a
    /// peer repeating a refused request costs a counter, not a log line each.
    pub fn refused(&mut self, now: Instant, message_type: u16, reason: Reason) {
        self.stats.refused_messages = self.stats.refused_messages.saturating_add(1);
        if let Some(refused) = self.refusal_log.admit(reason, now) {
            tracing::info!(
                cause = reason.counter_name(),
                rejected = refused,
                last_message = message_type,
                "messages refused since the last line of this reason"
            );
        }
    }

    /// Stamps from now on are strictly greater than `floor` (see [`TimeStamper::resume_after`]):
    /// a GCS started again continues after what its previous process may have sent, so an
    /// answer to one of those is never taken for an answer to its own (ICD §3: stamps are
    /// identities).
    pub fn resume_stamps_after(&mut self, floor: Timestamp) {
        self.stamper.resume_after(floor);
    }

    /// Messages the outgoing queue has room for until the driver drains it: a sender of data
    /// messages sends one more only while more than [`OUTBOX_RESERVE`] are left, so that an
    /// answer or a cancel queued in the same call is never dropped.
    pub fn outbox_room(&self) -> usize {
        OUTBOX_CAPACITY - self.outbox.len()
    }

    /// The last time stamp this endpoint issued.
    pub fn last_stamp(&self) -> Option<Timestamp> {
        self.stamper.last()
    }

    /// Stamps `message` with the next time stamp of this sender and queues it; returns the stamp.
    pub fn send(&mut self, now: Instant, mut message: Message, ack_requested: bool) -> Timestamp {
        let ts = self.stamper.stamp(self.clock.utc(now)).unwrap_or_else(|e| {
            tracing::error!(%e, "sending with a repeated time stamp");
            Timestamp::from_millis(Timestamp::MAX_MILLIS).unwrap_or_default()
        });
        message.set_time_stamp(ts);
        self.stats.queued += 1;
        if self
            .outbox
            .push_back(Outgoing {
                message,
                ack_requested,
            })
            .is_err()
        {
            self.stats.outbox_overflow += 1;
            tracing::error!("outgoing queue full: message dropped, the sender's retry recovers it");
        }
        ts
    }

    /// Answers a received `message` with #17000 when its sender asked for it (`ack_requested`),
    /// as [`Endpoint::acknowledge`].
    pub fn answer(
        &mut self,
        now: Instant,
        message: &Message,
        ack_requested: bool,
        outcome: Result<(), Reason>,
    ) {
        if ack_requested {
            self.acknowledge(
                now,
                message.message_type() as u16,
                message.time_stamp(),
                outcome,
            );
        }
    }

    /// Answers the message `(original_type, original_time_stamp)` with #17000: type 2 when
    /// `outcome` is `Ok`, type 3 with the reason when not (paper §3.1.3).
    pub fn acknowledge(
        &mut self,
        now: Instant,
        original_type: u16,
        original_time_stamp: Timestamp,
        outcome: Result<(), Reason>,
    ) {
        let (ack_type, reason) = match outcome {
            Ok(()) => (AckType::Completed, Reason::None),
            Err(reason) => (AckType::Rejected, reason),
        };
        let ack = MessageAcknowledgement {
            time_stamp: Timestamp::default(),
            original_time_stamp,
            original_message_type: original_type,
            ack_type,
            reject_reason: Some(reason),
        };
        self.send(now, ack.into(), false);
    }

    /// The next message to send, with its envelope. Drivers take frames from
    /// [`Endpoint::poll_transmit`]; the message itself is for the GCS logic's own
    /// `poll_outgoing`.
    pub(crate) fn poll_outgoing(&mut self) -> Option<(Envelope, Message)> {
        let out = self.outbox.pop_front()?;
        let envelope =
            Envelope::new(self.config.local_id, self.config.peer_id).with_ack(out.ack_requested);
        Some((envelope, out.message))
    }

    /// Encodes the next message to send into `buf`; returns the frame length.
    pub fn poll_transmit(&mut self, buf: &mut [u8]) -> Option<Result<usize, EncodeError>> {
        let (envelope, message) = self.poll_outgoing()?;
        Some(wire::encode(&envelope, &message, buf))
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::{
        ChecksumWidth, ExecuteCommand, MAX_FRAME_LEN, MissionExecuteCommand, frame::checksum,
    };

    use super::*;
    use crate::link::rejects::LOG_INTERVAL;

    fn config(local_id: u32, peer_id: u32) -> EndpointConfig {
        EndpointConfig {
            local_id,
            peer_id,
            utc_at_zero: Timestamp::from_millis(848_577_600_000).unwrap(),
        }
    }

    /// A log line as the capture saw it: when (simulated), the cause or reason, the count.
    #[derive(Debug, Clone, PartialEq, Eq)]
    struct Line {
        at: Instant,
        cause: std::string::String,
        rejected: u64,
    }

    /// A tracing subscriber that keeps every event, stamped with the simulated time.
    #[derive(Clone, Default)]
    struct Capture {
        now: Arc<Mutex<Instant>>,
        lines: Arc<Mutex<Vec<Line>>>,
    }

    #[derive(Default)]
    struct Fields {
        cause: std::string::String,
        rejected: u64,
    }

    impl tracing::field::Visit for Fields {
        fn record_u64(&mut self, field: &tracing::field::Field, value: u64) {
            if field.name() == "rejected" {
                self.rejected = value;
            }
        }
        fn record_str(&mut self, field: &tracing::field::Field, value: &str) {
            if matches!(field.name(), "cause" | "reason") {
                self.cause = value.into();
            }
        }
        fn record_debug(&mut self, _: &tracing::field::Field, _: &dyn core::fmt::Debug) {}
    }

    impl tracing::Subscriber for Capture {
        fn enabled(&self, _: &tracing::Metadata<'_>) -> bool {
            true
        }
        fn new_span(&self, _: &tracing::span::Attributes<'_>) -> tracing::span::Id {
            tracing::span::Id::from_u64(1)
        }
        fn record(&self, _: &tracing::span::Id, _: &tracing::span::Record<'_>) {}
        fn record_follows_from(&self, _: &tracing::span::Id, _: &tracing::span::Id) {}
        fn event(&self, event: &tracing::Event<'_>) {
            let mut fields = Fields::default();
            event.record(&mut fields);
            let at = *self.now.lock().unwrap();
            self.lines.lock().unwrap().push(Line {
                at,
                cause: fields.cause,
                rejected: fields.rejected,
            });
        }
        fn enter(&self, _: &tracing::span::Id) {}
        fn exit(&self, _: &tracing::span::Id) {}
    }

    /// A #50000 from the GCS, freshly stamped at `now`.
    fn execute(gcs: &mut Endpoint, now: Instant) -> std::vec::Vec<u8> {
        let message = MissionExecuteCommand {
            time_stamp: Timestamp::default(),
            command: ExecuteCommand::Execute,
            mission_id: None,
        };
        gcs.send(now, message.into(), false);
        let mut buf = [0u8; MAX_FRAME_LEN];
        let len = gcs.poll_transmit(&mut buf).unwrap().unwrap();
        buf[..len].to_vec()
    }

    #[test]
    fn a_flood_of_bad_input_is_counted_in_full_and_logged_once_a_second_per_cause() {
        const N: u64 = 3000;
        let step = core::time::Duration::from_millis(1);
        let mut fcc = Endpoint::new(config(FCC_ID, GCS_ID));
        let mut gcs = Endpoint::new(config(GCS_ID, FCC_ID));
        let capture = Capture::default();
        tracing::subscriber::with_default(capture.clone(), || {
            let mut now = Instant::from_millis(5);
            for _ in 0..N {
                *capture.now.lock().unwrap() = now;
                let good = execute(&mut gcs, now);
                // Wrapper: a corrupted checksum, and a frame cut short of its header. The voter
                // counts these; should such bytes reach the endpoint, they are refused and
                // neither counted nor logged a second time.
                let mut corrupted = good.clone();
                *corrupted.last_mut().unwrap() ^= 0x5a;
                assert!(fcc.receive(now, &corrupted).is_err());
                assert!(fcc.receive(now, &good[..10]).is_err());
                // Message: Command 9 is no #50000 command (ICD §4), under a sound checksum.
                let mut unsupported = good;
                let data_end = unsupported.len() - 4;
                unsupported[data_end - 1] = 9;
                let sum = checksum(&unsupported[..data_end], ChecksumWidth::Four);
                unsupported[data_end..].copy_from_slice(&sum.to_be_bytes());
                assert!(matches!(
                    fcc.receive(now, &unsupported),
                    Ok(Inbound::Rejected(_))
                ));
                now = now + step;
            }
        });
        let stats = fcc.stats();
        assert_eq!(stats.rejected_messages.get(Reason::Unsupported), N);
        assert_eq!(stats.rejected_messages.total(), N);
        let counters: std::collections::HashMap<_, _> = stats.counters().collect();
        assert_eq!(counters["rejected_messages"], N);
        assert_eq!(counters["reason_unsupported"], N);
        assert!(
            !counters.contains_key("rejected_frames"),
            "the voter's counter"
        );

        let lines = capture.lines.lock().unwrap().clone();
        assert_eq!(lines.len() as u64, fcc.reject_log_lines());
        // N ms of flood: lines at 0 s, 1 s and 2 s of it.
        for cause in ["reason_unsupported"] {
            let of_cause: std::vec::Vec<_> = lines.iter().filter(|l| l.cause == cause).collect();
            assert_eq!(of_cause.len(), 3, "{cause}: {of_cause:?}");
            for pair in of_cause.windows(2) {
                assert!(pair[1].at - pair[0].at >= LOG_INTERVAL, "{pair:?}");
            }
            // Each line counts what happened since the one before: all but the last second's
            // rejections after the last line are accounted for.
            let logged: u64 = of_cause.iter().map(|l| l.rejected).sum();
            assert_eq!(of_cause[0].rejected, 1);
            assert_eq!(of_cause[1].rejected, 1000);
            assert_eq!(logged, 2001);
        }
        assert_eq!(lines.len(), 3, "{lines:?}");
    }

    #[test]
    fn refused_requests_are_counted_in_full_and_logged_once_a_second_per_reason() {
        let mut fcc = Endpoint::new(config(FCC_ID, GCS_ID));
        let capture = Capture::default();
        tracing::subscriber::with_default(capture.clone(), || {
            // 2.5 s of clears refused while guidance flies, one every millisecond.
            for ms in 0..2500u64 {
                let now = Instant::from_millis(ms);
                *capture.now.lock().unwrap() = now;
                fcc.refused(now, 13000, Reason::GuidanceActive);
            }
        });
        assert_eq!(fcc.stats().refused_messages, 2500);
        let lines = capture.lines.lock().unwrap().clone();
        assert_eq!(lines.len(), 3, "{lines:?}");
        assert_eq!(fcc.reject_log_lines(), 3);
        assert!(lines.iter().all(|l| l.cause == "reason_guidance_active"));
        assert_eq!(
            lines
                .iter()
                .map(|l| l.rejected)
                .collect::<std::vec::Vec<_>>(),
            [1, 1000, 1000]
        );
    }
}
