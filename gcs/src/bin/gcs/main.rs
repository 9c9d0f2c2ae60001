//! `gcs`: the ground control station tool. Mission commands over the two UDP links (validate,
//! upload, download, clear, execute, return to home, land, monitor; the staged missions of ICD
//! §8: stage, activate, delete, missions), driving the GCS logic of paper Figure 11, and the
//! frame inspector (`inspect`, `encode`) for captured traffic.
//!
//! **The state directory** (`--state-dir`, default `$XDG_STATE_HOME/missionlink`, else
//! `$HOME/.local/state/missionlink`) keeps the missions this GCS uploaded or staged last, one
//! mission file each, named by the mission's checksum (ICD §11): `missions/<CHECKSUM>.toml`, the
//! newest [`CACHE_KEEP`] kept. An edit takes the FCC's mission from there when the FCC's report
//! shows that checksum for the list edited, and downloads it otherwise.

use std::io::{self, BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};
use missionlink_gcs::gcs_link::GcsLink;
use missionlink_gcs::inspect::{
    Inspected, MessageJson, encode_json, inspect_datagram, parse_hex, render_text,
};
use missionlink_gcs::mission_file::{self, Dropped, MissionFile, MissionFileError};
use missionlink_gcs::pcap::PcapWriter;
use missionlink_gcs::service::client::{self, Call, Connection, Reply, What};
use missionlink_gcs::service::fleet::{Fleet, SOLE_VEHICLE};
use missionlink_gcs::service::request::{self, Answer, Listener as _, Request};
use missionlink_gcs::service::{ServeOptions, replay_lease, stamp_lease, state_base, status};
use missionlink_gcs::{geojson, map, profile, qgc, report_table};
use missionlink_ground::ground_station::{
    self as ground_station, GcsEvent, MissionPlan, ValidatedPlan, plan_in_wind,
};
use missionlink_ground::safety_gateway::{EnergyEstimate, SafetyGateway, Violation};
use missionlink_interfaces::wire::{
    ExecuteCommand, GeoPoint, Message, MissionReport, SafetyOffset,
};
use missionlink_platform::config::{LinkArgs, LinkConfig, parse_id};
use missionlink_platform::keys;
use missionlink_platform::udp::LinkPair;
use missionlink_protocol::link::signing::Keyring;
use missionlink_protocol::transfer::areas::AreaList;
use missionlink_protocol::transfer::integrity;
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::staged::MissionId;

mod cli;

use cli::{Cli, Command};

/// Missions kept in the state directory.
const CACHE_KEEP: usize = 16;

/// Where this GCS keeps what it uploaded (see the module documentation).
#[derive(Debug, Clone, Default, clap::Args)]
struct StateArgs {
    /// State directory (default: $XDG_STATE_HOME/missionlink, else
    /// $HOME/.local/state/missionlink): the missions uploaded and staged last, by checksum.
    #[arg(long, value_name = "DIR")]
    state_dir: Option<PathBuf>,
}

impl StateArgs {
    /// The cache directory, if one can be named.
    fn missions_dir(&self) -> Option<PathBuf> {
        Some(state_base(self.state_dir.clone())?.join("missions"))
    }

    /// The missions in the cache whose file name is their checksum, as mission files (a file
    /// that does not read or whose content has another checksum is left out).
    fn known(&self) -> Vec<String> {
        let Some(dir) = self.missions_dir() else {
            return Vec::new();
        };
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return Vec::new();
        };
        entries
            .filter_map(|e| e.ok())
            .filter_map(|e| {
                let path = e.path();
                let name = path.file_stem()?.to_str()?.to_owned();
                let text = std::fs::read_to_string(&path).ok()?;
                let plan = MissionFile::parse(&text).and_then(|f| f.to_plan()).ok()?;
                let mission = plan.assemble().ok()?.mission;
                (integrity::mission_checksum(&mission).to_string() == name).then_some(text)
            })
            .collect()
    }

    /// Keeps `plan` in the cache (a failure is a warning: the cache only saves a download).
    fn remember(&self, plan: &ValidatedPlan) {
        let Some(dir) = self.missions_dir() else {
            return;
        };
        let path = dir.join(format!(
            "{}.toml",
            integrity::mission_checksum(&plan.mission)
        ));
        let written = std::fs::create_dir_all(&dir)
            .and_then(|()| std::fs::write(&path, MissionFile::from_plan(plan, None).to_toml()));
        if let Err(e) = written {
            eprintln!("gcs: warning: {}: {e}", path.display());
            return;
        }
        // The newest CACHE_KEEP stay.
        let mut files: Vec<(std::time::SystemTime, PathBuf)> = std::fs::read_dir(&dir)
            .map(|entries| {
                entries
                    .filter_map(|e| e.ok())
                    .filter_map(|e| Some((e.metadata().ok()?.modified().ok()?, e.path())))
                    .collect()
            })
            .unwrap_or_default();
        files.sort();
        let excess = files.len().saturating_sub(CACHE_KEEP);
        for (_, old) in files.into_iter().take(excess) {
            let _ = std::fs::remove_file(old);
        }
    }
}

/// The inputs: the arguments, or the non-blank, non-comment lines of stdin.
fn inputs(args: Vec<String>) -> io::Result<Vec<String>> {
    if !args.is_empty() {
        return Ok(args);
    }
    let mut lines = Vec::new();
    for line in io::stdin().lock().lines() {
        let line = line?;
        let t = line.trim();
        if !t.is_empty() && !t.starts_with('#') {
            lines.push(t.to_owned());
        }
    }
    Ok(lines)
}

/// The keys of `gcs inspect --key`; none given: `None`.
fn read_keys(files: &[PathBuf]) -> Result<Option<Keyring>, String> {
    if files.is_empty() {
        return Ok(None);
    }
    let mut ring = Keyring::new();
    for file in files {
        let key = keys::read_key_file(file).map_err(|e| e.to_string())?;
        ring.insert(key)
            .map_err(|e| format!("{}: {e}", file.display()))?;
    }
    Ok(Some(ring))
}

