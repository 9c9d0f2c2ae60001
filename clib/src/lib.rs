//! The C library of missionlink: a partition written in C or C++ (a hardware-in-the-loop rig's
//! guidance, say) opens the FCC's iceoryx2 services with the contracts' payload types and stands
//! in for a Rust partition, as the Python guidance does (docs/hil.md says how a rig links it).
//!
//! iceoryx2's own C bindings for 0.10 are not on crates.io, so this crate builds a shared and a
//! static library of its own over the Rust partitions' IPC (`missionlink_partitions::ipc` and the
//! heartbeat), with the defaults of `[ipc]`: a C partition opens each service with the same QoS,
//! notifies and rings its consumers as a Rust one does, and sleeps in an iceoryx2 WaitSet on the
//! events of the services it subscribes to, whose listeners every publisher notifies
//! (docs/wait-path.md). The API is in clib/include/missionlink.h (kept by hand
//! beside interfaces/c/missionlink_contracts.h, whose payload structs it takes).
//!
//! Every function returns a status code (`status`) and never lets a panic cross into C; every
//! pointer and size from C is checked first (`boundary`).

// The crate is the boundary with C: exported functions (`#[unsafe(no_mangle)]`) and the raw
// pointers C passes cannot be had without `unsafe`, which the workspace denies everywhere else.
// Every unsafe block is one pointer conversion in `boundary` or here, after its checks, with its
// SAFETY comment.
#![allow(unsafe_code)]

pub mod boundary;
pub mod ports;
pub mod status;

use core::ffi::{c_char, c_void};
use std::time::Duration;

use iceoryx2::prelude::ipc;
use iceoryx2::prelude::{CallbackProgression, SignalHandlingMode, WaitSetBuilder};
use missionlink_interfaces::contracts::{DEFAULT_HEARTBEAT_PERIOD, FccService, Partition};
use missionlink_partitions::config;
use missionlink_partitions::health::Heartbeat;
use missionlink_partitions::ipc::{Ipc, quiet_iceoryx2_log};

use boundary::{bytes, bytes_mut, guard, handle, null, put, text};
use ports::{In, Out, SERVICES, check_size, open_publisher, open_subscriber};
use status::{Failure, Status};

/// A partition opened from C (`missionlink_partition` in the header, opaque there): the node
/// under the prefix, its heartbeat, and the ports it opened, one publisher and one subscriber at
/// most per service.
pub struct CPartition {
    ipc: Ipc<ipc::Service>,
    heartbeat: Heartbeat<ipc::Service>,
    publishers: [Option<Box<dyn Out>>; SERVICES.len()],
    subscribers: [Option<Box<dyn In>>; SERVICES.len()],
}

impl CPartition {
    /// Opens the node `name` under `prefix` for `role`, beating every `period`.
    pub fn open(
        name: &str,
        prefix: &str,
        role: Partition,
        period: Duration,
    ) -> Result<Self, Failure> {
        quiet_iceoryx2_log();
        // The defaults of `[ipc]` under the caller's prefix: the C partition's publishers ring
        // the doorbells of the Rust partitions that wait on theirs (`doorbell::waits`), as a
        // Rust publisher does; the C partition itself sleeps in a WaitSet on its listeners,
        // which have no name, so every publisher notifies them (`doorbell::Ringers::notifies`).
        let settings = config::Ipc::with_prefix(prefix);
        let ipc = Ipc::<ipc::Service>::open(name, &settings).map_err(|e| {
            // A node name iceoryx2 refuses is the caller's argument, not a refusal of the
            // system.
            Failure::new(Status::InvalidArgument, e.0)
        })?;
        let heartbeat = Heartbeat::open(&ipc, role, period)?;
        Ok(Self {
            ipc,
            heartbeat,
            publishers: Default::default(),
            subscribers: Default::default(),
        })
    }

    fn index(service: FccService) -> usize {
        SERVICES.iter().position(|s| *s == service).unwrap_or(0)
    }

    /// Opens the publisher of `service` (once; again is a no-op).
    pub fn open_publisher(&mut self, service: FccService) -> Result<(), Failure> {
        let slot = self.publishers.get_mut(Self::index(service));
        if let Some(slot @ None) = slot {
            *slot = Some(open_publisher(&self.ipc, service)?);
        }
        Ok(())
    }

