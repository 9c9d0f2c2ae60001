//! MAVLink mission and fence items as a QGroundControl `.plan`, and back: the bridge has no
//! converter of its own. Uploaded items are written as the `.plan` document QGC would save for
//! them (each mission item a `SimpleItem` with its command, frame and seven params; the fence
//! items gathered into `geoFence` polygons and circles) and imported by
//! [`crate::qgc::import_plan`], so a MAVLink client's mission is taken, or refused, by exactly the
//! rules and command tables of a `.plan` import ([`crate::qgc`]). A refusal names the `.plan`
//! element; [`Refusal`] maps it back to the MAVLink list and item index the client sent.
//!
//! The other way, the FCC's lists are exported by [`crate::qgc::export_plan`] and its items read
//! back as MAVLink items.

use core::fmt;

use missionlink_ground::ground_station::ValidatedPlan;
use serde_json::{Value, json};

use crate::import::{Dropped, MissionFileError};
use crate::qgc::{ExportOptions, Home, ImportOptions, QgcImport, export_plan, import_plan};

/// MAV_CMD_NAV_FENCE_POLYGON_VERTEX_INCLUSION: param 1 the polygon's vertex count.
pub const FENCE_POLYGON_INCLUSION: u16 = 5001;
/// MAV_CMD_NAV_FENCE_POLYGON_VERTEX_EXCLUSION.
pub const FENCE_POLYGON_EXCLUSION: u16 = 5002;
/// MAV_CMD_NAV_FENCE_CIRCLE_INCLUSION: param 1 the radius, metres.
pub const FENCE_CIRCLE_INCLUSION: u16 = 5003;
/// MAV_CMD_NAV_FENCE_CIRCLE_EXCLUSION.
pub const FENCE_CIRCLE_EXCLUSION: u16 = 5004;
/// MAV_FRAME_GLOBAL, the frame of fence items.
const FRAME_GLOBAL: u8 = 0;

/// One MAVLink mission item (MISSION_ITEM_INT) as the mission protocol carries it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Item {
    /// MAV_CMD.
    pub command: u16,
    /// MAV_FRAME.
    pub frame: u8,
    /// Params 1 to 4.
    pub params: [f32; 4],
    /// Param 5: latitude, degrees * 10^7.
    pub x: i32,
    /// Param 6: longitude, degrees * 10^7.
    pub y: i32,
    /// Param 7: altitude, metres.
    pub z: f32,
}

/// The two lists of the mission protocol the bridge holds (MAV_MISSION_TYPE 0 and 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum List {
    /// MAV_MISSION_TYPE_MISSION.
    Mission,
    /// MAV_MISSION_TYPE_FENCE.
    Fence,
}

impl fmt::Display for List {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Mission => "mission",
            Self::Fence => "fence",
        })
    }
}

/// Why uploaded items do not make a plan: the `.plan` import's error, with the MAVLink item it
/// is about where it is about one.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// The list and index of the first item the import names, if it names one.
    pub item: Option<(List, u16)>,
    /// What the import said, in the words of the MAVLink items (`mission item 3: ...`).
    pub reason: String,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.reason)
    }
}

/// How the items map onto the `.plan` elements: mission items 1:1 onto `mission.items`; each
/// fence polygon and circle onto the index of its first item.
#[derive(Debug, Clone, Default)]
struct Layout {
    /// MAVLink mission items before `mission.items[0]`: 1 when the first item is a QGC WPL
    /// home row ([`home_row`]).
    mission_offset: u16,
    polygons: Vec<u16>,
    circles: Vec<u16>,
}

impl Layout {
    /// The MAVLink item a `.plan` path (`mission.items[3].params[4]`, `geoFence.polygons[1]`)
    /// is about.
    fn item(&self, path: &str) -> Option<(List, u16)> {
        let index = |prefix: &str| -> Option<usize> {
            let rest = path.strip_prefix(prefix)?;
            rest.split(']').next()?.parse().ok()
        };
        if let Some(i) = index("mission.items[") {
            return u16::try_from(i)
                .ok()
                .map(|i| (List::Mission, i.saturating_add(self.mission_offset)));
        }
        if let Some(i) = index("geoFence.polygons[") {
            return self.polygons.get(i).map(|&s| (List::Fence, s));
        }
        if let Some(i) = index("geoFence.circles[") {
            return self.circles.get(i).map(|&s| (List::Fence, s));
        }
        None
    }

