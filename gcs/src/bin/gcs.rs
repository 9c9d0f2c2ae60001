//! `gcs`: the ground control station tool. Mission commands over the two UDP links (validate,
//! upload, download, clear, execute, return to home, land, monitor), driving the GCS logic of
//! paper Figure 11, and the frame inspector (`inspect`, `encode`) for captured traffic.

use std::io::{self, BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};
use missionlink_gcs::gcs_link::{Finished, GcsLink};
use missionlink_gcs::inspect::{
    MessageJson, encode_json, inspect_datagram, parse_hex, render_text,
};
use missionlink_gcs::mission_file::{self, Dropped, MissionFile, MissionFileError};
use missionlink_gcs::{geojson, map, profile, qgc};
use missionlink_interfaces::wire::{
    Checksum, ExecuteCommand, GeoPoint, GeofenceCheck, MissionReport, SafetyOffset,
};
use missionlink_partitions::config::{Config, ConfigArgs, parse_id};
use missionlink_services::ground_station::outcome::UploadOutcome;
use missionlink_services::ground_station::{GcsError, GcsEvent, MissionPlan, ValidatedPlan};
use missionlink_services::safety_gateway::{EnergyEstimate, SafetyGateway, Violation};
use missionlink_services::transfer::areas::AreaList;
use missionlink_services::transfer::integrity;
use missionlink_services::transfer::mission::Mission;

