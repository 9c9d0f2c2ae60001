//! The C API called from Rust as C calls it: a partition publishes, another takes with the
//! payload types; every bad pointer, size, service and payload gets its code.

use core::ffi::{CStr, c_void};
use std::ffi::CString;

use missionlink_interfaces::contracts::{GuidanceProgressPayload, HeartbeatPayload};
use zerocopy::IntoBytes;

use super::*;

const PROGRESS: i32 = 5;
const HEALTH_GUIDANCE: i32 = 10;
const ROLE_GUIDANCE: i32 = 3;
const ROLE_SYSTEM_AUTOMATION: i32 = 2;

fn open(name: &str, prefix: &str, role: i32) -> *mut CPartition {
    let name = CString::new(name).unwrap();
    let prefix = CString::new(prefix).unwrap();
    let mut p = core::ptr::null_mut();
    // SAFETY: NUL-terminated strings and a writable out-pointer.
    let status =
        unsafe { missionlink_partition_open(name.as_ptr(), prefix.as_ptr(), role, 0, &mut p) };
    assert_eq!(status, 0, "{}", last_error());
    assert!(!p.is_null());
    p
}

fn last_error() -> String {
    let mut buffer = [0 as c_char; 256];
    // SAFETY: 256 writable bytes.
    let n = unsafe { missionlink_last_error(buffer.as_mut_ptr(), buffer.len()) };
    // SAFETY: NUL-terminated by missionlink_last_error.
    let text = unsafe { CStr::from_ptr(buffer.as_ptr()) };
    assert!(n >= text.to_bytes().len());
    text.to_string_lossy().into_owned()
}

fn name(status: i32) -> String {
    // SAFETY: a static NUL-terminated string.
    unsafe { CStr::from_ptr(missionlink_status_name(status)) }
        .to_string_lossy()
        .into_owned()
}

#[test]
fn a_sample_published_by_one_partition_is_taken_by_another_and_wakes_its_wait() {
    let prefix = format!("clib-test-pubsub-{}", std::process::id());
    let guidance = open("clib-test-guidance", &prefix, ROLE_GUIDANCE);
    let automation = open("clib-test-automation", &prefix, ROLE_SYSTEM_AUTOMATION);
    // SAFETY: live handles; the payloads below are the types' own bytes.
    unsafe {
        assert_eq!(missionlink_publisher_open(guidance, PROGRESS), 0);
        assert_eq!(missionlink_subscriber_open(automation, PROGRESS), 0);
        let mut out = GuidanceProgressPayload::IDLE;
        let size = size_of::<GuidanceProgressPayload>();
        let out_ptr = (&raw mut out).cast::<c_void>();
        assert_eq!(
            missionlink_take(automation, PROGRESS, out_ptr, size),
            Status::NoSample as i32
        );
        let sent = GuidanceProgressPayload {
            sequence: 7,
            from: 1,
            to: 2,
            next: 3,
            on_ground: false,
            ..GuidanceProgressPayload::IDLE
        };
        let sent_ptr = (&raw const sent).cast::<c_void>();
        assert_eq!(missionlink_publish(guidance, PROGRESS, sent_ptr, size), 0);
        // The sample waits: the wait returns at once, long before its timeout.
        let start = std::time::Instant::now();
        assert_eq!(missionlink_wait(automation, 10_000_000_000), 0);
        assert!(start.elapsed() < Duration::from_secs(5));
        assert_eq!(
            missionlink_take_latest(automation, PROGRESS, out_ptr, size),
            0
        );
        assert_eq!(out.as_bytes(), sent.as_bytes());
        assert_eq!(
            missionlink_take(automation, PROGRESS, out_ptr, size),
            Status::NoSample as i32
        );

        // The heartbeat: the first beat at once, the next within the period.
        let mut next = u64::MAX;
        assert_eq!(missionlink_subscriber_open(automation, HEALTH_GUIDANCE), 0);
        assert_eq!(missionlink_heartbeat(guidance, &mut next), 0);
        assert!(next <= DEFAULT_HEARTBEAT_PERIOD.as_nanos() as u64, "{next}");
        let mut beat = HeartbeatPayload {
            sequence: 0,
            time_ns: 0,
            period_ns: 0,
            pid: 0,
            reserved: [0; 4],
        };
        assert_eq!(
            missionlink_take_latest(
                automation,
                HEALTH_GUIDANCE,
                (&raw mut beat).cast(),
                size_of::<HeartbeatPayload>()
            ),
            0
        );
        assert_eq!((beat.sequence, beat.pid), (1, std::process::id()));
        assert_eq!(beat.period_ns, DEFAULT_HEARTBEAT_PERIOD.as_nanos() as u64);

        missionlink_partition_close(automation);
        missionlink_partition_close(guidance);
    }
}

