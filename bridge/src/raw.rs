//! The raw bytes of a contract's payload, as they lie in shared memory: what the bridge sends
//! to Zenoh (docs/design.md "Across hosts": raw fixed-layout bytes). The one unsafe part of the
//! bridge; the way back (bytes to a payload) is zerocopy's `TryFromBytes`, which checks every
//! field (a `bool` byte that is neither 0 nor 1 is refused) and is safe.
#![allow(unsafe_code)]

use iceoryx2::prelude::ZeroCopySend;

/// The payload's bytes, `size_of::<T>()` of them.
///
/// Padding: two contracts have some (`FramePayload` ends in 4 bytes of it,
/// `AutomationStatePayload` has 1 inside and 6 at the end). Those bytes are copied as they lie
/// in the sample's shared memory, which iceoryx2 maps zero-filled; the receiver's
/// `TryFromBytes` never reads them.
pub fn bytes_of<T: ZeroCopySend + Copy>(value: &T) -> &[u8] {
    // SAFETY: `value` is a valid reference to `size_of::<T>()` bytes that live as long as the
    // returned slice; `T: ZeroCopySend` is `#[repr(C)]` plain data without pointers (iceoryx2's
    // contract for shared memory), and `u8` has no alignment requirement.
    unsafe { core::slice::from_raw_parts((value as *const T).cast::<u8>(), size_of::<T>()) }
}

/// The payload type's iceoryx2 type name (`missionlink::FramePayload/v5`, ...), which the
/// header carries and the receiver checks.
pub fn type_name<T: ZeroCopySend>() -> &'static str {
    // SAFETY: `type_name` only returns a static string; iceoryx2 marks it unsafe to discourage
    // overriding it, not calling it.
    unsafe { <T as ZeroCopySend>::type_name() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::contracts::HeartbeatPayload;
    use zerocopy::TryFromBytes;

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
        assert_eq!(HeartbeatPayload::try_read_from_bytes(bytes).unwrap(), beat);
        assert_eq!(
            type_name::<HeartbeatPayload>(),
            "missionlink::HeartbeatPayload/v5"
        );
    }
}
