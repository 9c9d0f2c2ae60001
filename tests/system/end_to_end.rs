//! End to end through the real binaries: the FCC partitions as separate processes sharing
//! iceoryx2 services, the GCS over the two UDP links. Every test has its own service prefix,
//! ports and state directory (tests/common), so they run in parallel.

use std::time::{Duration, Instant};

use iceoryx2::prelude::ipc;
use missionlink::harness::fcc::FccProcess;
use missionlink::harness::*;
use missionlink_ground::ground_station::outcome::UploadOutcome;
use missionlink_ground::ground_station::{GcsError, Phase, Sequence};
use missionlink_interfaces::contracts::{AreaListPayload, FccService, WaypointListPayload};
use missionlink_interfaces::wire::{self, Envelope, MAX_FRAME_LEN};
use missionlink_partitions::ipc::Ipc;

fn same_waypoints(a: &WaypointListPayload, b: &WaypointListPayload) -> bool {
    a.generation == b.generation
        && a.take_off_height == b.take_off_height
        && a.initial_waypoint == b.initial_waypoint
        && a.bidirectional == b.bidirectional
        && a.waypoints() == b.waypoints()
}

fn same_areas(a: &AreaListPayload, b: &AreaListPayload) -> bool {
    a.generation == b.generation
        && a.safety_offset == b.safety_offset
        && a.fly_zone == b.fly_zone
        && a.no_fly_polygons() == b.no_fly_polygons()
        && a.no_fly_circles() == b.no_fly_circles()
}

#[test]
fn upload_then_download_over_udp_through_all_partitions_gives_back_the_same_lists() {
    let (_rig, _fcc, mut link) = Rig::with_gcs("roundtrip");
    for file in ["mission-1.toml", "mission-2.toml"] {
        let plan = plan(file);
        let valid = link.station().validate(&plan).unwrap();
        upload(&mut link, &plan).unwrap_or_else(|e| panic!("{file}: {e}"));
        let downloaded = download(&mut link).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(downloaded, valid, "{file}");
    }
    // The atomic upload of `gcs upload` (staged, activated, the staged copy deleted) too: the
    // download gives back every field, the operator's Mission ID included.
    for file in ["mission-1.toml", "mission-2.toml"] {
        let plan = plan(file);
        let valid = link.station().validate(&plan).unwrap();
        let now = link.now();
        link.station()
            .upload_with(now, &plan, Sequence::Atomic)
            .unwrap();
        finish(&mut link).unwrap_or_else(|e| panic!("{file}: {e}"));
        let downloaded = download(&mut link).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(downloaded, valid, "{file}, atomic upload");
        assert!(
            downloaded
                .mission
                .mission_id
                .is_some_and(|id| id.as_str().starts_with("MEDEVAC-"))
        );
    }
}

#[test]
fn guidance_receives_exactly_the_assembled_lists_even_when_started_late() {
    let mut rig = Rig::new("late-guidance");
    let mut vm = rig.start("voting-monitoring");
    let mut mdh = rig.start("mission-data-handling");
    let mut sa = rig.start("system-automation");
    for partition in [&mut vm, &mut mdh, &mut sa] {
        rig.ready(partition);
    }
    let mut link = rig.gcs(&mut vm);
    let config = rig.config.clone();
    let plan = plan("mission-2.toml");
    let valid = link.station().validate(&plan).unwrap();
    upload(&mut link, &plan).unwrap();

    // Guidance starts after the lists were published: the history of the services gives them.
    let guidance = rig.start("guidance-stub");
    wait_for_log(
        &guidance,
        "waypoint list received generation=1 waypoints=3",
        Duration::from_secs(20),
    );
    wait_for_log(
        &guidance,
        "area list received generation=1 areas=3",
        Duration::from_secs(5),
    );

    // A subscriber started late, here, gets exactly the assembled lists.
    let late = Ipc::<ipc::Service>::open("late-subscriber", &config.ipc).unwrap();
    let waypoints = late
        .subscriber::<WaypointListPayload>(FccService::WaypointList)
        .unwrap();
    let areas = late
        .subscriber::<AreaListPayload>(FccService::AreaList)
        .unwrap();
    let w = eventually(Duration::from_secs(5), || waypoints.latest()).expect("waypoint list");
    let a = eventually(Duration::from_secs(5), || areas.latest()).expect("area list");
    assert!(same_waypoints(&w, &valid.mission.to_payload(1)), "{w:?}");
    assert!(same_areas(&a, &valid.areas.to_payload(1)), "{a:?}");
}

