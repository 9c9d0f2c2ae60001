//! `demo`: the paper's medical evacuation demo (section 4), end to end, with no configuration.
//!
//! It starts the FCC (the `fcc` launcher and its four partitions, separate processes sharing
//! iceoryx2 services under a fresh prefix, on UDP ports the system chooses), then acts as the GCS: validates
//! (ICD §7 and the safety gateway with the demo eVTOL's profile) and uploads mission 1 (TROL to CCP) with its fly-zone and prints the message sequence as the
//! paper's Figure 15 does; executes it (time-scaled) and prints each FROM-TO-NEXT change; while
//! mission 1 flies, stages the richer mission 2 (radius-to-fix leg, circle and polygon
//! no-fly-zones, bidirectional route) under a Mission ID (ICD §8: the paper's future work,
//! "multiple missions defined prior to flight") and prints the FCC's report; once the aircraft
//! has landed, activates it (both lists in one step) and flies it; downloads mission and areas
//! and shows that they equal the upload; prints the per-frame latency percentiles of every
//! partition; shuts all down.
//! Exit status 0 on success, 1 with the error otherwise.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::Parser;
use missionlink::harness::binaries;
use missionlink::harness::fcc::{FccProcess, local_config};
use missionlink_gcs::gcs_link::{Direction, Finished, GcsLink, Logged};
use missionlink_gcs::mission_file::MissionFile;
use missionlink_gcs::pcap::PcapWriter;
use missionlink_gcs::report_table;
use missionlink_ground::ground_station::outcome::UploadOutcome;
use missionlink_ground::ground_station::{GcsError, GcsEvent, MissionPlan};
use missionlink_ground::safety_gateway::{Report, SafetyGateway};
use missionlink_interfaces::wire::{ExecuteCommand, Message, Reason};
use missionlink_partitions::latency;
use missionlink_partitions::launcher;
use missionlink_platform::udp::LocalEnds;
use missionlink_protocol::transfer::integrity;
use missionlink_protocol::transfer::staged::MissionId;

const MISSION_1: &str = include_str!("../../missions/mission-1.toml");
const MISSION_2: &str = include_str!("../../missions/mission-2.toml");
/// The Mission ID mission 2 is staged under (ICD §8).
const MISSION_2_ID: &str = "MEDEVAC-2";

/// The paper's demo, end to end.
#[derive(Debug, Parser)]
#[command(name = "demo", version)]
struct Args {
    /// Simulated seconds per second of the flights.
    #[arg(long, default_value_t = 20.0)]
    time_scale: f64,
    /// Where the partition binaries are (default: next to this one).
    #[arg(long, value_name = "DIR")]
    bin_dir: Option<PathBuf>,
    /// Write every datagram the GCS sends and receives on both links to FILE (pcap, UDP over
    /// IPv4 with the real ports; open it with tools/wireshark/missionlink.lua).
    #[arg(long, value_name = "FILE")]
    pcap: Option<PathBuf>,
}

type Link = GcsLink<SafetyGateway>;

/// How long the FCC may take to start (a debug build on a busy machine is slow).
const STARTUP: Duration = Duration::from_secs(20);

/// The message sequence of `log` from `from`, as the paper's Figure 15 lists a transfer.
fn print_sequence(log: &[Logged], from: usize) {
    let Some(start) = log.get(from).map(|l| l.at) else {
        return;
    };
    println!("      time   direction  message");
    for l in log.get(from..).unwrap_or_default() {
        if matches!(l.message, Message::FromToNext(_)) {
            continue;
        }
        let dir = match l.direction {
            Direction::Up => "GCS -> FCC",
            Direction::Down => "FCC -> GCS",
        };
        println!(
            "  {:>7.1} ms  {dir}  {}",
            (l.at - start).as_secs_f64() * 1000.0,
            l.message
        );
    }
}

fn plan(text: &str, name: &str) -> Result<MissionPlan, String> {
    MissionFile::parse(text)
        .and_then(|f| f.to_plan().map(|p| *p))
        .map_err(|e| format!("{name}: {e}"))
}

/// Runs the link until the request in progress ends; prints FROM-TO-NEXT changes meanwhile.
fn finish(link: &mut Link) -> Result<Finished, GcsError<Report>> {
    link.finish(|event| {
        if let GcsEvent::FromToNext(f) = event {
            println!("  {f}");
        }
    })
}