fn inspect(
    json: bool,
    addressing: Option<(u32, u32)>,
    keys: Option<&Keyring>,
    hex: Vec<String>,
    out: &mut impl Write,
) -> io::Result<bool> {
    let mut all_ok = true;
    for (n, text) in inputs(hex)?.iter().enumerate() {
        let datagram = n + 1;
        let results = match parse_hex(text) {
            Ok(bytes) => inspect_datagram(&bytes, addressing, keys),
            Err(e) => vec![Err(e)],
        };
        for (i, result) in results.into_iter().enumerate() {
            let message = i + 1;
            let json_of = |m: Inspected| {
                MessageJson::new(&m.envelope, &m.message, m.length).map(|mut j| {
                    j.signature = m.signature;
                    j
                })
            };
            match result.and_then(json_of) {
                Ok(m) if json => {
                    let line = serde_json::to_string(&m).map_err(io::Error::other)?;
                    writeln!(out, "{line}")?;
                }
                Ok(m) => write!(out, "{}", render_text(&m))?,
                Err(e) => {
                    all_ok = false;
                    eprintln!("datagram {datagram}, message {message}: {e}");
                }
            }
        }
    }
    Ok(all_ok)
}

fn encode(json: Vec<String>, out: &mut impl Write) -> io::Result<bool> {
    let mut all_ok = true;
    for (n, text) in inputs(json)?.iter().enumerate() {
        match encode_json(text) {
            Ok(frame) => writeln!(out, "{}", hex::encode(frame))?,
            Err(e) => {
                all_ok = false;
                eprintln!("message {}: {e}", n + 1);
            }
        }
    }
    Ok(all_ok)
}

type Link = GcsLink<SafetyGateway>;

/// The capture of `--pcap`, set once in `main` before any link opens (a flag of the whole
/// process, read by every command that opens the links).
static CAPTURE: OnceLock<Arc<PcapWriter>> = OnceLock::new();

fn open(config: &LinkConfig, gateway: SafetyGateway) -> Result<Link, String> {
    let link = match CAPTURE.get() {
        None => GcsLink::open(config, gateway).map_err(|e| e.to_string())?,
        Some(capture) => {
            // The same ends `GcsLink::open` binds, with the capture on them.
            let links = LinkPair::bind(
                config.links.gcs_direct,
                config.links.gcs_lte,
                config.links.fcc_direct,
                config.links.fcc_lte,
            )
            .and_then(|l| l.with_tap(capture.clone()))
            .map_err(|e| e.to_string())?;
            GcsLink::with_links(config, links, gateway).map_err(|e| e.to_string())?
        }
    };
    // Time stamps reserved across gcs runs (see `gcs_link`), in the default state directory;
    // without one (no HOME), each run stamps with the clock alone.
    match state_base(None) {
        Some(dir) => {
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            link.with_stamp_lease(&stamp_lease(&dir, config.ids.fcc))
                .map(|l| l.with_replay_lease(&replay_lease(&dir, config.ids.fcc)))
                .map_err(|e| e.to_string())
        }
        None => Ok(link),
    }
}

/// What `--drop` may leave out of an imported file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Droppable {
    /// Every element of a .plan or GeoJSON file that the ICD cannot carry or the FCC cannot
    /// hold; each one is listed on stderr, and the plan is what remains.
    Unsupported,
}

/// The safety gateway's inputs (paper §2.2) and the sources of the plan.
#[derive(Debug, Clone, Default, clap::Args)]
struct SafetyArgs {
    /// Aircraft profile (TOML; default: the demo eVTOL, see gcs/src/profile.rs).
    #[arg(long, value_name = "FILE")]
    profile: Option<PathBuf>,
    /// Environment (TOML: wind_speed_mps, wind_from_deg, temperature_c; default calm, 15 C).
    #[arg(long, value_name = "FILE")]
    environment: Option<PathBuf>,
    /// Wind speed in m/s (overrides the environment file).
    #[arg(long, value_name = "M/S")]
    wind_mps: Option<f64>,
    /// Direction the wind blows from, degrees (overrides the environment file).
    #[arg(long, value_name = "DEG")]
    wind_from_deg: Option<f64>,
    /// Outside air temperature in C (overrides the environment file).
    #[arg(long, value_name = "C")]
    temperature_c: Option<f64>,
    /// Take the areas from this GeoJSON file instead of the mission file.
    #[arg(long, value_name = "FILE")]
    areas: Option<PathBuf>,
    /// Safety offset in metres for areas from a .plan or GeoJSON file (they carry none).
    #[arg(long, value_name = "M")]
    safety_offset_m: Option<f64>,
    /// Drop what an imported file holds that cannot be uploaded exactly, instead of refusing
    /// the file; every dropped element is listed.
    #[arg(long, value_enum, value_name = "WHAT")]
    drop: Option<Droppable>,
}

impl SafetyArgs {
    /// The gateway of the profile and environment; a file that cannot be read is unreadable
    /// input.
    fn gateway(&self) -> Result<SafetyGateway, Failure> {
        let profile = profile::aircraft(self.profile.as_deref()).map_err(Failure::input)?;
        let mut environment =
            profile::environment(self.environment.as_deref()).map_err(Failure::input)?;
        if let Some(v) = self.wind_mps {
            environment.wind_speed_mps = v;
        }
        if let Some(v) = self.wind_from_deg {
            environment.wind_from_deg = v;
        }
        if let Some(v) = self.temperature_c {
            environment.temperature_c = v;
        }
        Ok(SafetyGateway::new(profile, environment))
    }

    fn unsupported(&self) -> qgc::Unsupported {
        match self.drop {
            Some(Droppable::Unsupported) => qgc::Unsupported::Drop,
            None => qgc::Unsupported::Refuse,
        }
    }
}

/// Why a command failed, and the exit status that says so.
#[derive(Debug)]
struct Failure {
    /// 2 for unreadable or unusable input, 1 for every other failure.
    status: u8,
    /// What to print.
    message: String,
    /// For `validate --json`: the elements an import refused (empty otherwise).
    refused: Vec<Dropped>,
}

impl Failure {
    /// Unreadable or unusable input: exit status 2.
    fn input(message: impl Into<String>) -> Self {
        Self {
            status: 2,
            message: message.into(),
            refused: Vec::new(),
        }
    }

