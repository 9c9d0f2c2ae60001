//! `gcs`: the ground control station tool. Mission commands over the two UDP links (validate,
//! upload, download, clear, execute, return to home, land, monitor), driving the GCS logic of
//! paper Figure 11, and the frame inspector (`inspect`, `encode`) for captured traffic.

use std::io::{self, BufRead, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand};
use missionlink_interfaces::wire::{
    AreaTransferMode, AreaTransmissionCommand, ExecuteCommand, Message, MissionExecuteCommand,
    Timestamp,
};
use missionlink_partitions::config::{Config, ConfigArgs, parse_id};
use missionlink_partitions::gcs_link::{GcsLink, describe_from_to_next};
use missionlink_partitions::inspect::{
    MessageJson, encode_json, inspect_datagram, parse_hex, render_text,
};
use missionlink_partitions::mission_file::MissionFile;
use missionlink_services::gcs::{GcsEvent, MissionPlan, ValidatedPlan, WithoutGateway};

/// Ground control station of missionlink: STANAG 4586 mission and area transfer.
#[derive(Debug, Parser)]
#[command(name = "gcs", version, about)]
struct Cli {
    #[command(flatten)]
    config: ConfigArgs,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Check a mission file: assemble the waypoint and area lists and apply the checks of ICD §7
    /// (and the safety gateway). Exit status 0 only for a valid mission.
    Validate {
        /// Mission file (TOML, see missions/).
        file: PathBuf,
    },
    /// Validate, then upload the waypoints, then the areas (paper Figure 11).
    Upload {
        /// Mission file (TOML).
        file: PathBuf,
        /// Edit the active mission: send no clear, only the waypoints of the file change.
        #[arg(long)]
        edit: bool,
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

type Link = GcsLink<WithoutGateway>;

fn open(config: &Config) -> Result<Link, String> {
    GcsLink::open(config, WithoutGateway).map_err(|e| e.to_string())
}

fn read_plan(file: &Path) -> Result<MissionPlan, String> {
    MissionFile::read(file)
        .and_then(|f| f.to_plan())
        .map_err(|e| format!("{}: {e}", file.display()))
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

fn summary(plan: &ValidatedPlan) -> String {
    let m = &plan.mission;
    let route: Vec<String> = m
        .waypoints
        .iter()
        .map(|r| r.waypoint.waypoint_number.to_string())
        .collect();
    format!(
        "mission {:?}: take-off {:.1} m, {} waypoints ({}), route {}; {} areas, safety offset {:.1} m",
        m.mission_id
            .map(|t| t.as_str().to_owned())
            .unwrap_or_default(),
        m.take_off_height().metres(),
        m.waypoints.len(),
        route.join(" -> "),
        if m.route.bidirectional {
            "bidirectional"
        } else {
            "one-way"
        },
        plan.areas.areas.len(),
        plan.areas.safety_offset.metres(),
    )
}

fn mission_command(config: &Config, command: Command) -> Result<(), String> {
    match command {
        Command::Validate { file } => {
            let plan = read_plan(&file)?;
            let gcs = missionlink_services::gcs::GroundStation::new(
                missionlink_services::gcs::GcsConfig {
                    endpoint: missionlink_services::endpoint::EndpointConfig {
                        local_id: config.ids.gcs,
                        peer_id: config.ids.fcc,
                        utc_at_zero: Default::default(),
                        sampling_window: config.timing.transfer_timeout(),
                    },
                    ack_timeout: config.timing.ack_timeout(),
                    transfer_timeout: config.timing.transfer_timeout(),
                },
                WithoutGateway,
            );
            let valid = gcs
                .validate(&plan)
                .map_err(|e| format!("{}: {e}", file.display()))?;
            println!("{}: valid. {}", file.display(), summary(&valid));
            Ok(())
        }
        Command::Upload { file, edit } => {
            let plan = read_plan(&file)?;
            let mut link = open(config)?;
            let now = link.now();
            link.station()
                .upload(now, &plan, !edit)
                .map_err(|e| format!("{}: {e}", file.display()))?;
            finish(&mut link)?;
            println!("upload complete: waypoints and areas are active on the FCC");
            Ok(())
        }
        Command::Download { output } => {
            let mut link = open(config)?;
            let now = link.now();
            link.station().download(now).map_err(|e| e.to_string())?;
            let plan = finish(&mut link)?.ok_or("the download ended without lists")?;
            println!("downloaded {}", summary(&plan));
            if let Some(path) = output {
                std::fs::write(&path, MissionFile::from_plan(&plan).to_toml())
                    .map_err(|e| format!("{}: {e}", path.display()))?;
                println!("written to {}", path.display());
            }
            Ok(())
        }
        Command::Clear => {
            let mut link = open(config)?;
            let now = link.now();
            link.station()
                .clear_mission(now)
                .map_err(|e| e.to_string())?;
            finish(&mut link)?;
            println!("mission cleared");
            Ok(())
        }
        Command::ClearAreas | Command::Execute | Command::Rth | Command::Land => {
            let message: Message = match command {
                Command::ClearAreas => AreaTransmissionCommand {
                    time_stamp: Timestamp::default(),
                    mode: AreaTransferMode::ClearAreas,
                    loop_count: None,
                    area_id: None,
                    safety_offset: None,
                    activity_id: None,
                }
                .into(),
                other => MissionExecuteCommand {
                    time_stamp: Timestamp::default(),
                    command: match other {
                        Command::Execute => ExecuteCommand::Execute,
                        Command::Rth => ExecuteCommand::ReturnToHome,
                        _ => ExecuteCommand::Land,
                    },
                }
                .into(),
            };
            let mut link = open(config)?;
            let now = link.now();
            link.station()
                .command(now, message)
                .map_err(|e| e.to_string())?;
            finish(&mut link)?;
            println!("accepted by the FCC");
            Ok(())
        }
        Command::Monitor { seconds } => {
            let mut link = open(config)?;
            let limit = seconds.map_or(Duration::MAX, Duration::from_secs);
            let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
            for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
                let _ = signal_hook::flag::register(signal, std::sync::Arc::clone(&stop));
            }
            let start = std::time::Instant::now();
            while start.elapsed() < limit && !stop.load(std::sync::atomic::Ordering::Relaxed) {
                link.run_until(Duration::from_millis(200), |event| {
                    if let GcsEvent::FromToNext(f) = event {
                        println!("{}", describe_from_to_next(f));
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