#[test]
fn kill_9_of_mission_data_handling_mid_upload_aborts_restarts_and_keeps_what_was_active() {
    let mut rig = Rig::new("kill9");
    // One attempt: this test is about the abort; a second one would complete the upload on the
    // restarted partition (tests/system/link_faults.rs).
    rig.config.timing.upload_attempts = 1;
    // Stop and wait: the kill below comes after the fourth message up, which then means that
    // the clear was answered. With a window above 1 the clear and the data go together (ICD
    // §10.3), and the kill may come before the clear arrived (the previous lists then stay).
    rig.config.timing.transfer_window = 1;
    let mut fcc = rig.start_fcc();
    let mut link = rig.gcs(&mut fcc);
    let config = rig.config.clone();
    let mission_1 = plan("mission-1.toml");
    let mission_2 = plan("mission-2.toml");
    let valid_1 = link.station().validate(&mission_1).unwrap();
    let valid_2 = link.station().validate(&mission_2).unwrap();
    upload(&mut link, &mission_1).unwrap();

    // Watch the waypoint list guidance sees, all along.
    let watch = Ipc::<ipc::Service>::open("watch", &config.ipc).unwrap();
    let seen = watch
        .subscriber::<WaypointListPayload>(FccService::WaypointList)
        .unwrap();
    let mut lists = Vec::new();
    let observe = |lists: &mut Vec<WaypointListPayload>| {
        seen.for_each(|l| lists.push(*l));
    };
    eventually(Duration::from_secs(5), || {
        observe(&mut lists);
        (!lists.is_empty()).then_some(())
    })
    .expect("the list of mission 1");

    // Start uploading mission 2 by the paper's sequence; after the clear (which deletes mission
    // 1, ICD §5.1), the take-off height and two waypoints, kill mission data handling.
    link.enable_log();
    let now = link.now();
    link.station().upload(now, &mission_2, true).unwrap();
    while link
        .log
        .iter()
        .filter(|l| l.direction == missionlink_gcs::gcs_link::Direction::Up)
        .count()
        < 4
    {
        link.pump(Duration::from_millis(5));
    }
    signal_partition(&fcc, "mission-data-handling", rustix::process::Signal::KILL);

    // The GCS reports the abort after its retry, naming the message, then asks the FCC what is
    // active (ICD §11): no mission (its clear deleted it), or unknown while the partition is
    // still down.
    let outcome = finish(&mut link);
    let Err(GcsError::Upload(report)) = &outcome else {
        panic!("the upload did not fail: {outcome:?}");
    };
    assert!(
        matches!(report.failure, Some((Phase::MissionUpload, _))),
        "{report}"
    );
    assert!(
        matches!(
            report.outcome(),
            UploadOutcome::NoMission | UploadOutcome::Unknown
        ),
        "{report}"
    );
    eprintln!("the GCS reported: {report}");
    // The launcher restarted the partition, which resumed with what was active: no mission, the
    // areas of mission 1.
    wait_for_log(&fcc, "partition died", Duration::from_secs(5));
    assert!(
        fcc.log_text().contains("killed by signal 9"),
        "{}",
        fcc.log_text()
    );
    wait_for_log(
        &fcc,
        "resumed with the lists active before the restart",
        Duration::from_secs(10),
    );
    observe(&mut lists);

    // The next upload succeeds.
    upload(&mut link, &mission_2).unwrap();
    assert_eq!(download(&mut link).unwrap(), valid_2);
    eventually(Duration::from_secs(5), || {
        observe(&mut lists);
        lists.last().is_some_and(|l| l.count == 3).then_some(())
    })
    .unwrap_or_else(|| panic!("the list of mission 2 never came: {lists:#?}"));

    // Guidance was handed whole lists only: mission 1, the empty list of the clear, then
    // mission 2; never a part of mission 2.
    let one = valid_1.mission.to_payload(1);
    assert!(
        lists.iter().all(|l| {
            (l.generation == 1 && same_waypoints(l, &one))
                || (l.generation == 2 && l.count == 0)
                || (l.generation > 2
                    && same_waypoints(l, &valid_2.mission.to_payload(l.generation)))
        }),
        "{lists:#?}"
    );
}

