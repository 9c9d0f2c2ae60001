//! Areas as GeoJSON (RFC 7946): a `FeatureCollection` whose features are the fly-zone and the
//! no-fly-zones, so that areas drawn in any GIS tool (QGIS, geojson.io, ...) can be uploaded, and
//! areas downloaded from the FCC can be looked at in one.
//!
//! # Format
//!
//! ```json
//! {
//!   "type": "FeatureCollection",
//!   "features": [
//!     {
//!       "type": "Feature",
//!       "properties": { "zone": "fly-zone", "area_id": 1 },
//!       "geometry": {
//!         "type": "Polygon",
//!         "coordinates": [[[11.635, 48.255], [11.69, 48.255], [11.69, 48.285],
//!                          [11.635, 48.285], [11.635, 48.255]]]
//!       }
//!     },
//!     {
//!       "type": "Feature",
//!       "properties": {
//!         "zone": "no-fly-zone", "area_id": 2, "radius_m": 296.947,
//!         "lower_altitude_m": 0, "upper_altitude_m": 300, "altitude_type": "wgs84"
//!       },
//!       "geometry": { "type": "Point", "coordinates": [11.675, 48.268] }
//!     }
//!   ]
//! }
//! ```
//!
//! - Positions are GeoJSON's `[longitude, latitude]` (a third value, an altitude, is ignored).
//! - A `Polygon` is one ring, closed as GeoJSON wants it (the last position repeats the first;
//!   the repeat is dropped, a #2012 polygon is not closed; an unclosed ring is taken as it is).
//!   A hole (a ring after the first) is not supported: an area has none (draw the hole as a
//!   no-fly-zone of its own).
//! - A circle is a `Point`, its centre, with the property `radius_m`; its #2012 border point is
//!   placed due north of the centre at that geodesic distance on WGS-84, as the mission file
//!   does. On export the radius is the geodesic distance centre -> border,
//!   to the millimetre.
//! - Properties: `zone`, `"fly-zone"` or `"no-fly-zone"` (required); optional `area_id`
//!   (1..=65534; features without one get the smallest IDs not given to another, in order),
//!   `lower_altitude_m`, `upper_altitude_m`, `altitude_type` (`pressure`, `baro`, `agl`,
//!   `wgs84`). Other properties (a name, a colour) are ignored.
//! - Features of another geometry (`LineString`, `MultiPolygon`, ...) and features without
//!   geometry (`null`) are not supported.
//! - The safety offset is not part of the file (it belongs to the mission: the mission file or
//!   a command-line option).
//!
//! # Exact or refused
//!
//! What the ICD cannot carry or the FCC cannot hold is not supported: a feature that is not an
//! area (above), a hole, a polygon of more than 60 vertices, a second fly-zone (the ICD has
//! one), more than ten no-fly-zones (the FCC holds eleven areas, one of them the fly-zone; the
//! no-fly-zones after the tenth in feature order). The import refuses the file for any of them
//! ([`Error::Unsupported`], every element with its path, e.g. `features[2]`, and the reason),
//! unless it is told to drop them ([`Unsupported::Drop`]): then it leaves each out (a hole: the
//! ring is kept without it) and lists it.
//!
//! Whether the areas make a valid list (a fly-zone, and it a polygon, at least three vertices)
//! is left to validation, as for the mission file. A bad file is an error with the JSON path
//! (e.g. `features[2].geometry.coordinates[0][3]`) and the reason, or with the line and column
//! of a JSON syntax error.
//!
//! # Why not the `geojson` crate
//!
//! Evaluated (geojson 1.0) and not taken: its errors name no element. A string coordinate in
//! the third feature gives `Error while deserializing GeoJSON: invalid type: string "n",
//! expected f64 at line 4 column 126` (ours: `features[2].geometry.coordinates[0][1]` and the
//! reason), and a position of one number (`[11.7]`) is accepted without a word, where ours
//! refuses it with its path. What this reader does beyond parsing (the `zone`, `area_id` and
//! altitude properties, circles as a `Point` with `radius_m`, holes, the FCC's limits, the
//! list of what is not supported) would stay ours on top of the crate's types, walking them
//! with paths of our own; the export is a few `json!` literals. Adding the crate would add a
//! dependency and not remove this module.

