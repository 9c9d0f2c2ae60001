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

#[cfg(test)]
mod tests {
    use super::*;
    use missionlink_interfaces::contracts::{
        AreaAltitudes, CircleArea, FlightPhase, Link, Partition, PolygonArea, WaypointEntry,
    };
    use missionlink_interfaces::wire::{
        Altitude, AltitudeType, Angle, ExecuteCommand, GeoPoint, SafetyOffset, Speed,
    };

    /// A value of a payload with something other than zero in most of its fields, so that a
    /// byte lost or moved on the way shows.
    trait Sample {
        fn sample() -> Self;
    }

    fn point(latitude: f64, longitude: f64) -> GeoPoint {
        GeoPoint {
            latitude: Angle::from_degrees(latitude).unwrap(),
            longitude: Angle::from_degrees(longitude).unwrap(),
        }
    }

    impl Sample for FramePayload {
        fn sample() -> Self {
            Self {
                published_ns: 2,
                sequence: 3,
                ..FramePayload::new(Link::Lte, &[0xff, 0xff, 0x00, 0x03, 1, 2, 3], 1).unwrap()
            }
        }
    }

    impl Sample for WaypointListPayload {
        fn sample() -> Self {
            let mut list = Self {
                generation: 4,
                activation: 7,
                take_off_height: Altitude::from_metres(30.0).unwrap(),
                count: 2,
                initial_waypoint: 1,
                bidirectional: true,
                planning_wind: Speed::from_raw(10),
                ..Self::EMPTY
            };
            for (n, w) in (1..).zip(list.waypoints.iter_mut().take(2)) {
                *w = WaypointEntry {
                    number: n,
                    next: if n == 1 { 2 } else { 0 },
                    position: point(47.0 + f64::from(n) * 1e-3, 11.0),
                    altitude: Altitude::from_metres(100.0).unwrap(),
                    speed: Speed::from_raw(40),
                    ..WaypointEntry::EMPTY
                };
                w.set_altitude_type(Some(AltitudeType::Wgs84));
            }
            list
        }
    }

    impl Sample for AreaListPayload {
        fn sample() -> Self {
            let altitudes = AreaAltitudes::new(
                Some(Altitude::from_metres(10.0).unwrap()),
                None,
                Some(AltitudeType::Agl),
            );
            let mut fly_zone = PolygonArea {
                area_id: 1,
                vertex_count: 3,
                altitudes,
                ..PolygonArea::EMPTY
            };
            fly_zone.vertices[..3].copy_from_slice(&[
                point(47.0, 11.0),
                point(47.1, 11.0),
                point(47.0, 11.1),
            ]);
            let mut list = Self {
                generation: 3,
                activation: 7,
                safety_offset: SafetyOffset::from_raw(150),
                no_fly_circle_count: 1,
                fly_zone,
                ..Self::EMPTY
            };
            list.no_fly_circles[0] = CircleArea {
                area_id: 2,
                centre: point(47.05, 11.05),
                border: point(47.051, 11.05),
                ..CircleArea::EMPTY
            };
            list
        }
    }

    impl Sample for AutomationStatePayload {
        fn sample() -> Self {
            Self {
                sequence: 5,
                changed_ns: 6,
                flown_waypoint_list: 4,
                flight_phase: FlightPhase::Cruise as u8,
                trajectory_generation_active: true,
                land_at: 9,
                guidance_alive: true,
                ..Self::ON_GROUND
            }
        }
    }

    impl Sample for GuidanceProgressPayload {
        fn sample() -> Self {
            // Heading known, bank and the rest not (NaN): NaN's bytes cross as they are.
            Self {
                sequence: 8,
                time_ns: 9,
                waypoint_list: 4,
                latitude_deg: 47.0005,
                longitude_deg: 11.0,
                altitude_m: 100.0,
                ground_speed_mps: 20.0,
                from: 1,
                to: 2,
                inside_fly_zone: true,
                trajectory_generation_active: true,
                on_ground: false,
                heading_deg: 12.5,
                ..Self::IDLE
            }
        }
    }

    impl Sample for AutomationCommandPayload {
        fn sample() -> Self {
            Self {
                sequence: 1,
                accepted_ns: 2,
                command: ExecuteCommand::ReturnToHome as u8,
                reserved: [0; 7],
            }
        }
    }

    impl Sample for HeartbeatPayload {
        fn sample() -> Self {
            Self {
                sequence: 11,
                time_ns: 12,
                period_ns: 100_000_000,
                pid: 4242,
                reserved: [0; 4],
            }
        }
    }

    /// The bytes the outgoing side sends of `T`'s sample (`raw::bytes_of`).
    fn sample_bytes<T: Sample + IntoBytes + Immutable>() -> Vec<u8> {
        raw::bytes_of(&T::sample()).to_vec()
    }

    #[test]
    fn every_payload_crosses_the_raw_encoding_and_the_ports_unchanged() {
        // What a bridge does with a sample of each service (docs/design.md "Across hosts"): the
        // incoming side reads the bytes from Zenoh as the payload (`raw::read`) and publishes it
        // on iceoryx2; the outgoing side of the other host takes it and sends its bytes
        // (`raw::bytes_of`). Here both sides are on one host: the bytes must come out as they
        // went in, every one of them, for the payload of every service.
        missionlink_partitions::ipc::quiet_iceoryx2_log();
        let prefix = format!("bridge-raw-test-{}", std::process::id());
        let ipc = Ipc::<ipc::Service>::open(
            "bridge-raw-test",
            &missionlink_partitions::config::Ipc::with_prefix(&prefix),
        )
        .unwrap();
        for service in FccService::ALL {
            let sent = with_payload!(service, T => sample_bytes::<T>());
            assert_eq!(sent.len(), contract_of(service).size, "{service}");
            let out = outgoing(&ipc, service).unwrap();
            let inbound = incoming(&ipc, service).unwrap();
            inbound.publish(&sent).unwrap();
            let mut received = Vec::new();
            out.take_all(&[], &mut |bytes, _| received.push(bytes.to_vec()));
            assert_eq!(received, [sent.as_slice()], "{service}");
            // A payload of another length is refused before iceoryx2 sees it.
            assert!(
                matches!(
                    inbound.publish(&sent[1..]),
                    Err(PublishError::Refused(Refusal::Size(n))) if n as usize == sent.len() - 1
                ),
                "{service}"
            );
            out.take_all(&[], &mut |_, _| {
                panic!("{service}: a refused sample was published")
            });
        }
        assert_eq!(
            contract_of(FccService::Heartbeat(Partition::Guidance)).type_name(),
            "missionlink::HeartbeatPayload/v5"
        );
    }
}
