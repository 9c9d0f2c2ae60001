//! What the two session targets, [`crate::fcc`] and [`crate::gcs`], share: a machine under test
//! with an endpoint that plays its peer, driven by records through simulated time. The records
//! `raw`, `wrap`, `send`, `time` and `answer` mean the same in both targets (their tables);
//! after every record the FCC's lists keep the invariants of [`crate::fcc`] ([`Lists`]), and a
//! deadline that fires does not stay due.

use core::time::Duration;

use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_flight::testkit::{self, Transmit};
use missionlink_interfaces::wire::{self, Envelope, MAX_FRAME_LEN, Message};
use missionlink_protocol::link::endpoint::Endpoint;
use missionlink_protocol::link::time::Instant;

use crate::fcc::Lists;
use crate::input::{MessageBody, answer_outcome, records, u16_at, wrap};

/// The record tags both session targets read alike (the tag byte modulo the target's `TAGS`).
pub mod tag {
    /// Raw bytes to the machine under test.
    pub const RAW: u8 = 0;
    /// Message data in a frame from the peer with a correct checksum.
    pub const WRAP: u8 = 1;
    /// A message sent by the peer endpoint with a fresh time stamp.
    pub const SEND: u8 = 2;
    /// The clock moves on.
    pub const TIME: u8 = 3;
}

/// How many deadlines one clock step may fire before the target calls it a deadline that stays
/// due (a hang in a driver's loop).
const MAX_FIRINGS: usize = 10_000;

/// What every session rig holds: the FCC (the machine under test, or the GCS's peer), the
/// endpoint that plays the peer of the machine under test, the clock and the last request.
pub struct Core {
    /// Mission data handling.
    pub fcc: MissionDataHandling,
    /// The endpoint that plays the peer: it sends from `Session::PEER.0` to `Session::PEER.1`.
    pub peer: Endpoint,
    /// The simulated time.
    pub now: Instant,
    /// The last message of the machine under test that asked for an answer.
    pub request: Option<Message>,
}

impl Core {
    /// A fresh FCC at 1 ms, the peer sending from `source` to `destination`.
    pub fn new((source, destination): (u32, u32)) -> Self {
        Self {
            fcc: MissionDataHandling::new(testkit::fcc_config()),
            peer: Endpoint::new(testkit::endpoint(source, destination)),
            now: Instant::from_millis(1),
            request: None,
        }
    }
}

/// A target's rig: the machine under test, its peer endpoint, the clock.
pub trait Session {
    /// Kinds of records of the target (the tag byte modulo this).
    const TAGS: u8;
    /// The target's tag of "the peer answers the last request".
    const ANSWER: u8;
    /// Source and destination IDs of the peer's frames.
    const PEER: (u32, u32);

    /// What the rig holds in common.
    fn core(&self) -> &Core;
    /// The same, to change.
    fn core_mut(&mut self) -> &mut Core;
    /// The earliest deadline of the machines.
    fn next_deadline(&self) -> Option<Instant>;
    /// The machines handle their deadlines at [`Session::now`].
    fn handle_timeout(&mut self);
    /// Takes what the machines send and their events, as a driver does, and checks them.
    fn drain(&mut self);
    /// Bytes to the machine under test, then [`Session::drain`].
    fn hand(&mut self, frame: &[u8]);
    /// A record of the target's own tags.
    fn other(&mut self, tag: u8, body: &[u8]);

    /// The FCC whose lists are checked after every record.
    fn fcc(&self) -> &MissionDataHandling {
        &self.core().fcc
    }

    /// The simulated time.
    fn now(&self) -> Instant {
        self.core().now
    }

    /// Sets the simulated time.
    fn set_now(&mut self, now: Instant) {
        self.core_mut().now = now;
    }

    /// The endpoint that plays the peer.
    fn peer(&mut self) -> &mut Endpoint {
        &mut self.core_mut().peer
    }

    /// The last message of the machine under test that asked for an answer.
    fn last_request(&self) -> Option<Message> {
        self.core().request.clone()
    }

    /// What the peer endpoint queued goes to the machine under test.
    fn peer_sent(&mut self) {
        for frame in Transmit::frames(self.peer()) {
            self.hand(&frame);
        }
    }

    /// One record: every record but `time` moves the clock 1 ms first.
    fn step(&mut self, record: u8, body: &[u8]) {
        let record = record % Self::TAGS;
        if record != tag::TIME {
            self.advance(Duration::from_millis(1));
        }
        match record {
            tag::RAW => self.hand(body),
            tag::WRAP => {
                let (source, destination) = Self::PEER;
                if let Some(frame) =
                    MessageBody::parse(body).and_then(|b| wrap(&b, source, destination))
                {
                    self.hand(&frame);
                }
            }
            tag::SEND => {
                if let Some(body) = MessageBody::parse(body)
                    && let Some(message) = body.message()
                {
                    let now = self.now();
                    self.peer().send(now, message, body.ack_requested());
                    self.peer_sent();
                }
            }
            tag::TIME => self.advance(Duration::from_millis(u64::from(u16_at(body, 0)))),
            r if r == Self::ANSWER => {
                if let Some(request) = self.last_request() {
                    let now = self.now();
                    self.peer()
                        .answer(now, &request, true, answer_outcome(body));
                    self.peer_sent();
                }
            }
            r => self.other(r, body),
        }
    }

    /// The clock moves `by`; the machines' deadlines fire in order, each at its time.
    fn advance(&mut self, by: Duration) {
        let until = self.now() + by;
        let mut fired = 0;
        while let Some(at) = self.next_deadline().filter(|at| *at <= until) {
            self.set_now(self.now().max(at));
            self.handle_timeout();
            self.drain();
            fired += 1;
            assert!(fired < MAX_FIRINGS, "a deadline stays due at {at:?}");
        }
        self.set_now(until);
    }
}

/// Feeds `input`'s records to `rig`, checking the FCC's lists after each.
pub fn run(rig: &mut impl Session, input: &[u8]) {
    for (tag, body) in records(input) {
        let before = Lists::of(rig.fcc());
        rig.step(tag, body);
        rig.drain();
        before.check_against(rig.fcc());
    }
}

/// Every frame `machine` (`name`: "FCC" or "GCS") has to send, each checked: it encodes,
/// decodes and goes from `route.0` to `route.1` (`to`: the addressee's name); `each` gets the
/// bytes and what they decode to.
pub fn checked_frames(
    machine: &mut impl Transmit,
    (name, to): (&str, &str),
    route: (u32, u32),
    mut each: impl FnMut(&[u8], Envelope, Message),
) {
    let mut buf = [0u8; MAX_FRAME_LEN];
    while let Some(sent) = machine.transmit(&mut buf) {
        let len = sent.unwrap_or_else(|e| panic!("the {name} cannot encode its message: {e}"));
        let frame = buf.get(..len).unwrap_or_default();
        let (envelope, message) = wire::decode(frame)
            .unwrap_or_else(|e| panic!("the {name} sent a frame that does not decode: {e}"));
        assert_eq!(
            (envelope.source_id, envelope.destination_id),
            route,
            "the {name} sent a frame not addressed to the {to}"
        );
        each(frame, envelope, message);
    }
}