use missionlink_interfaces::capacity::{MAX_AREAS, MAX_NO_FLY_ZONES, MAX_POLYGON_VERTICES};
use missionlink_interfaces::wire::{
    AltitudeType, AreaPolygonLoopSegment, AreaShape, AreaType, GeoPoint, PolygonVertices, Timestamp,
};
use missionlink_protocol::transfer::areas::{AreaBuffer, AreaList};
use serde_json::{Map, Value, json};

pub use crate::import::Unsupported;
use crate::import::{exact_or_dropped, note};
use crate::json_path::{At, parse_json};
pub use crate::mission_file::{Dropped, MissionFileError as Error};
use crate::qgc::pretty;
use crate::values::{
    altitude, altitude_bounds, border_due_north, degrees, field_error, latitude, longitude, metres,
    radius_mm,
};

const ALTITUDE_TYPES: [(&str, AltitudeType); 4] = [
    ("pressure", AltitudeType::Pressure),
    ("baro", AltitudeType::Baro),
    ("agl", AltitudeType::Agl),
    ("wgs84", AltitudeType::Wgs84),
];

/// One area read from a feature, before its ID is settled.
struct Read {
    path: String,
    area_id: Option<u16>,
    area: AreaPolygonLoopSegment,
}

/// The areas of a GeoJSON `FeatureCollection`, in feature order, and what was dropped
/// ([`Unsupported::Drop`]; see [Exact or refused](self#exact-or-refused)).
pub fn import_areas(
    text: &str,
    unsupported: Unsupported,
) -> Result<(AreaBuffer, Vec<Dropped>), Error> {
    let root = parse_json(text)?;
    let at = At::root(&root);
    at.expect_string("type", "FeatureCollection")?;
    let mut dropped = Vec::new();
    let mut read: Vec<Read> = Vec::new();
    let mut fly_zone: Option<String> = None;
    let mut no_fly_zones = 0;
    for feature in at.field("features")?.items()? {
        let Some(r) = read_feature(&feature, &mut dropped)? else {
            continue;
        };
        match r.area.area_type {
            AreaType::FlyZone => {
                if let Some(first) = &fly_zone {
                    dropped.push(note(
                        &r.path,
                        format!("a second fly-zone: the ICD has one ({first})"),
                    ));
                    continue;
                }
                fly_zone = Some(r.path.clone());
            }
            AreaType::NoFlyZone => {
                if no_fly_zones == MAX_NO_FLY_ZONES {
                    dropped.push(note(
                        &r.path,
                        format!(
                            "more than {MAX_NO_FLY_ZONES} no-fly-zones: the FCC holds \
                             {MAX_AREAS} areas, one of them the fly-zone"
                        ),
                    ));
                    continue;
                }
                no_fly_zones += 1;
            }
        }
        read.push(r);
    }
    let dropped = exact_or_dropped(dropped, unsupported)?;

    // IDs: the given ones must be unique; the others take the smallest free ones.
    let mut used: Vec<(u16, String)> = Vec::new();
    for r in &read {
        if let Some(id) = r.area_id {
            if let Some((_, first)) = used.iter().find(|(u, _)| *u == id) {
                return Err(field_error(
                    format!("{}.properties.area_id", r.path),
                    format!("area ID {id} is also {first}.properties.area_id"),
                ));
            }
            used.push((id, r.path.clone()));
        }
    }
    let mut buffer = AreaBuffer::new();
    let mut next = 1u16;
    for mut r in read {
        let id = match r.area_id {
            Some(id) => id,
            None => {
                while used.iter().any(|(u, _)| *u == next) {
                    next = next.saturating_add(1);
                }
                used.push((next, r.path.clone()));
                next
            }
        };
        r.area.area_id = id;
        // At most one fly-zone and MAX_NO_FLY_ZONES no-fly-zones: the buffer holds them.
        buffer.store(&r.area).map_err(|_| {
            field_error(
                r.path.clone(),
                format!("more than {MAX_AREAS} areas (the FCC's capacity)"),
            )
        })?;
    }
    Ok((buffer, dropped))
}