    /// `file` cannot be read or imported: exit status 2. A refused import lists its elements,
    /// one a line, and says how to drop them.
    fn file(file: &Path, e: MissionFileError) -> Self {
        match e {
            MissionFileError::Unsupported { elements } => {
                let mut message = format!(
                    "{}: refused: it holds what the ICD cannot carry or the FCC cannot hold:",
                    file.display()
                );
                for element in &elements {
                    message.push_str(&format!("\n  {element}"));
                }
                message
                    .push_str("\n  (--drop unsupported leaves these out and checks what remains)");
                Self {
                    refused: elements,
                    ..Self::input(message)
                }
            }
            other => Self::input(format!("{}: {other}", file.display())),
        }
    }
}

/// Every other failure (an infeasible mission, the link, the FCC's answer): exit status 1.
impl From<String> for Failure {
    fn from(message: String) -> Self {
        Self {
            status: 1,
            message,
            refused: Vec::new(),
        }
    }
}

impl From<request::Failure> for Failure {
    fn from(f: request::Failure) -> Self {
        Self {
            status: f.status,
            message: f.message,
            refused: Vec::new(),
        }
    }
}

impl From<&str> for Failure {
    fn from(message: &str) -> Self {
        message.to_owned().into()
    }
}

fn note(file: &Path, n: &impl std::fmt::Display) {
    eprintln!("{}: note: {n}", file.display());
}

/// A plan read from its files, and what the imports dropped (`--drop unsupported`), each with
/// its file.
struct Read {
    plan: MissionPlan,
    dropped: Vec<(PathBuf, Dropped)>,
}

/// Reads a mission by its extension, with the areas of `--areas` if given. An import that
/// cannot carry the file exactly is refused, or with `--drop unsupported` what it dropped is
/// listed on stderr, one element a line.
fn read_plan(file: &Path, safety: &SafetyArgs) -> Result<Read, Failure> {
    let unsupported = safety.unsupported();
    let read_text = |path: &Path| {
        std::fs::read_to_string(path).map_err(|e| Failure::file(path, io_error(path, e)))
    };
    let mut dropped = Vec::new();
    let mut plan = match file.extension().and_then(|e| e.to_str()) {
        Some("plan") => {
            let text = read_text(file)?;
            let options = qgc::ImportOptions {
                safety_offset_m: safety.safety_offset_m.unwrap_or(0.0),
                unsupported,
                ..Default::default()
            };
            let import = qgc::import_plan(&text, &options).map_err(|e| Failure::file(file, e))?;
            dropped.extend(import.dropped.into_iter().map(|d| (file.to_owned(), d)));
            import.plan
        }
        Some("toml") => *MissionFile::read(file)
            .and_then(|f| f.to_plan())
            .map_err(|e| Failure::file(file, e))?,
        _ => {
            return Err(Failure::input(format!(
                "{}: a mission file is .toml (missionlink) or .plan (QGroundControl)",
                file.display()
            )));
        }
    };
    if let Some(areas) = &safety.areas {
        let text = read_text(areas)?;
        let (buffer, from_areas) =
            geojson::import_areas(&text, unsupported).map_err(|e| Failure::file(areas, e))?;
        dropped.extend(from_areas.into_iter().map(|d| (areas.clone(), d)));
        plan.areas = buffer;
    }
    if let Some(m) = safety.safety_offset_m {
        plan.safety_offset = SafetyOffset::from_metres(m)
            .map_err(|e| Failure::input(format!("--safety-offset-m: {e}")))?;
    }
    for (path, d) in &dropped {
        eprintln!("{}: dropped: {d}", path.display());
    }
    Ok(Read { plan, dropped })
}

