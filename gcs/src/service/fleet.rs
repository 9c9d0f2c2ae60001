//! The fleet file of the ground service (`gcs serve --fleet FILE`): the control station's
//! CUCS ID and, per vehicle, a name, its Vehicle ID, its two links, its link keys and its MAVLink
//! system ID. Each vehicle becomes the [`LinkConfig`] its ground station talks to it with, the
//! same configuration a `gcs` command alone reads; a fleet of one is made from today's link flags
//! and file ([`Fleet::of_one`]).
//!
//! ```toml
//! cucs_id = 0x0A000001                  # this control station (ICD §1)
//!
//! [timing]                              # optional, as in the link configuration
//! ack_timeout_ms = 500
//!
//! [fleet]                               # optional: the separation checked before upload
//! separation_m = 500.0                  # horizontally, metres (0: no check)
//! vertical_separation_m = 150.0         # unless the altitudes differ this much
//!
//! [[vehicle]]
//! name = "alpha"                        # what `gcs ... --vehicle` names
//! vehicle_id = 0x0B000001
//! mavlink_system_id = 1                 # 1..=255; default: its place in the file
//! direct = { ground = "0.0.0.0:4587", fcc = "10.0.0.2:4586" }
//! lte = { ground = "0.0.0.0:4589", fcc = "10.0.1.2:4588" }
//! key_files = ["/etc/missionlink/alpha.key"]
//! # send_key_id = 1                     # needed with several key files
//! # signing = "require"                 # require (the default) | accept | off
//! ```
//!
//! A file that cannot be used names the line and column: TOML and value errors as the link
//! configuration does, and a second vehicle with a name, Vehicle ID, MAVLink system ID, ground
//! port or FCC address the file gave already (two vehicles on one port would take each other's
//! frames; QGroundControl merges two vehicles of one system ID without a word).

use std::collections::HashMap;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};

use missionlink_platform::config::{
    ConfigError, Ids, LinkConfig, Links, Signing, SigningPolicy, Timing, line_column,
};
use serde::Deserialize;
use toml::Spanned;

/// One vehicle of the fleet.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Its name in the fleet.
    pub name: String,
    /// Its MAVLink system ID, 1..=255.
    pub mavlink_system_id: u8,
    /// The link configuration its ground station talks to it with.
    pub link: LinkConfig,
}

/// The fleet the service serves, in the file's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Fleet {
    /// The vehicles.
    pub vehicles: Vec<Vehicle>,
    /// The separation a vehicle's mission keeps from the others' active missions.
    pub separation: Separation,
}

/// `[fleet]`: how far apart the paths of the fleet's vehicles must stay, checked before a
/// mission goes to a vehicle against the active missions of the others (the safety gateway's
/// separation check). `separation_m = 0` turns the check off.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Separation {
    /// Horizontal separation, metres: the least distance between two paths wherever their
    /// altitudes are closer than [`Separation::vertical_separation_m`].
    pub separation_m: f64,
    /// Vertical separation, metres: paths whose altitudes differ by this much or more may
    /// cross.
    pub vertical_separation_m: f64,
}

impl Default for Separation {
    /// 500 m horizontally, 150 m (about 500 ft, the vertical minimum of manned traffic below
    /// the flight levels) vertically: conservative for the demo eVTOL's turns and the
    /// positions of two aircraft that report at 2 Hz.
    fn default() -> Self {
        Self {
            separation_m: 500.0,
            vertical_separation_m: 150.0,
        }
    }
}

/// The name of the vehicle of a fleet of one made from the link configuration.
pub const SOLE_VEHICLE: &str = "fcc";

impl Fleet {
    /// The fleet of one vehicle that `config` (the link flags and file of every `gcs`
    /// command) describes, named [`SOLE_VEHICLE`], MAVLink system 1.
    pub fn of_one(config: LinkConfig) -> Self {
        Self {
            vehicles: vec![Vehicle {
                name: SOLE_VEHICLE.to_owned(),
                mavlink_system_id: 1,
                link: config,
            }],
            separation: Separation::default(),
        }
    }

    /// Reads the fleet file `path`.
    pub fn read(path: &Path) -> Result<Self, FleetError> {
        let text = std::fs::read_to_string(path).map_err(|error| {
            FleetError::Config(ConfigError::Io {
                path: path.to_owned(),
                error,
            })
        })?;
        Self::parse(&text, path)
    }

