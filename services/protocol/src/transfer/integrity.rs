//! End-to-end mission integrity (ICD §11, ext): the canonical byte strings of a mission and of
//! an area list, and their CRC-32/ISO-HDLC checksums. One implementation for the GCS (what it
//! means to upload, what it downloaded) and the FCC (what it assembled).
//!
//! The canonical form is written field by field into a sink ([`Canonical`]): the checksum feeds
//! a CRC without any buffer (the FCC computes it without allocating), and a test can collect the
//! bytes to compare them with the ICD text. Big-endian as on the wire; a field marked [opt] in
//! ICD §11 is one presence byte (0x01 then its value, 0x00 then as many 0x00 as its width).

use missionlink_interfaces::wire::{
    Altitude, AreaPolygonLoopSegment, AreaShape, AreaType, Checksum, GeoPoint, LegType,
    SpecificData,
};

use super::areas::AreaList;
use super::mission::Mission;

/// Where canonical bytes go.
pub trait Canonical {
    /// Takes the next bytes of the canonical form.
    fn put(&mut self, bytes: &[u8]);
}

impl Canonical for crc32fast::Hasher {
    fn put(&mut self, bytes: &[u8]) {
        self.update(bytes);
    }
}

impl Canonical for Vec<u8> {
    fn put(&mut self, bytes: &[u8]) {
        self.extend_from_slice(bytes);
    }
}

/// ALT3: the 24-bit two's complement of the raw altitude, big-endian.
fn alt3(a: Altitude) -> [u8; 3] {
    let [_, b1, b2, b3] = a.raw().to_be_bytes();
    [b1, b2, b3]
}

/// An [opt] field: presence byte, then the value or as many zeros.
fn optional<const N: usize>(out: &mut impl Canonical, value: Option<[u8; N]>) {
    match value {
        Some(v) => {
            out.put(&[1]);
            out.put(&v);
        }
        None => {
            out.put(&[0]);
            out.put(&[0; N]);
        }
    }
}

/// The canonical form of a mission (ICD §11): take-off height [opt], initial waypoint, route
/// flags (and the planning wind where flags bit 1 says so), waypoint count, then each waypoint in flight-plan order with its radius-to-fix centre
/// (or nine zero bytes).
pub fn write_mission(mission: &Mission, out: &mut impl Canonical) {
    let take_off = match mission.take_off.data {
        SpecificData::TakeOffHeight { height } => Some(alt3(height)),
        SpecificData::RfCentre { .. } => None,
    };
    optional(out, take_off);
    out.put(&mission.route.initial_waypoint.to_be_bytes());
    // The planning wind sizes every turn flown (ICD §7 "Turns in wind"): covered, as route
    // flags bit 1 and the SPD2 after them, so that a mission without one keeps the form (and
    // the checksum) it had before the field existed.
    let wind = mission.route.planning_wind;
    out.put(&[u8::from(mission.route.bidirectional) | (u8::from(wind.is_some()) << 1)]);
    if let Some(w) = wind {
        out.put(&w.raw().to_be_bytes());
    }
    out.put(&(mission.waypoints.len() as u16).to_be_bytes());
    for record in &mission.waypoints {
        let w = &record.waypoint;
        out.put(&w.waypoint_number.to_be_bytes());
        out.put(&w.next_waypoint.to_be_bytes());
        out.put(&w.latitude.raw().to_be_bytes());
        out.put(&w.longitude.raw().to_be_bytes());
        out.put(&alt3(w.altitude));
        optional(out, w.altitude_type.map(|t| [t as u8]));
        out.put(&w.speed.raw().to_be_bytes());
        optional(out, w.speed_type.map(|t| [t as u8]));
        out.put(&[w.turn_type as u8, w.leg_type as u8]);
        match (w.leg_type, record.rf_centre.map(|c| c.data)) {
            (
                LegType::RadiusToFix,
                Some(SpecificData::RfCentre {
                    latitude,
                    longitude,
                    turn_direction,
                    ..
                }),
            ) => {
                out.put(&latitude.raw().to_be_bytes());
                out.put(&longitude.raw().to_be_bytes());
                out.put(&[turn_direction as u8]);
            }
            _ => out.put(&[0; 9]),
        }
    }
}

