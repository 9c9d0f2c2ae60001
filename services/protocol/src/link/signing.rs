//! Link signing (ICD §9): a receiver accepts only frames from holders of a pre-shared key.
//!
//! The byte-sum checksum of ICD §2 detects noise, not intent: anyone who can send datagrams to
//! a link and knows the IDs could clear or replace the mission. After MAVLink 2's message
//! signing, made stronger where it is known to be weak: the whole HMAC-SHA-256 construction
//! (not a secret-prefix hash) truncated to 96 bits (not 48), and replay protection by identity
//! with a memory that counts as full when it is lost (a restarted receiver does not take back
//! what it accepted before).
//!
//! - [`LinkKey`]: a 32-byte key with its Key ID, kept only as the keyed HMAC state; its
//!   `Debug` shows the ID, never key material.
//! - [`Signer`]: the sender's half. Every frame is signed per link (the trailer names the link),
//!   so a driver signs each copy it sends.
//! - [`SignatureCheck`]: the receiver's half. [`Policy`] `off`, `accept` or `require`;
//!   [`SignatureCheck::verify`] checks the trailer (Key ID, Link ID, signature), then, once the
//!   message's time stamp is read, [`SignatureCheck::admit`] checks it for replay.
//!
//! Sans-IO: keys come in as bytes (the driver reads the key files), time as an [`Instant`] and
//! the UTC time of instant zero. Fixed memory: the replay memory of each link is allocated once,
//! when the check is built.

use core::fmt;
use core::str::FromStr;
use core::time::Duration;

use hmac::{Hmac, Mac};
use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::{self, Frame, FrameError, SignatureTrailer, Timestamp};
use sha2::Sha256;
use zerocopy::IntoBytes;

use crate::link::time::{Instant, UtcClock};

/// Bytes of a link key.
pub const KEY_LEN: usize = 32;

/// Keys one side holds at most: the key in use and the ones a rotation brings or retires.
pub const MAX_KEYS: usize = 8;

/// How far a signed frame's time stamp may be from the receiver's UTC clock, before or after
/// (ICD §9).
pub const REPLAY_WINDOW: Duration = Duration::from_secs(60);

/// Identities the replay memory of one link holds (ICD §9: at least 4096).
pub const REPLAY_MEMORY: usize = 4096;

/// Bytes of the signature in the trailer.
const SIGNATURE_LEN: usize = 12;

/// A link key: its Key ID and the HMAC-SHA-256 state keyed with its 32 bytes.
#[derive(Clone)]
pub struct LinkKey {
    id: u8,
    keyed: Hmac<Sha256>,
}

impl LinkKey {
    /// The key `secret` under Key ID `id`.
    pub fn new(id: u8, secret: &[u8; KEY_LEN]) -> Self {
        // HMAC takes keys of any length; a 32-byte key is never refused.
        let keyed = <Hmac<Sha256> as Mac>::new_from_slice(secret)
            .unwrap_or_else(|_| <Hmac<Sha256> as hmac::digest::KeyInit>::new(&Default::default()));
        Self { id, keyed }
    }

    /// The Key ID.
    pub fn id(&self) -> u8 {
        self.id
    }

    /// The HMAC over the frame and the signed prefix of the trailer (ICD §9).
    fn mac(&self, frame: &[u8], trailer: &SignatureTrailer) -> Hmac<Sha256> {
        let mut mac = self.keyed.clone();
        mac.update(frame);
        mac.update(trailer.signed_prefix());
        mac
    }
}

/// The Key ID only: key material never reaches a log.
impl fmt::Debug for LinkKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("LinkKey")
            .field("id", &self.id)
            .finish_non_exhaustive()
    }
}

/// The keys of one side, by Key ID.
#[derive(Debug, Clone, Default)]
pub struct Keyring {
    keys: heapless::Vec<LinkKey, MAX_KEYS>,
}

/// A key that cannot join a [`Keyring`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyringError {
    /// Another key has this Key ID.
    DuplicateId(u8),
    /// The keyring holds [`MAX_KEYS`] already.
    Full,
}

impl fmt::Display for KeyringError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DuplicateId(id) => write!(f, "two keys have the Key ID {id}"),
            Self::Full => write!(f, "more than {MAX_KEYS} keys"),
        }
    }
}

impl Keyring {
    /// No keys.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `key`.
    pub fn insert(&mut self, key: LinkKey) -> Result<(), KeyringError> {
        if self.get(key.id).is_some() {
            return Err(KeyringError::DuplicateId(key.id));
        }
        self.keys.push(key).map_err(|_| KeyringError::Full)
    }

    /// The key with Key ID `id`.
    pub fn get(&self, id: u8) -> Option<&LinkKey> {
        self.keys.iter().find(|k| k.id == id)
    }

    /// The Key IDs, in the order the keys were added.
    pub fn ids(&self) -> impl Iterator<Item = u8> + '_ {
        self.keys.iter().map(|k| k.id)
    }

    /// No key.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }
}

/// The Link ID of the trailer: 0 direct, 1 LTE; `None` for [`Link::Both`], which is no link a
/// datagram travels on.
pub const fn link_id(link: Link) -> Option<u8> {
    match link {
        Link::Direct => Some(0),
        Link::Lte => Some(1),
        Link::Both => None,
    }
}