    /// Parses a fleet file's `text`; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, FleetError> {
        let file: FleetFile = missionlink_platform::config::parse(text, path)?;
        let at = |offset: usize| {
            let (line, column) = line_column(text, offset);
            (path.to_owned(), line, column)
        };
        if file.vehicle.is_empty() {
            return Err(FleetError::Empty {
                path: path.to_owned(),
            });
        }
        let mut seen = Seen::default();
        let mut vehicles = Vec::with_capacity(file.vehicle.len());
        for (index, v) in file.vehicle.into_iter().enumerate() {
            let name = v.name.get_ref().trim().to_owned();
            if name.is_empty() || name.contains(',') || name.chars().any(char::is_whitespace) {
                let (path, line, column) = at(v.name.span().start);
                return Err(FleetError::BadName {
                    path,
                    line,
                    column,
                    name,
                });
            }
            let system_id = match &v.mavlink_system_id {
                Some(id) => match u8::try_from(*id.get_ref()) {
                    Ok(n) if n > 0 => (n, Some(id.span().start)),
                    _ => {
                        let (path, line, column) = at(id.span().start);
                        return Err(FleetError::BadSystemId {
                            path,
                            line,
                            column,
                            value: *id.get_ref(),
                        });
                    }
                },
                None => (
                    u8::try_from(index + 1).map_err(|_| FleetError::TooMany {
                        path: path.to_owned(),
                    })?,
                    None,
                ),
            };
            let span_of_vehicle = v.name.span().start;
            let checks: [(&'static str, String, usize); 7] = [
                ("name", name.clone(), v.name.span().start),
                (
                    "Vehicle ID",
                    format!("{:#010X}", v.vehicle_id.get_ref()),
                    v.vehicle_id.span().start,
                ),
                (
                    "MAVLink system ID",
                    system_id.0.to_string(),
                    system_id.1.unwrap_or(span_of_vehicle),
                ),
                (
                    "ground port",
                    port_key(v.direct.get_ref().ground),
                    v.direct.span().start,
                ),
                (
                    "ground port",
                    port_key(v.lte.get_ref().ground),
                    v.lte.span().start,
                ),
                (
                    "FCC address",
                    v.direct.get_ref().fcc.to_string(),
                    v.direct.span().start,
                ),
                (
                    "FCC address",
                    v.lte.get_ref().fcc.to_string(),
                    v.lte.span().start,
                ),
            ];
            for (what, value, offset) in checks {
                // Port 0 is chosen by the system at bind: never a duplicate.
                if value.is_empty() {
                    continue;
                }
                if let Some(first) = seen.insert(what, &value, &name) {
                    let (path, line, column) = at(offset);
                    return Err(FleetError::Duplicate {
                        path,
                        line,
                        column,
                        what,
                        value,
                        first,
                    });
                }
            }
            let direct = *v.direct.get_ref();
            let lte = *v.lte.get_ref();
            vehicles.push(Vehicle {
                name,
                mavlink_system_id: system_id.0,
                link: LinkConfig::new(
                    Ids {
                        gcs: file.cucs_id,
                        fcc: *v.vehicle_id.get_ref(),
                    },
                    Links {
                        fcc_direct: direct.fcc,
                        gcs_direct: direct.ground,
                        fcc_lte: lte.fcc,
                        gcs_lte: lte.ground,
                    },
                    file.timing,
                    Signing {
                        policy: v.signing,
                        key_files: v.key_files,
                        send_key_id: v.send_key_id,
                    },
                ),
            });
        }
        let separation = file.fleet;
        let metres = |m: f64| m.is_finite() && m >= 0.0;
        if !metres(separation.separation_m) || !metres(separation.vertical_separation_m) {
            return Err(FleetError::BadSeparation {
                path: path.to_owned(),
            });
        }
        Ok(Self {
            vehicles,
            separation,
        })
    }

    /// The vehicle `name` names; `None` names the only one of a fleet of one.
    pub fn vehicle(&self, name: Option<&str>) -> Result<&Vehicle, UnknownVehicle> {
        match name {
            Some(name) => self.vehicles.iter().find(|v| v.name == name),
            None if self.vehicles.len() == 1 => self.vehicles.first(),
            None => None,
        }
        .ok_or_else(|| UnknownVehicle {
            asked: name.map(str::to_owned),
            names: self.vehicles.iter().map(|v| v.name.clone()).collect(),
        })
    }
}

/// A vehicle the fleet does not hold, or none named in a fleet of several.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}", match asked {
    Some(name) => format!("no vehicle {name:?} in the fleet (it holds {})", names.join(", ")),
    None => format!("the fleet holds {} vehicles: name one with --vehicle ({})", names.len(), names.join(", ")),
})]
pub struct UnknownVehicle {
    /// The name asked for, if any.
    pub asked: Option<String>,
    /// The fleet's names.
    pub names: Vec<String>,
}