#[test]
fn frames_from_a_wrong_source_or_with_a_bad_checksum_change_nothing_and_are_counted() {
    let (rig, mut fcc, mut link) = Rig::with_gcs("bad-frames");
    let config = rig.config.clone();
    let mission_1 = plan("mission-1.toml");
    let valid = link.station().validate(&mission_1).unwrap();
    upload(&mut link, &mission_1).unwrap();

    // A clear and a transmit of the empty list from a foreign source, and from the GCS with a
    // broken checksum: either would clear the mission if it were processed.
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let stamp = |ms| wire::Timestamp::from_millis(900_000_000_000 + ms).unwrap();
    for (i, (source, break_checksum)) in [(0x0C00_0001, false), (config.ids.gcs, true)]
        .into_iter()
        .enumerate()
    {
        for (j, m) in clearing_commands().into_iter().enumerate() {
            let mut m = m;
            m.set_time_stamp(stamp((i * 2 + j) as u64));
            let envelope = Envelope::new(source, config.ids.fcc).with_ack(true);
            let len = wire::encode(&envelope, &m, &mut buf).unwrap();
            if break_checksum {
                buf[len - 1] ^= 0x01;
            }
            socket
                .send_to(&buf[..len], config.links.fcc_direct)
                .unwrap();
        }
    }
    // No wait needed: the download's frames reach the direct link's socket after these (each
    // send_to on loopback has queued its datagram when it returns), voting-monitoring reads a
    // socket in order and mission data handling handles the uplink in order, so the download
    // sees whatever these frames did.
    assert_eq!(download(&mut link).unwrap(), valid, "nothing changed");

    fcc.stop().unwrap();
    let counters = rig.counters("voting-monitoring");
    assert_eq!(counters["unknown_source"], 2, "{counters:?}");
    assert_eq!(counters["checksum_mismatch"], 2, "{counters:?}");
    assert_eq!(counters["rejected_frames"], 4, "{counters:?}");
}

#[test]
fn the_fcc_stops_when_the_process_that_started_it_is_killed() {
    let rig = Rig::new("started-by");
    // The harness's command for the launcher (`--exit-with-parent` among its arguments), run
    // by a shell that is then killed as a test or a benchmark killed by a signal would be.
    let command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    let log = std::fs::File::create(rig.dir.join("fcc.log")).unwrap();
    let mut shell = std::process::Command::new("sh");
    shell
        .arg("-c")
        .arg("\"$0\" \"$@\" & wait")
        .arg(command.get_program())
        .args(command.get_args())
        .stderr(log);
    for (key, value) in command.get_envs() {
        match value {
            Some(v) => shell.env(key, v),
            None => shell.env_remove(key),
        };
    }
    let mut shell = shell.spawn().unwrap();
    let state_dir = rig.config.ipc.state_dir();
    let launcher: i32 = eventually(Duration::from_secs(20), || {
        std::fs::read_to_string(state_dir.join("ready").join("fcc"))
            .ok()?
            .trim()
            .parse()
            .ok()
    })
    .expect("the FCC came up");
    shell.kill().unwrap();
    shell.wait().unwrap();
    let gone = eventually(Duration::from_secs(5), || (!runs(launcher)).then_some(()));
    let text = std::fs::read_to_string(rig.dir.join("fcc.log")).unwrap();
    assert!(gone.is_some(), "the FCC outlived what started it:\n{text}");
    assert!(
        text.contains("the parent process is gone: stopping"),
        "{text}"
    );
}