/// A frame that cannot be signed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SignError {
    /// The bytes are not one frame that passes ICD §2.
    Frame(FrameError),
    /// The output has no room for the frame and its trailer.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
    },
    /// [`Link::Both`] has no Link ID: each link's copy is signed on its own.
    NoLinkId,
}

impl fmt::Display for SignError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Frame(e) => write!(f, "not a frame: {e}"),
            Self::BufferTooSmall { needed } => write!(f, "{needed} bytes needed"),
            Self::NoLinkId => write!(f, "a frame is signed for one link, not both"),
        }
    }
}

/// The sender's half: signs every frame with the key the configuration names for sending.
#[derive(Debug, Clone)]
pub struct Signer {
    key: LinkKey,
}

impl Signer {
    /// Signs with `key`.
    pub fn new(key: LinkKey) -> Self {
        Self { key }
    }

    /// The Key ID it signs with.
    pub fn key_id(&self) -> u8 {
        self.key.id
    }

    /// Writes `frame` (one frame, wrapper to checksum) into `out` as a signed frame for `link`:
    /// bit 5 set, the checksum written again, the trailer appended. Returns the signed length
    /// (the frame's plus [`wire::TRAILER_LEN`]).
    pub fn sign(&self, link: Link, frame: &[u8], out: &mut [u8]) -> Result<usize, SignError> {
        let link_id = link_id(link).ok_or(SignError::NoLinkId)?;
        let len = frame.len();
        let needed = len + wire::TRAILER_LEN;
        let Some((copy, rest)) = out.split_at_mut_checked(len) else {
            return Err(SignError::BufferTooSmall { needed });
        };
        let Some(trailer_out) = rest.get_mut(..wire::TRAILER_LEN) else {
            return Err(SignError::BufferTooSmall { needed });
        };
        copy.copy_from_slice(frame);
        wire::mark_signed(copy).map_err(SignError::Frame)?;
        let mut trailer = SignatureTrailer {
            key_id: self.key.id,
            link_id,
            reserved: 0.into(),
            signature: [0; SIGNATURE_LEN],
        };
        let tag = self.key.mac(copy, &trailer).finalize().into_bytes();
        for (s, t) in trailer.signature.iter_mut().zip(tag) {
            *s = t;
        }
        trailer_out.copy_from_slice(trailer.as_bytes());
        Ok(needed)
    }
}

/// What a receiver does with signature trailers (ICD §9), configured per receiver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Policy {
    /// The trailer is ignored and not checked (edition 1).
    #[default]
    Off,
    /// A signed frame must verify; unsigned frames are still accepted (the step of a rollout).
    Accept,
    /// Only frames that verify are accepted.
    Require,
}

impl Policy {
    /// The name in the configuration.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Off => "off",
            Self::Accept => "accept",
            Self::Require => "require",
        }
    }
}

impl fmt::Display for Policy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A policy name that is none of `off`, `accept`, `require`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownPolicy;

impl fmt::Display for UnknownPolicy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("the signing policy is one of off, accept, require")
    }
}

impl FromStr for Policy {
    type Err = UnknownPolicy;
    fn from_str(s: &str) -> Result<Self, UnknownPolicy> {
        match s {
            "off" => Ok(Self::Off),
            "accept" => Ok(Self::Accept),
            "require" => Ok(Self::Require),
            _ => Err(UnknownPolicy),
        }
    }
}

crate::causes! {
    /// Why a frame failed the signature check (ICD §9): one counter and one log cause each.
    pub enum SignatureCause {
        /// Unsigned under `require`, or marked signed without the 16 bytes of a trailer.
        NoTrailer => "signature_no_trailer",
        /// The trailer's Key ID names no configured key.
        UnknownKey => "signature_unknown_key",
        /// The signature does not verify, or the Link ID names another link than the one the
        /// datagram arrived on.
        BadSignature => "signature_bad",
        /// The time stamp is more than [`REPLAY_WINDOW`] from the receiver's clock, or the identity
        /// (Source ID, Message Type, Time Stamp) was accepted on this link before, or the stamp is
        /// older than what the replay memory still holds, or it cannot be read.
        Replay => "signature_replay",
    }
}

/// The signature of `frame` checked with `keys`, whatever link it arrived on: its trailer when
/// it verifies. For the receiver ([`SignatureCheck::verify`], which also checks the Link ID)
/// and for tools that read captures.
pub fn check_signature<'a>(
    keys: &Keyring,
    frame: &Frame<'a>,
) -> Result<&'a SignatureTrailer, SignatureCause> {
    let trailer = frame.trailer().ok_or(SignatureCause::NoTrailer)?;
    let key = keys.get(trailer.key_id).ok_or(SignatureCause::UnknownKey)?;
    // Constant time: the comparison does not tell a forger how many bytes were right.
    key.mac(frame.as_bytes(), trailer)
        .verify_truncated_left(&trailer.signature)
        .map_err(|_| SignatureCause::BadSignature)?;
    Ok(trailer)
}

