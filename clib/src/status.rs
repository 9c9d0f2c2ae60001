//! The return codes of the C API and their names, and the message of the last error on the
//! calling thread: C has no `Result`, so every function returns a [`Status`] and the detail of
//! an iceoryx2 refusal is kept for `missionlink_last_error`.

use core::ffi::CStr;
use std::cell::RefCell;

/// What a call of the C API did (`missionlink_status` in clib/include/missionlink.h, the same
/// values). Zero is success, positive values are outcomes that are not errors, negative values
/// are errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(i32)]
pub enum Status {
    /// Done.
    Ok = 0,
    /// A take found no sample waiting (not an error).
    NoSample = 1,
    /// A pointer argument was null.
    NullPointer = -1,
    /// A payload's size was not the size of the service's payload type.
    WrongSize = -2,
    /// An argument out of range: an unknown service or role, a name that is not UTF-8 or that
    /// iceoryx2 does not take.
    InvalidArgument = -3,
    /// A payload whose bytes are not a valid value of its type (a `bool` neither 0 nor 1).
    InvalidPayload = -4,
    /// Publish or take on a service the partition has not opened for it.
    NotOpen = -5,
    /// iceoryx2 refused (opening a service with another type or QoS, a full publisher...); the
    /// detail is in `missionlink_last_error`.
    Ipc = -6,
    /// The library failed inside (a panic, caught at the boundary); the detail is in
    /// `missionlink_last_error`.
    Internal = -7,
}

impl Status {
    /// Every status, for the names and the tests.
    pub const ALL: [Status; 9] = [
        Self::Ok,
        Self::NoSample,
        Self::NullPointer,
        Self::WrongSize,
        Self::InvalidArgument,
        Self::InvalidPayload,
        Self::NotOpen,
        Self::Ipc,
        Self::Internal,
    ];

    /// The name of the status, as the header spells the constant.
    pub const fn name(self) -> &'static CStr {
        match self {
            Self::Ok => c"MISSIONLINK_OK",
            Self::NoSample => c"MISSIONLINK_NO_SAMPLE",
            Self::NullPointer => c"MISSIONLINK_ERROR_NULL_POINTER",
            Self::WrongSize => c"MISSIONLINK_ERROR_WRONG_SIZE",
            Self::InvalidArgument => c"MISSIONLINK_ERROR_INVALID_ARGUMENT",
            Self::InvalidPayload => c"MISSIONLINK_ERROR_INVALID_PAYLOAD",
            Self::NotOpen => c"MISSIONLINK_ERROR_NOT_OPEN",
            Self::Ipc => c"MISSIONLINK_ERROR_IPC",
            Self::Internal => c"MISSIONLINK_ERROR_INTERNAL",
        }
    }

    /// The status of a return code, if it is one.
    pub fn of(code: i32) -> Option<Self> {
        Self::ALL.into_iter().find(|s| *s as i32 == code)
    }
}

/// The name of a code no function returns.
pub const UNKNOWN_NAME: &CStr = c"MISSIONLINK_UNKNOWN_STATUS";

/// An error with what was being done, kept for `missionlink_last_error`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    /// The code returned.
    pub status: Status,
    /// What happened, for a person.
    pub message: String,
}

impl Failure {
    /// A failure with `status` and `message`.
    pub fn new(status: Status, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
}

impl From<missionlink_partitions::ipc::IpcError> for Failure {
    fn from(e: missionlink_partitions::ipc::IpcError) -> Self {
        Self::new(Status::Ipc, e.0)
    }
}

thread_local! {
    /// The message of the last failure on this thread (empty after none).
    static LAST: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Keeps `failure`'s message as the thread's last error and returns its status.
pub fn record(failure: Failure) -> Status {
    LAST.with(|last| {
        if let Ok(mut last) = last.try_borrow_mut() {
            *last = failure.message;
        }
    });
    failure.status
}

/// Hands the thread's last error message to `f`.
pub fn with_last<R>(f: impl FnOnce(&str) -> R) -> R {
    LAST.with(|last| match last.try_borrow() {
        Ok(message) => f(&message),
        Err(_) => f(""),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_status_has_its_own_name_and_is_found_by_its_code() {
        let mut names: Vec<_> = Status::ALL.iter().map(|s| s.name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), Status::ALL.len());
        for s in Status::ALL {
            assert_eq!(Status::of(s as i32), Some(s));
        }
        assert_eq!(Status::of(42), None);
    }

    #[test]
    fn the_last_error_is_the_message_of_the_last_failure_recorded() {
        assert_eq!(
            record(Failure::new(Status::WrongSize, "size 3, expected 8")),
            Status::WrongSize
        );
        with_last(|m| assert_eq!(m, "size 3, expected 8"));
    }
}