#[test]
fn partitions_stop_and_nothing_is_left_in_the_temp_directory_when_the_launcher_is_killed() {
    let rig = Rig::new("orphans");
    // The launcher's and its partitions' temporary directory: empty at the end.
    let tmp = rig.dir.join("tmp");
    std::fs::create_dir_all(&tmp).unwrap();
    let mut command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    command.env("TMPDIR", &tmp);
    let log = rig.dir.join("fcc.log");
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&log)).unwrap();
    rig.ready(&mut fcc);
    let pids: Vec<i32> = fcc
        .log_text()
        .lines()
        .filter(|l| l.contains(" started ") || l.contains("started partition"))
        .filter_map(|l| l.split("pid=").nth(1))
        .filter_map(|p| p.trim().parse().ok())
        .collect();
    assert_eq!(pids.len(), 4, "{}", fcc.log_text());
    fcc.kill().unwrap();
    // Gone, or a zombie waiting for init to reap it: either way no longer running.
    let left = eventually(Duration::from_secs(5), || {
        (!pids.iter().any(|pid| runs(*pid))).then_some(())
    });
    assert!(left.is_some(), "partitions outlived the launcher: {pids:?}");
    assert!(
        fcc.log_text()
            .contains("the parent process is gone: stopping")
    );
    let left_behind: Vec<_> = std::fs::read_dir(&tmp)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(left_behind.is_empty(), "{left_behind:?}");
}

#[test]
fn sigusr1_logs_the_latency_percentiles_and_the_partition_keeps_running() {
    let rig = Rig::new("usr1");
    let mut automation = rig.start("system-automation");
    rig.ready(&mut automation);
    let pid = rustix::process::Pid::from_raw(automation.id() as i32).unwrap();
    // Two reports: the second can only come from a process that went on after the first.
    for n in 1..=2 {
        rustix::process::kill_process(pid, rustix::process::Signal::USR1).unwrap();
        wait_for_logs(
            &automation,
            "latency command: accepted to carried out",
            n,
            Duration::from_secs(10),
        );
    }
    assert_eq!(automation.try_wait().unwrap(), None, "still running");
    let status = automation.stop().unwrap();
    assert!(status.success(), "{status:?}\n{}", automation.log_text());
}

