//! The raw bytes of a contract's payload, as they lie in shared memory: what the bridge sends
//! to Zenoh and takes from it (docs/design.md "Across hosts": raw fixed-layout bytes; ICD §14).
//!
//! Both ways go through zerocopy, with no unsafe code. A payload has no padding (every payload
//! derives `IntoBytes`, interfaces/src/contracts.rs), so its bytes are all its fields' and
//! `as_bytes` gives them; the way back is `TryFromBytes` (not `FromBytes`: a payload's `bool`
//! has two valid bytes), which checks every field, and refuses a `bool` byte that is neither 0
//! nor 1, before anything is published.

use zerocopy::{Immutable, IntoBytes, KnownLayout, TryFromBytes};

use crate::header::Refusal;

/// The payload's bytes, `size_of::<T>()` of them, every one written by whoever made the value.
pub fn bytes_of<T: IntoBytes + Immutable>(value: &T) -> &[u8] {
    value.as_bytes()
}

/// A payload from bytes of the network. Refused, never a panic: bytes of another length than
/// `size_of::<T>()` ([`Refusal::Size`], with the length received), or bytes that are not a valid
/// value of `T` ([`Refusal::Invalid`]). The value is copied out, so the bytes need no alignment
/// (a Zenoh payload has none to promise).
pub fn read<T: TryFromBytes + KnownLayout + Immutable>(bytes: &[u8]) -> Result<T, Refusal> {
    if bytes.len() != size_of::<T>() {
        return Err(Refusal::Size(
            u32::try_from(bytes.len()).unwrap_or(u32::MAX),
        ));
    }
    T::try_read_from_bytes(bytes).map_err(|_| Refusal::Invalid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::contracts::{AutomationStatePayload, HeartbeatPayload};

    #[test]
    fn bytes_of_a_payload_read_back_as_the_same_payload() {
        let beat = HeartbeatPayload {
            sequence: 7,
            time_ns: 8,
            period_ns: 100_000_000,
            pid: 42,
            reserved: [0; 4],
        };
        let bytes = bytes_of(&beat);
        assert_eq!(bytes.len(), 32);
        assert_eq!(bytes[..8], 7u64.to_ne_bytes());
        assert_eq!(read::<HeartbeatPayload>(bytes), Ok(beat));
    }

    #[test]
    fn bytes_of_another_length_or_no_valid_value_are_refused() {
        let bytes = bytes_of(&AutomationStatePayload::ON_GROUND).to_vec();
        assert_eq!(
            read::<AutomationStatePayload>(&bytes[..39]),
            Err(Refusal::Size(39))
        );
        let mut longer = bytes.clone();
        longer.push(0);
        assert_eq!(
            read::<AutomationStatePayload>(&longer),
            Err(Refusal::Size(41))
        );
        assert_eq!(read::<AutomationStatePayload>(&[]), Err(Refusal::Size(0)));
        // `trajectory_generation_active` (byte 25) is a bool: 2 is no value of it.
        let mut invalid = bytes;
        invalid[25] = 2;
        assert_eq!(
            read::<AutomationStatePayload>(&invalid),
            Err(Refusal::Invalid)
        );
    }
}
