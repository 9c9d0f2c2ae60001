//! The services as C numbers them (`missionlink_service`, `missionlink_role`) and the ports of
//! one partition, typed by the service's payload: C hands bytes, and the port checks that they
//! are as many as the payload type has and a valid value of it before anything is published.
//!
//! The ports are those of `missionlink_partitions::ipc`, so a C partition opens every service
//! with the QoS of the contracts and notifies its event service, as the Rust partitions do.

use core::ffi::CStr;
use core::fmt::Debug;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::{ZeroCopySend, ipc};
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationCommandPayload, AutomationStatePayload, FccService, FramePayload,
    GuidanceProgressPayload, HeartbeatPayload, Partition, WaypointListPayload,
};
use missionlink_partitions::ipc::{Ipc, Publisher, Subscriber};
use zerocopy::{Immutable, IntoBytes, KnownLayout, TryFromBytes};

use crate::status::{Failure, Status};

/// The services in the order of `missionlink_service` (its values are the indices).
pub const SERVICES: [FccService; 11] = FccService::ALL;

/// The services' paths under the prefix as C strings, in the order of [`SERVICES`] (for
/// `missionlink_service_path`; a test checks them against `FccService::path`).
pub const PATHS: [&CStr; SERVICES.len()] = [
    c"fcc/link/uplink",
    c"fcc/link/downlink",
    c"fcc/mission/waypoint-list",
    c"fcc/mission/area-list",
    c"fcc/automation/state",
    c"fcc/guidance/progress",
    c"fcc/automation/command",
    c"fcc/health/voting-monitoring",
    c"fcc/health/mission-data-handling",
    c"fcc/health/system-automation",
    c"fcc/health/guidance",
];

/// The roles in the order of `missionlink_role` (its values are the indices).
pub const ROLES: [Partition; 4] = Partition::ALL;

/// The service numbered `id` by C.
pub fn service(id: i32) -> Result<FccService, Failure> {
    usize::try_from(id)
        .ok()
        .and_then(|i| SERVICES.get(i).copied())
        .ok_or_else(|| Failure::new(Status::InvalidArgument, format!("no service {id}")))
}

/// The role numbered `id` by C.
pub fn role(id: i32) -> Result<Partition, Failure> {
    usize::try_from(id)
        .ok()
        .and_then(|i| ROLES.get(i).copied())
        .ok_or_else(|| Failure::new(Status::InvalidArgument, format!("no role {id}")))
}

/// The size of `service`'s payload type in bytes (`sizeof` of its struct in the header).
pub const fn payload_size(service: FccService) -> usize {
    match service {
        FccService::Uplink | FccService::Downlink => size_of::<FramePayload>(),
        FccService::WaypointList => size_of::<WaypointListPayload>(),
        FccService::AreaList => size_of::<AreaListPayload>(),
        FccService::AutomationState => size_of::<AutomationStatePayload>(),
        FccService::GuidanceProgress => size_of::<GuidanceProgressPayload>(),
        FccService::AutomationCommand => size_of::<AutomationCommandPayload>(),
        FccService::Heartbeat(_) => size_of::<HeartbeatPayload>(),
    }
}

/// The size check every publish and take makes.
pub fn check_size(service: FccService, size: usize) -> Result<(), Failure> {
    let expected = payload_size(service);
    if size == expected {
        Ok(())
    } else {
        Err(Failure::new(
            Status::WrongSize,
            format!("{service}: a payload of {size} bytes, its type has {expected}"),
        ))
    }
}

/// The payload types: what iceoryx2 and zerocopy need of them.
pub trait Payload:
    Debug + Copy + ZeroCopySend + TryFromBytes + IntoBytes + KnownLayout + Immutable + 'static
{
}

impl<T> Payload for T where
    T: Debug + Copy + ZeroCopySend + TryFromBytes + IntoBytes + KnownLayout + Immutable + 'static
{
}

/// A publisher of some payload type, fed bytes.
pub trait Out {
    /// Publishes `bytes` (exactly the payload's size) as a value of the payload type, rings and
    /// notifies, and connects late subscribers.
    fn publish(&self, service: FccService, bytes: &[u8]) -> Result<(), Failure>;
}

impl<T: Payload> Out for Publisher<ipc::Service, T> {
    fn publish(&self, service: FccService, bytes: &[u8]) -> Result<(), Failure> {
        // The value is read and checked here (a bool must be 0 or 1): iceoryx2 and every
        // subscriber take it as a `T`.
        let value = T::try_read_from_bytes(bytes).map_err(|_| {
            Failure::new(
                Status::InvalidPayload,
                format!("{service}: the bytes are not a valid payload (a bool neither 0 nor 1)"),
            )
        })?;
        self.send(&value)?;
        self.update_connections();
        Ok(())
    }
}

