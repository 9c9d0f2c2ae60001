//! #2012 Area Polygon Loop Segment (ICD §4, icd): one whole area, a fly-zone or no-fly-zone,
//! polygon or circle (ICD §5.3, §5.4).

use core::fmt;

use zerocopy::byteorder::big_endian::I32;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

use super::{GeoPoint, MessageBody, MessageType, is_waypoint_number, reader};
use crate::capacity::MAX_POLYGON_VERTICES;
use crate::wire::enums::{AltitudeType, AreaType};
use crate::wire::error::{Cause, EncodeError, MessageError};
use crate::wire::field::{Altitude, Angle, Timestamp, U3};
use crate::wire::presence::Writer;

/// The vertices of a polygon, in order, not closed.
pub type PolygonVertices = heapless::Vec<GeoPoint, MAX_POLYGON_VERTICES>;

/// The shape of an area, carried in Activity ID (bit 3: 0 polygon, 1 circle).
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
#[allow(
    clippy::large_enum_variant,
    reason = "decoding allocates nothing: the polygon lives inline"
)]
pub enum AreaShape {
    /// 3..=60 vertices in order; the last connects to the first.
    Polygon(PolygonVertices),
    /// Two vertices: the centre, then a point on the border (radius = their distance).
    Circle {
        /// First vertex.
        centre: GeoPoint,
        /// Second vertex.
        border: GeoPoint,
    },
}

impl AreaShape {
    const POLYGON: u32 = 0;
    const CIRCLE: u32 = 1;
}

/// #2012.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AreaPolygonLoopSegment {
    /// Bit 0, M.
    pub time_stamp: Timestamp,
    /// Bit 1, M: 1..=65534, unique in the list.
    pub area_id: u16,
    /// Bit 2, M.
    pub area_type: AreaType,
    /// Bit 4.
    pub lower_altitude: Option<Altitude>,
    /// Bit 5: not below the lower altitude.
    pub upper_altitude: Option<Altitude>,
    /// Bit 6.
    pub altitude_type: Option<AltitudeType>,
    /// Bits 3 (shape), 7 (Vertex Count) and 8 (Vertices).
    pub shape: AreaShape,
}

/// One vertex on the wire: latitude and longitude, BAM4 each.
#[derive(FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned)]
#[repr(C)]
struct Vertex {
    latitude: I32,
    longitude: I32,
}

const VERTICES: u8 = 8;