/// Uploads `plan`; while the FCC still flies the previous mission its clear is refused
/// (`GuidanceActive`, and the GCS confirms that the previous lists are still active), and the
/// upload is tried again until the aircraft has landed. Prints the upload's outcome with the
/// checksums (ICD §11); returns the time the successful attempt took and where its messages
/// start in the log.
fn upload(
    link: &mut Link,
    plan: &MissionPlan,
    patience: Duration,
) -> Result<(Duration, usize), String> {
    let deadline = Instant::now() + patience;
    let mut told = false;
    loop {
        let start = Instant::now();
        let from = link.log.len();
        let now = link.now();
        link.station()
            .upload(now, plan, true)
            .map_err(|e| e.to_string())?;
        match finish(link) {
            Ok(finished) => {
                let took = start.elapsed();
                if let Finished::Uploaded(report) = finished {
                    println!("  {report}");
                }
                return Ok((took, from));
            }
            Err(GcsError::Upload(report))
                if report.outcome() == UploadOutcome::PreviousActive
                    && report
                        .failure
                        .is_some_and(|(_, e)| e.reason() == Some(Reason::GuidanceActive))
                    && Instant::now() < deadline =>
            {
                if !told {
                    println!(
                        "  the FCC still flies: clear refused (GuidanceActive); waiting for the landing"
                    );
                    told = true;
                }
                link.run_until(Duration::from_millis(500), |event| {
                    if let GcsEvent::FromToNext(f) = event {
                        println!("  {f}");
                    }
                    false
                });
            }
            Err(e) => return Err(e.to_string()),
        }
    }
}

/// Executes the active mission. Right after the FCC started, system automation may not have
/// heard guidance's heartbeat yet, or mission data handling guidance's first position
/// (docs/design.md "Health", ICD §7): the FCC refuses with `WrongState` and changes nothing, and
/// execute is asked again every 200 ms for up to 10 s.
fn execute(link: &mut Link) -> Result<(), String> {
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut told = false;
    loop {
        let now = link.now();
        link.station()
            .execute(now, ExecuteCommand::Execute)
            .map_err(|e| e.to_string())?;
        match finish(link) {
            Ok(_) => return Ok(()),
            Err(GcsError::Transfer { error, .. })
                if error.reason() == Some(Reason::WrongState) && Instant::now() < deadline =>
            {
                if !told {
                    println!(
                        "  execute refused (WrongState): guidance not heard yet; asking again"
                    );
                    told = true;
                }
                link.run_until(Duration::from_millis(200), |_| false);
            }
            Err(e) => return Err(e.to_string()),
        }
    }
}

/// Activates the staged mission `id` (ICD §8, #50000 command 4). Until the aircraft has landed
/// (trajectory generation active) the FCC refuses it (`WrongState`) and changes nothing; it is
/// asked again every 500 ms for up to `patience`. Returns the time the accepted request took.
fn activate(link: &mut Link, id: MissionId, patience: Duration) -> Result<Duration, String> {
    let deadline = Instant::now() + patience;
    let mut told = false;
    loop {
        let start = Instant::now();
        let now = link.now();
        link.station()
            .activate(now, id)
            .map_err(|e| e.to_string())?;
        match finish(link) {
            Ok(_) => return Ok(start.elapsed()),
            Err(GcsError::Staged { error, .. })
                if error.reason() == Some(Reason::WrongState) && Instant::now() < deadline =>
            {
                if !told {
                    println!(
                        "  the FCC still flies: activation refused (WrongState); waiting for the landing"
                    );
                    told = true;
                }
                link.run_until(Duration::from_millis(500), |_| false);
            }
            Err(e) => return Err(e.to_string()),
        }
    }
}

/// Asks the FCC for its report (ICD §8) and prints it as `gcs missions` does.
fn print_missions(link: &mut Link) -> Result<(), String> {
    let now = link.now();
    link.station().report(now).map_err(|e| e.to_string())?;
    let Finished::Reported(entries) = finish(link).map_err(|e| e.to_string())? else {
        return Err("the report request ended without a report".to_owned());
    };
    for line in report_table::render(&entries).lines() {
        println!("  {line}");
    }
    Ok(())
}