    /// `path: reason` with the path in MAVLink's words where it names an item.
    fn words(&self, path: &str, reason: &str) -> String {
        match self.item(path) {
            Some((list, i)) => format!("{list} item {i}: {reason}"),
            None => format!("{path}: {reason}"),
        }
    }

    fn refusal(&self, e: &MissionFileError) -> Refusal {
        match e {
            MissionFileError::Unsupported { elements } => {
                let first = elements.first();
                Refusal {
                    item: first.and_then(|d| self.item(&d.path)),
                    reason: elements
                        .iter()
                        .map(|d: &Dropped| self.words(&d.path, &d.reason))
                        .collect::<Vec<_>>()
                        .join("; "),
                }
            }
            MissionFileError::Field { path, reason } => Refusal {
                item: self.item(path),
                reason: self.words(path, reason),
            },
            other => Refusal {
                item: None,
                reason: other.to_string(),
            },
        }
    }
}

/// Degrees from MAVLink's degrees * 10^7.
fn degrees(e7: i32) -> f64 {
    f64::from(e7) / 1e7
}

/// MAVLink's degrees * 10^7 from degrees (clamped to the i32 range: never reached by a value
/// the ICD carries).
fn e7(degrees: f64) -> i32 {
    (degrees * 1e7)
        .round()
        .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
}

/// A number as JSON: `null` for NaN (MAVLink's "unused" param, QGC's `null`).
fn number(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

/// What the `.plan` needs that MAVLink items do not say.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanContext {
    /// The planning speed of waypoints before any DO_CHANGE_SPEED (QGC's `cruiseSpeed`), m/s.
    pub cruise_speed_mps: f64,
    /// The vehicle's home: the reference of AMSL take-off altitudes and the take-off position
    /// when the take-off item has none (the aircraft's last position, from the downlink).
    pub home: Option<Home>,
    /// The import's choices (safety offset, bidirectional route); unsupported items refuse.
    pub import: ImportOptions,
}

/// MAV_CMD_NAV_WAYPOINT.
const NAV_WAYPOINT: u16 = 16;
/// MAV_CMD_NAV_TAKEOFF and MAV_CMD_NAV_VTOL_TAKEOFF.
const NAV_TAKEOFF: [u16; 2] = [22, 84];

/// The home row of a QGC WPL 110 file, as MAVProxy and Mission Planner write and send it: item
/// 0 a waypoint (ArduPilot's home), the take-off after it. A waypoint before the take-off
/// cannot be flown (the ICD's take-off comes first, and the `.plan` import refuses one), so
/// the one case is read as what the file means: the planned home (the take-off position when
/// the take-off has none, and the reference of AMSL take-off altitudes), not a waypoint. Its
/// altitude is above mean sea level in a global frame (0, 5); in any other frame it is the
/// home's own, 0 above itself, which says nothing of sea level: the vehicle's home altitude
/// stands.
fn home_row(mission: &[Item], context: &PlanContext) -> Option<Home> {
    let (first, second) = (mission.first()?, mission.get(1)?);
    if first.command != NAV_WAYPOINT || !NAV_TAKEOFF.contains(&second.command) {
        return None;
    }
    let altitude_m = match first.frame {
        0 | 5 => f64::from(first.z),
        _ => context.home.map_or(0.0, |h| h.altitude_m),
    };
    Some(Home {
        latitude_deg: degrees(first.x),
        longitude_deg: degrees(first.y),
        altitude_m,
    })
}

