//! The ground service (`gcs serve`, docs/gcs.md) with real FCCs, the `gcs` commands run as an
//! operator types them: two vehicles served side by side, the same output through the service
//! as alone, the monitor's state at once, and a service killed and started again.

use std::process::Output;
use std::time::Duration;

use missionlink::harness::service::{FleetVehicle, GroundService, fleet_file, gcs_binary};
use missionlink::harness::*;
use missionlink_platform::fence::status_shows_fence;

fn mission(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("missions")
        .join(name)
        .display()
        .to_string()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[track_caller]
fn ok(output: &Output) -> String {
    assert!(
        output.status.success(),
        "exit {:?}\nstdout:\n{}\nstderr:\n{}",
        output.status.code(),
        text(&output.stdout),
        text(&output.stderr)
    );
    text(&output.stdout)
}

/// The checksums `gcs download` printed: "checksums (ICD §11): mission X, areas Y".
fn downloaded_checksums(stdout: &str) -> String {
    stdout
        .lines()
        .find(|l| l.starts_with("checksums (ICD §11)"))
        .unwrap_or_else(|| panic!("no checksums in {stdout}"))
        .to_owned()
}

/// The checksums `gcs validate` gives for a mission file.
fn planned_checksums(file: &str) -> String {
    let out = std::process::Command::new(gcs_binary())
        .args(["validate", &mission(file)])
        .output()
        .unwrap();
    let line = ok(&out)
        .lines()
        .find_map(|l| {
            l.trim()
                .strip_prefix("checksums (ICD §11): ")
                .map(str::to_owned)
        })
        .unwrap();
    format!("checksums (ICD §11): {line}")
}

/// Two FCCs (Vehicle IDs 1 and 2) with their links learnt, and the service for both, started
/// with `args`.
fn two_vehicles(test: &str, args: &[&str]) -> (Rig, Rig, Process, Process, GroundService) {
    let mut a = Rig::new(&format!("{test}-a"));
    let mut b = Rig::new(&format!("{test}-b"));
    b.config.ids.fcc = 0x0B00_0002;
    let mut fcc_a = a.start_fcc();
    let mut fcc_b = b.start_fcc();
    a.learn_links(&mut fcc_a);
    b.learn_links(&mut fcc_b);
    let fleet = fleet_file(&mut [
        FleetVehicle {
            name: "alpha",
            rig: &mut a,
        },
        FleetVehicle {
            name: "bravo",
            rig: &mut b,
        },
    ]);
    let service = GroundService::start(&a.dir, &fleet, args);
    (a, b, fcc_a, fcc_b, service)
}

#[test]
fn ground_service_serves_two_fccs_side_by_side() {
    let (_a, _b, _fcc_a, _fcc_b, service) = two_vehicles("service-two", &[]);

    // Both uploads at once, each to its vehicle.
    let upload = |vehicle: &'static str, file: &'static str| {
        service
            .gcs_command(&["--vehicle", vehicle, "upload", &mission(file)])
            .spawn()
            .unwrap()
    };
    let (alpha, bravo) = (
        upload("alpha", "mission-2.toml"),
        upload("bravo", "mission-1.toml"),
    );
    let (alpha, bravo) = (
        alpha.wait_with_output().unwrap(),
        bravo.wait_with_output().unwrap(),
    );
    ok(&alpha);
    ok(&bravo);

    // Each holds its own mission.
    let down_a = ok(&service.gcs(&["--vehicle", "alpha", "download"]));
    let down_b = ok(&service.gcs(&["--vehicle", "bravo", "download"]));
    assert_eq!(
        downloaded_checksums(&down_a),
        planned_checksums("mission-2.toml")
    );
    assert_eq!(
        downloaded_checksums(&down_b),
        planned_checksums("mission-1.toml")
    );

    // A fleet of two needs the vehicle named.
    let unnamed = service.gcs(&["download"]);
    assert_eq!(unnamed.status.code(), Some(2), "{}", text(&unnamed.stderr));
    assert!(
        text(&unnamed.stderr).contains("name one with --vehicle (alpha, bravo)"),
        "{}",
        text(&unnamed.stderr)
    );

    // The status: a row each, the active lists the ones planned, heard on both links.
    let status = ok(&service.gcs(&["status"]));
    let row = |name: &str| {
        status
            .lines()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no row {name}:\n{status}"))
            .to_owned()
    };
    for name in ["alpha", "bravo"] {
        let row = row(name);
        assert!(row.contains(" planned"), "{row}");
        assert!(!row.contains("never heard"), "{row}");
        assert!(!row.contains("FCC silent"), "{row}");
    }
    assert!(row("alpha").contains("0x0B000001"), "{status}");
    assert!(row("bravo").contains("0x0B000002"), "{status}");

    // All of it served from behind its fence: no new privileges and the seccomp allow-list on
    // every thread, Landlock as far as the kernel goes (logged).
    let proc_status = std::fs::read_to_string(format!("/proc/{}/status", service.pid())).unwrap();
    assert!(status_shows_fence(&proc_status), "{proc_status}");
    assert!(
        service.log_text().contains("isolation applied"),
        "{}",
        service.log_text()
    );
}

#[test]
fn ground_service_monitor_shows_from_to_next_and_position_at_once() {
    let (_a, _b, _fcc_a, _fcc_b, service) = two_vehicles("service-monitor", &[]);
    ok(&service.gcs(&["--vehicle", "alpha", "upload", &mission("mission-2.toml")]));
    ok(&service.gcs(&["--vehicle", "alpha", "execute"]));
    // The service heard FROM-TO-NEXT while no command ran: a monitor started now shows it
    // first, before any change, and the position beside it.
    let flying = eventually(Duration::from_secs(20), || {
        let status = ok(&service.gcs(&["status"]));
        status
            .lines()
            .any(|l| l.starts_with("alpha") && l.contains(" -> ") && !l.contains("not yet"))
            .then_some(())
    });
    assert!(
        flying.is_some(),
        "alpha never reported FROM-TO-NEXT and position"
    );
    let out = ok(&service.gcs(&["--vehicle", "alpha", "monitor", "--seconds", "1"]));
    let mut lines = out.lines();
    let first = lines.next().unwrap_or_default();
    assert!(
        first.contains("FROM"),
        "the first line is not FROM-TO-NEXT: {out}"
    );
    let second = lines.next().unwrap_or_default();
    assert!(
        second.starts_with("position ") && !second.contains("not yet reported"),
        "{out}"
    );
    // Bravo was not flown: its monitor has nothing to show at once but its position.
    let out = ok(&service.gcs(&["--vehicle", "bravo", "monitor", "--seconds", "1"]));
    assert!(
        out.lines().all(|l| l.starts_with("position ")),
        "bravo flew nothing: {out}"
    );
}

/// What an operator sees of one command: exit status, stdout, and stderr without the log
/// lines (`tracing`, each after its time: the log of the work is the service's then).
fn seen(output: &Output) -> (Option<i32>, String, String) {
    let stderr: Vec<String> = text(&output.stderr)
        .lines()
        .filter(|l| !l.starts_with("20"))
        .map(str::to_owned)
        .collect();
    (
        output.status.code(),
        text(&output.stdout),
        stderr.join("\n"),
    )
}

#[test]
fn ground_service_commands_print_the_same_through_the_service_as_alone() {
    let mut rig = Rig::new("service-same");
    let mut fcc = rig.start_fcc();
    rig.learn_links(&mut fcc);
    let fleet = fleet_file(&mut [FleetVehicle {
        name: "solo",
        rig: &mut rig,
    }]);
    let fleet_path = rig.dir.join("solo-fleet.toml");
    std::fs::write(&fleet_path, &fleet).unwrap();
    // One state directory for the commands alone and the service: they share the missions
    // uploaded last and the time stamps, as on an operator's machine.
    let state_home = rig.dir.join("xdg-state");
    let socket = rig.dir.join("run").join("gcs.sock");
    let (m1, m2) = (mission("mission-1.toml"), mission("mission-2.toml"));
    let sequence: Vec<Vec<&str>> = vec![
        vec!["missions"],
        vec!["upload", &m1],
        vec!["missions"],
        vec!["download"],
        vec!["activate", "NO-SUCH"],
        vec!["stage", "--id", "S1", &m2],
        vec!["missions"],
        vec!["download", "--id", "S1"],
        vec!["delete", "S1"],
        vec!["upload", "--edit", &m2],
        vec!["clear"],
        vec!["clear-areas"],
        vec!["missions"],
    ];
    let run = |args: &[&str]| {
        std::process::Command::new(gcs_binary())
            .arg("--fleet")
            .arg(&fleet_path)
            .arg("--service-socket")
            .arg(&socket)
            .args(args)
            .env("XDG_STATE_HOME", &state_home)
            .output()
            .unwrap()
    };
    let alone: Vec<_> = sequence.iter().map(|args| seen(&run(args))).collect();
    // The sequence ends as it began: no lists. Now through the service.
    let service = GroundService::start_with_state(
        &rig.dir,
        &fleet,
        &state_home.join("missionlink"),
        &socket,
        &[],
    );
    let through: Vec<_> = sequence.iter().map(|args| seen(&run(args))).collect();
    // Through the service an upload may go on the report the request before left it (ICD
    // §10.3: a fresh report is not asked again): it then sends one message fewer, the report
    // request, and a full upload would too. The rest is the same.
    let counted = |out: &str| -> (Option<(usize, usize)>, String) {
        let numbers = out.lines().find_map(|l| {
            let rest = l.strip_prefix("sent ")?;
            let (sent, rest) = rest.split_once(" messages (a full upload: ")?;
            Some((sent.parse().ok()?, rest.strip_suffix(')')?.parse().ok()?))
        });
        let rest = out
            .lines()
            .filter(|l| !l.starts_with("sent "))
            .collect::<Vec<_>>()
            .join("\n");
        (numbers, rest)
    };
    for ((args, alone), through) in sequence.iter().zip(&alone).zip(&through) {
        let (alone_sent, alone_rest) = counted(&alone.1);
        let (through_sent, through_rest) = counted(&through.1);
        assert_eq!(
            (alone.0, alone_rest, &alone.2),
            (through.0, through_rest, &through.2),
            "gcs {}",
            args.join(" ")
        );
        let fewer = alone_sent
            .zip(through_sent)
            .map(|((a, af), (t, tf))| (a.checked_sub(t), af.checked_sub(tf)));
        assert!(
            alone_sent == through_sent || fewer == Some((Some(1), Some(1))),
            "gcs {}: {alone_sent:?} alone, {through_sent:?} through the service",
            args.join(" ")
        );
    }
    // Not a sequence of failures: it did what it says.
    assert_eq!(alone[1].0, Some(0), "{:?}", alone[1]);
    assert_eq!(alone[4].0, Some(1), "{:?}", alone[4]);
    assert!(alone[9].1.contains("sent "), "{:?}", alone[9]);
    drop(service);
}

#[test]
fn ground_service_killed_gives_clients_a_clear_error_and_resumes_what_it_kept() {
    let (_a, _b, _fcc_a, _fcc_b, mut service) = two_vehicles("service-kill", &[]);
    ok(&service.gcs(&["--vehicle", "bravo", "upload", &mission("mission-1.toml")]));
    service.kill();
    let down = service.gcs(&["--vehicle", "bravo", "download"]);
    assert_eq!(down.status.code(), Some(1));
    assert!(
        text(&down.stderr).contains("no service answers on it"),
        "{}",
        text(&down.stderr)
    );
    service.restart();
    // The lists it uploaded last are still known as planned.
    let planned = eventually(Duration::from_secs(10), || {
        let status = ok(&service.gcs(&["status"]));
        status
            .lines()
            .any(|l| l.starts_with("bravo") && l.contains(" planned"))
            .then_some(())
    });
    assert!(planned.is_some(), "{}", service.log_text());
    let down = ok(&service.gcs(&["--vehicle", "bravo", "download"]));
    assert_eq!(
        downloaded_checksums(&down),
        planned_checksums("mission-1.toml")
    );
}

#[test]
fn ground_service_mavlink_client_and_gcs_commands_side_by_side() {
    // QGroundControl is not listening in a test: the vehicles answer the client that talks.
    let (_a, _b, _fcc_a, _fcc_b, service) = two_vehicles(
        "service-mavlink",
        &[
            "--mavlink",
            "--mavlink-bind",
            "127.0.0.1:0",
            "--mavlink-to",
            "127.0.0.1:9",
        ],
    );
    let port = service.mavlink_port().expect("the MAVLink side's port");
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/clients/pymavlink_fleet.py");
    // pymavlink uploads to bravo (system 2) while gcs uploads to alpha.
    let client = std::process::Command::new(python())
        .arg(script)
        .args([port.to_string().as_str(), "2", "1", "2"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("{:?}: {e}; run the tests with tools/test", python()));
    ok(&service.gcs(&["--vehicle", "alpha", "upload", &mission("mission-2.toml")]));
    ok(&service.gcs(&["status"]));
    let out = client.wait_with_output().unwrap();
    println!("{}", text(&out.stdout));
    assert!(
        out.status.success(),
        "pymavlink:\n{}\n{}\n{}",
        text(&out.stdout),
        text(&out.stderr),
        service.log_text()
    );
    let down_a = ok(&service.gcs(&["--vehicle", "alpha", "download"]));
    assert_eq!(
        downloaded_checksums(&down_a),
        planned_checksums("mission-2.toml")
    );
    let down_b = ok(&service.gcs(&["--vehicle", "bravo", "download"]));
    assert!(down_b.contains("2 waypoints"), "{down_b}");
}

#[test]
fn ground_service_killed_during_an_atomic_upload_leaves_lists_whole_and_no_staged_copy() {
    let (_a, _b, _fcc_a, _fcc_b, mut service) = two_vehicles("service-kill-staging", &[]);
    ok(&service.gcs(&["--vehicle", "alpha", "upload", &mission("mission-1.toml")]));
    let leftover = ["--vehicle", "alpha", "stage", "--id", "LEFTOVER-1"];
    ok(&service.gcs(&[&leftover[..], &[mission("mission-2.toml").as_str()]].concat()));
    let copies = service
        .state_dir
        .join("vehicles")
        .join("alpha")
        .join("copies-to-delete");
    // Killed while the upload's staged copy may be on the FCC: from the moment the service
    // kept its ID until its delete is answered (the file is empty again then). An upload over
    // loopback may end between two looks: then it is tried again.
    let mut killed = false;
    for file in ["mission-2.toml", "mission-1.toml"].iter().cycle().take(10) {
        let client = service
            .gcs_command(&["--vehicle", "alpha", "upload", &mission(file)])
            .spawn()
            .unwrap();
        let mut client = client;
        while client.try_wait().unwrap().is_none() {
            let kept = std::fs::read_to_string(&copies).unwrap_or_default();
            if !kept.trim().is_empty() {
                service.kill();
                killed = true;
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let out = client.wait_with_output().unwrap();
        if killed {
            // The client was told the truth: the service ended before the upload did.
            assert_eq!(out.status.code(), Some(5), "{}", text(&out.stderr));
            assert!(
                text(&out.stderr).contains("ended before the request did"),
                "{}",
                text(&out.stderr)
            );
            break;
        }
        ok(&out);
    }
    assert!(killed, "no upload was caught with its staged copy kept");
    // A copy whose delete a run never saw answered, kept as the service keeps them: one on
    // the FCC for certain (the kill above may come before the FCC stored the upload's copy).
    let mut kept = std::fs::read_to_string(&copies).unwrap_or_default();
    kept.push_str("LEFTOVER-1\n");
    std::fs::write(&copies, kept).unwrap();
    service.restart();
    // The copy the killed run may have left on the FCC is deleted as the service starts.
    let clean = eventually(Duration::from_secs(20), || {
        let status = ok(&service.gcs(&["status"]));
        let row = status.lines().find(|l| l.starts_with("alpha"))?.to_owned();
        (row.contains("none staged") && !row.contains("busy") && !row.contains("no report"))
            .then_some(row)
    });
    assert!(
        clean.is_some(),
        "{}\n{}",
        ok(&service.gcs(&["status"])),
        service.log_text()
    );
    assert!(
        service
            .log_text()
            .contains("a staged copy a previous run left is deleted"),
        "{}",
        service.log_text()
    );
    assert_eq!(
        std::fs::read_to_string(&copies).unwrap_or_default().trim(),
        "",
        "no copy left to delete"
    );
    // The active lists are whole: the old ones or the new ones.
    let down = downloaded_checksums(&ok(&service.gcs(&["--vehicle", "alpha", "download"])));
    assert!(
        down == planned_checksums("mission-1.toml") || down == planned_checksums("mission-2.toml"),
        "{down}"
    );
    // And the next upload completes.
    ok(&service.gcs(&["--vehicle", "alpha", "upload", &mission("mission-2.toml")]));
}

#[test]
fn ground_service_uploads_to_several_vehicles_at_once_each_outcome_its_own() {
    let (_a, _b, _fcc_a, fcc_b, service) = two_vehicles("service-fleet-upload", &[]);
    let both = ok(&service.gcs(&[
        "--vehicle",
        "alpha,bravo",
        "upload",
        &mission("mission-2.toml"),
    ]));
    for name in ["alpha", "bravo"] {
        assert!(
            both.lines()
                .any(|l| l.starts_with(&format!("{name}: upload complete"))),
            "{both}"
        );
    }
    // Bravo's FCC stops: alpha's upload completes all the same, bravo's outcome is its own.
    drop(fcc_b);
    let out = service.gcs(&[
        "--vehicle",
        "alpha,bravo",
        "upload",
        &mission("mission-1.toml"),
    ]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("alpha: upload complete")),
        "{stdout}\n{stderr}"
    );
    assert!(stderr.contains("gcs: bravo: "), "{stderr}");
    assert!(
        stderr.contains("1 of 2 vehicles did not complete"),
        "{stderr}"
    );
    assert_ne!(out.status.code(), Some(0));
    let down = ok(&service.gcs(&["--vehicle", "alpha", "download"]));
    assert_eq!(
        downloaded_checksums(&down),
        planned_checksums("mission-1.toml")
    );
}

#[test]
fn ground_service_mavsdk_sees_every_system_and_uploads_to_one() {
    let (_a, _b, _fcc_a, _fcc_b, service) = two_vehicles(
        "service-mavsdk",
        &[
            "--mavlink",
            "--mavlink-bind",
            "127.0.0.1:0",
            "--mavlink-to",
            "127.0.0.1:9",
        ],
    );
    let port = service.mavlink_port().expect("the MAVLink side's port");
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/clients/mavsdk_fleet.py");
    let out = std::process::Command::new(python())
        .arg(script)
        .args([port.to_string().as_str(), "1", "1", "2"])
        .output()
        .unwrap_or_else(|e| panic!("{:?}: {e}; run the tests with tools/test", python()));
    println!("{}", text(&out.stdout));
    assert!(
        out.status.success(),
        "MAVSDK:\n{}\n{}\n{}",
        text(&out.stdout),
        text(&out.stderr),
        service.log_text()
    );
    assert!(
        text(&out.stdout).contains("systems: [1, 2]"),
        "{}",
        text(&out.stdout)
    );
    // Alpha (system 1) holds what MAVSDK uploaded; bravo is untouched.
    let down_a = ok(&service.gcs(&["--vehicle", "alpha", "download"]));
    assert!(down_a.contains("2 waypoints"), "{down_a}");
    let down_b = service.gcs(&["--vehicle", "bravo", "download"]);
    assert_ne!(down_b.status.code(), Some(0), "{}", text(&down_b.stdout));
}

#[test]
fn ground_service_uploads_at_once_over_lossy_links_and_each_outcome_is_true() {
    use missionlink::link_emulator::Profile;
    let mut a = Rig::new("service-lossy-a");
    let mut b = Rig::new("service-lossy-b");
    b.config.ids.fcc = 0x0B00_0002;
    let (_fcc_a, _emulator_a, _) = a.start_fcc_behind(Profile::Lte.flows(), 7);
    let (_fcc_b, _emulator_b, _) = b.start_fcc_behind(Profile::Bad.flows(), 11);
    let fleet = fleet_file(&mut [
        FleetVehicle {
            name: "alpha",
            rig: &mut a,
        },
        FleetVehicle {
            name: "bravo",
            rig: &mut b,
        },
    ]);
    let service = GroundService::start(&a.dir, &fleet, &[]);
    let out = service.gcs(&[
        "--vehicle",
        "alpha,bravo",
        "upload",
        &mission("mission-2.toml"),
    ]);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    // Over LTE (1 % loss on each link) the upload completes.
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("alpha: upload complete")),
        "{stdout}\n{stderr}"
    );
    let down = ok(&service.gcs(&["--vehicle", "alpha", "download"]));
    assert_eq!(
        downloaded_checksums(&down),
        planned_checksums("mission-2.toml")
    );
    // Over the bad link (10 % loss in bursts, reordering) bravo's outcome is its own and true:
    // complete, or a failure that names what the FCC holds, which a download confirms.
    let bravo_done = stdout
        .lines()
        .any(|l| l.starts_with("bravo: upload complete"));
    let down = service.gcs(&["--vehicle", "bravo", "download"]);
    if bravo_done {
        assert_eq!(
            downloaded_checksums(&ok(&down)),
            planned_checksums("mission-2.toml")
        );
    } else {
        assert!(stderr.contains("gcs: bravo: "), "{stdout}\n{stderr}");
        assert!(
            stderr.contains("previous")
                || stderr.contains("unknown")
                || stderr.contains("no mission"),
            "{stderr}"
        );
    }
}

#[test]
fn ground_service_refuses_a_fleet_file_with_a_duplicate_where_it_stands() {
    let dir = tempfile_dir("service-duplicate");
    let fleet = "cucs_id = 0x0A000001\n\n\
                 [[vehicle]]\nname = \"alpha\"\nvehicle_id = 0x0B000001\n\
                 direct = { ground = \"127.0.0.1:0\", fcc = \"127.0.0.1:6001\" }\n\
                 lte = { ground = \"127.0.0.1:0\", fcc = \"127.0.0.1:6002\" }\n\n\
                 [[vehicle]]\nname = \"bravo\"\nvehicle_id = 0x0B000001\n\
                 direct = { ground = \"127.0.0.1:0\", fcc = \"127.0.0.1:6003\" }\n\
                 lte = { ground = \"127.0.0.1:0\", fcc = \"127.0.0.1:6004\" }\n";
    let path = dir.join("fleet.toml");
    std::fs::write(&path, fleet).unwrap();
    let out = std::process::Command::new(gcs_binary())
        .arg("--fleet")
        .arg(&path)
        .arg("--service-socket")
        .arg(dir.join("gcs.sock"))
        .arg("serve")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", text(&out.stderr));
    assert!(
        text(&out.stderr)
            .contains("fleet.toml:11:14: Vehicle ID 0x0B000001 is vehicle \"alpha\"'s already"),
        "{}",
        text(&out.stderr)
    );
    assert!(!dir.join("gcs.sock").exists(), "nothing was served");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A directory of this test's own.
fn tempfile_dir(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("missionlink-test-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn ground_service_refuses_a_mission_that_comes_too_close_to_another_vehicles() {
    let mut a = Rig::new("service-separation-a");
    let mut b = Rig::new("service-separation-b");
    b.config.ids.fcc = 0x0B00_0002;
    let mut fcc_a = a.start_fcc();
    let mut fcc_b = b.start_fcc();
    a.learn_links(&mut fcc_a);
    b.learn_links(&mut fcc_b);
    let fleet = fleet_file(&mut [
        FleetVehicle {
            name: "alpha",
            rig: &mut a,
        },
        FleetVehicle {
            name: "bravo",
            rig: &mut b,
        },
    ]);
    // The defaults of [fleet]: 500 m apart wherever the altitudes are within 150 m.
    let fleet = fleet.replace("[fleet]\nseparation_m = 0.0\n", "");
    let mut service = GroundService::start(&a.dir, &fleet, &[]);
    ok(&service.gcs(&["--vehicle", "alpha", "upload", &mission("mission-2.toml")]));
    // The same route for bravo: refused, every conflict named, nothing sent.
    let refused = |service: &GroundService| {
        let out = service.gcs(&["--vehicle", "bravo", "upload", &mission("mission-2.toml")]);
        assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
        let stderr = text(&out.stderr);
        assert!(
            stderr.contains(
                "separation conflicts with the fleet's active missions; nothing was sent"
            ),
            "{stderr}"
        );
        assert!(
            stderr.contains("FLEET-SEP") && stderr.contains("of alpha"),
            "{stderr}"
        );
        let down = service.gcs(&["--vehicle", "bravo", "download"]);
        assert_ne!(down.status.code(), Some(0), "bravo holds nothing");
    };
    refused(&service);
    // Started again, the service learns alpha's mission from its FCC and refuses as before.
    service.kill();
    service.restart();
    let learnt = eventually(Duration::from_secs(20), || {
        let status = ok(&service.gcs(&["status"]));
        status
            .lines()
            .any(|l| l.starts_with("alpha") && !l.contains("busy"))
            .then_some(())
    });
    assert!(learnt.is_some(), "{}", service.log_text());
    refused(&service);
    // Nor through the MAVLink side: its commit passes the same check.
    drop(service);
    let service = GroundService::start(
        &a.dir,
        &fleet,
        &[
            "--mavlink",
            "--mavlink-bind",
            "127.0.0.1:0",
            "--mavlink-to",
            "127.0.0.1:9",
        ],
    );
    let port = service.mavlink_port().expect("the MAVLink side's port");
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/clients/pymavlink_fleet.py");
    let out = std::process::Command::new(python())
        .arg(script)
        .args(["--refused", port.to_string().as_str(), "2", "1", "2"])
        .output()
        .unwrap_or_else(|e| panic!("{:?}: {e}; run the tests with tools/test", python()));
    assert!(
        out.status.success(),
        "pymavlink:\n{}\n{}\n{}",
        text(&out.stdout),
        text(&out.stderr),
        service.log_text()
    );
    let down = service.gcs(&["--vehicle", "bravo", "download"]);
    assert_ne!(down.status.code(), Some(0), "bravo holds nothing");
    // Alpha's mission cleared, bravo's goes: the service follows what each FCC holds.
    ok(&service.gcs(&["--vehicle", "alpha", "clear"]));
    ok(&service.gcs(&["--vehicle", "bravo", "upload", &mission("mission-2.toml")]));
}

/// The status row of `name`.
fn status_row(service: &GroundService, name: &str) -> String {
    let status = ok(&service.gcs(&["status"]));
    status
        .lines()
        .find(|l| l.starts_with(name))
        .unwrap_or_else(|| panic!("no row {name}:\n{status}"))
        .to_owned()
}

#[test]
fn ground_service_fcc_killed_during_uploads_to_all_the_others_complete_and_it_comes_back() {
    // Three FCCs, each behind 100 ms each way (no loss), so that an upload lasts round trips
    // long enough to kill one FCC in the middle of it.
    let delayed = [missionlink_linksim::channel::Impairments {
        delay: Duration::from_millis(100),
        ..missionlink_linksim::channel::Impairments::NONE
    }; 4];
    let names = ["alpha", "bravo", "charlie"];
    let mut rigs: Vec<Rig> = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let mut rig = Rig::new(&format!("service-killed-fcc-{name}"));
            rig.config.ids.fcc = 0x0B00_0001 + i as u32;
            rig
        })
        .collect();
    let mut running: Vec<_> = rigs
        .iter_mut()
        .zip(0u64..)
        .map(|(rig, seed)| rig.start_fcc_behind(delayed, seed))
        .collect();
    let fleet = {
        let mut vehicles: Vec<FleetVehicle<'_>> = names
            .iter()
            .zip(rigs.iter_mut())
            .map(|(name, rig)| FleetVehicle { name, rig })
            .collect();
        fleet_file(&mut vehicles)
    };
    let service = GroundService::start(&rigs[0].dir, &fleet, &[]);
    let all = names.join(",");
    ok(&service.gcs(&["--vehicle", &all, "upload", &mission("mission-1.toml")]));

    // Mission 2 to all three; bravo's FCC is killed (SIGKILL, launcher and partitions at once,
    // as a crash of its computer) while all three uploads run.
    let upload = service
        .gcs_command(&["--vehicle", &all, "upload", &mission("mission-2.toml")])
        .spawn()
        .unwrap();
    let all_busy = eventually(Duration::from_secs(10), || {
        let status = ok(&service.gcs(&["status", "--json"]));
        let rows: Vec<serde_json::Value> = serde_json::from_str(&status).unwrap();
        rows.iter()
            .all(|r| r["busy"].as_str() == Some("upload"))
            .then_some(())
    });
    assert!(all_busy.is_some(), "the uploads did not run at once");
    let bravo = &mut running[1].0;
    let partitions: Vec<i32> = missionlink::harness::binaries::FCC_BINARIES[1..]
        .iter()
        .map(|p| partition_pid(bravo, p))
        .collect();
    for pid in std::iter::once(bravo.id() as i32).chain(partitions) {
        if let Some(pid) = rustix::process::Pid::from_raw(pid) {
            let _ = rustix::process::kill_process(pid, rustix::process::Signal::KILL);
        }
    }
    let _ = bravo.kill();

    let out = upload.wait_with_output().unwrap();
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    for name in ["alpha", "charlie"] {
        assert!(
            stdout
                .lines()
                .any(|l| l.starts_with(&format!("{name}: upload complete"))),
            "{stdout}\n{stderr}"
        );
        let down = ok(&service.gcs(&["--vehicle", name, "download"]));
        assert_eq!(
            downloaded_checksums(&down),
            planned_checksums("mission-2.toml")
        );
    }
    assert!(stderr.contains("gcs: bravo: "), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("1 of 3 vehicles did not complete"),
        "{stderr}"
    );
    assert_ne!(out.status.code(), Some(0));

    // The status shows bravo lost...
    let lost = eventually(Duration::from_secs(10), || {
        status_row(&service, "bravo")
            .contains("FCC silent on both links")
            .then_some(())
    });
    assert!(lost.is_some(), "{}", status_row(&service, "bravo"));
    assert!(!status_row(&service, "alpha").contains("silent"));

    // ... and back once its FCC runs again on its ports, with lists whole: mission 1 or 2.
    let own = running[1].2;
    let rig = &mut rigs[1];
    let behind = [rig.config.links.fcc_direct, rig.config.links.fcc_lte];
    [rig.config.links.fcc_direct, rig.config.links.fcc_lte] = own;
    let _bravo_again = rig.start_fcc();
    [rig.config.links.fcc_direct, rig.config.links.fcc_lte] = behind;
    let back = eventually(Duration::from_secs(20), || {
        let row = status_row(&service, "bravo");
        (!row.contains("silent") && !row.contains("position not")).then_some(row)
    });
    assert!(back.is_some(), "{}", status_row(&service, "bravo"));
    let down = ok(&service.gcs(&["--vehicle", "bravo", "download"]));
    let held = downloaded_checksums(&down);
    assert!(
        held == planned_checksums("mission-1.toml") || held == planned_checksums("mission-2.toml"),
        "{held}"
    );
}

/// A rig for `test` and its fleet file (`fleet.toml` in the rig's directory) of one vehicle
/// whose FCC does not run: the service serves it all the same.
fn vehicle_without_fcc(test: &str) -> Rig {
    let mut rig = Rig::new(test);
    // Where no FCC listens (the discard port and the one after it).
    rig.config.links.fcc_direct = "127.0.0.1:9".parse().unwrap();
    rig.config.links.fcc_lte = "127.0.0.1:10".parse().unwrap();
    let fleet = fleet_file(&mut [FleetVehicle {
        name: "alpha",
        rig: &mut rig,
    }]);
    std::fs::write(rig.dir.join("fleet.toml"), fleet).unwrap();
    rig
}

/// `gcs serve` of the fleet file [`vehicle_without_fcc`] wrote in `dir`, its socket and state
/// directory in `dir` too: the arguments, to start it as a test needs.
fn serve_args(dir: &std::path::Path) -> Vec<std::ffi::OsString> {
    vec![
        "--fleet".into(),
        dir.join("fleet.toml").into(),
        "--service-socket".into(),
        dir.join("gcs.sock").into(),
        "serve".into(),
        "--state-dir".into(),
        dir.join("ground-state").into(),
    ]
}

/// The first line `child` writes on its piped stdout; the pipe's reader is gone after it.
fn first_line(child: &mut std::process::Child) -> String {
    let mut line = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(child.stdout.take().unwrap()),
        &mut line,
    )
    .unwrap();
    line
}