/// Prints FROM-TO-NEXT until the route is flown (TO and NEXT none).
fn fly(link: &mut Link, limit: Duration) -> Result<(), String> {
    let done = link.run_until(limit, |event| match event {
        GcsEvent::FromToNext(f) => {
            println!("  {f}");
            f.to.waypoint_number == Some(0) && f.from.waypoint_number.is_some_and(|n| n != 0)
        }
        _ => false,
    });
    if done {
        Ok(())
    } else {
        Err(format!(
            "the route was not flown within {} s",
            limit.as_secs()
        ))
    }
}

fn run(args: &Args) -> Result<(), String> {
    let started = Instant::now();
    let bin_dir = args
        .bin_dir
        .clone()
        .or_else(binaries::build_dir)
        .ok_or("cannot find the partition binaries: give --bin-dir")?;
    let absent = binaries::missing(&bin_dir, &binaries::FCC_BINARIES);
    if !absent.is_empty() {
        // On a fresh clone: the first run builds them, which takes a while.
        println!(
            "building the partition binaries ({}) ...",
            absent.join(", ")
        );
    }
    let bin_dir = binaries::ensure(
        &bin_dir,
        &binaries::FCC_BINARIES,
        binaries::Build::UnderCargo,
    )?;
    let run_dir = std::env::temp_dir().join(format!("missionlink-demo-{}", std::process::id()));
    std::fs::create_dir_all(&run_dir).map_err(|e| e.to_string())?;
    // The GCS binds its ends (port 0) and tells the FCC; voting-monitoring binds the FCC's and
    // announces them: every port is chosen by the process that binds it.
    let gcs_ends = LocalEnds::bind_loopback().map_err(|e| e.to_string())?;
    let prefix = format!("demo-{}", std::process::id());
    let mut config = local_config(&run_dir, prefix, &gcs_ends).map_err(|e| e.to_string())?;
    config.guidance.time_scale = args.time_scale;
    // The links are signed (ICD §9) with the key `local_config` made for this run: every frame
    // on both links, both ways, and each side requires it (the default policy).

    println!(
        "missionlink demo: medical evacuation after Heimsch et al. (Aerospace 2024), section 4"
    );
    let mut fcc =
        FccProcess::start(&bin_dir, launcher::NAME, &config, None).map_err(|e| e.to_string())?;
    // Every partition's services open before the GCS sends: a frame published before its
    // subscriber exists would be lost.
    if !fcc.wait_ready(STARTUP) {
        return Err(format!(
            "the FCC's partitions were not all up within {} s",
            STARTUP.as_secs()
        ));
    }
    fcc.links(STARTUP)
        .ok_or("the FCC did not announce its links")?
        .apply(&mut config.links);
    println!(
        "FCC: 4 partitions, iceoryx2 prefix {:?}; links: direct {}, LTE {}; time scale {}x\n",
        config.ipc.service_prefix, config.links.fcc_direct, config.links.fcc_lte, args.time_scale
    );
    println!(
        "Links signed (ICD §9): HMAC-SHA-256 with key 1, made for this run; both sides require it\n"
    );
    let mut links = gcs_ends
        .connect(config.links.fcc_direct, config.links.fcc_lte)
        .map_err(|e| e.to_string())?;
    if let Some(path) = &args.pcap {
        let capture = PcapWriter::create(path)
            .map_err(|e| format!("cannot write the capture {}: {e}", path.display()))?;
        links = links
            .with_tap(Arc::new(capture))
            .map_err(|e| e.to_string())?;
    }
    let mut link = GcsLink::with_links(&config.link(), links, SafetyGateway::default())
        .map_err(|e| e.to_string())?;
    link.enable_log();

    let mission_1 = plan(MISSION_1, "missions/mission-1.toml")?;
    let mission_2 = plan(MISSION_2, "missions/mission-2.toml")?;

    println!("1. Validate and upload mission 1 (TROL -> CCP) and its fly-zone");
    let valid_1 = link
        .station()
        .validate(&mission_1)
        .map_err(|e| e.to_string())?;
    println!(
        "  valid (ICD §7 and the safety gateway: geography, geometry, route, energy): {} waypoint, {} area",
        valid_1.mission.waypoints.len(),
        valid_1.areas.areas.len()
    );
    let (took, from) = upload(&mut link, &mission_1, Duration::from_secs(5))?;
    print_sequence(&link.log, from);
    println!(
        "  mission 1 transfer: {:.1} ms for {} messages (the paper reports about 400 ms)\n",
        took.as_secs_f64() * 1000.0,
        link.log.len() - from
    );

    println!("2. Execute mission 1, and stage mission 2 while it flies (ICD §8)");
    execute(&mut link)?;
    let valid_2 = link
        .station()
        .validate(&mission_2)
        .map_err(|e| e.to_string())?;
    let id = MissionId::new(MISSION_2_ID).map_err(|e| e.to_string())?;
    let start = Instant::now();
    let from = link.log.len();
    let now = link.now();
    link.station()
        .stage(now, id, &mission_2)
        .map_err(|e| e.to_string())?;
    match finish(&mut link).map_err(|e| e.to_string())? {
        Finished::Uploaded(report) => println!("  {report}"),
        other => return Err(format!("staging ended without its report: {other:?}")),
    }
    let sent = link
        .log
        .get(from..)
        .unwrap_or_default()
        .iter()
        .filter(|l| l.direction == Direction::Up)
        .count();
    println!(
        "  mission 2 (CCP -> W1 -> ROLE2: radius-to-fix leg, circle and polygon no-fly-zones, bidirectional) staged as {id:?} in {:.1} ms, {sent} messages up, {} down; mission 1 flies on",
        start.elapsed().as_secs_f64() * 1000.0,
        link.log.len() - from - sent
    );
    print_missions(&mut link)?;
    fly(&mut link, Duration::from_secs(60))?;
    println!();

    println!("3. Landed: activate mission 2 (waypoints and areas replaced in one step)");
    let took = activate(&mut link, id, Duration::from_secs(120))?;
    println!(
        "  #50000 command 4 accepted in {:.1} ms",
        took.as_secs_f64() * 1000.0
    );
    print_missions(&mut link)?;
    println!();

    println!("4. Execute mission 2");
    execute(&mut link)?;
    fly(&mut link, Duration::from_secs(90))?;
    println!();

    println!("5. Download mission and areas");
    let now = link.now();
    link.station().download(now).map_err(|e| e.to_string())?;
    let downloaded = finish(&mut link)
        .map_err(|e| e.to_string())?
        .into_plan()
        .ok_or("the download ended without lists")?;
    if downloaded != valid_2 {
        return Err(format!(
            "the download differs from the upload:\n  up:   {valid_2:?}\n  down: {downloaded:?}"
        ));
    }
    println!(
        "  {} waypoints, {} areas: equal to the upload, every field (checksums: mission {}, areas {}, as the FCC sent them)\n",
        downloaded.mission.waypoints.len(),
        downloaded.areas.areas.len(),
        integrity::mission_checksum(&downloaded.mission),
        integrity::areas_checksum(&downloaded.areas),
    );

    println!(
        "6. Shut down; per-frame latency of the partitions (a debug build is several times slower than --release)"
    );
    fcc.stop().map_err(|e| e.to_string())?;
    let voted = link.voter();
    println!(
        "  link signing on the ground: {} downlink frames verified, {} rejected, {} sent \
         before the ground started (dropped, no attack)",
        voted.signatures().stats().verified,
        voted.stats().rejected_signatures.total(),
        voted.stats().before_start
    );
    println!(
        "  {:<22} {:<45} {:>6} {:>9} {:>9} {:>9} {:>9}",
        "partition", "measured", "frames", "p50 us", "p99 us", "p99.9 us", "max us"
    );
    for summary in latency::read_summaries(&run_dir.join("latency")) {
        for l in summary.latencies.iter().filter(|l| l.count > 0) {
            println!(
                "  {:<22} {:<45} {:>6} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                summary.partition, l.name, l.count, l.p50_us, l.p99_us, l.p999_us, l.max_us
            );
        }
    }
    let _ = std::fs::remove_dir_all(&run_dir);
    println!(
        "\ndemo complete in {:.1} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn main() -> ExitCode {
    missionlink_platform::init_logging_at("error");
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("demo failed: {e}");
            ExitCode::FAILURE
        }
    }
}