fn io_error(path: &Path, e: io::Error) -> MissionFileError {
    MissionFileError::Io {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// The lists of ICD §7, assembled with the FCC's own code; a plan that does not assemble is
/// no input for a map or a conversion (exit status 2).
fn assemble(plan: &MissionPlan, file: &Path) -> Result<ValidatedPlan, Failure> {
    plan.assemble()
        .map_err(|e| Failure::input(format!("{}: {e}", file.display())))
}

/// The safety gateway's violations of the lists and the energy estimate, the route flown from
/// the plan's take-off position (the one place the binary asks the gateway directly).
fn gateway_report(
    gateway: &SafetyGateway,
    take_off: Option<GeoPoint>,
    mission: &Mission,
    areas: &AreaList,
) -> (Vec<Violation>, EnergyEstimate) {
    (
        gateway.violations(mission, areas, take_off),
        gateway.estimate_energy(mission, take_off),
    )
}

/// The wind the turns were checked in, as `gcs validate` names it (ICD §7 "Turns in wind").
fn turns_in_wind(gateway: &SafetyGateway, mission: &Mission) -> String {
    match gateway.turn_wind_mps(mission) {
        w if w > 0.0 => format!(
            "turns checked in a wind of {w} m/s from any direction (radius (v + {w})²/(g·tan {}°))",
            gateway.profile.max_bank_deg
        ),
        _ => format!(
            "turns checked in calm air (radius v²/(g·tan {}°)): give --wind-mps or an \
             environment file for the wind of the flight",
            gateway.profile.max_bank_deg
        ),
    }
}

fn position_json(p: Option<GeoPoint>) -> serde_json::Value {
    serde_json::json!(p.map(mission_file::position))
}

fn dropped_json(dropped: &[(PathBuf, Dropped)]) -> serde_json::Value {
    dropped
        .iter()
        .map(|(file, d)| serde_json::json!({ "file": file, "path": d.path, "reason": d.reason }))
        .collect()
}

fn violation_json(v: &Violation) -> serde_json::Value {
    serde_json::json!({
        "code": v.code.code(),
        "element": v.element.to_string(),
        "detail": v.detail,
        "margin_m": v.margin_m,
        "value": v.value,
        "limit": v.limit,
        "position": v.position.map(|(lat, lon)| [lat, lon]),
    })
}

/// The FCC's report (ICD §8) as a table, one line per entry.
fn print_report(entries: &[MissionReport]) {
    print!("{}", report_table::render(entries));
}

/// `gcs validate`: the verdict on the plan as it will be uploaded (see the exit status in the
/// command's help).
fn validate(file: &Path, json: bool, safety: &SafetyArgs) -> Result<(), Failure> {
    let inputs = safety
        .gateway()
        .and_then(|gateway| Ok((gateway, read_plan(file, safety)?)));
    let (gateway, Read { plan, dropped }) = match inputs {
        Ok(inputs) => inputs,
        Err(f) => {
            if json {
                let refused: Vec<serde_json::Value> = f
                    .refused
                    .iter()
                    .map(|d| serde_json::json!({ "path": d.path, "reason": d.reason }))
                    .collect();
                println!(
                    "{}",
                    serde_json::json!({
                        "file": file,
                        "readable": false,
                        "error": f.message,
                        "refused": refused,
                    })
                );
            }
            return Err(f);
        }
    };
    // The ICD §7 assembly; an area list that fails it still goes through the gateway,
    // unchecked, so that its defects come back as violations naming the area.
    let (valid, icd_error) = match plan.lists_to_check() {
        Ok(mut lists) => {
            plan_in_wind(&gateway, &mut lists.mission);
            let error = lists.invalid;
            (
                Some(ValidatedPlan {
                    mission: lists.mission,
                    areas: lists.areas,
                }),
                error,
            )
        }
        Err(e) => (None, Some(e)),
    };
    let (violations, energy) = match &valid {
        Some(v) => {
            let (violations, energy) =
                gateway_report(&gateway, plan.take_off_position, &v.mission, &v.areas);
            (violations, Some(energy))
        }
        None => (Vec::new(), None),
    };
    let feasible = violations.is_empty() && icd_error.is_none();
    // ICD §11: what the FCC will report for these lists once they are active.
    let checksums = valid.as_ref().filter(|_| feasible).map(|v| {
        (
            integrity::mission_checksum(&v.mission),
            integrity::areas_checksum(&v.areas),
        )
    });
    let summary = match (&valid, icd_error) {
        (Some(v), None) => v.to_string(),
        _ => plan.to_string(),
    };
    if json {
        println!(
            "{}",
            serde_json::json!({
                "file": file,
                "feasible": feasible,
                "summary": summary,
                "take_off_position": position_json(plan.take_off_position),
                "turn_wind_mps": valid.as_ref().map(|v| gateway.turn_wind_mps(&v.mission)),
                "energy_wh": energy.map(|e| serde_json::json!({ "total": e.total_wh, "with_return": e.with_return_wh(), "limit": e.limit_wh })),
                "violations": violations.iter().map(violation_json).collect::<Vec<_>>(),
                "error": icd_error.map(|e| e.to_string()),
                "mission_checksum": checksums.map(|(m, _)| m.to_string()),
                "area_checksum": checksums.map(|(_, a)| a.to_string()),
                "dropped": dropped_json(&dropped),
            })
        );
    } else {
        println!("{}: {summary}", file.display());
        match plan.take_off_position.map(mission_file::position) {
            Some([lat, lon]) => println!("  take-off position: {lat}, {lon}"),
            None => println!("  take-off position: none"),
        }
        if let Some(v) = &valid {
            println!("  {}", turns_in_wind(&gateway, &v.mission));
        }
        if let Some(e) = energy {
            match e.with_return_wh() {
                Some(home) => println!(
                    "  energy: {:.0} Wh needed ({home:.0} Wh with a return to home from the last \
                     waypoint) of {:.0} Wh usable after the reserve",
                    e.total_wh, e.limit_wh
                ),
                None => println!(
                    "  energy: {:.0} Wh needed of {:.0} Wh usable after the reserve",
                    e.total_wh, e.limit_wh
                ),
            }
        }
        for v in &violations {
            println!("  {v}");
        }
        if let Some(e) = icd_error {
            println!("  {e}");
        }
        if feasible {
            println!("  feasible: every check of the safety gateway passes");
        }
        if let Some((m, a)) = checksums {
            println!("  checksums (ICD §11): mission {m}, areas {a}");
        }
    }
    match (violations.len(), icd_error) {
        (0, None) => Ok(()),
        (0, Some(e)) => Err(format!("{}: infeasible: {e}", file.display()).into()),
        (n, _) => Err(format!(
            "{}: infeasible: {n} violation{}",
            file.display(),
            if n == 1 { "" } else { "s" }
        )
        .into()),
    }
}

/// `gcs upload` and `gcs stage`: validates, then uploads (or edits) `file` into `target`
/// (`stage`: a staged mission's ID), prints the outcome and keeps the mission in the state
/// directory once it is there.
fn send_plan(
    ground: &Ground,
    file: &Path,
    stage: Option<MissionId>,
    paper_sequence: bool,
    edit: bool,
    state: &StateArgs,
    safety: &SafetyArgs,
) -> Result<(), Failure> {
    let gateway = safety.gateway()?;
    let plan = read_plan(file, safety)?.plan;
    // Validated here, so that an infeasible plan is refused before anything is asked of the
    // links; the one who carries the request out validates it again (module `request`).
    let validated = ground_station::validate(&gateway, &plan)
        .map_err(|e| format!("{}: {e}; nothing was sent", file.display()))?;
    let request = Request::Upload(Box::new(request::Upload {
        file: file.display().to_string(),
        mission: MissionFile::from_plan(&validated, plan.take_off_position).to_toml(),
        stage: stage.map(|id| id.as_str().to_owned()),
        paper_sequence,
        edit,
        known: if edit { state.known() } else { Vec::new() },
        profile: gateway.profile.into(),
        environment: gateway.environment.into(),
    }));
    let vehicles = ground.vehicles();
    if vehicles.len() > 1 {
        return send_to_fleet(ground, &vehicles, &request, &validated, state);
    }
    if let Answer::Uploaded { report, edit } = ground.exchange(request)? {
        println!("{report}");
        if let Some((sent, full)) = edit {
            println!("sent {sent} messages (a full upload: {full})");
        }
        state.remember(&validated);
    }
    Ok(())
}

/// `gcs upload --vehicle a,b,c` (and `stage`): the request to every vehicle at once, each on
/// its own link, each vehicle's outcome printed on its own lines after its name, in the order
/// given. The exit status is the highest of the vehicles' (0 when every one completed).
fn send_to_fleet(
    ground: &Ground,
    vehicles: &[String],
    request: &Request,
    validated: &ValidatedPlan,
    state: &StateArgs,
) -> Result<(), Failure> {
    let outcomes: Vec<Result<Answer, Failure>> = std::thread::scope(|scope| {
        let running: Vec<_> = vehicles
            .iter()
            .map(|name| {
                let one = Ground {
                    vehicle: Some(name.clone()),
                    progress: false,
                    ..ground.clone()
                };
                let request = request.clone();
                std::thread::Builder::new()
                    .name(format!("gcs {name}"))
                    .stack_size(COMMAND_STACK)
                    .spawn_scoped(scope, move || one.exchange(request))
            })
            .collect();
        running
            .into_iter()
            .map(|spawned| match spawned.map(|thread| thread.join()) {
                Ok(Ok(outcome)) => outcome,
                Ok(Err(_)) => Err(Failure::from("the request's thread failed")),
                Err(e) => Err(Failure::from(format!("cannot start the request: {e}"))),
            })
            .collect()
    });
    let mut status = 0;
    let mut failed = 0;
    for (name, outcome) in vehicles.iter().zip(outcomes) {
        match outcome {
            Ok(Answer::Uploaded { report, edit }) => {
                println!("{name}: {report}");
                if let Some((sent, full)) = edit {
                    println!("{name}: sent {sent} messages (a full upload: {full})");
                }
            }
            Ok(_) => println!("{name}: done"),
            Err(f) => {
                failed += 1;
                status = status.max(f.status);
                for line in f.message.lines() {
                    eprintln!("gcs: {name}: {line}");
                }
            }
        }
    }
    if failed < vehicles.len() {
        state.remember(validated);
    }
    match failed {
        0 => Ok(()),
        n => Err(Failure {
            status,
            message: format!("{n} of {} vehicles did not complete", vehicles.len()),
            refused: Vec::new(),
        }),
    }
}

/// Where a command's requests go: to the ground service when one runs, else over the links the
/// command opens itself (the link flags and file, or `--vehicle` of `--fleet`).
#[derive(Clone)]
struct Ground {
    args: LinkArgs,
    vehicle: Option<String>,
    fleet: Option<PathBuf>,
    socket: Option<PathBuf>,
    /// Progress of a transfer on a terminal (not when several run at once).
    progress: bool,
}

impl Ground {
    /// The vehicles `--vehicle a,b,c` names, when it names several (else none: the one).
    fn vehicles(&self) -> Vec<String> {
        match &self.vehicle {
            Some(list) if list.contains(',') => list
                .split(',')
                .map(str::trim)
                .filter(|n| !n.is_empty())
                .map(str::to_owned)
                .collect(),
            _ => Vec::new(),
        }
    }

    /// The configuration of the links a command alone opens.
    fn config(&self) -> Result<LinkConfig, Failure> {
        let config = LinkConfig::resolve(&self.args).map_err(|e| Failure::input(e.to_string()))?;
        match (&self.fleet, self.vehicle.as_deref()) {
            (Some(file), vehicle) => {
                let fleet = Fleet::read(file).map_err(|e| Failure::input(e.to_string()))?;
                let vehicle = fleet
                    .vehicle(vehicle)
                    .map_err(|e| Failure::input(e.to_string()))?;
                Ok(vehicle.link.clone())
            }
            (None, None) => Ok(config),
            (None, Some(name)) if name == SOLE_VEHICLE => Ok(config),
            (None, Some(name)) => Err(Failure::input(format!(
                "--vehicle {name}: no ground service runs and no fleet file names it (give \
                 --fleet, or start the service: gcs serve)"
            ))),
        }
    }

    /// The running service, if one runs (an error when its socket is there but nobody answers).
    fn service(&self) -> Result<Option<Connection>, Failure> {
        match client::socket_path(self.socket.as_deref()) {
            Some(path) => Ok(Connection::open(&path)?),
            None => Ok(None),
        }
    }

    /// Carries `request` out (module `request`), through the service or alone, and gives its
    /// answer; prints progress on a terminal.
    fn exchange(&self, request: Request) -> Result<Answer, Failure> {
        let mut terminal = Terminal(self.progress && io::stderr().is_terminal());
        let answer = match self.service()? {
            Some(service) => {
                // What the FCC holds after an upload the service did not finish is unknown.
                let lost = if matches!(request, Request::Upload(_)) {
                    5
                } else {
                    1
                };
                let call = Call {
                    vehicle: self.vehicle.clone(),
                    what: What::Request(request),
                };
                let reply = service.call(&call, lost, |reply| {
                    if let Some(Reply::Progress(p)) = reply {
                        terminal.progress(p.clone());
                    }
                    true
                })?;
                match reply {
                    Some(Reply::Finished(answer)) => Ok(answer),
                    Some(Reply::Failed(failure)) => Err(failure),
                    _ => Err(request::Failure::other(
                        "the ground service answered out of turn",
                    )),
                }
            }
            None => {
                let mut link = open(&self.config()?, SafetyGateway::default())?;
                request::carry_out(&mut link, request, &mut terminal)
            }
        };
        if terminal.0 {
            eprintln!();
        }
        Ok(answer?)
    }
}

/// A request's progress on the terminal, when stderr is one.
struct Terminal(bool);

impl request::Listener for Terminal {
    fn progress(&mut self, p: request::Progress) {
        if self.0 {
            eprint!("\r{}: {}/{} messages   ", p.phase, p.sent, p.total);
        }
    }
}

fn mission_command(ground: &Ground, command: Command) -> Result<(), Failure> {
    match command {
        Command::Validate { file, json, safety } => validate(&file, json, &safety),
        Command::Upload {
            file,
            edit,
            paper_sequence,
            state,
            safety,
        } => send_plan(ground, &file, None, paper_sequence, edit, &state, &safety),
        Command::Stage {
            file,
            id,
            edit,
            state,
            safety,
        } => send_plan(ground, &file, Some(id), false, edit, &state, &safety),
        Command::Activate { id } => {
            let id_text = id.as_str().to_owned();
            ground.exchange(Request::Activate { id: id_text })?;
            println!("staged mission {id:?} is active (mission and areas in one step)");
            Ok(())
        }
        Command::Delete { id } => {
            let id_text = id.as_str().to_owned();
            ground.exchange(Request::Delete { id: id_text })?;
            println!("staged mission {id:?} deleted");
            Ok(())
        }
        Command::Map {
            file,
            output,
            safety,
        } => {
            let gateway = safety.gateway()?;
            let plan = read_plan(&file, &safety)?.plan;
            // The map shows a plan with defects too: the lists as far as they assemble.
            let valid = plan
                .lists_to_check()
                .map(|mut lists| {
                    plan_in_wind(&gateway, &mut lists.mission);
                    ValidatedPlan {
                        mission: lists.mission,
                        areas: lists.areas,
                    }
                })
                .map_err(|e| Failure::input(format!("{}: {e}", file.display())))?;
            let markers: Vec<map::Marker> = gateway_report(
                &gateway,
                plan.take_off_position,
                &valid.mission,
                &valid.areas,
            )
            .0
            .iter()
            .map(|v| map::Marker {
                code: v.code.code().to_owned(),
                label: v.to_string(),
                position: v.position,
            })
            .collect();
            let title = file
                .file_name()
                .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
            std::fs::write(
                &output,
                map::render(&valid, plan.take_off_position, &markers, &title, &gateway),
            )
            .map_err(|e| format!("{}: {e}", output.display()))?;
            println!(
                "{} written: {} violation{} marked",
                output.display(),
                markers.len(),
                if markers.len() == 1 { "" } else { "s" }
            );
            Ok(())
        }
        Command::Convert {
            input,
            output,
            safety,
        } => {
            let plan = read_plan(&input, &safety)?.plan;
            let valid = assemble(&plan, &input)?;
            let text = match output.extension().and_then(|e| e.to_str()) {
                Some("toml") => MissionFile::from_plan(&valid, plan.take_off_position).to_toml(),
                Some("plan") => {
                    let options = qgc::ExportOptions {
                        take_off_position: plan.take_off_position,
                        ..qgc::ExportOptions::default()
                    };
                    let (text, notes) = qgc::export_plan(&valid, &options);
                    for n in &notes {
                        note(&output, n);
                    }
                    text
                }
                Some("geojson" | "json") => geojson::export_areas(&valid.areas),
                _ => {
                    return Err(Failure::input(format!(
                        "{}: write .toml, .plan or .geojson",
                        output.display()
                    )));
                }
            };
            std::fs::write(&output, text).map_err(|e| format!("{}: {e}", output.display()))?;
            println!("{} written", output.display());
            Ok(())
        }
        Command::Download { output, id } => {
            let request = Request::Download {
                id: id.map(|id| id.as_str().to_owned()),
            };
            let Answer::Downloaded { mission } = ground.exchange(request)? else {
                return Err("the download ended without lists".into());
            };
            let plan = MissionFile::parse(&mission)
                .and_then(|f| f.to_plan())
                .map_err(|e| e.to_string())
                .and_then(|p| p.assemble().map_err(|e| e.to_string()))
                .map_err(|e| format!("the downloaded lists: {e}"))?;
            match id {
                Some(id) => println!("downloaded staged mission {id:?}: {plan}"),
                None => println!("downloaded {plan}"),
            }
            println!(
                "checksums (ICD §11): mission {}, areas {}",
                integrity::mission_checksum(&plan.mission),
                integrity::areas_checksum(&plan.areas)
            );
            if let Some(path) = output {
                // The FCC does not hold the take-off position: the file has none (its header
                // says so), and it must be added before the file is uploaded again.
                std::fs::write(&path, mission).map_err(|e| format!("{}: {e}", path.display()))?;
                println!(
                    "written to {} (without a take-off position: the FCC does not hold it)",
                    path.display()
                );
            }
            Ok(())
        }
        Command::Missions => {
            let Answer::Reported { entries } = ground.exchange(Request::Report)? else {
                return Err("the FCC sent no report".into());
            };
            let entries: Vec<MissionReport> = entries
                .into_iter()
                .filter_map(|m| match m {
                    Message::MissionReport(r) => Some(r),
                    _ => None,
                })
                .collect();
            print_report(&entries);
            Ok(())
        }
        Command::Clear => {
            ground.exchange(Request::ClearMission)?;
            println!("mission cleared");
            Ok(())
        }
        Command::ClearAreas | Command::Execute | Command::Rth | Command::Land => {
            let request = match command {
                Command::ClearAreas => Request::ClearAreas,
                Command::Execute => Request::Execute {
                    command: ExecuteCommand::Execute,
                },
                Command::Rth => Request::Execute {
                    command: ExecuteCommand::ReturnToHome,
                },
                _ => Request::Execute {
                    command: ExecuteCommand::Land,
                },
            };
            ground.exchange(request)?;
            println!("accepted by the FCC");
            Ok(())
        }
        Command::Monitor { seconds } => {
            if let Some(service) = ground.service()? {
                return monitor_through(service, ground.vehicle.clone(), seconds);
            }
            let mut link = open(&ground.config()?, SafetyGateway::default())?;
            let limit = seconds.map_or(Duration::MAX, Duration::from_secs);
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
                let _ = signal_hook::flag::register(signal, std::sync::Arc::clone(&stop));
            }
            let start = std::time::Instant::now();
            let mut monitor = missionlink_gcs::monitor::Monitor::new();
            while start.elapsed() < limit && !stop.load(std::sync::atomic::Ordering::Relaxed) {
                link.run_until(Duration::from_millis(200), |event| {
                    match event {
                        GcsEvent::FromToNext(f) => println!("{}", monitor.from_to_next(f)),
                        GcsEvent::Position(p) => println!("{}", monitor.position(p)),
                        _ => {}
                    }
                    false
                });
            }
            Ok(())
        }
        Command::Mavlink {
            to,
            bind,
            cruise_speed,
            fence_wait_ms,
            tlog,
            safety,
            state,
        } => {
            use missionlink_gcs::mavlink::driver::{self, MavlinkSocket};
            use missionlink_gcs::mavlink::vehicle::{Vehicle, VehicleConfig};
            if ground.service()?.is_some() {
                return Err(
                    "a ground service runs and owns the links: its MAVLink side is gcs \
                            serve --mavlink (see docs/gcs.md)"
                        .into(),
                );
            }
            let gateway = safety.gateway()?;
            let mut link = open(&ground.config()?, gateway)?;
            let mut socket = MavlinkSocket::bind(bind, to)
                .map_err(|e| format!("cannot bind the MAVLink socket {bind}: {e}"))?;
            if let Some(path) = &tlog {
                socket = socket
                    .with_tlog(path)
                    .map_err(|e| format!("cannot write the capture {}: {e}", path.display()))?;
            }
            let memory = state_base(state.state_dir.clone()).and_then(|dir| {
                std::fs::create_dir_all(&dir).ok()?;
                Some(dir.join("mavlink-memory"))
            });
            let local = socket.local_addr().map_err(|e| e.to_string())?;
            let mut vehicle = Vehicle::new(VehicleConfig::standard(
                missionlink_gcs::mavlink::vehicle::SYSTEM_ID,
                Duration::from_millis(fence_wait_ms),
                cruise_speed,
            ));
            driver::read_lists(&mut link, &mut vehicle, memory.as_deref());
            say(&format!("MAVLink vehicle on {local}, sending to {to}\n"));
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
                let _ = signal_hook::flag::register(signal, std::sync::Arc::clone(&stop));
            }
            driver::run(&mut link, &mut vehicle, &socket, memory.as_deref(), &stop)
                .map_err(|e| e.to_string())?;
            Ok(())
        }
        Command::Serve {
            state,
            safety,
            mavlink,
            mavlink_to,
            mavlink_bind,
            cruise_speed,
            fence_wait_ms,
            tlog,
            no_isolation,
            exit_with_parent,
        } => {
            // The parent now, before anything: the service watches it once its fence is up.
            let parent = exit_with_parent.then(rustix::process::getppid).flatten();
            let mavlink = mavlink.then_some(ServeMavlink {
                to: mavlink_to,
                bind: mavlink_bind,
                cruise_speed,
                fence_wait: Duration::from_millis(fence_wait_ms),
                tlog,
            });
            serve(ground, &state, &safety, mavlink, !no_isolation, parent)
        }
        Command::Status { watch, json } => status(ground, watch, json),
        Command::Inspect { .. } | Command::Encode { .. } | Command::Keygen { .. } => Ok(()),
    }
}