/// What [`SignatureCheck::verify`] found in a frame that passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Authenticity {
    /// Not checked: policy `off`, or an unsigned frame under `accept`. No replay check follows.
    Unchecked,
    /// The signature verifies: [`SignatureCheck::admit`] must pass its time stamp.
    Verified,
}

/// A message's identity (ICD §3): Source ID, Message Type, Time Stamp.
type Identity = (u32, u16, Timestamp);

/// The identities one link accepted, in fixed memory (ICD §9 "Replay"), allocated once when the
/// check is built: a ring of [`REPLAY_MEMORY`] identities in the order they were accepted (the
/// oldest is forgotten first) and an index over it with twice as many slots, open addressing
/// with linear probing, so that a look-up probes a slot or two: 80 KB a link. (A set that holds
/// its identities itself beside the ring took 300 KB a link, all of it resident: too much for
/// a ground service with a check per vehicle.)
#[derive(Clone)]
struct ReplayMemory {
    /// The identities; `len` of them from `head` on, wrapping round.
    ring: Box<[Identity]>,
    head: usize,
    len: usize,
    /// Per slot, the ring position of an identity whose probe passes it, or [`EMPTY`]. Never
    /// more than half full, so every probe ends at an empty slot.
    index: Box<[u16]>,
    /// Stamps below this are refused: the memory no longer proves they are new. It rises past
    /// every identity forgotten while its stamp could still pass the window, and starts at the
    /// receiver's start (what a lost memory held cannot be taken back: this choice counts a
    /// memory lost in a restart as full at that moment).
    lowest: Timestamp,
    /// The receiver's start: a stamp below it is refused as [`NotAdmitted::BeforeStart`], sent
    /// while the receiver was down or starting, not as a replay.
    start: Timestamp,
}

/// Slots of a [`ReplayMemory`]'s index: a power of two, twice its identities.
const SLOTS: usize = 2 * REPLAY_MEMORY;
/// An empty slot of the index (no ring position is this large).
const EMPTY: u16 = u16::MAX;
const _: () = assert!(SLOTS.is_power_of_two() && REPLAY_MEMORY < EMPTY as usize);

/// Its size and floors: the identities are no one's business in a log.
impl fmt::Debug for ReplayMemory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ReplayMemory")
            .field("len", &self.len)
            .field("lowest", &self.lowest)
            .field("start", &self.start)
            .finish_non_exhaustive()
    }
}

/// Why the replay check drops a frame whose signature verified.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotAdmitted {
    /// Outside the window, seen before, or below what the memory still proves new
    /// ([`SignatureCause::Replay`]).
    Replay,
    /// Stamped before this receiver started, within the window: its peer sent it while the
    /// receiver was down or starting (positions queued in the socket before the ground opened
    /// its links, say). What a lost memory held cannot be taken back, so it is dropped as a
    /// replay would be, but it is no sign of one: counted apart, not as a rejection.
    BeforeStart,
}

impl From<NotAdmitted> for SignatureCause {
    fn from(_: NotAdmitted) -> Self {
        Self::Replay
    }
}

impl ReplayMemory {
    fn new(lowest: Timestamp) -> Self {
        Self {
            ring: vec![(0, 0, Timestamp::default()); REPLAY_MEMORY].into_boxed_slice(),
            head: 0,
            len: 0,
            index: vec![EMPTY; SLOTS].into_boxed_slice(),
            lowest,
            start: lowest,
        }
    }

    /// The slot an identity's probe starts at: its fields mixed (the finaliser of SplitMix64),
    /// so that the stamps of one source, which differ in their low bits, spread over the
    /// table. Only identities of frames whose signature verified get here: no stranger
    /// chooses them.
    fn home(identity: &Identity) -> usize {
        let (source, message_type, stamp) = *identity;
        let mut z = ((u64::from(source) << 16) | u64::from(message_type))
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ stamp.millis();
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        (z ^ (z >> 31)) as usize & (SLOTS - 1)
    }

    /// The identity at ring position `position` of slot `slot`, if the slot holds one.
    fn at(&self, slot: usize) -> Option<(u16, &Identity)> {
        let position = *self.index.get(slot)?;
        let identity = self.ring.get(usize::from(position))?;
        Some((position, identity))
    }

    /// The slot that points at `identity`'s ring position, if it is held.
    fn slot_of(&self, identity: &Identity) -> Option<usize> {
        let mut slot = Self::home(identity);
        // At most every slot once: the index is never full, so an empty one ends the probe
        // long before.
        for _ in 0..SLOTS {
            let (_, held) = self.at(slot)?;
            if held == identity {
                return Some(slot);
            }
            slot = (slot + 1) & (SLOTS - 1);
        }
        None
    }

    fn contains(&self, identity: &Identity) -> bool {
        self.slot_of(identity).is_some()
    }

    fn is_full(&self) -> bool {
        self.len == REPLAY_MEMORY
    }

    /// The oldest identity.
    fn front(&self) -> Option<Identity> {
        (self.len > 0)
            .then(|| self.ring.get(self.head).copied())
            .flatten()
    }