/// Ground control station of missionlink: STANAG 4586 mission and area transfer.
#[derive(Debug, Parser)]
#[command(name = "gcs", version)]
struct Cli {
    #[command(flatten)]
    config: ConfigArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Check a mission file: assemble the waypoint and area lists (ICD §7), then run the safety
    /// gateway, flying from the plan's take-off position, and print every violation.
    ///
    /// A .plan or GeoJSON file is imported exactly or not at all: an element the ICD cannot carry
    /// or the FCC cannot hold (a return-to-launch or other unsupported item, a second inclusion
    /// polygon, an inclusion circle, an eleventh no-fly-zone, a polygon of more than 60
    /// vertices, ...) refuses the file, naming the element's path and the reason, unless
    /// `--drop unsupported` is given.
    #[command(after_help = "Exit status:\n  \
        0  feasible: the lists assemble (ICD §7) and every check of the safety gateway passes\n  \
        1  infeasible: a violation of the safety gateway, or the lists refused by the ICD §7 \
           assembly\n  \
        2  unreadable input: a file missing or unreadable, a syntax error or a bad value, an \
           import refused for what it cannot carry, bad flags")]
    Validate {
        /// Mission file: our TOML (.toml) or a QGroundControl plan (.plan).
        file: PathBuf,
        /// One JSON object instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Validate (the safety gateway included), then upload the waypoints, then the areas (paper
    /// Figure 11). An infeasible mission is refused with the report; nothing is sent.
    ///
    /// Toward an edition-2 FCC the checksums of both lists (ICD §11) go with the closers and
    /// the FCC refuses a list it assembled otherwise. When the transfer fails, the GCS asks the
    /// FCC what is active (its report, or a download from an edition-1 FCC) and says so, list
    /// by list, with the checksums.
    #[command(after_help = "Exit status:\n  \
        0  complete: the new mission and areas are active (also when an answer was lost and the \
           GCS confirmed it by asking)\n  \
        1  nothing sent: the plan is infeasible or invalid; or the FCC did not answer at all\n  \
        2  unreadable input\n  \
        3  failed: the previous mission and areas are still active, whole\n  \
        4  failed half way: one list is the new one, the other the previous one (the message \
           says which)\n  \
        5  failed, and what the FCC holds is unknown: it did not answer the question\n  \
        6  failed: the FCC holds a list that is neither the new one nor the previous one")]
    Upload {
        /// Mission file (.toml or .plan).
        file: PathBuf,
        /// Edit the active mission: send no clear, only the waypoints of the file change.
        #[arg(long)]
        edit: bool,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Draw the mission as SVG: areas with their safety offsets, waypoints, legs and arcs, the
    /// take-off, and every violation of the safety gateway in red.
    Map {
        /// Mission file (.toml or .plan).
        file: PathBuf,
        /// Where to write the SVG.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Convert a mission between formats, by extension: .toml (ours), .plan (QGroundControl),
    /// .geojson (the areas only, as output).
    Convert {
        /// Mission file to read (.toml or .plan).
        input: PathBuf,
        /// File to write (.toml, .plan or .geojson).
        output: PathBuf,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Download the active mission and areas; print them, or write a mission file.
    Download {
        /// Write the mission file here (upload it again for a round trip).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
    },
    /// Print what the FCC holds (ICD §8 report, #50001): for the active lists (and each staged
    /// mission) the waypoint and area counts, the onboard geofence check and the checksums of
    /// ICD §11, to compare with what `gcs validate` and `gcs upload` print. An edition-1 FCC
    /// gives no report (exit status 1).
    Missions,
    /// Clear the active mission (#13000 clear, then transmit of an empty list).
    Clear,
    /// Clear the active areas (#2011 mode 6).
    ClearAreas,
    /// Take off and fly the active mission (#50000 execute).
    Execute,
    /// Fly the route backwards to its start (#50000 return to home, bidirectional routes).
    Rth,
    /// Land at the next waypoint (#50000 land).
    Land,
    /// Print FROM-TO-NEXT (#4001) as it changes.
    Monitor {
        /// Stop after this many seconds (default: until interrupted).
        #[arg(long, value_name = "S")]
        seconds: Option<u64>,
    },
    /// Decode captured frames: every message with every field in readable units.
    ///
    /// Each argument is one datagram in hex (spaces, colons and a 0x prefix are ignored); with no
    /// argument, one datagram per line of stdin (blank lines and lines starting with # are
    /// skipped). A datagram may hold several messages back to back. Exits 1 if any frame or
    /// message is rejected, printing the ICD rule it breaks.
    Inspect {
        /// One JSON object per message instead of text (the input format of `gcs encode`).
        #[arg(long)]
        json: bool,
        /// Apply the addressing rules of ICD §2 as the node with this ID (needs --peer-id).
        #[arg(long, value_parser = parse_id, requires = "peer_id")]
        local_id: Option<u32>,
        /// The configured peer whose frames are accepted (needs --local-id).
        #[arg(long, value_parser = parse_id, requires = "local_id")]
        peer_id: Option<u32>,
        /// Datagrams in hex.
        hex: Vec<String>,
    },
    /// Encode messages given as JSON (the objects `gcs inspect --json` prints) into hex frames.
    ///
    /// Each argument is one JSON object; with no argument, one object per line of stdin. Absent
    /// wrapper fields take the ICD defaults (source GCS 0x0A000001, destination FCC 0x0B000001,
    /// no ack, IDD 40, 4-byte checksum).
    Encode {
        /// Messages in JSON.
        json: Vec<String>,
    },
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

fn inspect(
    json: bool,
    addressing: Option<(u32, u32)>,
    hex: Vec<String>,
    out: &mut impl Write,
) -> io::Result<bool> {
    let mut all_ok = true;
    for (n, text) in inputs(hex)?.iter().enumerate() {
        let datagram = n + 1;
        let results = match parse_hex(text) {
            Ok(bytes) => inspect_datagram(&bytes, addressing),
            Err(e) => vec![Err(e)],
        };
        for (i, result) in results.into_iter().enumerate() {
            let message = i + 1;
            match result.and_then(|m| MessageJson::new(&m.envelope, &m.message, m.length)) {
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

fn open(config: &Config, gateway: SafetyGateway) -> Result<Link, String> {
    GcsLink::open(config, gateway).map_err(|e| e.to_string())
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
        Some("toml") => MissionFile::read(file)
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

/// Runs the link until the request ends; prints progress on a terminal.
fn finish(link: &mut Link) -> Result<Finished, Failure> {
    let progress = io::stderr().is_terminal();
    let outcome = link.finish(|event| {
        if let (true, GcsEvent::Progress { phase, sent, total }) = (progress, event) {
            eprint!("\r{phase}: {sent}/{total} messages   ");
        }
    });
    if progress {
        eprintln!();
    }
    outcome.map_err(|e| match e {
        GcsError::Upload(report) => Failure {
            status: upload_status(report.outcome()),
            message: report.to_string(),
            refused: Vec::new(),
        },
        other => other.to_string().into(),
    })
}

/// The exit status of `gcs upload` for each outcome (see the command's help).
fn upload_status(outcome: UploadOutcome) -> u8 {
    match outcome {
        UploadOutcome::Complete | UploadOutcome::CompleteAfterLostAnswer => 0,
        UploadOutcome::PreviousActive => 3,
        UploadOutcome::Mixed => 4,
        UploadOutcome::Unknown => 5,
        UploadOutcome::Foreign => 6,
    }
}

/// The FCC's report (ICD §8) as a table, one line per entry.
fn print_report(entries: &[MissionReport]) {
    println!(
        "{:<20} {:>9} {:>5} {:<24} {:<10} {:<10}",
        "mission", "waypoints", "areas", "geofence check", "mission", "areas"
    );
    let checksum = |c: Option<Checksum>| c.map_or_else(|| "-".to_owned(), |c| c.to_string());
    for e in entries {
        let name = match e.mission_id.as_ref().map(|t| t.as_str()) {
            None | Some("") => "(active)".to_owned(),
            Some(id) => id.to_owned(),
        };
        let check = match (e.geofence_check, e.reason) {
            (GeofenceCheck::NotRun, _) => "not run".to_owned(),
            (GeofenceCheck::Passed, _) => "passed".to_owned(),
            (GeofenceCheck::Failed, Some(r)) => format!("failed: {r}"),
            (GeofenceCheck::Failed, None) => "failed".to_owned(),
        };
        println!(
            "{:<20} {:>9} {:>5} {:<24} {:<10} {:<10}",
            name,
            e.waypoint_count,
            e.area_count,
            check,
            checksum(e.mission_checksum),
            checksum(e.area_checksum)
        );
    }
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
        Ok(lists) => {
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
                "energy_wh": energy.map(|e| serde_json::json!({ "total": e.total_wh, "limit": e.limit_wh })),
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
        if let Some(e) = energy {
            println!(
                "  energy: {:.0} Wh needed of {:.0} Wh usable after the reserve",
                e.total_wh, e.limit_wh
            );
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

fn mission_command(config: &Config, command: Command) -> Result<(), Failure> {
    match command {
        Command::Validate { file, json, safety } => validate(&file, json, &safety),
        Command::Upload { file, edit, safety } => {
            let gateway = safety.gateway()?;
            let plan = read_plan(&file, &safety)?.plan;
            let mut link = open(config, gateway)?;
            let now = link.now();
            link.station()
                .upload(now, &plan, !edit)
                .map_err(|e| format!("{}: {e}; nothing was sent", file.display()))?;
            if let Finished::Uploaded(report) = finish(&mut link)? {
                println!("{report}");
            }
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
                .map(|lists| ValidatedPlan {
                    mission: lists.mission,
                    areas: lists.areas,
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
                map::render(&valid, plan.take_off_position, &markers, &title),
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
        Command::Download { output } => {
            let mut link = open(config, SafetyGateway::default())?;
            let now = link.now();
            link.station().download(now).map_err(|e| e.to_string())?;
            let plan = finish(&mut link)?
                .into_plan()
                .ok_or("the download ended without lists")?;
            println!("downloaded {plan}");
            println!(
                "checksums (ICD §11): mission {}, areas {}",
                integrity::mission_checksum(&plan.mission),
                integrity::areas_checksum(&plan.areas)
            );
            if let Some(path) = output {
                // The FCC does not hold the take-off position: the file has none (its header
                // says so), and it must be added before the file is uploaded again.
                std::fs::write(&path, MissionFile::from_plan(&plan, None).to_toml())
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                println!(
                    "written to {} (without a take-off position: the FCC does not hold it)",
                    path.display()
                );
            }
            Ok(())
        }
        Command::Missions => {
            let mut link = open(config, SafetyGateway::default())?;
            let now = link.now();
            link.station().report(now).map_err(|e| e.to_string())?;
            let Finished::Reported(entries) = finish(&mut link)? else {
                return Err("the FCC sent no report".to_owned().into());
            };
            print_report(&entries);
            Ok(())
        }
        Command::Clear => {
            let mut link = open(config, SafetyGateway::default())?;
            let now = link.now();
            link.station()
                .clear_mission(now)
                .map_err(|e| e.to_string())?;
            finish(&mut link)?;
            println!("mission cleared");
            Ok(())
        }
        Command::ClearAreas | Command::Execute | Command::Rth | Command::Land => {
            let mut link = open(config, SafetyGateway::default())?;
            let now = link.now();
            let station = link.station();
            match command {
                Command::ClearAreas => station.clear_areas(now),
                Command::Execute => station.execute(now, ExecuteCommand::Execute),
                Command::Rth => station.execute(now, ExecuteCommand::ReturnToHome),
                _ => station.execute(now, ExecuteCommand::Land),
            }
            .map_err(|e| e.to_string())?;
            finish(&mut link)?;
            println!("accepted by the FCC");
            Ok(())
        }
        Command::Monitor { seconds } => {
            let mut link = open(config, SafetyGateway::default())?;
            let limit = seconds.map_or(Duration::MAX, Duration::from_secs);
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
                let _ = signal_hook::flag::register(signal, std::sync::Arc::clone(&stop));
            }
            let start = std::time::Instant::now();
            while start.elapsed() < limit && !stop.load(std::sync::atomic::Ordering::Relaxed) {
                link.run_until(Duration::from_millis(200), |event| {
                    if let GcsEvent::FromToNext(f) = event {
                        println!("{f}");
                    }
                    false
                });
            }
            Ok(())
        }
        Command::Inspect { .. } | Command::Encode { .. } => Ok(()),
    }
}

fn main() -> ExitCode {
    missionlink_partitions::init_logging();
    let cli = Cli::parse();
    if !matches!(
        cli.command,
        Command::Inspect { .. } | Command::Encode { .. }
    ) {
        let config = match cli.config.resolve() {
            Ok(c) => c,
            Err(e) => {
                eprintln!("gcs: {e}");
                return ExitCode::from(2);
            }
        };
        return match mission_command(&config, cli.command) {
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
            hex,
        } => inspect(json, local_id.zip(peer_id), hex, &mut out),
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