    /// Opens the subscriber of `service` (once; again is a no-op).
    pub fn open_subscriber(&mut self, service: FccService) -> Result<(), Failure> {
        let slot = self.subscribers.get_mut(Self::index(service));
        if let Some(slot @ None) = slot {
            *slot = Some(open_subscriber(&self.ipc, service)?);
        }
        Ok(())
    }

    fn publisher(&self, service: FccService) -> Result<&dyn Out, Failure> {
        self.publishers
            .get(Self::index(service))
            .and_then(|p| p.as_deref())
            .ok_or_else(|| not_open(service, "publisher"))
    }

    fn subscriber(&self, service: FccService) -> Result<&dyn In, Failure> {
        self.subscribers
            .get(Self::index(service))
            .and_then(|s| s.as_deref())
            .ok_or_else(|| not_open(service, "subscriber"))
    }

    /// Publishes the payload `bytes` on `service`.
    pub fn publish(&self, service: FccService, bytes: &[u8]) -> Result<(), Failure> {
        check_size(service, bytes.len())?;
        self.publisher(service)?.publish(service, bytes)
    }

    /// Takes the oldest (or with `latest` the newest) sample of `service` into `out`.
    pub fn take(
        &self,
        service: FccService,
        out: &mut [u8],
        latest: bool,
    ) -> Result<Status, Failure> {
        check_size(service, out.len())?;
        let subscriber = self.subscriber(service)?;
        let taken = if latest {
            subscriber.take_latest(out)
        } else {
            subscriber.take(out)
        };
        Ok(if taken { Status::Ok } else { Status::NoSample })
    }

    /// Sleeps until a publisher of a service this partition subscribes to notifies its event,
    /// or `timeout` passes; at once while a subscribed service has a sample waiting. The
    /// notifications of what was taken before are consumed first, so each wake-up is for
    /// something new. The WaitSet is made for the call: its attachments borrow the listeners,
    /// which the partition owns.
    pub fn wait(&self, timeout: Duration) -> Result<(), Failure> {
        for subscriber in self.subscribers.iter().flatten() {
            subscriber.drain();
        }
        if timeout.is_zero() || self.subscribers.iter().flatten().any(|s| s.has_samples()) {
            return Ok(());
        }
        // The C program owns its signals: iceoryx2's handling of termination requests would
        // replace its SIGTERM and SIGINT handlers with iceoryx2's own, and the program's loop
        // would never see its flag. Without it, a signal ends the wait (EINTR) and the program
        // looks at its flag.
        let waitset = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| Failure::new(Status::Ipc, format!("WaitSet: {e:?}")))?;
        let mut guards = Vec::with_capacity(SERVICES.len());
        for subscriber in self.subscribers.iter().flatten() {
            guards.push(
                waitset
                    .attach_notification(subscriber.listener())
                    .map_err(|e| Failure::new(Status::Ipc, format!("WaitSet: {e:?}")))?,
            );
        }
        if guards.is_empty() {
            // Nothing to wait for but the deadline.
            std::thread::sleep(timeout);
            return Ok(());
        }
        waitset
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Stop, timeout)
            .map_err(|e| Failure::new(Status::Ipc, format!("WaitSet: {e:?}")))?;
        Ok(())
    }

    /// Beats if a beat is due; how long until the next one is.
    pub fn heartbeat(&mut self) -> Result<Duration, Failure> {
        Ok(self.heartbeat.beat_if_due()?)
    }
}

fn not_open(service: FccService, port: &str) -> Failure {
    Failure::new(
        Status::NotOpen,
        format!("{service}: no {port} open (missionlink_{port}_open first)"),
    )
}