    /// Adds `identity` as the newest; nothing when full (the caller makes room first).
    fn push_back(&mut self, identity: Identity) {
        if self.is_full() {
            return;
        }
        let position = (self.head + self.len) % REPLAY_MEMORY;
        let Some(entry) = self.ring.get_mut(position) else {
            return;
        };
        *entry = identity;
        let mut slot = Self::home(&identity);
        while self.index.get(slot).is_some_and(|p| *p != EMPTY) {
            slot = (slot + 1) & (SLOTS - 1);
        }
        if let Some(free) = self.index.get_mut(slot) {
            // REPLAY_MEMORY < EMPTY: every position fits.
            *free = position as u16;
            self.len += 1;
        }
    }

    /// Forgets the oldest identity.
    fn pop_front(&mut self) {
        let Some(oldest) = self.front() else {
            return;
        };
        if let Some(slot) = self.slot_of(&oldest) {
            self.free_slot(slot);
        }
        self.head = (self.head + 1) % REPLAY_MEMORY;
        self.len -= 1;
    }

    /// Empties `slot`, moving back every entry after it whose probe passes it (backward-shift
    /// deletion), so that no probe meets a gap before its identity.
    fn free_slot(&mut self, slot: usize) {
        let mut hole = slot;
        let mut next = (slot + 1) & (SLOTS - 1);
        while let Some((position, identity)) = self.at(next) {
            // The entry at `next` may fill the hole if the hole lies on its probe: no farther
            // back from `next` than its home.
            let from_home = next.wrapping_sub(Self::home(identity)) & (SLOTS - 1);
            let from_hole = next.wrapping_sub(hole) & (SLOTS - 1);
            if from_home >= from_hole {
                if let Some(h) = self.index.get_mut(hole) {
                    *h = position;
                }
                hole = next;
            }
            next = (next + 1) & (SLOTS - 1);
        }
        if let Some(h) = self.index.get_mut(hole) {
            *h = EMPTY;
        }
    }

    fn admit(&mut self, utc: Timestamp, identity: Identity) -> Result<(), NotAdmitted> {
        let stamp = identity.2.millis();
        let now = utc.millis();
        let window = REPLAY_WINDOW.as_millis() as u64;
        if stamp.abs_diff(now) > window {
            return Err(NotAdmitted::Replay);
        }
        if identity.2 < self.start {
            return Err(NotAdmitted::BeforeStart);
        }
        if identity.2 < self.lowest || self.contains(&identity) {
            return Err(NotAdmitted::Replay);
        }
        // Identities whose stamps the window refuses now need no memory.
        let expired = now.saturating_sub(window);
        while let Some(oldest) = self.front() {
            if oldest.2.millis() >= expired && !self.is_full() {
                break;
            }
            self.pop_front();
            if oldest.2.millis() >= expired {
                // Forgotten while it could still pass the window: nothing at or below it may.
                self.lowest = self.lowest.max(
                    Timestamp::from_millis(oldest.2.millis().saturating_add(1)).unwrap_or(oldest.2),
                );
            }
        }
        // Room was made above.
        self.push_back(identity);
        Ok(())
    }
}

/// Counters of a [`SignatureCheck`] beyond its rejections (which the owner counts by
/// [`SignatureCause`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SignatureStats {
    /// Frames whose signature verified and whose identity was new.
    pub verified: u64,
    /// Unsigned frames let through under `accept`.
    pub unsigned_accepted: u64,
}

/// The receiver's half: the policy, the keys, a replay memory per link.
#[derive(Debug, Clone)]
pub struct SignatureCheck {
    policy: Policy,
    keys: Keyring,
    clock: UtcClock,
    /// Direct, then LTE. None under policy `off`, which never checks a replay.
    memories: Option<[ReplayMemory; 2]>,
    stats: SignatureStats,
    /// The highest stamp admitted on either link, for a receiver that keeps its replay window
    /// across restarts ([`SignatureCheck::resume_after`]).
    highest: Option<Timestamp>,
}

impl SignatureCheck {
    /// A check with `policy` and `keys` on a receiver whose [`Instant::ZERO`] is `utc_at_zero`,
    /// started at `now`: stamps older than `now` are refused (see [`ReplayMemory`]'s lowest).
    pub fn new(policy: Policy, keys: Keyring, utc_at_zero: Timestamp, now: Instant) -> Self {
        let clock = UtcClock::new(utc_at_zero);
        let start = clock.utc(now);
        Self {
            policy,
            keys,
            clock,
            memories: (policy != Policy::Off)
                .then(|| [ReplayMemory::new(start), ReplayMemory::new(start)]),
            stats: SignatureStats::default(),
            highest: None,
        }
    }

    /// A receiver that kept, across its restart, a stamp at or above every stamp it admitted
    /// before (`floor`, a lease it renewed ahead of [`SignatureCheck::admitted_up_to`]):
    /// stamps at or below it are refused as sent before the start, and stamps above it are
    /// new, whatever the time of this start, so that what its peer sent while it restarted
    /// counts. Call it before the first frame.
    pub fn resume_after(&mut self, floor: Timestamp) {
        let next = Timestamp::from_millis(floor.millis().saturating_add(1)).unwrap_or(floor);
        for memory in self.memories.iter_mut().flatten() {
            memory.lowest = next;
            memory.start = next;
        }
    }

