//! One end of the STANAG link, as the FCC and the GCS both have it: preprocessing of incoming
//! frames (paper §3.1.2: integrity and addressing of ICD §2, decoding, message sampling of
//! §3.1.1), acknowledgement (§3.1.3, ICD §4 #17000), and the outgoing queue with the sender's
//! time stamps (ICD §3).
//!
//! Which function handles a fresh message (the moding of §3.1.2) is decided by the owner of the
//! endpoint: [`crate::mission_data_handling::MissionDataHandling`] on the FCC, [`crate::ground_station::GroundStation`] on
//! the GCS.

use core::time::Duration;

use heapless::Deque;
use missionlink_interfaces::wire::{
    self, AckType, EncodeError, Envelope, Frame, FrameError, Message, MessageAcknowledgement,
    MessageError, Reason, Timestamp,
};

use crate::link::sampling::{MessageSampler, Sample};
use crate::link::time::{Instant, UtcClock};
use crate::link::time_stamp::TimeStamper;

/// Messages the outgoing queue holds. A driver drains it after every call into the core; a
/// call queues at most an acknowledgement and the next message of each transfer.
pub const OUTBOX_CAPACITY: usize = 16;

/// Addresses and clocks of an endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EndpointConfig {
    /// This node's ID (ICD §1: FCC 0x0B000001, GCS 0x0A000001).
    pub local_id: u32,
    /// The configured peer; frames from others are rejected (ICD §2).
    pub peer_id: u32,
    /// UTC time of [`Instant::ZERO`], from which time stamps are derived.
    pub utc_at_zero: Timestamp,
    /// How long sampling remembers a (source, type); the transfer timeout.
    pub sampling_window: Duration,
}

/// A message waiting to be sent.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Outgoing {
    /// The message, stamped.
    pub message: Message,
    /// Ask the peer for an answer.
    pub ack_requested: bool,
}

/// What preprocessing makes of one incoming message.
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
    /// A copy already processed, or older than one processed: dropped (paper §3.1.1).
    Dropped(Sample),
}

/// Counters of an endpoint, for monitoring.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EndpointStats {
    /// Frames rejected at the wrapper (ICD §2).
    pub rejected_frames: u64,
    /// Messages rejected by ICD §3 or §4.
    pub rejected_messages: u64,
    /// Copies dropped by sampling.
    pub dropped_copies: u64,
    /// Messages queued for sending.
    pub queued: u64,
    /// Messages lost because the driver did not drain the queue.
    pub outbox_overflow: u64,
}

/// One end of the link.
#[derive(Debug, Clone)]
pub struct Endpoint {
    config: EndpointConfig,
    clock: UtcClock,
    stamper: TimeStamper,
    sampler: MessageSampler,
    outbox: Deque<Outgoing, OUTBOX_CAPACITY>,
    stats: EndpointStats,
}

impl Endpoint {
    /// An endpoint that has sent and received nothing.
    pub fn new(config: EndpointConfig) -> Self {
        Self {
            config,
            clock: UtcClock::new(config.utc_at_zero),
            stamper: TimeStamper::new(),
            sampler: MessageSampler::new(config.sampling_window),
            outbox: Deque::new(),
            stats: EndpointStats::default(),
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

    /// Preprocesses one message (wrapper to checksum) received at `now`. A frame error is
    /// returned for the driver to count and log; it is never answered (ICD §2).
    pub fn receive(&mut self, now: Instant, bytes: &[u8]) -> Result<Inbound, FrameError> {
        let frame = Frame::new_checked(bytes)
            .and_then(|f| {
                f.check_addressing(self.config.local_id, self.config.peer_id)
                    .map(|()| f)
            })
            .inspect_err(|_| self.stats.rejected_frames += 1)?;
        let ack_requested = frame.properties().ack_requested();
        let source = frame.source_id();
        let message_type = frame.message_type();
        match frame.message() {
            Ok(message) => {
                match self
                    .sampler
                    .sample(now, source, message_type, message.time_stamp())
                {
                    Sample::Fresh => Ok(Inbound::Message {
                        message,
                        ack_requested,
                    }),
                    dropped => {
                        self.stats.dropped_copies += 1;
                        Ok(Inbound::Dropped(dropped))
                    }
                }
            }
            Err(error) => {
                if let Some(ts) = error.time_stamp {
                    match self.sampler.sample(now, source, message_type, ts) {
                        Sample::Fresh => {}
                        dropped => {
                            self.stats.dropped_copies += 1;
                            return Ok(Inbound::Dropped(dropped));
                        }
                    }
                    if ack_requested {
                        self.acknowledge(now, message_type, ts, Err(error.reason()));
                    }
                }
                self.stats.rejected_messages += 1;
                tracing::warn!(%error, "message rejected");
                Ok(Inbound::Rejected(error))
            }
        }
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

    /// The next message to send, with its envelope.
    pub fn poll_outgoing(&mut self) -> Option<(Envelope, Message)> {
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
