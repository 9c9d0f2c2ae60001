//! The boundary with C: every pointer and length C passes is checked here before Rust uses it,
//! and every call runs inside [`guard`], so that no panic unwinds into C (undefined behaviour)
//! and every failure becomes a return code with its message kept.
//!
//! What cannot be checked is said in the header: a non-null pointer must point to as many
//! bytes as the size passed with it, a name must end with NUL, a partition handle must come
//! from `missionlink_partition_open` and not be closed. Null pointers, sizes other than the
//! payload type's and bytes that are no valid payload are refused with their codes.

use core::ffi::{CStr, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::status::{Failure, Status, record};

/// Runs `f`, turning its failure or panic into a return code (the message kept for
/// `missionlink_last_error`).
pub fn guard(f: impl FnOnce() -> Result<Status, Failure>) -> i32 {
    // AssertUnwindSafe: after a panic the caller gets MISSIONLINK_ERROR_INTERNAL; a handle
    // the panic left half-changed is at worst a port that is not open, which later calls
    // report as such.
    let status = match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(status)) => status,
        Ok(Err(failure)) => record(failure),
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            record(Failure::new(
                Status::Internal,
                format!("the library panicked: {what}"),
            ))
        }
    };
    status as i32
}

/// The failure of a null `what`.
pub fn null(what: &str) -> Failure {
    Failure::new(Status::NullPointer, format!("{what} is a null pointer"))
}

/// The `size` bytes at `ptr`, which C passed as a payload to read.
///
/// # Safety
///
/// `ptr`, when not null, points to `size` bytes readable for the lifetime `'a`, which nothing
/// writes meanwhile.
pub unsafe fn bytes<'a>(ptr: *const c_void, size: usize) -> Result<&'a [u8], Failure> {
    if ptr.is_null() {
        return Err(null("the payload"));
    }
    // SAFETY: not null (checked above); the caller promises `size` readable bytes, unchanged
    // while the slice lives. Any alignment will do for bytes.
    Ok(unsafe { core::slice::from_raw_parts(ptr.cast::<u8>(), size) })
}

/// The `size` bytes at `ptr`, which C passed for a payload to be written into.
///
/// # Safety
///
/// `ptr`, when not null, points to `size` bytes writable for the lifetime `'a`, which nothing
/// else reads or writes meanwhile.
pub unsafe fn bytes_mut<'a>(ptr: *mut c_void, size: usize) -> Result<&'a mut [u8], Failure> {
    if ptr.is_null() {
        return Err(null("the payload"));
    }
    // SAFETY: not null (checked above); the caller promises `size` writable bytes that nothing
    // else touches while the slice lives. Any alignment will do for bytes.
    Ok(unsafe { core::slice::from_raw_parts_mut(ptr.cast::<u8>(), size) })
}

/// The NUL-terminated UTF-8 string `what` at `ptr`.
///
/// # Safety
///
/// `ptr`, when not null, points to a string that ends with NUL, unchanged for `'a`.
pub unsafe fn text<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: not null (checked above); the caller promises a NUL-terminated string that
    // nothing changes while the reference lives.
    let s = unsafe { CStr::from_ptr(ptr) };
    s.to_str()
        .map_err(|_| Failure::new(Status::InvalidArgument, format!("{what} is not UTF-8")))
}

/// The object behind a handle C holds (`Box::into_raw` made it).
///
/// # Safety
///
/// `ptr`, when not null, came from `Box::<T>::into_raw` and was not freed, and no other
/// reference to it lives during `'a` (C calls a partition from one thread at a time).
pub unsafe fn handle<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: not null (checked above); the caller promises a live box of ours, used by this
    // call alone.
    Ok(unsafe { &mut *ptr })
}

/// Writes `value` to where C asked for it, if it asked (`ptr` not null).
///
/// # Safety
///
/// `ptr`, when not null, points to a writable `T` (any alignment).
pub unsafe fn put<T>(ptr: *mut T, value: T) {
    if !ptr.is_null() {
        // SAFETY: not null (checked above), writable as the caller promises; unaligned, since
        // C may hand any address.
        unsafe { ptr.write_unaligned(value) };
    }
}