#[test]
fn ground_service_keeps_serving_when_its_stdout_is_closed() {
    let rig = vehicle_without_fcc("service-stdout");
    let dir = rig.dir.clone();
    let log = std::fs::File::create(dir.join("gcs-serve.log")).unwrap();
    let mut service = std::process::Command::new(gcs_binary())
        .args(serve_args(&dir))
        .stdout(std::process::Stdio::piped())
        .stderr(log)
        .spawn()
        .unwrap();
    // The first line of its banner read, then the pipe's only reader gone.
    let first = first_line(&mut service);
    assert!(first.starts_with("ground service for 1 vehicle"), "{first}");
    let log_text = || std::fs::read_to_string(dir.join("gcs-serve.log")).unwrap_or_default();
    let status = std::process::Command::new(gcs_binary())
        .arg("--service-socket")
        .arg(dir.join("gcs.sock"))
        .arg("status")
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}\n{}",
        text(&status.stderr),
        log_text()
    );
    assert!(
        text(&status.stdout).contains("alpha"),
        "{}",
        text(&status.stdout)
    );
    // Stopped, it says so to no one: its exit is a clean one, not a panic on the closed pipe.
    rustix::process::kill_process(
        rustix::process::Pid::from_child(&service),
        rustix::process::Signal::TERM,
    )
    .unwrap();
    let exit = service.wait().unwrap();
    assert!(exit.success(), "{exit:?}\n{}", log_text());
}