impl MessageBody for AreaPolygonLoopSegment {
    const TYPE: MessageType = MessageType::AreaPolygonLoopSegment;
    const FIELDS: &'static [&'static str] = &[
        "Time Stamp",
        "Area ID",
        "Area Type",
        "Activity ID",
        "Lower Altitude",
        "Upper Altitude",
        "Altitude Type",
        "Vertex Count",
        "Vertices",
    ];
    const PV_BYTES: usize = 2;

    fn decode(data: &[u8]) -> Result<Self, MessageError> {
        let mut r = reader::<Self>(data)?;
        let time_stamp = r.time_stamp()?;
        let id: u16 = r.mandatory(1)?;
        // Area IDs share the range of waypoint numbers: 1..=65534.
        let area_id = r.in_range(1, id, is_waypoint_number(id))?;
        let area_type = r.mandatory(2)?;
        let shape = r.mandatory::<U3>(3)?.get();
        let lower_altitude: Option<Altitude> = r.optional(4)?;
        let upper_altitude: Option<Altitude> = r.optional(5)?;
        if let (Some(lo), Some(up)) = (lower_altitude, upper_altitude) {
            if lo > up {
                return Err(r.error(5, Cause::Inconsistent));
            }
        }
        let altitude_type = r.optional(6)?;
        let count = usize::from(r.mandatory::<u8>(7)?);
        match shape {
            AreaShape::POLYGON if count < 3 => {
                return Err(r.error(7, Cause::BadGeometry { count }));
            }
            AreaShape::POLYGON if count > MAX_POLYGON_VERTICES => {
                return Err(r.error(
                    7,
                    Cause::Capacity {
                        count,
                        max: MAX_POLYGON_VERTICES,
                    },
                ));
            }
            AreaShape::CIRCLE if count != 2 => {
                return Err(r.error(7, Cause::BadGeometry { count }));
            }
            AreaShape::POLYGON | AreaShape::CIRCLE => {}
            other => return Err(r.error(3, Cause::Unsupported { value: other })),
        }
        let bytes = r.bytes(VERTICES, count * size_of::<Vertex>())?;
        let bytes = r.require(VERTICES, bytes)?;
        let raw =
            <[Vertex]>::ref_from_bytes(bytes).map_err(|_| r.error(VERTICES, Cause::Truncated))?;
        let mut points = PolygonVertices::new();
        for v in raw {
            let latitude = Angle::from_raw(v.latitude.get());
            if !latitude.is_latitude() {
                return Err(r.error(
                    VERTICES,
                    Cause::OutOfRange {
                        value: i64::from(latitude.raw()),
                    },
                ));
            }
            let point = GeoPoint {
                latitude,
                longitude: Angle::from_raw(v.longitude.get()),
            };
            // `count` was checked against the capacity above.
            points.push(point).map_err(|_| {
                r.error(
                    VERTICES,
                    Cause::Capacity {
                        count,
                        max: MAX_POLYGON_VERTICES,
                    },
                )
            })?;
        }
        r.finish()?;
        let shape = match (shape, points.as_slice()) {
            (AreaShape::CIRCLE, [centre, border]) => AreaShape::Circle {
                centre: *centre,
                border: *border,
            },
            _ => AreaShape::Polygon(points),
        };
        Ok(Self {
            time_stamp,
            area_id,
            area_type,
            lower_altitude,
            upper_altitude,
            altitude_type,
            shape,
        })
    }

    fn encode(&self, out: &mut [u8]) -> Result<usize, EncodeError> {
        let mut w = Writer::new(out, Self::PV_BYTES)?;
        w.field(0, &self.time_stamp)?;
        w.field(1, &self.area_id)?;
        w.field(2, &self.area_type)?;
        let circle;
        let (shape, points): (u32, &[GeoPoint]) = match &self.shape {
            AreaShape::Polygon(v) => (AreaShape::POLYGON, v.as_slice()),
            AreaShape::Circle { centre, border } => {
                circle = [*centre, *border];
                (AreaShape::CIRCLE, &circle)
            }
        };
        w.field(3, &U3::new(shape).unwrap_or_default())?;
        w.optional(4, self.lower_altitude.as_ref())?;
        w.optional(5, self.upper_altitude.as_ref())?;
        w.optional(6, self.altitude_type.as_ref())?;
        // At most MAX_POLYGON_VERTICES (60) points, so the count fits a U1.
        w.field(7, &(points.len() as u8))?;
        let bytes = w.bytes(VERTICES, points.len() * size_of::<Vertex>())?;
        let raw = <[Vertex]>::mut_from_bytes(bytes).map_err(|_| EncodeError::TooLong)?;
        for (slot, p) in raw.iter_mut().zip(points) {
            slot.latitude.set(p.latitude.raw());
            slot.longitude.set(p.longitude.raw());
        }
        Ok(w.finish())
    }

    fn time_stamp(&self) -> Timestamp {
        self.time_stamp
    }
}