/// SIGINT and SIGTERM set the flag this returns.
fn stop_on_signals() -> Arc<std::sync::atomic::AtomicBool> {
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        let _ = signal_hook::flag::register(signal, Arc::clone(&stop));
    }
    stop
}

/// The MAVLink side of `gcs serve`, as its flags give it.
struct ServeMavlink {
    to: std::net::SocketAddr,
    bind: std::net::SocketAddr,
    cruise_speed: f64,
    fence_wait: Duration,
    tlog: Option<PathBuf>,
}

/// What a long-running command (`gcs serve`, `gcs mavlink`) says on stdout, flushed: a stdout
/// closed by whoever started it (a pipe whose reader went) costs the lines, never the command.
fn say(text: &str) {
    let mut out = io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}

/// `gcs serve`: the ground service until SIGINT or SIGTERM.
fn serve(
    ground: &Ground,
    state: &StateArgs,
    safety: &SafetyArgs,
    mavlink: Option<ServeMavlink>,
    isolation: bool,
    parent: Option<rustix::process::Pid>,
) -> Result<(), Failure> {
    use missionlink_gcs::mavlink::driver::MavlinkSocket;
    use missionlink_gcs::service::MavlinkOptions;
    let fleet = match &ground.fleet {
        Some(file) => Fleet::read(file).map_err(|e| Failure::input(e.to_string()))?,
        None => Fleet::of_one(
            LinkConfig::resolve(&ground.args).map_err(|e| Failure::input(e.to_string()))?,
        ),
    };
    let socket = client::socket_path(ground.socket.as_deref())
        .ok_or("no place for the service's socket: give --service-socket")?;
    let state_dir = state_base(state.state_dir.clone());
    let fence =
        isolation.then(|| missionlink_gcs::service::service_fence(&socket, state_dir.as_deref()));
    let mut options = ServeOptions {
        socket: socket.clone(),
        state_dir,
        capture: CAPTURE.get().cloned(),
        gateway: safety.gateway()?,
        mavlink: None,
        fence,
        parent,
    };
    // The socket and the fleet's links first: the MAVLink endpoint's port may be the system's
    // pick, which must not be one the fleet file names.
    let opened = missionlink_gcs::service::open(&fleet, &options)
        .map_err(|e| Failure::from(e.to_string()))?;
    let endpoint = |m: &ServeMavlink| {
        let endpoint = MavlinkSocket::bind(m.bind, m.to)
            .map_err(|e| format!("cannot bind the MAVLink socket {}: {e}", m.bind))?;
        match &m.tlog {
            Some(path) => endpoint
                .with_tlog(path)
                .map_err(|e| format!("cannot write the capture {}: {e}", path.display())),
            None => Ok(endpoint),
        }
    };
    options.mavlink = match mavlink.as_ref().map(|m| (m, endpoint(m))) {
        None => None,
        Some((m, Ok(endpoint))) => Some(MavlinkOptions {
            socket: Arc::new(endpoint),
            cruise_speed_mps: m.cruise_speed,
            fence_wait: m.fence_wait,
        }),
        // Nothing served: the socket goes with the service that could not start.
        Some((_, Err(e))) => {
            let _ = std::fs::remove_file(&socket);
            return Err(e.into());
        }
    };
    let mavlink_line = match &options.mavlink {
        Some(m) => Some(format!(
            "MAVLink vehicles on {}, sending to {}: {}",
            m.socket.local_addr().map_err(|e| e.to_string())?,
            m.socket.to(),
            fleet
                .vehicles
                .iter()
                .map(|v| format!("system {} {}", v.mavlink_system_id, v.name))
                .collect::<Vec<_>>()
                .join(", ")
        )),
        None => None,
    };
    let stop = stop_on_signals();
    missionlink_gcs::service::serve(&fleet, opened, &options, &stop, |bound| {
        let mut text = format!(
            "ground service for {} vehicle{} on {}\n",
            bound.len(),
            if bound.len() == 1 { "" } else { "s" },
            socket.display()
        );
        for b in bound {
            text += &format!(
                "vehicle {} ({:#010X}): direct {}, LTE {}\n",
                b.name, b.vehicle_id, b.direct, b.lte
            );
        }
        if let Some(line) = &mavlink_line {
            text += &format!("{line}\n");
        }
        say(&text);
    })
    .map_err(|e| Failure::from(e.to_string()))?;
    say("ground service stopped\n");
    Ok(())
}