/// Opens a partition: the iceoryx2 node `node_name` under `service_prefix` (removing what dead
/// nodes left), and the heartbeat
/// of `role` beating every `heartbeat_period_ns` (0: the contracts' default). On success
/// `*partition` is the handle; on failure it is set to null.
///
/// # Safety
///
/// `node_name` and `service_prefix` are null or NUL-terminated strings; `partition` is null or
/// points to a writable pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_partition_open(
    node_name: *const c_char,
    service_prefix: *const c_char,
    role: i32,
    heartbeat_period_ns: u64,
    partition: *mut *mut CPartition,
) -> i32 {
    guard(|| {
        if partition.is_null() {
            return Err(null("the partition out-pointer"));
        }
        // SAFETY: `partition` is not null (checked above) and writable as the caller promises.
        unsafe { put(partition, core::ptr::null_mut()) };
        // SAFETY: null or NUL-terminated, as the caller promises.
        let name = unsafe { text(node_name, "the node name") }?;
        // SAFETY: as above.
        let prefix = unsafe { text(service_prefix, "the service prefix") }?;
        let role = ports::role(role)?;
        let period = if heartbeat_period_ns == 0 {
            DEFAULT_HEARTBEAT_PERIOD
        } else {
            Duration::from_nanos(heartbeat_period_ns)
        };
        let opened = Box::new(CPartition::open(name, prefix, role, period)?);
        // SAFETY: as above; the box is C's from here until missionlink_partition_close.
        unsafe { put(partition, Box::into_raw(opened)) };
        Ok(Status::Ok)
    })
}

/// Closes a partition and every port it opened (null: nothing to do).
///
/// # Safety
///
/// `partition` is null or a handle from [`missionlink_partition_open`] not closed yet; it is
/// not used again.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_partition_close(partition: *mut CPartition) {
    guard(|| {
        if !partition.is_null() {
            // SAFETY: a live handle of ours (the caller promises), given back once.
            drop(unsafe { Box::from_raw(partition) });
        }
        Ok(Status::Ok)
    });
}

/// Opens the publisher of `service` (a `missionlink_service`) for [`missionlink_publish`].
///
/// # Safety
///
/// `partition` is null or a live handle from [`missionlink_partition_open`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_publisher_open(
    partition: *mut CPartition,
    service: i32,
) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the caller promises).
        let p = unsafe { handle(partition, "the partition") }?;
        p.open_publisher(ports::service(service)?)?;
        Ok(Status::Ok)
    })
}

/// Opens the subscriber of `service` for [`missionlink_take`] and [`missionlink_take_latest`];
/// its samples wake [`missionlink_wait`].
///
/// # Safety
///
/// `partition` is null or a live handle from [`missionlink_partition_open`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_subscriber_open(
    partition: *mut CPartition,
    service: i32,
) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the caller promises).
        let p = unsafe { handle(partition, "the partition") }?;
        p.open_subscriber(ports::service(service)?)?;
        Ok(Status::Ok)
    })
}

/// Publishes the `size` bytes at `payload` (the service's payload struct; `size` must be its
/// `sizeof`) on `service`, then wakes its subscribers.
///
/// # Safety
///
/// `partition` is null or a live handle; `payload` is null or points to `size` readable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_publish(
    partition: *mut CPartition,
    service: i32,
    payload: *const c_void,
    size: usize,
) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the caller promises).
        let p = unsafe { handle(partition, "the partition") }?;
        let service = ports::service(service)?;
        // The size first: no slice of a length other than the payload's is ever made.
        check_size(service, size)?;
        // SAFETY: null or `size` readable bytes (the caller promises).
        let payload = unsafe { bytes(payload, size) }?;
        p.publish(service, payload)?;
        Ok(Status::Ok)
    })
}

fn take(
    partition: *mut CPartition,
    service: i32,
    payload: *mut c_void,
    size: usize,
    latest: bool,
) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the callers' callers promise).
        let p = unsafe { handle(partition, "the partition") }?;
        let service = ports::service(service)?;
        check_size(service, size)?;
        // SAFETY: null or `size` writable bytes (the callers' callers promise).
        let out = unsafe { bytes_mut(payload, size) }?;
        p.take(service, out, latest)
    })
}

/// Copies the oldest sample waiting on `service` into `payload` (`size` must be the payload
/// struct's `sizeof`): `MISSIONLINK_OK`, or `MISSIONLINK_NO_SAMPLE` when none waits.
///
/// # Safety
///
/// `partition` is null or a live handle; `payload` is null or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_take(
    partition: *mut CPartition,
    service: i32,
    payload: *mut c_void,
    size: usize,
) -> i32 {
    take(partition, service, payload, size, false)
}

