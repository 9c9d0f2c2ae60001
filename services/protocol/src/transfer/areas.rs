//! The area list: what an area upload stores (paper §3.1.8; ICD §5.3), its assembly with the
//! validity checks of ICD §7, and the list as a whole, which an area download sends back (paper
//! §3.1.9; ICD §5.4) and the FCC publishes to guidance with the circles kept apart from the
//! polygons (paper Figure 8).

use heapless::Vec;
use missionlink_interfaces::capacity::{MAX_AREAS, MAX_NO_FLY_ZONES, MIN_POLYGON_VERTICES};
use missionlink_interfaces::contracts::{AreaAltitudes, AreaListPayload, CircleArea};
use missionlink_interfaces::wire::{
    AreaPolygonLoopSegment, AreaShape, AreaType, Reason, SafetyOffset, Timestamp,
};

use crate::geofence::zone::{Zone, ZoneKind};

/// An assembled, valid area list: exactly one fly-zone (a polygon) and up to ten no-fly-zones
/// (polygons or circles), in the order they were uploaded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AreaList {
    /// Distance the geofence keeps from every area border (#2011 field 4).
    pub safety_offset: SafetyOffset,
    /// The #2012 of each area, time stamp zero, in upload order.
    pub areas: Vec<AreaPolygonLoopSegment, MAX_AREAS>,
}

impl AreaList {
    /// The list of the one area `area_id` with this list's safety offset (a #2011 mode 3 of
    /// one area, ICD §4), if the list holds it.
    pub fn only(&self, area_id: u16) -> Option<Self> {
        let area = self.areas.iter().find(|a| a.area_id == area_id)?;
        let mut areas = Vec::new();
        areas.push(area.clone()).ok()?;
        Some(Self {
            safety_offset: self.safety_offset,
            areas,
        })
    }

    /// The list as guidance receives it (`fcc/mission/area-list`): the fly-zone, the polygonal
    /// no-fly-zones and the circular ones apart.
    pub fn to_payload(&self, generation: u64) -> AreaListPayload {
        let mut p = AreaListPayload::EMPTY;
        p.generation = generation;
        p.safety_offset = self.safety_offset;
        let mut polygons = 0usize;
        let mut circles = 0usize;
        for area in &self.areas {
            let altitudes =
                AreaAltitudes::new(area.lower_altitude, area.upper_altitude, area.altitude_type);
            match (&area.shape, area.area_type) {
                (AreaShape::Polygon(vertices), area_type) => {
                    let slot = match area_type {
                        AreaType::FlyZone => Some(&mut p.fly_zone),
                        AreaType::NoFlyZone => {
                            polygons += 1;
                            p.no_fly_polygons.get_mut(polygons - 1)
                        }
                    };
                    if let Some(slot) = slot {
                        slot.area_id = area.area_id;
                        slot.vertex_count = vertices.len() as u8;
                        slot.altitudes = altitudes;
                        for (v, p) in slot.vertices.iter_mut().zip(vertices) {
                            *v = *p;
                        }
                    }
                }
                (AreaShape::Circle { centre, border }, _) => {
                    circles += 1;
                    if let Some(slot) = p.no_fly_circles.get_mut(circles - 1) {
                        *slot = CircleArea {
                            area_id: area.area_id,
                            altitudes,
                            centre: *centre,
                            border: *border,
                            ..CircleArea::EMPTY
                        };
                    }
                }
            }
        }
        p.no_fly_polygon_count = polygons.min(MAX_NO_FLY_ZONES) as u8;
        p.no_fly_circle_count = circles.min(MAX_NO_FLY_ZONES) as u8;
        p
    }

    /// The fly-zone.
    pub fn fly_zone(&self) -> Option<&AreaPolygonLoopSegment> {
        self.areas.iter().find(|a| a.area_type == AreaType::FlyZone)
    }
}

/// The areas an upload (or download) has stored so far. An Area ID sent again overwrites.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct AreaBuffer {
    areas: Vec<AreaPolygonLoopSegment, MAX_AREAS>,
}