    /// The highest stamp admitted so far, on either link.
    pub fn admitted_up_to(&self) -> Option<Timestamp> {
        self.highest
    }

    /// Policy `off`: nothing is checked (edition 1).
    pub fn off() -> Self {
        Self::new(
            Policy::Off,
            Keyring::new(),
            Timestamp::default(),
            Instant::ZERO,
        )
    }

    /// The policy.
    pub fn policy(&self) -> Policy {
        self.policy
    }

    /// The counters.
    pub fn stats(&self) -> &SignatureStats {
        &self.stats
    }

    /// Checks the trailer of `frame`, which arrived on `link`, as the policy says.
    pub fn verify(
        &mut self,
        link: Link,
        frame: &Frame<'_>,
    ) -> Result<Authenticity, SignatureCause> {
        let signed = frame.properties().signed();
        match (self.policy, signed) {
            (Policy::Off, _) => return Ok(Authenticity::Unchecked),
            (Policy::Accept, false) => {
                self.stats.unsigned_accepted += 1;
                return Ok(Authenticity::Unchecked);
            }
            (Policy::Require, false) => return Err(SignatureCause::NoTrailer),
            (Policy::Accept | Policy::Require, true) => {}
        }
        let trailer = check_signature(&self.keys, frame)?;
        if link_id(link) != Some(trailer.link_id) {
            return Err(SignatureCause::BadSignature);
        }
        Ok(Authenticity::Verified)
    }