/// The `.plan` document of `mission` and `fence` items, and where its elements came from.
fn plan_document(mission: &[Item], fence: &[Item], context: &PlanContext) -> (String, Layout) {
    let home_row = home_row(mission, context);
    let mission = if home_row.is_some() {
        mission.get(1..).unwrap_or_default()
    } else {
        mission
    };
    let items: Vec<Value> = mission
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let [p1, p2, p3, p4] = item.params.map(f64::from);
            json!({
                "type": "SimpleItem",
                "autoContinue": true,
                "doJumpId": i + 1,
                "command": item.command,
                "frame": item.frame,
                "params": [number(p1), number(p2), number(p3), number(p4),
                    degrees(item.x), degrees(item.y), number(f64::from(item.z))],
            })
        })
        .collect();
    let mut layout = Layout {
        mission_offset: u16::from(home_row.is_some()),
        ..Layout::default()
    };
    let mut polygons = Vec::new();
    let mut circles = Vec::new();
    let mut i = 0usize;
    while let Some(item) = fence.get(i) {
        let index = u16::try_from(i).unwrap_or(u16::MAX);
        match item.command {
            FENCE_POLYGON_INCLUSION | FENCE_POLYGON_EXCLUSION => {
                // Param 1: the vertex count; the vertices are this item and the ones after.
                let count = (item.params[0].max(1.0) as usize).max(1);
                let vertices: Vec<Value> = fence
                    .iter()
                    .skip(i)
                    .take(count)
                    .map(|v| json!([degrees(v.x), degrees(v.y)]))
                    .collect();
                polygons.push(json!({
                    "inclusion": item.command == FENCE_POLYGON_INCLUSION,
                    "polygon": vertices,
                    "version": 1,
                }));
                layout.polygons.push(index);
                i += count;
            }
            FENCE_CIRCLE_INCLUSION | FENCE_CIRCLE_EXCLUSION => {
                circles.push(json!({
                    "inclusion": item.command == FENCE_CIRCLE_INCLUSION,
                    "circle": {
                        "center": [degrees(item.x), degrees(item.y)],
                        "radius": f64::from(item.params[0]),
                    },
                    "version": 1,
                }));
                layout.circles.push(index);
                i += 1;
            }
            // Anything else in the fence list: an exclusion polygon of no vertex makes the
            // import refuse it with its index.
            _ => {
                polygons.push(json!({"inclusion": false, "polygon": [], "version": 1}));
                layout.polygons.push(index);
                i += 1;
            }
        }
    }
    let home = home_row.or(context.home).map_or(Value::Null, |h| {
        json!([h.latitude_deg, h.longitude_deg, h.altitude_m])
    });
    let mut mission_json = json!({
        "version": 2,
        "firmwareType": 12,
        "vehicleType": 22,
        "cruiseSpeed": context.cruise_speed_mps,
        "hoverSpeed": context.cruise_speed_mps,
        "items": items,
    });
    if let (false, Some(fields)) = (home.is_null(), mission_json.as_object_mut()) {
        fields.insert("plannedHomePosition".to_owned(), home);
    }
    let document = json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": "missionlink gcs mavlink",
        "mission": mission_json,
        "geoFence": {"version": 2, "polygons": polygons, "circles": circles},
        "rallyPoints": {"version": 2, "points": []},
    });
    (document.to_string(), layout)
}

/// The plan of uploaded `mission` and `fence` items, by the `.plan` import's rules; a refusal
/// names the item.
pub fn to_plan(
    mission: &[Item],
    fence: &[Item],
    context: &PlanContext,
) -> Result<QgcImport, Refusal> {
    let (document, layout) = plan_document(mission, fence, context);
    import_plan(&document, &context.import).map_err(|e| layout.refusal(&e))
}