/// The area of one feature; `None` (and the feature in `dropped`) when it is not one the ICD
/// carries. A hole is dropped and the feature kept.
fn read_feature(feature: &At<'_>, dropped: &mut Vec<Dropped>) -> Result<Option<Read>, Error> {
    feature.expect_string("type", "Feature")?;
    let geometry = feature.field("geometry")?;
    if geometry.value.is_null() {
        dropped.push(note(&feature.path, "no geometry: not an area"));
        return Ok(None);
    }
    let kind = geometry.field("type")?.string()?;
    if kind != "Polygon" && kind != "Point" {
        dropped.push(note(
            &feature.path,
            format!("a {kind} is not an area (only Polygon, and Point with radius_m)"),
        ));
        return Ok(None);
    }
    let properties = feature.field("properties")?;
    properties.object()?;
    let zone_at = properties.field("zone")?;
    let area_type = match zone_at.string()? {
        "fly-zone" => AreaType::FlyZone,
        "no-fly-zone" => AreaType::NoFlyZone,
        other => {
            return Err(zone_at.error(format!(
                "{other:?} is not one of \"fly-zone\", \"no-fly-zone\""
            )));
        }
    };
    let area_id = match properties.opt("area_id") {
        Some(id) => {
            let v = id.integer()?;
            Some(
                u16::try_from(v)
                    .ok()
                    .filter(|v| (1..=65534).contains(v))
                    .ok_or_else(|| id.error(format!("{v} is outside 1..=65534")))?,
            )
        }
        None => None,
    };
    let bound = |key: &str| match properties.opt(key) {
        Some(a) if !a.value.is_null() => altitude(&a.path, a.number()?).map(Some),
        _ => Ok(None),
    };
    let lower_altitude = bound("lower_altitude_m")?;
    let upper_altitude = bound("upper_altitude_m")?;
    altitude_bounds(
        &format!("{}.upper_altitude_m", properties.path),
        lower_altitude,
        upper_altitude,
    )?;
    let altitude_type = match properties.opt("altitude_type") {
        Some(t) if !t.value.is_null() => {
            let word = t.string()?;
            Some(
                ALTITUDE_TYPES
                    .iter()
                    .find(|(w, _)| *w == word)
                    .map(|(_, v)| *v)
                    .ok_or_else(|| {
                        t.error(format!(
                            "{word:?} is not one of \"pressure\", \"baro\", \"agl\", \"wgs84\""
                        ))
                    })?,
            )
        }
        _ => None,
    };
    let coordinates = geometry.field("coordinates")?;
    let shape = if kind == "Polygon" {
        let rings = coordinates.items()?;
        let Some((ring, holes)) = rings.split_first() else {
            return Err(coordinates.error("no ring: a Polygon needs one"));
        };
        for hole in holes {
            dropped.push(note(
                &hole.path,
                "a hole: an area has none (draw the hole as a no-fly-zone of its own)",
            ));
        }
        let mut vertices = Vec::new();
        for p in ring.items()? {
            vertices.push(position(&p)?);
        }
        if vertices.len() > 1 && vertices.first() == vertices.last() {
            vertices.pop();
        }
        let Ok(polygon) = PolygonVertices::from_slice(&vertices) else {
            dropped.push(note(
                &feature.path,
                format!(
                    "{} vertices, at most {MAX_POLYGON_VERTICES} fit a #2012",
                    vertices.len()
                ),
            ));
            return Ok(None);
        };
        AreaShape::Polygon(polygon)
    } else {
        let centre = position(&coordinates)?;
        let radius_at = properties.field("radius_m")?;
        let border = border_due_north(&radius_at.path, centre, radius_at.number()?)?;
        AreaShape::Circle { centre, border }
    };
    Ok(Some(Read {
        path: feature.path.clone(),
        area_id,
        area: AreaPolygonLoopSegment {
            time_stamp: Timestamp::default(),
            area_id: 0,
            area_type,
            lower_altitude,
            upper_altitude,
            altitude_type,
            shape,
        },
    }))
}