/// A ground port as a duplicate key: its port (any two addresses on one port collide when one
/// is the wildcard); empty for port 0.
fn port_key(addr: SocketAddr) -> String {
    match addr.port() {
        0 => String::new(),
        port => port.to_string(),
    }
}

/// The values given so far, each with the vehicle that gave it first.
#[derive(Default)]
struct Seen(HashMap<(&'static str, String), String>);

impl Seen {
    /// Records `value` of kind `what` for `vehicle`; the vehicle that gave it before, if one did.
    fn insert(&mut self, what: &'static str, value: &str, vehicle: &str) -> Option<String> {
        match self.0.get(&(what, value.to_owned())) {
            Some(first) => Some(first.clone()),
            None => {
                self.0.insert((what, value.to_owned()), vehicle.to_owned());
                None
            }
        }
    }
}

/// A fleet file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum FleetError {
    /// Unreadable, or not TOML of this form (line and column).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// No `[[vehicle]]`.
    #[error("{}: the fleet holds no [[vehicle]]", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A separation below 0 or not a number.
    #[error("{}: [fleet] separation_m and vertical_separation_m are metres, 0 or more", path.display())]
    BadSeparation {
        /// The file.
        path: PathBuf,
    },
    /// More than 255 vehicles without MAVLink system IDs to tell them apart.
    #[error("{}: more than 255 vehicles: MAVLink has no system ID for the rest", path.display())]
    TooMany {
        /// The file.
        path: PathBuf,
    },
    /// A name that is empty or holds a comma or a space (`--vehicle a,b,c` lists names).
    #[error("{}:{line}:{column}: vehicle name {name:?}: give one word without commas", path.display())]
    BadName {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The name given.
        name: String,
    },
    /// A MAVLink system ID outside 1..=255 (0 addresses every system).
    #[error("{}:{line}:{column}: mavlink_system_id {value}: a MAVLink system ID is 1 to 255", path.display())]
    BadSystemId {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The value given.
        value: i64,
    },
    /// A value two vehicles share that must be one vehicle's alone.
    #[error("{}:{line}:{column}: {what} {value} is vehicle {first:?}'s already", path.display())]
    Duplicate {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Name, Vehicle ID, MAVLink system ID, ground port or FCC address.
        what: &'static str,
        /// The value.
        value: String,
        /// The vehicle that has it.
        first: String,
    },
}

/// The file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FleetFile {
    #[serde(default = "default_cucs")]
    cucs_id: u32,
    #[serde(default)]
    timing: Timing,
    #[serde(default)]
    fleet: Separation,
    #[serde(default)]
    vehicle: Vec<VehicleEntry>,
}

fn default_cucs() -> u32 {
    Ids::default().gcs
}

/// One `[[vehicle]]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct VehicleEntry {
    name: Spanned<String>,
    vehicle_id: Spanned<u32>,
    mavlink_system_id: Option<Spanned<i64>>,
    direct: Spanned<LinkEnds>,
    lte: Spanned<LinkEnds>,
    #[serde(default)]
    key_files: Vec<PathBuf>,
    #[serde(default)]
    send_key_id: Option<u8>,
    #[serde(default)]
    signing: SigningPolicy,
}

/// One link's two ends.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkEnds {
    /// Where the ground receives (the service binds it).
    ground: SocketAddr,
    /// Where the FCC receives.
    fcc: SocketAddr,
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO: &str = r#"cucs_id = 0x0A000009

[[vehicle]]
name = "alpha"
vehicle_id = 0x0B000001
direct = { ground = "127.0.0.1:5001", fcc = "127.0.0.1:6001" }
lte = { ground = "127.0.0.1:5002", fcc = "127.0.0.1:6002" }
key_files = ["/k/alpha.key"]