    /// The replay check of a verified frame: `time_stamp` within [`REPLAY_WINDOW`] of the UTC
    /// time of `now`, and (source, type, stamp) not accepted on `link` before. Remembers it
    /// when it passes. `None` (a stamp that cannot be read) cannot be shown to be fresh.
    pub fn admit(
        &mut self,
        now: Instant,
        link: Link,
        source: u32,
        message_type: u16,
        time_stamp: Option<Timestamp>,
    ) -> Result<(), NotAdmitted> {
        let time_stamp = time_stamp.ok_or(NotAdmitted::Replay)?;
        // Without a memory (policy `off`) nothing can be shown to be fresh: fail closed.
        let [direct, lte] = self.memories.as_mut().ok_or(NotAdmitted::Replay)?;
        let memory = match link {
            Link::Direct => direct,
            Link::Lte | Link::Both => lte,
        };
        memory.admit(self.clock.utc(now), (source, message_type, time_stamp))?;
        self.highest = self.highest.max(Some(time_stamp));
        self.stats.verified += 1;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{self, ts};
    use missionlink_interfaces::defaults::{FCC_ID, GCS_ID};
    use missionlink_interfaces::wire::{
        Envelope, LegType, MAX_SIGNED_FRAME_LEN, Message, UaPositionWaypoint,
    };

    const SECRET: [u8; KEY_LEN] = [0x42; KEY_LEN];
    /// UTC of instant zero in these tests: 2026-11-25T00:00:00Z.
    const T0: u64 = 848_880_000_000;

    fn keyring(keys: &[(u8, [u8; KEY_LEN])]) -> Keyring {
        let mut ring = Keyring::new();
        for (id, secret) in keys {
            ring.insert(LinkKey::new(*id, secret)).unwrap();
        }
        ring
    }

    fn frame_at(stamp_ms: u64) -> std::vec::Vec<u8> {
        let message = Message::from(UaPositionWaypoint {
            time_stamp: ts(stamp_ms),
            ..testkit::waypoint(1, 0, testkit::CCP, LegType::TrackToFix)
        });
        testkit::frame(&Envelope::new(GCS_ID, FCC_ID).with_ack(true), &message)
    }

    fn sign(key: &LinkKey, link: Link, frame: &[u8]) -> std::vec::Vec<u8> {
        let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
        let len = Signer::new(key.clone())
            .sign(link, frame, &mut out)
            .unwrap();
        out[..len].to_vec()
    }

    fn check(policy: Policy) -> SignatureCheck {
        SignatureCheck::new(
            policy,
            keyring(&[(1, SECRET), (2, [7; KEY_LEN])]),
            Timestamp::from_millis(T0).unwrap(),
            Instant::ZERO,
        )
    }

    /// Verify then admit, as a receiver does.
    fn receive(
        check: &mut SignatureCheck,
        now: Instant,
        link: Link,
        datagram: &[u8],
    ) -> Result<Authenticity, SignatureCause> {
        let frame = Frame::new_checked(datagram).unwrap();
        let verdict = check.verify(link, &frame)?;
        if verdict == Authenticity::Verified {
            let stamp = frame.message().ok().map(|m| m.time_stamp());
            check.admit(now, link, frame.source_id(), frame.message_type(), stamp)?;
        }
        Ok(verdict)
    }

    #[test]
    fn a_signed_frame_is_the_frame_with_bit_5_its_checksum_and_a_trailer() {
        let frame = frame_at(T0 + 5);
        let signed = sign(&LinkKey::new(1, &SECRET), Link::Lte, &frame);
        assert_eq!(signed.len(), frame.len() + 16);
        let parsed = Frame::new_checked(&signed).unwrap();
        assert!(parsed.properties().signed());
        assert_eq!(parsed.as_bytes().len(), frame.len());
        // Only bit 5 of the properties and the checksum (0x20 more) differ.
        let n = frame.len();
        assert_eq!(signed[..14], frame[..14]);
        assert_eq!(signed[15], frame[15] | 0x20);
        assert_eq!(signed[16..n - 4], frame[16..n - 4]);
        let sum = |b: &[u8]| u32::from_be_bytes(b.try_into().unwrap());
        assert_eq!(sum(&signed[n - 4..n]), sum(&frame[n - 4..n]) + 0x20);
        let trailer = parsed.trailer().unwrap();
        assert_eq!((trailer.key_id, trailer.link_id), (1, 1));
        assert_eq!(trailer.reserved.get(), 0);
    }

    /// The signature as an independent implementation computes it (Python's `hmac` module):
    /// `hmac.new(bytes([0x42]*32), frame_through_checksum + trailer[:4], 'sha256').digest()[:12]`.
    #[test]
    fn the_signature_is_hmac_sha256_truncated_to_12_bytes_golden() {
        let data = [0x01u8, 0x02, 0x03];
        let frame = {
            let mut f = vec![0xff, 0xff, 0x00, 0x03];
            f.extend_from_slice(&GCS_ID.to_be_bytes());
            f.extend_from_slice(&FCC_ID.to_be_bytes());
            f.extend_from_slice(&13000u16.to_be_bytes());
            f.extend_from_slice(&[0x28, 0x80]);
            f.extend_from_slice(&data);
            let sum: u32 = f.iter().map(|b| u32::from(*b)).sum();
            f.extend_from_slice(&sum.to_be_bytes());
            f
        };
        let signed = sign(&LinkKey::new(9, &SECRET), Link::Direct, &frame);
        let golden_header = "ffff00030a0000010b00000132c828a0010203";
        assert_eq!(hex(&signed[..19]), golden_header);
        assert_eq!(hex(&signed[19..23]), "000003e0");
        assert_eq!(hex(&signed[23..27]), "09000000");
        assert_eq!(hex(&signed[27..]), GOLDEN_SIGNATURE);
    }

    /// Computed with Python 3 `hmac` (see the test above).
    const GOLDEN_SIGNATURE: &str = "3e4f2fec0fb315731f480f10";

    fn hex(b: &[u8]) -> std::string::String {
        b.iter().map(|x| format!("{x:02x}")).collect()
    }

    #[test]
    fn require_accepts_a_frame_signed_with_any_configured_key() {
        let mut check = check(Policy::Require);
        for (i, id) in [1u8, 2].into_iter().enumerate() {
            let secret = if id == 1 { SECRET } else { [7; KEY_LEN] };
            let signed = sign(
                &LinkKey::new(id, &secret),
                Link::Direct,
                &frame_at(T0 + i as u64),
            );
            assert_eq!(
                receive(&mut check, Instant::ZERO, Link::Direct, &signed),
                Ok(Authenticity::Verified)
            );
        }
        assert_eq!(check.stats().verified, 2);
    }

    #[test]
    fn each_cause_is_told_apart() {
        let mut check = check(Policy::Require);
        let now = Instant::ZERO;
        let frame = frame_at(T0);
        assert_eq!(
            receive(&mut check, now, Link::Direct, &frame),
            Err(SignatureCause::NoTrailer)
        );
        // Marked signed, the trailer cut off.
        let signed = sign(&LinkKey::new(1, &SECRET), Link::Direct, &frame);
        assert_eq!(
            receive(&mut check, now, Link::Direct, &signed[..frame.len()]),
            Err(SignatureCause::NoTrailer)
        );
        let foreign = sign(&LinkKey::new(3, &SECRET), Link::Direct, &frame);
        assert_eq!(
            receive(&mut check, now, Link::Direct, &foreign),
            Err(SignatureCause::UnknownKey)
        );
        // The right Key ID, another key: a forger who guessed the ID.
        let forged = sign(&LinkKey::new(1, &[0x43; KEY_LEN]), Link::Direct, &frame);
        assert_eq!(
            receive(&mut check, now, Link::Direct, &forged),
            Err(SignatureCause::BadSignature)
        );
        // Signed for the LTE link, arriving on the direct one.
        let other_link = sign(&LinkKey::new(1, &SECRET), Link::Lte, &frame);
        assert_eq!(
            receive(&mut check, now, Link::Direct, &other_link),
            Err(SignatureCause::BadSignature)
        );
        assert_eq!(
            receive(&mut check, now, Link::Direct, &signed),
            Ok(Authenticity::Verified)
        );
        assert_eq!(
            receive(&mut check, now, Link::Direct, &signed),
            Err(SignatureCause::Replay)
        );
    }

    #[test]
    fn any_changed_byte_fails_the_signature() {
        let mut check = check(Policy::Require);
        let frame = frame_at(T0);
        let signed = sign(&LinkKey::new(1, &SECRET), Link::Direct, &frame);
        let n = frame.len();
        // Every byte of the frame before the checksum, and the trailer's signed prefix and
        // signature; the checksum is fixed up, so only the signature can catch it.
        for i in (0..n - 4).chain(n..signed.len()) {
            let mut bad = signed.clone();
            bad[i] ^= 0x01;
            if i < n - 4 {
                let sum: u32 = bad[..n - 4].iter().map(|b| u32::from(*b)).sum();
                bad[n - 4..n].copy_from_slice(&sum.to_be_bytes());
            }
            let Ok(parsed) = Frame::new_checked(&bad) else {
                continue; // the change broke the wrapper (length, properties): ICD §2 rejects it
            };
            let verdict = check.verify(Link::Direct, &parsed);
            assert!(verdict.is_err(), "byte {i}: {verdict:?}");
        }
    }

    #[test]
    fn accept_lets_unsigned_frames_through_but_not_bad_signatures() {
        let mut check = check(Policy::Accept);
        let frame = frame_at(T0);
        assert_eq!(
            receive(&mut check, Instant::ZERO, Link::Lte, &frame),
            Ok(Authenticity::Unchecked)
        );
        let forged = sign(&LinkKey::new(1, &[0; KEY_LEN]), Link::Lte, &frame);
        assert_eq!(
            receive(&mut check, Instant::ZERO, Link::Lte, &forged),
            Err(SignatureCause::BadSignature)
        );
        assert_eq!(check.stats().unsigned_accepted, 1);
    }

    #[test]
    fn off_checks_nothing() {
        let mut check = SignatureCheck::off();
        let forged = sign(&LinkKey::new(1, &[0; KEY_LEN]), Link::Lte, &frame_at(T0));
        assert_eq!(
            receive(&mut check, Instant::ZERO, Link::Lte, &forged),
            Ok(Authenticity::Unchecked)
        );
    }

    #[test]
    fn the_stamp_must_be_within_60_s_of_the_receivers_clock_before_or_after() {
        let key = LinkKey::new(1, &SECRET);
        let at = Instant::from_millis(120_000);
        let utc = T0 + 120_000;
        for (stamp, ok) in [
            (utc - 60_001, false),
            (utc - 60_000, true),
            (utc, true),
            (utc + 60_000, true),
            (utc + 60_001, false),
        ] {
            let mut check = check(Policy::Require);
            let got = receive(
                &mut check,
                at,
                Link::Direct,
                &sign(&key, Link::Direct, &frame_at(stamp)),
            );
            assert_eq!(
                got.is_ok(),
                ok,
                "stamp {} ms from now: {got:?}",
                stamp as i64 - utc as i64
            );
        }
    }

    #[test]
    fn out_of_order_is_not_a_replay_and_each_link_has_its_memory() {
        let key = LinkKey::new(1, &SECRET);
        let mut check = check(Policy::Require);
        let now = Instant::from_millis(1000);
        // 32 in flight, arriving in reverse.
        for stamp in (0..32).rev() {
            let signed = sign(&key, Link::Direct, &frame_at(T0 + 500 + stamp));
            assert!(receive(&mut check, now, Link::Direct, &signed).is_ok());
            // The redundant copy on the other link passes the signature check too (message
            // sampling drops it later).
            let copy = sign(&key, Link::Lte, &frame_at(T0 + 500 + stamp));
            assert!(receive(&mut check, now, Link::Lte, &copy).is_ok());
            assert_eq!(
                receive(&mut check, now, Link::Lte, &copy),
                Err(SignatureCause::Replay)
            );
        }
    }

    #[test]
    fn stamps_from_before_the_receiver_started_are_refused() {
        let key = LinkKey::new(1, &SECRET);
        let mut check = SignatureCheck::new(
            Policy::Require,
            keyring(&[(1, SECRET)]),
            Timestamp::from_millis(T0).unwrap(),
            Instant::from_millis(10_000),
        );
        let now = Instant::from_millis(10_000);
        for (stamp, ok) in [(T0 + 9_999, false), (T0 + 10_000, true)] {
            let got = receive(
                &mut check,
                now,
                Link::Direct,
                &sign(&key, Link::Direct, &frame_at(stamp)),
            );
            assert_eq!(got.is_ok(), ok, "{stamp}: {got:?}");
        }
    }

    #[test]
    fn a_full_memory_refuses_what_it_forgot_and_older() {
        let mut memory = ReplayMemory::new(Timestamp::from_millis(T0).unwrap());
        let utc = Timestamp::from_millis(T0 + 30_000).unwrap();
        let id = |ms: u64| (GCS_ID, 13002u16, Timestamp::from_millis(T0 + ms).unwrap());
        for ms in 0..REPLAY_MEMORY as u64 {
            memory.admit(utc, id(ms)).unwrap();
        }
        assert!(memory.is_full());
        // One more: the oldest (stamp 0) is forgotten, and with it everything up to it.
        memory.admit(utc, id(REPLAY_MEMORY as u64)).unwrap();
        assert_eq!(memory.admit(utc, id(0)), Err(NotAdmitted::Replay));
        // Below the start: sent before the receiver started, not a replay.
        let before = (GCS_ID, 13002u16, Timestamp::from_millis(T0 - 1).unwrap());
        assert_eq!(memory.admit(utc, before), Err(NotAdmitted::BeforeStart));
        assert_eq!(memory.len, REPLAY_MEMORY);
        // Still-held identities are still refused; new ones pass.
        assert_eq!(memory.admit(utc, id(7)), Err(NotAdmitted::Replay));
        assert!(memory.admit(utc, id(REPLAY_MEMORY as u64 + 1)).is_ok());
    }

    #[test]
    fn a_resumed_window_admits_what_came_after_its_floor_and_nothing_at_or_below() {
        let key = LinkKey::new(1, &SECRET);
        // Started at 40 s, having kept a floor of 10 s from the run before.
        let mut check = SignatureCheck::new(
            Policy::Require,
            keyring(&[(1, SECRET)]),
            Timestamp::from_millis(T0).unwrap(),
            Instant::from_millis(40_000),
        );
        check.resume_after(Timestamp::from_millis(T0 + 10_000).unwrap());
        let at = |ms: u64| sign(&key, Link::Direct, &frame_at(T0 + ms));
        let now = Instant::from_millis(40_000);
        // Sent while it was down: new.
        assert!(receive(&mut check, now, Link::Direct, &at(20_000)).is_ok());
        // At or below the floor: perhaps admitted by the run before.
        let bytes = at(10_000);
        let frame = Frame::new_checked(&bytes).unwrap();
        let stamp = frame.message().ok().map(|m| m.time_stamp());
        assert_eq!(
            check.admit(
                now,
                Link::Direct,
                frame.source_id(),
                frame.message_type(),
                stamp
            ),
            Err(NotAdmitted::BeforeStart)
        );
        assert_eq!(
            check.admitted_up_to(),
            Some(Timestamp::from_millis(T0 + 20_000).unwrap())
        );
    }

    /// The memory against a model of the same rule over std's set and queue: random identities
    /// of a few sources and types, stamps around a clock that advances, the memory full and
    /// wrapping round many times, so that every path of the index (probes that wrap, entries
    /// moved back into freed slots) is taken; after every step each identity the model holds
    /// is found, and only those.
    #[test]
    fn the_index_agrees_with_a_set_through_many_wraps() {
        use std::collections::{HashSet, VecDeque};
        let start = Timestamp::from_millis(T0).unwrap();
        let mut memory = ReplayMemory::new(start);
        let (mut order, mut seen) = (VecDeque::<Identity>::new(), HashSet::<Identity>::new());
        let mut lowest = start;
        let mut rng = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        for step in 0..60_000u64 {
            // The clock advances 1 ms a step; stamps up to 2 s behind it, or repeated.
            let now = T0 + 70_000 + step;
            let r = next();
            let id = (
                GCS_ID + (r % 3) as u32,
                13000 + ((r >> 8) % 4) as u16,
                Timestamp::from_millis(now - (r >> 16) % 2_000).unwrap(),
            );
            let utc = Timestamp::from_millis(now).unwrap();
            // The model: the rule of `admit` over std's collections.
            let expected = if id.2 < lowest || seen.contains(&id) {
                Err(NotAdmitted::Replay)
            } else {
                let expired = now - REPLAY_WINDOW.as_millis() as u64;
                while let Some(oldest) = order.front().copied() {
                    if oldest.2.millis() >= expired && order.len() < REPLAY_MEMORY {
                        break;
                    }
                    order.pop_front();
                    seen.remove(&oldest);
                    if oldest.2.millis() >= expired {
                        lowest = lowest.max(Timestamp::from_millis(oldest.2.millis() + 1).unwrap());
                    }
                }
                order.push_back(id);
                seen.insert(id);
                Ok(())
            };
            assert_eq!(memory.admit(utc, id), expected, "step {step}");
            assert_eq!(memory.len, order.len(), "step {step}");
            if step % 997 == 0 {
                assert!(order.iter().all(|i| memory.contains(i)), "step {step}");
                let used = memory.index.iter().filter(|p| **p != EMPTY).count();
                assert_eq!(used, order.len(), "one slot per identity, step {step}");
            }
        }
        assert!(
            lowest > start,
            "the memory was full and forgot within the window"
        );
    }

    #[test]
    fn identities_older_than_the_window_are_forgotten_without_raising_the_floor() {
        let mut memory = ReplayMemory::new(Timestamp::from_millis(T0).unwrap());
        let id = |ms: u64| (GCS_ID, 13002u16, Timestamp::from_millis(T0 + ms).unwrap());
        memory
            .admit(Timestamp::from_millis(T0).unwrap(), id(0))
            .unwrap();
        memory
            .admit(Timestamp::from_millis(T0 + 60_001).unwrap(), id(60_001))
            .unwrap();
        assert_eq!(memory.len, 1, "the identity out of the window is gone");
        assert_eq!(memory.lowest.millis(), T0);
    }

    #[test]
    fn keys_never_show_in_debug() {
        let key = LinkKey::new(5, &SECRET);
        let mut ring = Keyring::new();
        ring.insert(key.clone()).unwrap();
        let text = format!("{key:?} {ring:?} {:?}", Signer::new(key.clone()));
        assert!(text.contains("id: 5"), "{text}");
        assert!(!text.to_lowercase().contains("42"), "{text}");
        assert_eq!(
            ring.insert(LinkKey::new(5, &[1; KEY_LEN])),
            Err(KeyringError::DuplicateId(5))
        );
    }
}