/// The canonical form of one area.
fn write_area(area: &AreaPolygonLoopSegment, out: &mut impl Canonical) {
    out.put(&area.area_id.to_be_bytes());
    out.put(&[match area.area_type {
        AreaType::FlyZone => 0,
        AreaType::NoFlyZone => 1,
    }]);
    let circle: [GeoPoint; 2];
    let (shape, vertices): (u8, &[GeoPoint]) = match &area.shape {
        AreaShape::Polygon(v) => (0, v.as_slice()),
        // Two vertices: the centre, then the border point (ICD §4 #2012).
        AreaShape::Circle { centre, border } => {
            circle = [*centre, *border];
            (1, &circle)
        }
    };
    out.put(&[shape]);
    optional(out, area.lower_altitude.map(alt3));
    optional(out, area.upper_altitude.map(alt3));
    optional(out, area.altitude_type.map(|t| [t as u8]));
    out.put(&[vertices.len() as u8]);
    for p in vertices {
        out.put(&p.latitude.raw().to_be_bytes());
        out.put(&p.longitude.raw().to_be_bytes());
    }
}

/// The canonical form of an area list (ICD §11): safety offset, area count, then each area in
/// ascending Area ID, whatever order the list holds them in.
pub fn write_areas(list: &AreaList, out: &mut impl Canonical) {
    out.put(&list.safety_offset.raw().to_be_bytes());
    out.put(&[list.areas.len() as u8]);
    // Ascending Area ID without sorting a copy: the next larger ID each time (at most 11
    // areas, IDs unique in a list).
    let mut last: Option<u16> = None;
    for _ in 0..list.areas.len() {
        let next = list
            .areas
            .iter()
            .filter(|a| last.is_none_or(|l| a.area_id > l))
            .min_by_key(|a| a.area_id);
        let Some(area) = next else { break };
        write_area(area, out);
        last = Some(area.area_id);
    }
}

/// The checksum of a mission (ICD §11): CRC-32/ISO-HDLC of its canonical form.
pub fn mission_checksum(mission: &Mission) -> Checksum {
    let mut crc = crc32fast::Hasher::new();
    write_mission(mission, &mut crc);
    Checksum::new(crc.finalize())
}

/// The checksum of an area list (ICD §11): CRC-32/ISO-HDLC of its canonical form.
pub fn areas_checksum(list: &AreaList) -> Checksum {
    let mut crc = crc32fast::Hasher::new();
    write_areas(list, &mut crc);
    Checksum::new(crc.finalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testkit;
    use missionlink_interfaces::wire::{Altitude, AltitudeType, SafetyOffset};

    /// The area list's canonical form takes the areas in ascending Area ID, whatever the order
    /// they were uploaded (and are held) in.
    #[test]
    fn areas_go_in_ascending_area_id() {
        let valid = testkit::mission_2().assemble().unwrap();
        let mut reversed = valid.areas.clone();
        reversed.areas.reverse();
        assert_ne!(reversed.areas, valid.areas.areas);
        assert_eq!(areas_checksum(&reversed), areas_checksum(&valid.areas));
        let mut other = valid.areas.clone();
        other.safety_offset = SafetyOffset::from_metres(30.0).unwrap();
        assert_ne!(areas_checksum(&other), areas_checksum(&valid.areas));
    }

    /// An absent optional field is not the same as a present zero (the presence byte), and
    /// every covered field changes the checksum.
    #[test]
    fn presence_bytes_keep_absent_apart_from_zero() {
        let valid = testkit::mission_2().assemble().unwrap();
        let base = mission_checksum(&valid.mission);
        let mut absent = valid.mission.clone();
        absent.waypoints[0].waypoint.altitude_type = None;
        let mut zero = valid.mission.clone();
        zero.waypoints[0].waypoint.altitude_type = Some(AltitudeType::Pressure);
        let (a, z) = (mission_checksum(&absent), mission_checksum(&zero));
        assert!(a != z && a != base && z != base);
        let mut higher = valid.mission.clone();
        higher.waypoints[2].waypoint.altitude = Altitude::from_metres(121.0).unwrap();
        assert_ne!(mission_checksum(&higher), base);
        // Not covered: the Mission ID (ICD §11).
        let mut renamed = valid.mission.clone();
        renamed.mission_id = None;
        assert_eq!(mission_checksum(&renamed), base);
        let mut bytes = Vec::new();
        write_mission(&valid.mission, &mut bytes);
        // 4 + 2 + 1 + 2 header bytes, 32 bytes per waypoint.
        assert_eq!(bytes.len(), 9 + 32 * valid.mission.waypoints.len());
    }

    /// The check value of CRC-32/ISO-HDLC that ICD §11 quotes.
    #[test]
    fn the_crc_is_iso_hdlc() {
        let mut crc = crc32fast::Hasher::new();
        crc.put(b"123456789");
        assert_eq!(crc.finalize(), 0xCBF4_3926);
    }
}