[[vehicle]]
name = "bravo"
vehicle_id = 0x0B000002
mavlink_system_id = 7
direct = { ground = "127.0.0.1:5003", fcc = "127.0.0.1:6003" }
lte = { ground = "127.0.0.1:5004", fcc = "127.0.0.1:6004" }
signing = "off"
"#;

    fn parse(text: &str) -> Result<Fleet, FleetError> {
        Fleet::parse(text, Path::new("fleet.toml"))
    }

    #[test]
    fn each_vehicle_becomes_the_link_configuration_its_ground_station_uses() {
        let fleet = parse(TWO).unwrap();
        let [alpha, bravo] = [&fleet.vehicles[0], &fleet.vehicles[1]];
        assert_eq!((alpha.name.as_str(), alpha.mavlink_system_id), ("alpha", 1));
        assert_eq!((bravo.name.as_str(), bravo.mavlink_system_id), ("bravo", 7));
        assert_eq!(
            alpha.link.ids,
            Ids {
                gcs: 0x0A00_0009,
                fcc: 0x0B00_0001
            }
        );
        assert_eq!(alpha.link.links.gcs_lte, "127.0.0.1:5002".parse().unwrap());
        assert_eq!(
            alpha.link.links.fcc_direct,
            "127.0.0.1:6001".parse().unwrap()
        );
        assert_eq!(alpha.link.signing.policy, SigningPolicy::Require);
        assert_eq!(
            alpha.link.signing.key_files,
            vec![PathBuf::from("/k/alpha.key")]
        );
        assert_eq!(bravo.link.signing.policy, SigningPolicy::Off);
        assert_eq!(bravo.link.timing, Timing::default());
        assert_eq!(fleet.separation, Separation::default());
        let off = parse(&TWO.replace(
            "cucs_id = 0x0A000009\n",
            "cucs_id = 0x0A000009\n[fleet]\nseparation_m = 0.0\n",
        ))
        .unwrap();
        assert_eq!(off.separation.separation_m, 0.0);
        let e = parse(&TWO.replace(
            "cucs_id = 0x0A000009\n",
            "cucs_id = 0x0A000009\n[fleet]\nseparation_m = -1.0\n",
        ))
        .unwrap_err();
        assert!(e.to_string().contains("metres, 0 or more"), "{e}");
        assert_eq!(fleet.vehicle(Some("bravo")).unwrap().name, "bravo");
        let e = fleet.vehicle(None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the fleet holds 2 vehicles: name one with --vehicle (alpha, bravo)"
        );
        let e = fleet.vehicle(Some("charlie")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "no vehicle \"charlie\" in the fleet (it holds alpha, bravo)"
        );
    }

    #[test]
    fn a_fleet_of_one_needs_no_name() {
        let fleet = Fleet::of_one(LinkConfig::default());
        assert_eq!(fleet.vehicle(None).unwrap().name, SOLE_VEHICLE);
        assert_eq!(fleet.vehicle(None).unwrap().link, LinkConfig::default());
    }

    #[test]
    fn every_duplicate_is_refused_where_it_stands_naming_the_first_owner() {
        let cases = [
            (
                "name = \"bravo\"",
                "name = \"alpha\"",
                "fleet.toml:11:8: name alpha is vehicle \"alpha\"'s already",
            ),
            (
                "0x0B000002",
                "0x0B000001",
                "fleet.toml:12:14: Vehicle ID 0x0B000001 is vehicle \"alpha\"'s already",
            ),
            (
                "mavlink_system_id = 7",
                "mavlink_system_id = 1",
                "fleet.toml:13:21: MAVLink system ID 1 is vehicle \"alpha\"'s already",
            ),
            (
                "127.0.0.1:5004",
                "0.0.0.0:5001",
                "fleet.toml:15:7: ground port 5001 is vehicle \"alpha\"'s already",
            ),
            (
                "127.0.0.1:6003",
                "127.0.0.1:6002",
                "fleet.toml:14:10: FCC address 127.0.0.1:6002 is vehicle \"alpha\"'s already",
            ),
        ];
        for (from, to, expected) in cases {
            let text = TWO.replacen(from, to, 1);
            assert_ne!(text, TWO, "{from}");
            let e = parse(&text).unwrap_err();
            assert_eq!(e.to_string(), expected);
        }
    }

    #[test]
    fn port_zero_is_never_a_duplicate() {
        let mut text = TWO.to_owned();
        for n in 1..=4 {
            text = text.replace(&format!("127.0.0.1:500{n}"), "127.0.0.1:0");
        }
        let fleet = parse(&text).unwrap();
        assert_eq!(fleet.vehicles[1].link.links.gcs_direct.port(), 0);
    }

    #[test]
    fn a_bad_value_or_key_names_line_and_column() {
        let e = parse(&TWO.replace("mavlink_system_id = 7", "mavlink_system_id = 0")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "fleet.toml:13:21: mavlink_system_id 0: a MAVLink system ID is 1 to 255"
        );
        let e = parse(&TWO.replace("signing = \"off\"", "signin = \"off\"")).unwrap_err();
        assert!(e.to_string().starts_with("fleet.toml:16:1: "), "{e}");
        let e = parse(&TWO.replace("127.0.0.1:6003", "nowhere")).unwrap_err();
        assert!(e.to_string().starts_with("fleet.toml:14:"), "{e}");
        let e = parse(&TWO.replace("\"bravo\"", "\"b c\"")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "fleet.toml:11:8: vehicle name \"b c\": give one word without commas"
        );
        let e = parse("cucs_id = 1\n").unwrap_err();
        assert_eq!(e.to_string(), "fleet.toml: the fleet holds no [[vehicle]]");
    }
}