/// `#2012 Area Polygon Loop Segment: area 1 fly-zone, polygon of 4 vertices, 0.0 m to 300.0 m
/// WGS-84`; a circle gives its centre and border point.
impl fmt::Display for AreaPolygonLoopSegment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: area {} {}",
            Self::TYPE,
            self.area_id,
            self.area_type.name()
        )?;
        match &self.shape {
            AreaShape::Polygon(vertices) => write!(f, ", polygon of {} vertices", vertices.len())?,
            AreaShape::Circle { centre, border } => {
                write!(f, ", circle around {centre} through {border}")?
            }
        }
        match (self.lower_altitude, self.upper_altitude) {
            (Some(lower), Some(upper)) => {
                write!(f, ", {:.1} m to {:.1} m", lower.metres(), upper.metres())?
            }
            (Some(lower), None) => write!(f, ", above {:.1} m", lower.metres())?,
            (None, Some(upper)) => write!(f, ", below {:.1} m", upper.metres())?,
            (None, None) => {}
        }
        match self.altitude_type {
            Some(t) => write!(f, " {}", t.name()),
            None => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{ChecksumWidth, Envelope};

    /// #2012 the demo fly-zone: polygon of 4 corners, every field present; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_POLYGON: [u8; 73] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x35,                   // message length: 53 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x07, 0xdc,                   // message type 2012 = 0x07DC
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x01, 0xff,                   // presence vector 0x01FF: bits 0..=8
        0xc5, 0x93, 0x2a, 0x9a, 0x64, // time stamp 2026-11-21T12:00:00.100Z = 848_577_600_100 ms since 2000-01-01 = 0xC5_932A_9A64
        0x00, 0x01,                   // area ID 1
        0x00,                         // area type 0: stay-in (fly-zone)
        0x00, 0x00, 0x00,             // activity ID 0: polygon
        0x00, 0x00, 0x00,             // lower altitude 0 m: 0 / 0.02 = 0 = 0x00_0000
        0x00, 0x3a, 0x98,             // upper altitude 300 m: 300 / 0.02 = 15_000 = 0x00_3A98
        0x03,                         // altitude type 3: WGS-84
        0x04,                         // vertex count 4
        0x22, 0x50, 0x8d, 0xff,       // vertex 1 latitude 48.255 deg: 48.255 / 180 * 2^31 = 575_704_574.6 -> 575_704_575 = 0x2250_8DFF
        0x08, 0x46, 0x16, 0x4d,       // vertex 1 longitude 11.635 deg: 11.635 / 180 * 2^31 = 138_810_956.9 -> 138_810_957 = 0x0846_164D
        0x22, 0x50, 0x8d, 0xff,       // vertex 2 latitude 48.255 deg: 48.255 / 180 * 2^31 = 575_704_574.6 -> 575_704_575 = 0x2250_8DFF
        0x08, 0x50, 0x19, 0x7c,       // vertex 2 longitude 11.69 deg: 11.69 / 180 * 2^31 = 139_467_132.473 -> 139_467_132 = 0x0850_197C
        0x22, 0x56, 0x04, 0x19,       // vertex 3 latitude 48.285 deg: 48.285 / 180 * 2^31 = 576_062_488.6 -> 576_062_489 = 0x2256_0419
        0x08, 0x50, 0x19, 0x7c,       // vertex 3 longitude 11.69 deg: 11.69 / 180 * 2^31 = 139_467_132.473 -> 139_467_132 = 0x0850_197C
        0x22, 0x56, 0x04, 0x19,       // vertex 4 latitude 48.285 deg: 48.285 / 180 * 2^31 = 576_062_488.6 -> 576_062_489 = 0x2256_0419
        0x08, 0x46, 0x16, 0x4d,       // vertex 4 longitude 11.635 deg: 11.635 / 180 * 2^31 = 138_810_956.9 -> 138_810_957 = 0x0846_164D
        // checksum
        0x00, 0x00, 0x11, 0x11,       // checksum: byte sum of header and data = 4369 = 0x0000_1111
    ];

    /// #2012 the demo circular no-fly-zone, altitudes absent; GCS to FCC, ack.
    #[rustfmt::skip]
    static FRAME_CIRCLE: [u8; 50] = [
        // wrapper
        0xff, 0xff,                   // reserved (sequence): 0xFFFF
        0x00, 0x1e,                   // message length: 30 bytes of message data
        0x0a, 0x00, 0x00, 0x01,       // source ID: GCS 0x0A00_0001
        0x0b, 0x00, 0x00, 0x01,       // destination ID: FCC 0x0B00_0001
        0x07, 0xdc,                   // message type 2012 = 0x07DC
        0xa8, 0x80,                   // properties: ack 1 << 15 | IDD 40 << 8 | checksum 0b10 << 6 = 0xA880
        // message data
        0x01, 0x8f,                   // presence vector 0x018F: bits 0..=3, 7, 8
        0xc5, 0x93, 0x2a, 0x9a, 0xc8, // time stamp 2026-11-21T12:00:00.200Z = 848_577_600_200 ms since 2000-01-01 = 0xC5_932A_9AC8
        0x00, 0x02,                   // area ID 2
        0x01,                         // area type 1: keep-out (no-fly-zone)
        0x00, 0x00, 0x01,             // activity ID 1: circle
        0x02,                         // vertex count 2
        0x22, 0x52, 0xeb, 0xd7,       // centre latitude 48.268 deg: 48.268 / 180 * 2^31 = 575_859_670.7 -> 575_859_671 = 0x2252_EBD7
        0x08, 0x4d, 0x5e, 0x70,       // centre longitude 11.675 deg: 11.675 / 180 * 2^31 = 139_288_175.502 -> 139_288_176 = 0x084D_5E70
        0x22, 0x52, 0xeb, 0xd7,       // border latitude 48.268 deg: 48.268 / 180 * 2^31 = 575_859_670.7 -> 575_859_671 = 0x2252_EBD7
        0x08, 0x4e, 0x18, 0xd9,       // border longitude 11.679 deg: 11.679 / 180 * 2^31 = 139_335_897.4 -> 139_335_897 = 0x084E_18D9
        // checksum
        0x00, 0x00, 0x0e, 0x8e,       // checksum: byte sum of header and data = 3726 = 0x0000_0E8E
    ];

    /// GCS to FCC, acknowledgement requested.
    const ENVELOPE: Envelope = Envelope {
        source_id: 0x0A00_0001,
        destination_id: 0x0B00_0001,
        ack_requested: true,
        idd_version: 40,
        checksum: ChecksumWidth::Four,
    };

    fn point(latitude: i32, longitude: i32) -> GeoPoint {
        GeoPoint {
            latitude: Angle::from_raw(latitude),
            longitude: Angle::from_raw(longitude),
        }
    }

    fn repr_polygon() -> AreaPolygonLoopSegment {
        let corners = [
            point(575_704_575, 138_810_957),
            point(575_704_575, 139_467_132),
            point(576_062_489, 139_467_132),
            point(576_062_489, 138_810_957),
        ];
        AreaPolygonLoopSegment {
            time_stamp: Timestamp::from_millis(848_577_600_100).unwrap(),
            area_id: 1,
            area_type: AreaType::FlyZone,
            lower_altitude: Some(Altitude::from_metres(0.0).unwrap()),
            upper_altitude: Some(Altitude::from_metres(300.0).unwrap()),
            altitude_type: Some(AltitudeType::Wgs84),
            shape: AreaShape::Polygon(PolygonVertices::from_slice(&corners).unwrap()),
        }
    }

    fn repr_circle() -> AreaPolygonLoopSegment {
        AreaPolygonLoopSegment {
            time_stamp: Timestamp::from_millis(848_577_600_200).unwrap(),
            area_id: 2,
            area_type: AreaType::NoFlyZone,
            lower_altitude: None,
            upper_altitude: None,
            altitude_type: None,
            shape: AreaShape::Circle {
                centre: point(575_859_671, 139_288_176),
                border: point(575_859_671, 139_335_897),
            },
        }
    }

    fn assert_degrees(p: GeoPoint, latitude: f64, longitude: f64) {
        assert!((p.latitude.degrees() - latitude).abs() < Angle::LSB_DEGREES);
        assert!((p.longitude.degrees() - longitude).abs() < Angle::LSB_DEGREES);
        assert_eq!(GeoPoint::from_degrees(latitude, longitude).unwrap(), p);
    }

    #[test]
    fn golden_polygon() {
        super::super::assert_golden(&FRAME_POLYGON, ENVELOPE, repr_polygon().into());
    }

    #[test]
    fn physical_polygon() {
        let m = repr_polygon();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:00:00.100Z");
        assert_eq!(m.lower_altitude.unwrap().raw(), 0);
        assert_eq!(m.upper_altitude.unwrap().raw(), 15_000);
        assert_eq!(m.upper_altitude.unwrap().metres(), 300.0);
        let AreaShape::Polygon(vertices) = m.shape else {
            panic!("not a polygon");
        };
        let corners = [
            (48.255, 11.635),
            (48.255, 11.69),
            (48.285, 11.69),
            (48.285, 11.635),
        ];
        assert_eq!(vertices.len(), corners.len());
        for (p, (latitude, longitude)) in vertices.iter().zip(corners) {
            assert_degrees(*p, latitude, longitude);
        }
    }

    #[test]
    fn golden_circle() {
        super::super::assert_golden(&FRAME_CIRCLE, ENVELOPE, repr_circle().into());
    }

    #[test]
    fn physical_circle() {
        let m = repr_circle();
        assert_eq!(m.time_stamp.to_string(), "2026-11-21T12:00:00.200Z");
        let AreaShape::Circle { centre, border } = m.shape else {
            panic!("not a circle");
        };
        assert_degrees(centre, 48.268, 11.675);
        assert_degrees(border, 48.268, 11.679);
    }

    #[test]
    fn display_polygon() {
        super::super::assert_display(
            repr_polygon(),
            "#2012 Area Polygon Loop Segment: area 1 fly-zone, polygon of 4 vertices, 0.0 m to 300.0 m WGS-84",
        );
    }

    #[test]
    fn display_circle() {
        super::super::assert_display(
            repr_circle(),
            "#2012 Area Polygon Loop Segment: area 2 no-fly-zone, circle around 48.268000 N 11.675000 E through 48.268000 N 11.679000 E",
        );
    }
}