/// A GeoJSON position, `[longitude, latitude]` or `[longitude, latitude, altitude]`.
fn position(at: &At<'_>) -> Result<GeoPoint, Error> {
    let values = at.items()?;
    let (lon, lat) = match values.as_slice() {
        [lon, lat] | [lon, lat, _] => (lon, lat),
        _ => {
            return Err(at.error(format!(
                "{} values, expected [longitude, latitude]",
                values.len()
            )));
        }
    };
    Ok(GeoPoint {
        latitude: latitude(&at.path, lat.number()?)?,
        longitude: longitude(&at.path, lon.number()?)?,
    })
}

/// The area list as a GeoJSON `FeatureCollection`, in list order (see the
/// [module documentation](self)); every coordinate the shortest decimal of its wire value.
pub fn export_areas(list: &AreaList) -> String {
    let pair = |p: &GeoPoint| json!([degrees(p.longitude), degrees(p.latitude)]);
    let features: Vec<Value> = list
        .areas
        .iter()
        .map(|area| {
            let mut properties = Map::new();
            let zone = match area.area_type {
                AreaType::FlyZone => "fly-zone",
                AreaType::NoFlyZone => "no-fly-zone",
            };
            properties.insert("zone".into(), zone.into());
            properties.insert("area_id".into(), area.area_id.into());
            if let Some(a) = area.lower_altitude {
                properties.insert("lower_altitude_m".into(), metres(a).into());
            }
            if let Some(a) = area.upper_altitude {
                properties.insert("upper_altitude_m".into(), metres(a).into());
            }
            if let Some(t) = area.altitude_type {
                let word = ALTITUDE_TYPES
                    .iter()
                    .find(|(_, v)| *v == t)
                    .map_or("?", |(w, _)| w);
                properties.insert("altitude_type".into(), word.into());
            }
            let geometry = match &area.shape {
                AreaShape::Polygon(vertices) => {
                    let mut ring: Vec<Value> = vertices.iter().map(pair).collect();
                    if let Some(first) = vertices.first() {
                        ring.push(pair(first));
                    }
                    json!({ "type": "Polygon", "coordinates": [ring] })
                }
                AreaShape::Circle { centre, border } => {
                    properties.insert("radius_m".into(), radius_mm(*centre, *border).into());
                    json!({ "type": "Point", "coordinates": pair(centre) })
                }
            };
            json!({ "type": "Feature", "properties": properties, "geometry": geometry })
        })
        .collect();
    pretty(&json!({ "type": "FeatureCollection", "features": features }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mission_file::MissionFile;
    use missionlink_interfaces::wire::SafetyOffset;
    use missionlink_protocol::geofence::earth;

    use crate::mission_file::tests::MISSION_2;

    fn mission_2_areas() -> AreaList {
        let plan = MissionFile::parse(MISSION_2).unwrap().to_plan().unwrap();
        plan.areas.assemble(3, plan.safety_offset).unwrap()
    }

    fn err(text: &str) -> String {
        import_areas(text, Unsupported::Refuse)
            .unwrap_err()
            .to_string()
    }

    fn lines(dropped: &[Dropped]) -> Vec<String> {
        dropped.iter().map(ToString::to_string).collect()
    }

    /// A feature collection of `features` (JSON objects).
    fn collection(features: &[String]) -> String {
        format!(
            r#"{{"type": "FeatureCollection", "features": [{}]}}"#,
            features.join(",\n")
        )
    }

    /// A polygon feature of `zone` with the ring of a small square at (`lat`, `lon`) and
    /// `holes` more rings.
    fn square(zone: &str, lat: f64, lon: f64, holes: usize) -> String {
        let ring = |lat: f64, lon: f64, size: f64| {
            format!(
                "[[{lon}, {lat}], [{}, {lat}], [{}, {}], [{lon}, {}], [{lon}, {lat}]]",
                lon + size,
                lon + size,
                lat + size,
                lat + size
            )
        };
        let mut rings = vec![ring(lat, lon, 0.01)];
        rings.extend((0..holes).map(|_| ring(lat + 0.004, lon + 0.004, 0.002)));
        format!(
            r#"{{"type": "Feature", "properties": {{"zone": "{zone}"}},
                "geometry": {{"type": "Polygon", "coordinates": [{}]}}}}"#,
            rings.join(", ")
        )
    }

    #[test]
    fn demo_mission_2_areas_round_trip() {
        let mut list = mission_2_areas();
        // With altitude bounds too.
        list.areas[2].lower_altitude = Some(missionlink_interfaces::wire::Altitude::ZERO);
        list.areas[2].upper_altitude =
            Some(missionlink_interfaces::wire::Altitude::from_metres(300.0).unwrap());
        list.areas[2].altitude_type = Some(AltitudeType::Wgs84);
        let text = export_areas(&list);
        // GeoJSON order and closed rings.
        assert!(text.contains("\"type\": \"FeatureCollection\""), "{text}");
        assert!(text.contains(
            "\"coordinates\": [\n                    [\n                        [\n                            11.635,\n                            48.255\n"
        ), "{text}");
        let value: Value = serde_json::from_str(&text).unwrap();
        let ring = value["features"][0]["geometry"]["coordinates"][0]
            .as_array()
            .unwrap();
        assert_eq!(ring.len(), 5);
        assert_eq!(ring[0], ring[4]);
        assert_eq!(value["features"][1]["geometry"]["type"], "Point");
        let radius = value["features"][1]["properties"]["radius_m"]
            .as_f64()
            .unwrap();
        // The geodesic centre -> border on WGS-84: 0.004° of longitude at 48.268° N (the sphere
        // of the mean radius said 296.06 m; the ellipsoid's east-west radius of curvature there
        // is 0.3 % longer).
        assert!((radius - 296.947).abs() < 0.0005, "{radius}");
        assert_eq!(
            value["features"][2]["properties"]["upper_altitude_m"],
            300.0
        );

        let (buffer, dropped) = import_areas(&text, Unsupported::Refuse).unwrap();
        assert!(dropped.is_empty(), "{dropped:?}");
        let back = buffer.assemble(3, list.safety_offset).unwrap();
        crate::qgc::tests::assert_same_areas(&back.areas, &list.areas);
        for (a, b) in back.areas.iter().zip(&list.areas) {
            assert_eq!(
                (a.lower_altitude, a.upper_altitude, a.altitude_type),
                (b.lower_altitude, b.upper_altitude, b.altitude_type)
            );
        }
        // The circle's border is placed due north again, to the BAM4 step (about 9 mm): the
        // radius is kept within that.
        let again: Value = serde_json::from_str(&export_areas(&back)).unwrap();
        let r2 = again["features"][1]["properties"]["radius_m"]
            .as_f64()
            .unwrap();
        assert!((r2 - radius).abs() < 0.01, "{r2} {radius}");
    }

    #[test]
    fn ids_are_given_or_assigned_and_other_geometries_are_refused_or_dropped() {
        let text = r#"{"type": "FeatureCollection", "features": [
          {"type": "Feature", "properties": {"zone": "no-fly-zone", "radius_m": 150},
           "geometry": {"type": "Point", "coordinates": [11.66, 48.27, 500]}},
          {"type": "Feature", "properties": {"name": "route"},
           "geometry": {"type": "LineString", "coordinates": [[11.6, 48.2], [11.7, 48.3]]}},
          {"type": "Feature", "properties": {"zone": "fly-zone", "area_id": 1},
           "geometry": {"type": "Polygon",
                        "coordinates": [[[11.6, 48.2], [11.7, 48.2], [11.7, 48.3], [11.6, 48.2]]]}},
          {"type": "Feature", "properties": {}, "geometry": null}
        ]}"#;
        let expected = [
            "features[1]: a LineString is not an area (only Polygon, and Point with radius_m)",
            "features[3]: no geometry: not an area",
        ];
        match import_areas(text, Unsupported::Refuse) {
            Err(Error::Unsupported { elements }) => assert_eq!(lines(&elements), expected),
            other => panic!("{other:?}"),
        }
        let (buffer, dropped) = import_areas(text, Unsupported::Drop).unwrap();
        assert_eq!(lines(&dropped), expected);
        let list = buffer.assemble(2, SafetyOffset::default()).unwrap();
        // The list is in ascending Area ID (ICD §5.4): the fly-zone's 1 first.
        assert_eq!(list.areas[1].area_id, 2, "1 is given to the fly-zone");
        assert_eq!(list.areas[0].area_id, 1);
        let AreaShape::Polygon(v) = &list.areas[0].shape else {
            panic!()
        };
        assert_eq!(v.len(), 3, "the closing position is dropped");
        assert_eq!(v[1], GeoPoint::from_degrees(48.2, 11.7).unwrap());
        let AreaShape::Circle { centre, border } = list.areas[1].shape else {
            panic!()
        };
        assert_eq!(centre, GeoPoint::from_degrees(48.27, 11.66).unwrap());
        assert!((earth::distance_m(centre, border) - 150.0).abs() < 0.01);
    }

    #[test]
    fn bad_files_name_the_path() {
        let polygon = |coordinates: &str, properties: &str| {
            format!(
                r#"{{"type": "FeatureCollection", "features": [
                  {{"type": "Feature", "properties": {{"zone": "fly-zone"}},
                   "geometry": {{"type": "Polygon", "coordinates": [[[11.6, 48.2], [11.7, 48.2], [11.7, 48.3]]]}}}},
                  {{"type": "Feature", "properties": {{"zone": "no-fly-zone"}},
                   "geometry": {{"type": "Point", "coordinates": [11.6, 48.2]}}}},
                  {{"type": "Feature", "properties": {properties},
                   "geometry": {{"type": "Polygon", "coordinates": {coordinates}}}}}]}}"#
            )
        };
        let ring = "[[[11.6, 48.2], [11.7, 48.2], [11.7, 48.3], [11.65, 95], [11.6, 48.2]]]";
        let nfz = r#"{"zone": "no-fly-zone"}"#;
        let text = polygon(ring, nfz);
        // features[1] (the Point) has no radius: named first.
        assert_eq!(err(&text), "features[1].properties.radius_m: missing");
        let fixed = text.replace(
            r#"{"zone": "no-fly-zone"},
                   "geometry": {"type": "Point""#,
            r#"{"zone": "no-fly-zone", "radius_m": 100},
                   "geometry": {"type": "Point""#,
        );
        assert_eq!(
            err(&fixed),
            "features[2].geometry.coordinates[0][3]: latitude 95 deg is outside -90..=90"
        );
        let with_radius = |c: &str, p: &str| {
            polygon(c, p).replace(
                r#"{"zone": "no-fly-zone"},
                   "geometry": {"type": "Point""#,
                r#"{"zone": "no-fly-zone", "radius_m": 100},
                   "geometry": {"type": "Point""#,
            )
        };
        let square = "[[11.6, 48.2], [11.7, 48.2], [11.7, 48.3], [11.6, 48.2]]";
        let hole = "[[11.62, 48.22], [11.63, 48.22], [11.63, 48.23], [11.62, 48.22]]";
        let cases: &[(String, &str)] = &[
            (
                with_radius(&format!("[{square}, {hole}]"), nfz),
                "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
                 features[2].geometry.coordinates[1]: a hole: an area has none (draw the hole \
                 as a no-fly-zone of its own)",
            ),
            (
                with_radius("[[[11.6, 48.2], [11.7], [11.7, 48.3]]]", nfz),
                "features[2].geometry.coordinates[0][1]: 1 values, expected [longitude, latitude]",
            ),
            (
                with_radius(&format!("[{square}]"), r#"{"zone": "keep-out"}"#),
                "features[2].properties.zone: \"keep-out\" is not one of \"fly-zone\", \
                 \"no-fly-zone\"",
            ),
            (
                with_radius(
                    &format!("[{square}]"),
                    r#"{"zone": "no-fly-zone", "area_id": 0}"#,
                ),
                "features[2].properties.area_id: 0 is outside 1..=65534",
            ),
            (
                with_radius(
                    &format!("[{square}]"),
                    r#"{"zone": "no-fly-zone", "lower_altitude_m": 300, "upper_altitude_m": 0}"#,
                ),
                "features[2].properties.upper_altitude_m: 0 m is below lower_altitude_m (300 m)",
            ),
            (
                with_radius(
                    &format!("[{square}]"),
                    r#"{"zone": "no-fly-zone", "altitude_type": "msl"}"#,
                ),
                "features[2].properties.altitude_type: \"msl\" is not one of \"pressure\", \
                 \"baro\", \"agl\", \"wgs84\"",
            ),
            (
                with_radius("[]", nfz),
                "features[2].geometry.coordinates: no ring: a Polygon needs one",
            ),
            (
                with_radius(
                    &format!("[{square}]"),
                    r#"{"zone": "no-fly-zone", "area_id": 3}"#,
                )
                .replace(
                    r#"{"zone": "fly-zone"}"#,
                    r#"{"zone": "fly-zone", "area_id": 3}"#,
                ),
                "features[2].properties.area_id: area ID 3 is also features[0].properties.area_id",
            ),
            (
                r#"{"type": "Feature"}"#.to_owned(),
                "type: \"Feature\": expected \"FeatureCollection\"",
            ),
        ];
        for (text, expected) in cases {
            assert_eq!(&err(text), expected);
        }
        // A negative radius.
        let negative = with_radius(&format!("[{square}]"), nfz).replace("100}", "-5}");
        assert_eq!(
            err(&negative),
            "features[1].properties.radius_m: -5 m: the radius must be above 0"
        );
        // Syntax: line and column.
        match import_areas(
            "{\"type\": \"FeatureCollection\",\n \"features\": [}\n",
            Unsupported::Refuse,
        ) {
            Err(Error::Syntax { line, column, .. }) => assert_eq!((line, column), (2, 15)),
            other => panic!("{other:?}"),
        }
        // More than 60 vertices.
        let many: Vec<String> = (0..62)
            .map(|k| format!("[{}, 48.2]", 11.6 + f64::from(k) * 1e-3))
            .collect();
        let long = with_radius(&format!("[[{}]]", many.join(", ")), nfz);
        assert_eq!(
            err(&long),
            "not imported: 1 element the ICD cannot carry or the FCC cannot hold; \
             features[2]: 62 vertices, at most 60 fit a #2012"
        );
        let (areas, dropped) = import_areas(&long, Unsupported::Drop).unwrap();
        assert_eq!(
            lines(&dropped),
            ["features[2]: 62 vertices, at most 60 fit a #2012"]
        );
        assert_eq!(areas.len(), 2);
    }

    #[test]
    fn what_the_fcc_cannot_hold_is_refused_or_dropped() {
        // A second fly-zone, a hole, and eleven no-fly-zones.
        let mut features = vec![
            square("fly-zone", 48.0, 11.0, 0),
            square("fly-zone", 48.1, 11.0, 0),
        ];
        features.extend((0..11).map(|k| {
            square(
                "no-fly-zone",
                48.0,
                11.02 + 0.02 * f64::from(k),
                usize::from(k == 0),
            )
        }));
        let text = collection(&features);
        let expected = [
            "features[1]: a second fly-zone: the ICD has one (features[0])",
            "features[2].geometry.coordinates[1]: a hole: an area has none (draw the hole as a \
             no-fly-zone of its own)",
            "features[12]: more than 10 no-fly-zones: the FCC holds 11 areas, one of them the \
             fly-zone",
        ];
        match import_areas(&text, Unsupported::Refuse) {
            Err(Error::Unsupported { elements }) => assert_eq!(lines(&elements), expected),
            other => panic!("{other:?}"),
        }
        let (buffer, dropped) = import_areas(&text, Unsupported::Drop).unwrap();
        assert_eq!(lines(&dropped), expected);
        let list = buffer.assemble(11, SafetyOffset::default()).unwrap();
        let ids: Vec<u16> = list.areas.iter().map(|a| a.area_id).collect();
        assert_eq!(ids, (1..=11).collect::<Vec<u16>>());
        // The polygon whose hole was dropped keeps its ring.
        let AreaShape::Polygon(ring) = &list.areas[1].shape else {
            panic!()
        };
        assert_eq!(ring.len(), 4);
        assert_eq!(ring[0], GeoPoint::from_degrees(48.0, 11.02).unwrap());
    }
}