/// The MAVLink items of `plan` (the FCC's lists): its `.plan` export, read back. `home` and
/// `take_off` as [`ExportOptions`] take them.
pub fn from_plan(plan: &ValidatedPlan, options: &ExportOptions) -> (Vec<Item>, Vec<Item>) {
    let (text, _notes) = export_plan(plan, options);
    let Ok(root) = serde_json::from_str::<Value>(&text) else {
        return (Vec::new(), Vec::new());
    };
    let f32_of = |v: &Value| v.as_f64().map_or(f32::NAN, |v| v as f32);
    let list = |v: &Value, pointer: &str| -> Vec<Value> {
        v.pointer(pointer)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let number_at = |v: &Value, pointer: &str| v.pointer(pointer).and_then(Value::as_f64);
    let mission = list(&root, "/mission/items")
        .iter()
        .map(|item| {
            let p = |k: usize| {
                item.pointer(&format!("/params/{k}"))
                    .unwrap_or(&Value::Null)
            };
            Item {
                command: number_at(item, "/command").unwrap_or(0.0) as u16,
                frame: number_at(item, "/frame").unwrap_or(0.0) as u8,
                params: [f32_of(p(0)), f32_of(p(1)), f32_of(p(2)), f32_of(p(3))],
                x: e7(p(4).as_f64().unwrap_or(0.0)),
                y: e7(p(5).as_f64().unwrap_or(0.0)),
                z: f32_of(p(6)),
            }
        })
        .collect();
    let mut fence = Vec::new();
    let point = |v: &Value, pointer: &str| {
        (
            number_at(v, &format!("{pointer}/0")).unwrap_or(0.0),
            number_at(v, &format!("{pointer}/1")).unwrap_or(0.0),
        )
    };
    let inclusion = |v: &Value| v.pointer("/inclusion").and_then(Value::as_bool) == Some(true);
    for polygon in list(&root, "/geoFence/polygons") {
        let command = if inclusion(&polygon) {
            FENCE_POLYGON_INCLUSION
        } else {
            FENCE_POLYGON_EXCLUSION
        };
        let vertices = list(&polygon, "/polygon");
        for (i, _) in vertices.iter().enumerate() {
            let (lat, lon) = point(&polygon, &format!("/polygon/{i}"));
            fence.push(Item {
                command,
                frame: FRAME_GLOBAL,
                params: [vertices.len() as f32, 0.0, 0.0, 0.0],
                x: e7(lat),
                y: e7(lon),
                z: 0.0,
            });
        }
    }
    for circle in list(&root, "/geoFence/circles") {
        let command = if inclusion(&circle) {
            FENCE_CIRCLE_INCLUSION
        } else {
            FENCE_CIRCLE_EXCLUSION
        };
        let (lat, lon) = point(&circle, "/circle/center");
        fence.push(Item {
            command,
            frame: FRAME_GLOBAL,
            params: [
                number_at(&circle, "/circle/radius").unwrap_or(0.0) as f32,
                0.0,
                0.0,
                0.0,
            ],
            x: e7(lat),
            y: e7(lon),
            z: 0.0,
        });
    }
    (mission, fence)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAKE_OFF: u16 = 22;
    const WAYPOINT: u16 = 16;
    const LOITER_UNLIMITED: u16 = 17;
    /// MAV_FRAME_GLOBAL_RELATIVE_ALT.
    const RELATIVE: u8 = 3;

    fn item(command: u16, frame: u8, lat: f64, lon: f64, alt: f32) -> Item {
        Item {
            command,
            frame,
            params: [0.0; 4],
            x: e7(lat),
            y: e7(lon),
            z: alt,
        }
    }

    fn context() -> PlanContext {
        PlanContext {
            cruise_speed_mps: 25.0,
            home: None,
            import: ImportOptions::default(),
        }
    }

    /// Take-off at TROL, two waypoints (demo airspace, missions/README.md).
    fn mission() -> Vec<Item> {
        vec![
            item(TAKE_OFF, RELATIVE, 48.26, 11.66, 30.0),
            item(WAYPOINT, RELATIVE, 48.265, 11.655, 120.0),
            item(WAYPOINT, RELATIVE, 48.275, 11.645, 120.0),
        ]
    }

    /// The demo fly-zone as an inclusion polygon and a no-fly circle.
    fn fence() -> Vec<Item> {
        let corners = [
            (48.255, 11.635),
            (48.255, 11.69),
            (48.285, 11.69),
            (48.285, 11.635),
        ];
        let mut f: Vec<Item> = corners
            .iter()
            .map(|&(lat, lon)| Item {
                params: [4.0, 0.0, 0.0, 0.0],
                ..item(FENCE_POLYGON_INCLUSION, FRAME_GLOBAL, lat, lon, 0.0)
            })
            .collect();
        f.push(Item {
            params: [200.0, 0.0, 0.0, 0.0],
            ..item(FENCE_CIRCLE_EXCLUSION, FRAME_GLOBAL, 48.268, 11.675, 0.0)
        });
        f
    }

    #[test]
    fn items_import_as_the_plan_would() {
        let import = to_plan(&mission(), &fence(), &context()).unwrap();
        let plan = import.plan;
        let mission = plan
            .mission
            .assemble(Some(plan.mission.len() as u16), None)
            .unwrap();
        assert_eq!(mission.waypoints.len(), 2);
        assert_eq!(plan.areas.len(), 2);
        assert_eq!(
            plan.take_off_position.map(|p| p.to_string()).as_deref(),
            Some("48.260000 N 11.660000 E")
        );
    }

    #[test]
    fn an_item_the_icd_cannot_carry_is_refused_with_its_index() {
        let mut m = mission();
        m.insert(2, item(LOITER_UNLIMITED, RELATIVE, 48.27, 11.65, 120.0));
        let refusal = to_plan(&m, &fence(), &context()).unwrap_err();
        assert_eq!(refusal.item, Some((List::Mission, 2)), "{refusal}");
        assert!(refusal.reason.starts_with("mission item 2: "), "{refusal}");
    }

    /// A QGC WPL file's home row (item 0, a waypoint before the take-off, AMSL in frame 0) is
    /// the planned home, not a waypoint: an AMSL take-off is measured from it, and a refusal
    /// still names the item the client sent.
    #[test]
    fn a_home_row_is_the_planned_home() {
        let mut m = mission();
        m[0] = item(TAKE_OFF, FRAME_GLOBAL, 0.0, 0.0, 530.0);
        m.insert(0, item(WAYPOINT, FRAME_GLOBAL, 48.26, 11.66, 500.0));
        let import = to_plan(&m, &fence(), &context()).unwrap();
        let home = import.home.unwrap();
        assert_eq!(
            (home.latitude_deg, home.longitude_deg, home.altitude_m),
            (48.26, 11.66, 500.0)
        );
        let mission = import
            .plan
            .mission
            .assemble(Some(import.plan.mission.len() as u16), None)
            .unwrap();
        assert_eq!(mission.waypoints.len(), 2, "the home row is no waypoint");
        assert_eq!(mission.take_off_height().metres(), 30.0);
        assert_eq!(
            import
                .plan
                .take_off_position
                .map(|p| p.to_string())
                .as_deref(),
            Some("48.260000 N 11.660000 E")
        );
        m.insert(3, item(LOITER_UNLIMITED, RELATIVE, 48.27, 11.65, 120.0));
        let refusal = to_plan(&m, &fence(), &context()).unwrap_err();
        assert_eq!(refusal.item, Some((List::Mission, 3)), "{refusal}");
        // A waypoint first without a take-off after it is a waypoint.
        let plain = vec![mission_waypoint(), mission_waypoint()];
        assert!(home_row(&plain, &context()).is_none());
    }

    fn mission_waypoint() -> Item {
        item(WAYPOINT, RELATIVE, 48.265, 11.655, 120.0)
    }

    #[test]
    fn an_inclusion_circle_is_refused_with_its_fence_index() {
        let mut f = fence();
        f.push(Item {
            params: [500.0, 0.0, 0.0, 0.0],
            ..item(FENCE_CIRCLE_INCLUSION, FRAME_GLOBAL, 48.27, 11.66, 0.0)
        });
        let refusal = to_plan(&mission(), &f, &context()).unwrap_err();
        assert_eq!(refusal.item, Some((List::Fence, 5)), "{refusal}");
        assert!(refusal.reason.starts_with("fence item 5: "), "{refusal}");
    }

    #[test]
    fn a_fence_exports_back_to_the_same_items() {
        let import = to_plan(&mission(), &fence(), &context()).unwrap();
        let valid = missionlink_ground::ground_station::GroundStation::new(
            missionlink_ground::testkit::gcs_config(),
            missionlink_ground::ground_station::WithoutGateway,
        )
        .validate(&import.plan)
        .unwrap();
        let (items, fence_back) = from_plan(
            &valid,
            &ExportOptions {
                take_off_position: import.plan.take_off_position,
                ..ExportOptions::default()
            },
        );
        assert_eq!(fence_back.len(), fence().len());
        for (a, b) in fence_back.iter().zip(fence()) {
            assert_eq!((a.command, a.x, a.y), (b.command, b.x, b.y));
            assert!((a.params[0] - b.params[0]).abs() < 0.01, "{a:?} {b:?}");
        }
        // The route ends where the upload's last waypoint is (the export writes its land
        // there).
        let last = items.last().unwrap();
        assert_eq!((last.x, last.y), (e7(48.275), e7(11.645)), "{items:?}");
        assert_eq!(items.first().map(|i| i.command), Some(TAKE_OFF));
    }
}