/// `gcs status`: the service's rows, once or every `watch` seconds.
fn status(ground: &Ground, watch: Option<f64>, json: bool) -> Result<(), Failure> {
    let stop = stop_on_signals();
    loop {
        let Some(service) = ground.service()? else {
            return Err(format!(
                "no ground service runs (socket {}): start one with gcs serve",
                client::socket_path(ground.socket.as_deref())
                    .map_or_else(|| "none".to_owned(), |p| p.display().to_string())
            )
            .into());
        };
        let call = Call {
            vehicle: None,
            what: What::Status,
        };
        match service.call(&call, 1, |_| true)? {
            Some(Reply::Status(rows)) if json => {
                println!(
                    "{}",
                    serde_json::to_string(&rows).map_err(|e| e.to_string())?
                );
            }
            Some(Reply::Status(rows)) => print!("{}", status::render(&rows)),
            Some(Reply::Failed(f)) => return Err(f.into()),
            _ => return Err("the ground service answered out of turn".into()),
        }
        let _ = io::stdout().flush();
        let Some(every) = watch.filter(|s| *s > 0.0) else {
            return Ok(());
        };
        let until = std::time::Instant::now() + Duration::from_secs_f64(every);
        while std::time::Instant::now() < until {
            if stop.load(std::sync::atomic::Ordering::Relaxed) {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        println!();
    }
}

/// `gcs monitor` through the service: the vehicle's FROM-TO-NEXT and position now, then every
/// report, for `seconds` or until interrupted.
fn monitor_through(
    service: Connection,
    vehicle: Option<String>,
    seconds: Option<u64>,
) -> Result<(), Failure> {
    let limit = seconds.map_or(Duration::MAX, Duration::from_secs);
    let stop = stop_on_signals();
    let start = std::time::Instant::now();
    let mut monitor = missionlink_gcs::monitor::Monitor::new();
    service
        .set_read_timeout(Some(Duration::from_millis(200)))
        .map_err(|e| e.to_string())?;
    let call = Call {
        vehicle,
        what: What::Monitor,
    };
    let ended = service.call(&call, 1, |reply| {
        if let Some(Reply::Event(message)) = reply {
            match message.as_ref() {
                Message::FromToNext(f) => println!("{}", monitor.from_to_next(f)),
                Message::InertialStates(p) => println!("{}", monitor.position(p)),
                _ => {}
            }
        }
        start.elapsed() < limit && !stop.load(std::sync::atomic::Ordering::Relaxed)
    })?;
    match ended {
        Some(Reply::Failed(f)) => Err(f.into()),
        _ => Ok(()),
    }
}

/// The stack of the thread that runs a command. Mission plans, validated lists and the link hold
/// their fixed-capacity lists inline (a 256-waypoint mission is tens of KB), and a debug build
/// keeps a copy of each in every frame they pass through: measured, `gcs upload` of a debug
/// build needed between 3 and 4 MB. 64 MB leaves room for the largest plans in any build.
const COMMAND_STACK: usize = 64 << 20;

/// Gives the service one arena of the C library's allocator (glibc's `M_ARENA_MAX`) instead of
/// up to eight per CPU. The service's requests run on threads of their own, and glibc gives
/// threads that allocate at the same moment arenas of their own, each keeping what it held at
/// its fullest: at 16 vehicles on 2 CPUs, 15 arenas held 6.4 MiB at first and 7.3 MiB after 50
/// minutes of an upload to all every 10 s, all of the service's growth over that time (read
/// off `/proc/<pid>/smaps`); with one arena a vehicle adds 732-775 KiB instead of 960-964
/// (BENCHMARKS.md section 10). The requests mostly wait for their links, and small blocks come
/// from each thread's cache, so one lock for the rest costs nothing measurable. Other C
/// libraries (musl) keep no arenas per thread: nothing to set there.
#[allow(unsafe_code)]
fn one_allocator_arena() {
    // SAFETY: mallopt only sets a parameter of the allocator; glibc takes its own lock for it
    // and applies it to arenas made from now on. Called before the service starts a thread.
    #[cfg(target_env = "gnu")]
    let _ = unsafe { libc::mallopt(libc::M_ARENA_MAX, 1) };
}

fn main() -> ExitCode {
    missionlink_platform::init_logging();
    let cli = Cli::parse();
    // The service fences itself while it is the process's one thread (its threads inherit the
    // fence): it runs on this thread, whose stack it does not outgrow (its vehicles' threads
    // get the large stacks).
    if matches!(cli.command, Command::Serve { .. }) {
        one_allocator_arena();
        return run(cli);
    }
    let command = std::thread::Builder::new()
        .name("gcs".to_owned())
        .stack_size(COMMAND_STACK)
        .spawn(move || run(cli));
    match command.map(|thread| thread.join()) {
        Ok(Ok(status)) => status,
        Ok(Err(_)) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("gcs: cannot start: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> ExitCode {
    if let Some(path) = &cli.pcap {
        match PcapWriter::create(path) {
            Ok(w) => {
                let _ = CAPTURE.set(Arc::new(w));
            }
            Err(e) => {
                eprintln!("gcs: cannot write the capture {}: {e}", path.display());
                return ExitCode::from(2);
            }
        }
    }
    if !matches!(
        cli.command,
        Command::Inspect { .. } | Command::Encode { .. } | Command::Keygen { .. }
    ) {
        let ground = Ground {
            args: cli.config,
            vehicle: cli.vehicle,
            fleet: cli.fleet,
            socket: cli.service_socket,
            progress: true,
        };
        return match mission_command(&ground, cli.command) {
            Ok(()) => ExitCode::SUCCESS,
            Err(f) => {
                eprintln!("gcs: {}", f.message);
                ExitCode::from(f.status)
            }
        };
    }
    let mut out = io::stdout().lock();
    let result = match cli.command {
        Command::Inspect {
            json,
            local_id,
            peer_id,
            keys,
            hex,
        } => match read_keys(&keys) {
            Ok(ring) => inspect(json, local_id.zip(peer_id), ring.as_ref(), hex, &mut out),
            Err(e) => {
                eprintln!("gcs: {e}");
                return ExitCode::from(2);
            }
        },
        Command::Keygen {
            fcc,
            ground,
            key_id,
        } => match keys::generate_key_files(&[&fcc, &ground], key_id) {
            Ok(()) => {
                println!(
                    "wrote link key {key_id} (mode 0600) for the FCC to {} and for the ground to \
                     {}; name each in its side's [signing] key_files (or --key-file)",
                    fcc.display(),
                    ground.display()
                );
                Ok(true)
            }
            Err(e) => {
                eprintln!("gcs: {e}");
                return ExitCode::from(2);
            }
        },
        Command::Encode { json } => encode(json, &mut out),
        _ => Ok(true),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("gcs: {e}");
            ExitCode::FAILURE
        }
    }
}