/// A subscriber of some payload type, read into bytes.
pub trait In {
    /// Copies the oldest waiting sample into `out` (exactly the payload's size); whether there
    /// was one.
    fn take(&self, out: &mut [u8]) -> bool;
    /// Copies the newest waiting sample into `out`, dropping the older ones; whether there was
    /// one.
    fn take_latest(&self, out: &mut [u8]) -> bool;
    /// Whether a sample waits.
    fn has_samples(&self) -> bool;
    /// Consumes the notifications of the service's event.
    fn drain(&self);
    /// The listener of the service's event, which every publisher notifies (what a WaitSet
    /// waits on).
    fn listener(&self) -> &Listener<ipc::Service>;
}

/// Copies `value`'s bytes into `out` (whose size was checked); whether they fit.
fn copy_out<T: Payload>(value: &T, out: &mut [u8]) -> bool {
    let bytes = value.as_bytes();
    if bytes.len() != out.len() {
        return false;
    }
    out.copy_from_slice(bytes);
    true
}

impl<T: Payload> In for Subscriber<ipc::Service, T> {
    fn take(&self, out: &mut [u8]) -> bool {
        let mut copied = false;
        self.take_one(|v| copied = copy_out(v, out));
        copied
    }

    fn take_latest(&self, out: &mut [u8]) -> bool {
        let mut newest = self.latest();
        self.drain_notifications();
        // A sample published between the look and the drain is not left for the next wake-up.
        if let Some(v) = self.latest() {
            newest = Some(v);
        }
        newest.is_some_and(|v| copy_out(&v, out))
    }

    fn has_samples(&self) -> bool {
        Subscriber::has_samples(self)
    }

    fn drain(&self) {
        self.drain_notifications();
    }

    fn listener(&self) -> &Listener<ipc::Service> {
        Subscriber::listener(self)
    }
}

/// A publisher of `service` with its payload type.
pub fn open_publisher(
    ipc: &Ipc<ipc::Service>,
    service: FccService,
) -> Result<Box<dyn Out>, Failure> {
    Ok(match service {
        FccService::Uplink | FccService::Downlink => {
            Box::new(ipc.publisher::<FramePayload>(service)?)
        }
        FccService::WaypointList => Box::new(ipc.publisher::<WaypointListPayload>(service)?),
        FccService::AreaList => Box::new(ipc.publisher::<AreaListPayload>(service)?),
        FccService::AutomationState => Box::new(ipc.publisher::<AutomationStatePayload>(service)?),
        FccService::GuidanceProgress => {
            Box::new(ipc.publisher::<GuidanceProgressPayload>(service)?)
        }
        FccService::AutomationCommand => {
            Box::new(ipc.publisher::<AutomationCommandPayload>(service)?)
        }
        FccService::Heartbeat(_) => Box::new(ipc.publisher::<HeartbeatPayload>(service)?),
    })
}

/// A subscriber of `service` with its payload type.
pub fn open_subscriber(
    ipc: &Ipc<ipc::Service>,
    service: FccService,
) -> Result<Box<dyn In>, Failure> {
    Ok(match service {
        FccService::Uplink | FccService::Downlink => {
            Box::new(ipc.subscriber::<FramePayload>(service)?)
        }
        FccService::WaypointList => Box::new(ipc.subscriber::<WaypointListPayload>(service)?),
        FccService::AreaList => Box::new(ipc.subscriber::<AreaListPayload>(service)?),
        FccService::AutomationState => Box::new(ipc.subscriber::<AutomationStatePayload>(service)?),
        FccService::GuidanceProgress => {
            Box::new(ipc.subscriber::<GuidanceProgressPayload>(service)?)
        }
        FccService::AutomationCommand => {
            Box::new(ipc.subscriber::<AutomationCommandPayload>(service)?)
        }
        FccService::Heartbeat(_) => Box::new(ipc.subscriber::<HeartbeatPayload>(service)?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_c_numbers_name_the_services_and_roles_in_the_contracts_order() {
        assert_eq!(service(0).unwrap(), FccService::Uplink);
        assert_eq!(service(5).unwrap(), FccService::GuidanceProgress);
        assert_eq!(
            service(10).unwrap(),
            FccService::Heartbeat(Partition::Guidance)
        );
        assert_eq!(service(11).unwrap_err().status, Status::InvalidArgument);
        assert_eq!(service(-1).unwrap_err().status, Status::InvalidArgument);
        assert_eq!(role(3).unwrap(), Partition::Guidance);
        assert_eq!(role(4).unwrap_err().status, Status::InvalidArgument);
    }

    #[test]
    fn the_c_paths_are_the_contracts_paths() {
        for (service, path) in SERVICES.iter().zip(PATHS) {
            assert_eq!(path.to_str().unwrap(), service.path());
        }
    }

    #[test]
    fn a_size_other_than_the_payload_type_s_is_refused() {
        let s = FccService::GuidanceProgress;
        assert!(check_size(s, size_of::<GuidanceProgressPayload>()).is_ok());
        let e = check_size(s, size_of::<GuidanceProgressPayload>() - 1).unwrap_err();
        assert_eq!(e.status, Status::WrongSize);
        assert_eq!(check_size(s, 0).unwrap_err().status, Status::WrongSize);
    }
}