impl AreaBuffer {
    /// An empty buffer.
    pub fn new() -> Self {
        Self::default()
    }

    /// Areas stored.
    pub fn len(&self) -> usize {
        self.areas.len()
    }

    /// Whether nothing is stored.
    pub fn is_empty(&self) -> bool {
        self.areas.is_empty()
    }

    /// Stores one area in ascending Area ID (ICD §5.4: the FCC keeps its area lists so, and a
    /// windowed transfer, ICD §10, delivers them in any order); an Area ID already stored is
    /// replaced in place. More than [`MAX_AREAS`] different areas are refused (`Capacity`).
    pub fn store(&mut self, area: &AreaPolygonLoopSegment) -> Result<(), Reason> {
        let mut area = area.clone();
        area.time_stamp = Timestamp::default();
        let at = self.areas.partition_point(|a| a.area_id < area.area_id);
        match self.areas.get_mut(at) {
            Some(slot) if slot.area_id == area.area_id => {
                *slot = area;
                Ok(())
            }
            _ => self.areas.insert(at, area).map_err(|_| Reason::Capacity),
        }
    }

    /// The stored areas as a list without the checks of ICD §7, for the safety gateway to name
    /// every defect of a list that [`AreaBuffer::assemble`] refuses. Never sent, never active.
    pub fn unchecked(&self, safety_offset: SafetyOffset) -> AreaList {
        AreaList {
            safety_offset,
            areas: self.areas.clone(),
        }
    }

