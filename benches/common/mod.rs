//! Messages shared by the wire benchmarks.

use missionlink_interfaces::capacity::MAX_POLYGON_VERTICES;
use missionlink_interfaces::wire::{
    self, Altitude, AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, LegType,
    LocationType, Message, Speed, SpeedType, Timestamp, TurnType, U3, UaPositionWaypoint,
};

fn ts(ms: u64) -> Timestamp {
    Timestamp::from_millis(ms).expect("fits a U5")
}

/// A #13002 with all 18 fields.
pub fn waypoint() -> Message {
    Message::UaPositionWaypoint(UaPositionWaypoint {
        time_stamp: ts(848_577_600_000),
        waypoint_number: 2,
        latitude: wire::Angle::from_degrees(48.275).expect("latitude"),
        longitude: wire::Angle::from_degrees(11.645).expect("longitude"),
        location_type: Some(LocationType::Absolute),
        altitude: Altitude::from_metres(120.0).expect("altitude"),
        altitude_type: Some(AltitudeType::Wgs84),
        altitude_change_behaviour: Some(0),
        speed: Speed::from_mps(25.0).expect("speed"),
        speed_type: Some(SpeedType::IndicatedAirspeed),
        next_waypoint: 3,
        turn_type: TurnType::FlyBy,
        optional_messages: Some(1),
        leg_type: LegType::RadiusToFix,
        limit_type: Some(0),
        loop_limit: Some(0),
        arrival_time: Some(ts(848_577_700_000)),
        activity_id: U3::new(7),
    })
}

/// A fly-zone #2012 with 60 vertices (the largest frame of an upload).
pub fn polygon() -> Message {
    let mut vertices = wire::PolygonVertices::new();
    for i in 0..MAX_POLYGON_VERTICES {
        let a = (i as f64) / (MAX_POLYGON_VERTICES as f64) * std::f64::consts::TAU;
        let p = GeoPoint::from_degrees(48.27 + 0.01 * a.sin(), 11.66 + 0.015 * a.cos())
            .expect("vertex");
        vertices.push(p).expect("capacity");
    }
    Message::AreaPolygonLoopSegment(AreaPolygonLoopSegment {
        time_stamp: ts(848_577_600_000),
        area_id: 1,
        area_type: AreaType::FlyZone,
        lower_altitude: Some(Altitude::from_metres(0.0).expect("altitude")),
        upper_altitude: Some(Altitude::from_metres(300.0).expect("altitude")),
        altitude_type: Some(AltitudeType::Wgs84),
        shape: AreaShape::Polygon(vertices),
    })
}