#[test]
fn null_pointers_wrong_sizes_unknown_services_and_invalid_payloads_get_their_codes() {
    let prefix = format!("clib-test-errors-{}", std::process::id());
    let p = open("clib-test-errors", &prefix, ROLE_GUIDANCE);
    let size = size_of::<GuidanceProgressPayload>();
    let mut value = GuidanceProgressPayload::IDLE;
    let ptr = (&raw mut value).cast::<c_void>();
    // SAFETY: every pointer is null or points to `size` bytes of `value`; sizes other than
    // `size` are refused before any is used.
    unsafe {
        let null = core::ptr::null_mut::<CPartition>();
        assert_eq!(
            missionlink_publish(null, PROGRESS, ptr, size),
            Status::NullPointer as i32
        );
        assert!(last_error().contains("partition"), "{}", last_error());
        assert_eq!(
            missionlink_publish(p, PROGRESS, ptr, size),
            Status::NotOpen as i32
        );
        assert_eq!(missionlink_publisher_open(p, PROGRESS), 0);
        assert_eq!(
            missionlink_publish(p, PROGRESS, core::ptr::null(), size),
            Status::NullPointer as i32
        );
        assert_eq!(
            missionlink_publish(p, PROGRESS, ptr, size - 1),
            Status::WrongSize as i32
        );
        assert!(
            last_error().contains("fcc/guidance/progress"),
            "{}",
            last_error()
        );
        assert_eq!(
            missionlink_publish(p, PROGRESS, ptr, usize::MAX),
            Status::WrongSize as i32
        );
        assert_eq!(
            missionlink_publish(p, 99, ptr, size),
            Status::InvalidArgument as i32
        );
        assert_eq!(
            missionlink_publisher_open(p, -1),
            Status::InvalidArgument as i32
        );
        // A bool that is neither 0 nor 1 is no payload.
        let mut bytes = value.as_bytes().to_vec();
        let on_ground = core::mem::offset_of!(GuidanceProgressPayload, on_ground);
        bytes[on_ground] = 2;
        assert_eq!(
            missionlink_publish(p, PROGRESS, bytes.as_ptr().cast(), size),
            Status::InvalidPayload as i32
        );
        assert_eq!(missionlink_subscriber_open(p, PROGRESS), 0);
        assert_eq!(
            missionlink_take(p, PROGRESS, core::ptr::null_mut(), size),
            Status::NullPointer as i32
        );
        assert_eq!(
            missionlink_take(p, PROGRESS, ptr, 1),
            Status::WrongSize as i32
        );
        assert_eq!(missionlink_wait(null, 0), Status::NullPointer as i32);
        assert_eq!(
            missionlink_heartbeat(null, core::ptr::null_mut()),
            Status::NullPointer as i32
        );
        let mut out = core::ptr::null_mut();
        assert_eq!(
            missionlink_partition_open(core::ptr::null(), c"x".as_ptr(), 0, 0, &mut out),
            Status::NullPointer as i32
        );
        assert!(out.is_null());
        assert_eq!(
            missionlink_partition_open(c"x".as_ptr(), c"x".as_ptr(), 9, 0, &mut out),
            Status::InvalidArgument as i32
        );
        assert_eq!(
            missionlink_partition_open(c"x".as_ptr(), c"x".as_ptr(), 0, 0, core::ptr::null_mut()),
            Status::NullPointer as i32
        );
        // Nothing was sent by the refused calls.
        assert_eq!(
            missionlink_take(p, PROGRESS, ptr, size),
            Status::NoSample as i32
        );
        missionlink_partition_close(null);
        missionlink_partition_close(p);
    }
}

#[test]
fn the_payload_sizes_and_status_names_are_the_header_s() {
    assert_eq!(
        missionlink_payload_size(PROGRESS),
        size_of::<GuidanceProgressPayload>()
    );
    assert_eq!(
        missionlink_payload_size(HEALTH_GUIDANCE),
        size_of::<HeartbeatPayload>()
    );
    assert_eq!(missionlink_payload_size(11), 0);
    assert_eq!(name(0), "MISSIONLINK_OK");
    assert_eq!(name(-2), "MISSIONLINK_ERROR_WRONG_SIZE");
    assert_eq!(name(12345), "MISSIONLINK_UNKNOWN_STATUS");
    // A message longer than the buffer is cut and NUL-terminated; its full length returned.
    status::record(Failure::new(Status::Ipc, "0123456789"));
    let mut small = [1 as c_char; 4];
    // SAFETY: 4 writable bytes; then no buffer at all.
    let (n, none) = unsafe {
        (
            missionlink_last_error(small.as_mut_ptr(), small.len()),
            missionlink_last_error(core::ptr::null_mut(), 0),
        )
    };
    assert_eq!((n, none), (10, 10));
    assert_eq!(small.map(|c| c as u8), *b"012\0");
}