    /// Assembles and checks the area list (ICD §5.3 step 3, §7):
    /// - `CountMismatch`: the buffer does not hold `announced` areas;
    /// - `BadGeometry`: no fly-zone or several, a fly-zone that is a circle, a polygon with
    ///   fewer than 3 vertices or that is not simple (geofence's
    ///   [`Zone::defect`](crate::geofence::zone::Zone::defect)), or a circle whose border point
    ///   is its centre (radius 0);
    /// - `Capacity`: more than ten no-fly-zones (only possible without a fly-zone, which is
    ///   reported first as `BadGeometry`).
    ///
    /// A polygon holds at most 60 vertices by its type; a circle has its two points by its type.
    pub fn assemble(&self, announced: u8, safety_offset: SafetyOffset) -> Result<AreaList, Reason> {
        if usize::from(announced) != self.areas.len() {
            return Err(Reason::CountMismatch);
        }
        let fly_zones = self
            .areas
            .iter()
            .filter(|a| a.area_type == AreaType::FlyZone)
            .count();
        if fly_zones != 1 {
            return Err(Reason::BadGeometry);
        }
        if self.areas.len() - fly_zones > MAX_NO_FLY_ZONES {
            return Err(Reason::Capacity);
        }
        for area in &self.areas {
            match (&area.shape, area.area_type) {
                // Decode checks the count of a #2012 too; a plan the GCS built from a file has
                // not been through decode.
                (AreaShape::Polygon(v), _) if v.len() < MIN_POLYGON_VERTICES => {
                    return Err(Reason::BadGeometry);
                }
                (AreaShape::Circle { .. }, AreaType::FlyZone) => return Err(Reason::BadGeometry),
                (AreaShape::Circle { centre, border }, _) if centre == border => {
                    return Err(Reason::BadGeometry);
                }
                // Simple, with geodesic edges (ICD §7 rev. 2): no two edges cross or touch
                // except neighbours at their shared vertex, no vertex repeated.
                (AreaShape::Polygon(v), _)
                    if Zone::polygon(area.area_id, ZoneKind::NoFlyZone, v)
                        .defect()
                        .is_some() =>
                {
                    return Err(Reason::BadGeometry);
                }
                _ => {}
            }
        }
        Ok(AreaList {
            safety_offset,
            areas: self.areas.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testkit::{FLY_ZONE, NFZ_POLYGON, area_buffer as buffer, circle, polygon};

    #[test]
    fn circles_are_kept_apart_from_polygons() {
        let b = buffer(&[
            circle(3, (48.268, 11.675), (48.268, 11.679)),
            polygon(1, AreaType::FlyZone, &FLY_ZONE),
            polygon(2, AreaType::NoFlyZone, &NFZ_POLYGON),
        ]);
        let list = b
            .assemble(3, SafetyOffset::from_metres(25.0).unwrap())
            .unwrap();
        // Ascending Area ID whatever the arrival order (ICD §5.4, §10): the GCS's plan is
        // assembled the same way, so a download gives back the list as validated.
        let ids: std::vec::Vec<u16> = list.areas.iter().map(|a| a.area_id).collect();
        assert_eq!(ids, [1, 2, 3]);
        let p = list.to_payload(1);
        assert_eq!(p.fly_zone.area_id, 1);
        assert_eq!(p.fly_zone.vertices().len(), 4);
        assert_eq!(p.no_fly_polygons().len(), 1);
        assert_eq!(p.no_fly_polygons()[0].area_id, 2);
        assert_eq!(p.no_fly_circles().len(), 1);
        assert_eq!(p.no_fly_circles()[0].area_id, 3);
        assert_eq!(p.area_count(), 3);
        assert_eq!(p.safety_offset.metres(), 25.0);
    }

    #[test]
    fn every_validity_check_of_icd_7() {
        let fz = polygon(1, AreaType::FlyZone, &FLY_ZONE);
        let offset = SafetyOffset::default();
        assert_eq!(
            buffer(core::slice::from_ref(&fz)).assemble(2, offset),
            Err(Reason::CountMismatch)
        );
        assert_eq!(
            buffer(&[circle(2, (48.27, 11.66), (48.27, 11.67))]).assemble(1, offset),
            Err(Reason::BadGeometry),
            "no fly-zone"
        );
        let second = polygon(2, AreaType::FlyZone, &FLY_ZONE);
        assert_eq!(
            buffer(&[fz.clone(), second]).assemble(2, offset),
            Err(Reason::BadGeometry),
            "two fly-zones"
        );
        let mut round_fz = circle(2, (48.27, 11.66), (48.27, 11.67));
        round_fz.area_type = AreaType::FlyZone;
        assert_eq!(
            buffer(&[round_fz]).assemble(1, offset),
            Err(Reason::BadGeometry)
        );
        let zero = circle(2, (48.27, 11.66), (48.27, 11.66));
        assert_eq!(
            buffer(&[fz.clone(), zero]).assemble(2, offset),
            Err(Reason::BadGeometry),
            "zero radius"
        );
        // ICD §7 rev. 2: a polygon is simple.
        let bow_tie = polygon(
            3,
            AreaType::NoFlyZone,
            &[
                (48.262, 11.640),
                (48.266, 11.646),
                (48.262, 11.646),
                (48.266, 11.640),
            ],
        );
        assert_eq!(
            buffer(&[fz.clone(), bow_tie]).assemble(2, offset),
            Err(Reason::BadGeometry),
            "edges that cross"
        );
        let touching = polygon(
            3,
            AreaType::NoFlyZone,
            &[
                (48.262, 11.640),
                (48.262, 11.646),
                (48.266, 11.646),
                (48.262, 11.646),
            ],
        );
        assert_eq!(
            buffer(&[fz.clone(), touching]).assemble(2, offset),
            Err(Reason::BadGeometry),
            "a vertex repeated"
        );
        let mut full = AreaBuffer::new();
        for id in 1..=MAX_AREAS as u16 {
            full.store(&circle(id, (48.27, 11.66), (48.27, 11.67)))
                .unwrap();
        }
        assert_eq!(
            full.store(&circle(99, (48.27, 11.66), (48.27, 11.67))),
            Err(Reason::Capacity)
        );
        // An area ID sent again replaces the area.
        assert_eq!(
            full.store(&circle(1, (48.27, 11.66), (48.27, 11.68))),
            Ok(())
        );
        assert_eq!(full.len(), MAX_AREAS);
    }
}