#[test]
fn ground_service_stops_when_the_process_that_started_it_is_killed() {
    let rig = vehicle_without_fcc("service-started-by");
    let dir = rig.dir.clone();
    // As the harness starts it (`--exit-with-parent`), by a shell that is then killed as a test
    // or a benchmark killed by a signal would be.
    let log = std::fs::File::create(dir.join("gcs-serve.log")).unwrap();
    let mut shell = std::process::Command::new("sh")
        .arg("-c")
        .arg("\"$0\" \"$@\" >\"$SERVE_OUT\" & echo $! && wait")
        .arg(gcs_binary())
        .args(serve_args(&dir))
        .arg("--exit-with-parent")
        .env("SERVE_OUT", dir.join("gcs-serve.out"))
        .stdout(std::process::Stdio::piped())
        .stderr(log)
        .spawn()
        .unwrap();
    let pid: i32 = first_line(&mut shell).trim().parse().unwrap();
    let serving = eventually(Duration::from_secs(20), || {
        dir.join("gcs.sock").exists().then_some(())
    });
    let log_text = || std::fs::read_to_string(dir.join("gcs-serve.log")).unwrap_or_default();
    assert!(
        serving.is_some(),
        "the service did not start:\n{}",
        log_text()
    );
    shell.kill().unwrap();
    shell.wait().unwrap();
    let gone = eventually(Duration::from_secs(5), || (!runs(pid)).then_some(()));
    assert!(
        gone.is_some(),
        "the service outlived what started it:\n{}",
        log_text()
    );
    assert!(
        log_text().contains("the parent process is gone: stopping"),
        "{}",
        log_text()
    );
}

#[test]
fn ground_service_binds_the_fleets_links_before_its_mavlink_endpoint() {
    // A MAVLink endpoint on a port the system picks must never take a port the fleet file
    // names: the service binds the fleet's links first. Asked for one of them outright, the
    // MAVLink endpoint is what cannot start, and it says so.
    let rig = vehicle_without_fcc("service-bind-order");
    let dir = rig.dir.clone();
    let fleet = std::fs::read_to_string(dir.join("fleet.toml")).unwrap();
    let direct = fleet
        .lines()
        .find_map(|l| l.strip_prefix("direct = { ground = \""))
        .and_then(|rest| rest.split('"').next())
        .unwrap()
        .to_owned();
    let out = std::process::Command::new(gcs_binary())
        .args(serve_args(&dir))
        .args(["--mavlink", "--mavlink-bind", &direct])
        .output()
        .unwrap();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains(&format!("cannot bind the MAVLink socket {direct}")),
        "{stderr}"
    );
    assert!(!stderr.contains("cannot bind the direct link"), "{stderr}");
    assert!(!dir.join("gcs.sock").exists(), "nothing was served");
}