/// Copies the newest sample waiting on `service` into `payload`, dropping the older ones (the
/// state services: only the latest matters): `MISSIONLINK_OK`, or `MISSIONLINK_NO_SAMPLE`.
///
/// # Safety
///
/// As [`missionlink_take`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_take_latest(
    partition: *mut CPartition,
    service: i32,
    payload: *mut c_void,
    size: usize,
) -> i32 {
    take(partition, service, payload, size, true)
}

/// Sleeps until a publisher of a service the partition subscribes to notifies it (in an iceoryx2
/// WaitSet, on listeners every publisher notifies), or `timeout_ns` passes; returns at once while a subscribed
/// service has a sample waiting. A signal ends the wait early (check your own flag then).
///
/// # Safety
///
/// `partition` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_wait(partition: *mut CPartition, timeout_ns: u64) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the caller promises).
        let p = unsafe { handle(partition, "the partition") }?;
        p.wait(Duration::from_nanos(timeout_ns))?;
        Ok(Status::Ok)
    })
}

/// Sends the role's heartbeat if one is due (the first at once, then one per period); writes
/// the nanoseconds until the next is due to `next_due_ns` unless it is null.
///
/// # Safety
///
/// `partition` is null or a live handle; `next_due_ns` is null or points to a writable
/// `uint64_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_heartbeat(
    partition: *mut CPartition,
    next_due_ns: *mut u64,
) -> i32 {
    guard(|| {
        // SAFETY: null or a live handle (the caller promises).
        let p = unsafe { handle(partition, "the partition") }?;
        let next = p.heartbeat()?;
        let ns = u64::try_from(next.as_nanos()).unwrap_or(u64::MAX);
        // SAFETY: null or writable (the caller promises).
        unsafe { put(next_due_ns, ns) };
        Ok(Status::Ok)
    })
}

/// The size in bytes of `service`'s payload struct, 0 for an unknown service.
#[unsafe(no_mangle)]
pub extern "C" fn missionlink_payload_size(service: i32) -> usize {
    ports::service(service).map_or(0, ports::payload_size)
}

/// The path of `service` under the prefix ("fcc/guidance/progress", the header's
/// `MISSIONLINK_SERVICE_*_PATH`), a static string; NULL for an unknown service.
#[unsafe(no_mangle)]
pub extern "C" fn missionlink_service_path(service: i32) -> *const c_char {
    usize::try_from(service)
        .ok()
        .and_then(|i| ports::PATHS.get(i))
        .map_or(core::ptr::null(), |path| path.as_ptr())
}

/// The name of a status code ("MISSIONLINK_ERROR_WRONG_SIZE"), a static string;
/// "MISSIONLINK_UNKNOWN_STATUS" for a code no function returns.
#[unsafe(no_mangle)]
pub extern "C" fn missionlink_status_name(status: i32) -> *const c_char {
    Status::of(status)
        .map_or(status::UNKNOWN_NAME, Status::name)
        .as_ptr()
}

/// Copies the message of the calling thread's last error (what was refused and why) into
/// `buffer`, cut to `size - 1` bytes and NUL-terminated; returns the message's full length
/// (as snprintf: a buffer of that plus one holds it all). `buffer` may be null when `size` is 0.
///
/// # Safety
///
/// `buffer` is null or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn missionlink_last_error(buffer: *mut c_char, size: usize) -> usize {
    let mut length = 0;
    guard(|| {
        status::with_last(|message| {
            length = message.len();
            if size == 0 || buffer.is_null() {
                return;
            }
            // SAFETY: not null, `size` writable bytes (the caller promises).
            let out = unsafe { bytes_mut(buffer.cast::<c_void>(), size) };
            if let Ok(out) = out {
                let n = message.len().min(size - 1);
                if let (Some(dst), Some(src)) = (out.get_mut(..n), message.as_bytes().get(..n)) {
                    dst.copy_from_slice(src);
                }
                if let Some(nul) = out.get_mut(n) {
                    *nul = 0;
                }
            }
        });
        Ok(Status::Ok)
    });
    length
}

#[cfg(test)]
mod tests;
