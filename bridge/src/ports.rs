//! The bridge's iceoryx2 ports, one per service and direction, typed by the service's contract
//! (`interfaces::contracts`) but used through byte-level traits, so the bridge loops over
//! services without knowing their types.

use core::fmt::Debug;

use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::{ZeroCopySend, ipc};
use iceoryx2::service::static_config::message_type_details::{TypeDetail, TypeVariant};
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationCommandPayload, AutomationStatePayload, FccService, FramePayload,
    GuidanceProgressPayload, HeartbeatPayload, WaypointListPayload,
};
use missionlink_partitions::ipc::{Ipc, IpcError, Publisher, Subscriber};
use zerocopy::{Immutable, IntoBytes, KnownLayout, TryFromBytes};

use crate::header::Refusal;
use crate::raw;

/// A service's contract, as the header names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Contract {
    /// The payload's size.
    pub size: usize,
    /// The payload type as iceoryx2 describes it when a port of the service opens (type name,
    /// size, alignment): the type name is read from it, which is safe, where
    /// `ZeroCopySend::type_name` is an unsafe fn.
    detail: TypeDetail,
}

impl Contract {
    /// The contract of the payload type `T`.
    pub fn of<T: ZeroCopySend>() -> Self {
        Self {
            size: size_of::<T>(),
            detail: TypeDetail::new::<T>(TypeVariant::FixedSize),
        }
    }

    /// The iceoryx2 type name (`missionlink::FramePayload/v5`, ...), which the header carries
    /// and the receiver checks. Empty if it were not UTF-8 (it is made from a `&str`), which
    /// no header matches.
    pub fn type_name(&self) -> &str {
        core::str::from_utf8(self.detail.type_name()).unwrap_or_default()
    }
}

/// A subscriber of a service going out.
pub trait Outgoing {
    /// The contract.
    fn contract(&self) -> Contract;
    /// The listener to attach to the WaitSet.
    fn listener(&self) -> &Listener<ipc::Service>;
    /// Hands the bytes of every waiting sample to `f`, with whether one of `own` (the bridge's
    /// own publishers) sent it.
    fn take_all(&self, own: &[UniquePublisherId], f: &mut dyn FnMut(&[u8], bool));
}

/// A publisher of a service coming in.
pub trait Incoming {
    /// The contract.
    fn contract(&self) -> Contract;
    /// The publisher's ID (its samples are the bridge's own).
    fn id(&self) -> UniquePublisherId;
    /// Publishes `bytes` as the service's payload and notifies.
    fn publish(&self, bytes: &[u8]) -> Result<(), PublishError>;
    /// Connects local subscribers that joined since (they receive the history).
    fn update_connections(&self);
}

/// Why a sample from Zenoh was not published.
#[derive(Debug)]
pub enum PublishError {
    /// The bytes are not a value of the type.
    Refused(Refusal),
    /// iceoryx2 refused the send.
    Ipc(IpcError),
}

struct Out<T: Debug + ZeroCopySend + 'static> {
    subscriber: Subscriber<ipc::Service, T>,
}

impl<T: Debug + Copy + ZeroCopySend + IntoBytes + Immutable + 'static> Outgoing for Out<T> {
    fn contract(&self) -> Contract {
        Contract::of::<T>()
    }

    fn listener(&self) -> &Listener<ipc::Service> {
        self.subscriber.listener()
    }

    fn take_all(&self, own: &[UniquePublisherId], f: &mut dyn FnMut(&[u8], bool)) {
        self.subscriber.take_all_with_origin(|value, origin| {
            f(raw::bytes_of(value), own.contains(&origin));
        });
    }
}

struct In<T: Debug + ZeroCopySend + 'static> {
    publisher: Publisher<ipc::Service, T>,
}

impl<T> Incoming for In<T>
where
    T: Debug + Copy + ZeroCopySend + TryFromBytes + KnownLayout + Immutable + 'static,
{
    fn contract(&self) -> Contract {
        Contract::of::<T>()
    }

    fn id(&self) -> UniquePublisherId {
        self.publisher.id()
    }

    fn publish(&self, bytes: &[u8]) -> Result<(), PublishError> {
        let value = raw::read::<T>(bytes).map_err(PublishError::Refused)?;
        self.publisher.send(&value).map_err(PublishError::Ipc)
    }

    fn update_connections(&self) {
        self.publisher.update_connections();
    }
}

/// Runs `$body` with `$T` the payload type of `$service`.
macro_rules! with_payload {
    ($service:expr, $T:ident => $body:expr) => {
        match $service {
            FccService::Uplink | FccService::Downlink => {
                type $T = FramePayload;
                $body
            }
            FccService::WaypointList => {
                type $T = WaypointListPayload;
                $body
            }
            FccService::AreaList => {
                type $T = AreaListPayload;
                $body
            }
            FccService::AutomationState => {
                type $T = AutomationStatePayload;
                $body
            }
            FccService::GuidanceProgress => {
                type $T = GuidanceProgressPayload;
                $body
            }
            FccService::AutomationCommand => {
                type $T = AutomationCommandPayload;
                $body
            }
            FccService::Heartbeat(_) => {
                type $T = HeartbeatPayload;
                $body
            }
        }
    };
}

/// A subscriber of `service` on `ipc`.
pub fn outgoing(
    ipc: &Ipc<ipc::Service>,
    service: FccService,
) -> Result<Box<dyn Outgoing>, IpcError> {
    with_payload!(service, T => Ok(Box::new(Out::<T> { subscriber: ipc.subscriber(service)? })))
}

/// A publisher of `service` on `ipc`.
pub fn incoming(
    ipc: &Ipc<ipc::Service>,
    service: FccService,
) -> Result<Box<dyn Incoming>, IpcError> {
    with_payload!(service, T => Ok(Box::new(In::<T> { publisher: ipc.publisher(service)? })))
}

/// The contract of `service`.
pub fn contract_of(service: FccService) -> Contract {
    with_payload!(service, T => Contract::of::<T>())
}
