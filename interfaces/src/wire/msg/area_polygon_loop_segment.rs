//! #2012 Area Polygon Loop Segment (ICD §4, icd): one whole area, a fly-zone or no-fly-zone,
//! polygon or circle (ICD §5.3, §5.4).

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