#[test]
fn a_flood_of_bad_datagrams_costs_counters_not_log_lines() {
    let mut rig = Rig::new("flood");
    let mut fcc = rig.start_fcc();
    rig.learn_links(&mut fcc);
    let config = rig.config.clone();

    // One well-formed #50000 from the GCS, bent four ways: each breaks one rule of ICD §2.
    let mut buf = [0u8; MAX_FRAME_LEN];
    let execute = wire::MissionExecuteCommand {
        time_stamp: wire::Timestamp::from_millis(900_000_000_000).unwrap(),
        command: wire::ExecuteCommand::Execute,
        mission_id: None,
    };
    let mut encode = |source: u32| {
        let envelope = Envelope::new(source, config.ids.fcc).with_ack(true);
        let len = wire::encode(&envelope, &execute.into(), &mut buf).unwrap();
        buf[..len].to_vec()
    };
    let foreign = encode(0x0C00_0001);
    let mut bad_checksum = encode(config.ids.gcs);
    *bad_checksum.last_mut().unwrap() ^= 0x01;
    let mut bad_length = encode(config.ids.gcs);
    bad_length[2..4].copy_from_slice(&0u16.to_be_bytes());
    let too_short = vec![0xff, 0xff, 0x00];
    let kinds = [foreign, bad_checksum, bad_length, too_short];

    const N: usize = 20_000;
    let socket = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    let started = Instant::now();
    for i in 0..N {
        let to = if i % 2 == 0 {
            config.links.fcc_direct
        } else {
            config.links.fcc_lte
        };
        socket.send_to(&kinds[i % kinds.len()], to).unwrap();
        // Paced so that voting-monitoring's socket buffers rarely overflow.
        if i % 200 == 199 {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    fcc.stop().unwrap();
    let seconds = started.elapsed().as_secs() + 1;

    let counters = rig.counters("voting-monitoring");
    let rejected = counters["rejected_frames"];
    // The kernel may drop datagrams when a socket's buffer is full; every one that arrived is
    // counted, by its cause.
    assert!(rejected <= N as u64 && rejected > 0, "{counters:?}");
    for cause in [
        "unknown_source",
        "checksum_mismatch",
        "length_out_of_range",
        "too_short",
    ] {
        assert!(counters[cause] > 0, "{cause}: {counters:?}");
    }
    // At most one line per cause per second of flood (and one to start with), whatever the
    // number of frames.
    let lines = fcc
        .log_text()
        .lines()
        .filter(|l| l.contains("rejected since the last line"))
        .count() as u64;
    assert!(lines >= 4, "one line at least per cause: {lines}");
    assert!(
        lines <= 4 * (seconds + 1),
        "{lines} log lines for {rejected} rejected frames in {seconds} s"
    );
}

/// ICD §7 (ext): navigation puts the aircraft south of mission 2's polygonal no-fly-zone, so
/// the way from there to the initial waypoint (CCP) runs through it. The FCC refuses execute
/// with GeofenceViolation (14) and the lists stay as uploaded.
#[test]
fn execute_is_refused_when_the_way_from_the_take_off_point_crosses_a_no_fly_zone() {
    let mut rig = Rig::new("geofence");
    rig.config.guidance.start_latitude_deg = 48.258;
    rig.config.guidance.start_longitude_deg = 11.643;
    let mut fcc = rig.start_fcc();
    let mut link = rig.gcs(&mut fcc);
    let plan = plan("mission-2.toml");
    let valid = link.station().validate(&plan).unwrap();
    upload(&mut link, &plan).unwrap();
    // Until guidance's first progress has reached mission data handling there is no position
    // to check from (WrongState): ask again, bounded.
    let reason = eventually(Duration::from_secs(10), || {
        let now = link.now();
        link.station()
            .execute(now, wire::ExecuteCommand::Execute)
            .unwrap();
        match finish(&mut link) {
            Err(GcsError::Transfer { error, .. }) => match error.reason() {
                Some(wire::Reason::WrongState) => None,
                other => Some(other),
            },
            other => panic!("execute was not refused: {other:?}"),
        }
    });
    assert_eq!(reason, Some(Some(wire::Reason::GeofenceViolation)));
    assert_eq!(download(&mut link).unwrap(), valid, "nothing changed");
}

/// The clear follows paper §3.1 (ICD §5.1 step 1): an edition-1 peer, with signing off as the
/// FCC's configuration says in writing, clears the mission; guidance receives the empty list, a
/// download gets "no mission" (#17000 type 3 `WrongState`, ICD §5.2) and execute is refused
/// (`WrongState`, ICD §5.7) until a mission is uploaded again.
#[test]
fn after_an_edition_1_peers_clear_the_fcc_holds_no_mission() {
    use missionlink::harness::ground::Ground;
    use missionlink_partitions::config::{Signing, SigningPolicy};
    use missionlink_protocol::transfer::sender::mission_command;
    use wire::{ExecuteCommand, Message, MissionExecuteCommand, MissionPlanMode, Reason};

    let mut rig = Rig::new("edition-1-clear");
    rig.config.signing = Signing {
        policy: SigningPolicy::Off,
        key_files: Vec::new(),
        send_key_id: None,
    };
    let mut fcc = rig.start_fcc();
    let links = rig.gcs_links(&mut fcc);
    let mut peer = Ground::new(&rig.config, links);
    let valid = plan("mission-2.toml").assemble().unwrap();
    peer.upload(&valid);
    wait_for_log(
        &fcc,
        "waypoint list received generation=1 waypoints=3",
        Duration::from_secs(20),
    );

    peer.accepted(mission_command(MissionPlanMode::ClearMission, None, None));
    wait_for_log(
        &fcc,
        "waypoint list received generation=2 waypoints=0",
        Duration::from_secs(20),
    );
    // An edition-1 download request: no Transfer Window.
    assert_eq!(
        peer.refused(mission_command(MissionPlanMode::ReceiveMission, None, None)),
        Some(Reason::WrongState)
    );
    let execute = || {
        Message::from(MissionExecuteCommand {
            time_stamp: wire::Timestamp::default(),
            command: ExecuteCommand::Execute,
            mission_id: None,
        })
    };
    assert_eq!(peer.refused(execute()), Some(Reason::WrongState));

    // Uploaded again, the same execute is accepted once guidance has reported a position.
    peer.upload(&valid);
    let accepted = eventually(Duration::from_secs(10), || match peer.refused(execute()) {
        None => Some(()),
        Some(Reason::WrongState) => None,
        Some(other) => panic!("execute refused with {other:?}"),
    });
    assert_eq!(accepted, Some(()), "{}", fcc.log_text());
}
