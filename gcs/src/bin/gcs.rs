//! `gcs`: the ground control station tool. Mission commands over the two UDP links (validate,
//! upload, download, clear, execute, return to home, land, monitor), driving the GCS logic of
//! paper Figure 11, and the frame inspector (`inspect`, `encode`) for captured traffic.

use std::io::{self, BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use missionlink_gcs::gcs_link::GcsLink;
use missionlink_gcs::inspect::{
    MessageJson, encode_json, inspect_datagram, parse_hex, render_text,
};
use missionlink_gcs::mission_file::MissionFile;
use missionlink_gcs::{geojson, map, profile, qgc};
use missionlink_interfaces::wire::{ExecuteCommand, SafetyOffset};
use missionlink_partitions::config::{Config, ConfigArgs, parse_id};
use missionlink_services::ground_station::{GcsEvent, MissionPlan, ValidatedPlan};
use missionlink_services::safety_gateway::{SafetyGateway, Violation};

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
    /// gateway and print every violation. Exit status 0 only for a feasible mission.
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

/// The safety gateway's inputs (paper §2.2) and the sources of areas.
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
}

impl SafetyArgs {
    fn gateway(&self) -> Result<SafetyGateway, String> {
        let profile = profile::aircraft(self.profile.as_deref())?;
        let mut environment = profile::environment(self.environment.as_deref())?;
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
}

fn note(file: &Path, n: &impl std::fmt::Display) {
    eprintln!("{}: note: {n}", file.display());
}

/// Reads a mission by its extension, with the areas of `--areas` if given. Items a .plan holds
/// that this system does not fly are printed as notes, each with its index.
fn read_plan(file: &Path, safety: &SafetyArgs) -> Result<MissionPlan, String> {
    let at = |e: &dyn std::fmt::Display| format!("{}: {e}", file.display());
    let mut plan = match file.extension().and_then(|e| e.to_str()) {
        Some("plan") => {
            let text = std::fs::read_to_string(file).map_err(|e| at(&e))?;
            let options = qgc::ImportOptions {
                safety_offset_m: safety.safety_offset_m.unwrap_or(0.0),
                ..Default::default()
            };
            let import = qgc::import_plan(&text, &options).map_err(|e| at(&e))?;
            for n in &import.notes {
                note(file, n);
            }
            import.plan
        }
        Some("toml") => MissionFile::read(file)
            .and_then(|f| f.to_plan())
            .map_err(|e| at(&e))?,
        _ => {
            return Err(at(
                &"a mission file is .toml (missionlink) or .plan (QGroundControl)",
            ));
        }
    };
    if let Some(areas) = &safety.areas {
        let text =
            std::fs::read_to_string(areas).map_err(|e| format!("{}: {e}", areas.display()))?;
        let (buffer, notes) =
            geojson::import_areas(&text).map_err(|e| format!("{}: {e}", areas.display()))?;
        for n in &notes {
            note(areas, n);
        }
        plan.areas = buffer;
    }
    if let Some(m) = safety.safety_offset_m {
        plan.safety_offset = SafetyOffset::from_metres(m).map_err(|e| e.to_string())?;
    }
    Ok(plan)
}

/// The lists of ICD §7, assembled with the FCC's own code.
fn assemble(plan: &MissionPlan, file: &Path) -> Result<ValidatedPlan, String> {
    plan.assemble()
        .map_err(|e| format!("{}: {e}", file.display()))
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
fn finish(link: &mut Link) -> Result<Option<ValidatedPlan>, String> {
    let progress = io::stderr().is_terminal();
    let outcome = link.finish(|event| {
        if let (true, GcsEvent::Progress { phase, sent, total }) = (progress, event) {
            eprint!("\r{phase}: {sent}/{total} messages   ");
        }
    });
    if progress {
        eprintln!();
    }
    outcome.map_err(|e| e.to_string())
}

fn mission_command(config: &Config, command: Command) -> Result<(), String> {
    match command {
        Command::Validate { file, json, safety } => {
            let gateway = safety.gateway()?;
            let plan = read_plan(&file, &safety)?;
            let valid = match assemble(&plan, &file) {
                Ok(v) => v,
                Err(e) if json => {
                    println!(
                        "{}",
                        serde_json::json!({ "file": file, "feasible": false, "error": e })
                    );
                    return Err(e);
                }
                Err(e) => return Err(e),
            };
            let violations =
                gateway.violations(&valid.mission, &valid.areas, plan.take_off_position);
            let energy = gateway.estimate_energy(&valid.mission, plan.take_off_position);
            if json {
                println!(
                    "{}",
                    serde_json::json!({
                        "file": file,
                        "feasible": violations.is_empty(),
                        "summary": valid.to_string(),
                        "energy_wh": { "total": energy.total_wh, "limit": energy.limit_wh },
                        "violations": violations.iter().map(violation_json).collect::<Vec<_>>(),
                    })
                );
            } else {
                println!("{}: {valid}", file.display());
                println!(
                    "  energy: {:.0} Wh needed of {:.0} Wh usable after the reserve",
                    energy.total_wh, energy.limit_wh
                );
                for v in &violations {
                    println!("  {v}");
                }
            }
            if violations.is_empty() {
                if !json {
                    println!("  feasible: every check of the safety gateway passes");
                }
                Ok(())
            } else {
                Err(format!(
                    "{}: infeasible: {} violation{}",
                    file.display(),
                    violations.len(),
                    if violations.len() == 1 { "" } else { "s" }
                ))
            }
        }
        Command::Upload { file, edit, safety } => {
            let plan = read_plan(&file, &safety)?;
            let mut link = open(config, safety.gateway()?)?;
            let now = link.now();
            link.station()
                .upload(now, &plan, !edit)
                .map_err(|e| format!("{}: {e}; nothing was sent", file.display()))?;
            finish(&mut link)?;
            println!("upload complete: waypoints and areas are active on the FCC");
            Ok(())
        }
        Command::Map {
            file,
            output,
            safety,
        } => {
            let gateway = safety.gateway()?;
            let plan = read_plan(&file, &safety)?;
            let valid = assemble(&plan, &file)?;
            let markers: Vec<map::Marker> = gateway
                .violations(&valid.mission, &valid.areas, plan.take_off_position)
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
            std::fs::write(&output, map::render(&valid, &markers, &title))
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
            let plan = read_plan(&input, &safety)?;
            let valid = assemble(&plan, &input)?;
            let text = match output.extension().and_then(|e| e.to_str()) {
                Some("toml") => MissionFile::from_plan(&valid).to_toml(),
                Some("plan") => {
                    let (text, notes) = qgc::export_plan(&valid, &qgc::ExportOptions::default());
                    for n in &notes {
                        note(&output, n);
                    }
                    text
                }
                Some("geojson" | "json") => geojson::export_areas(&valid.areas),
                _ => {
                    return Err(format!(
                        "{}: write .toml, .plan or .geojson",
                        output.display()
                    ));
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
            let plan = finish(&mut link)?.ok_or("the download ended without lists")?;
            println!("downloaded {plan}");
            if let Some(path) = output {
                std::fs::write(&path, MissionFile::from_plan(&plan).to_toml())
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                println!("written to {}", path.display());
            }
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
            Err(e) => {
                eprintln!("gcs: {e}");
                ExitCode::FAILURE
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
