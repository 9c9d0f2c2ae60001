//! The launcher supervises like a supervisor (systemd's restart rules are the model): a
//! configuration a partition cannot work with stops the FCC before anything starts, with one
//! clear error and exit status 2; a partition that keeps dying is restarted with a growing pause
//! and given up after its start limit, said once by name, while the others keep running and the
//! FCC is no longer announced up. And voting-monitoring warns at every start while the links
//! are not authenticated.

use std::os::unix::fs::PermissionsExt;
use std::time::{Duration, Instant};

use missionlink::harness::*;
use missionlink_partitions::config::{Signing, SigningPolicy};
use missionlink_partitions::launcher::{FccProcess, PARTITIONS};
use missionlink_partitions::state;

/// Bound of every wait (a failure bound, never a timing assertion).
const LIMIT: Duration = Duration::from_secs(30);

/// Lines of `text` that hold every one of `parts`.
fn lines_with(text: &str, parts: &[&str]) -> usize {
    text.lines()
        .filter(|l| parts.iter().all(|p| l.contains(p)))
        .count()
}

/// Starts the launcher under `rig`'s configuration, which it must refuse: its exit status and
/// its log, once it has ended (within [`LIMIT`]).
fn launcher_refusing(rig: &Rig) -> (std::process::ExitStatus, String) {
    let log = rig.dir.join("fcc.log");
    let command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&log)).unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = fcc.try_wait().unwrap() {
            break status;
        }
        assert!(
            start.elapsed() < LIMIT,
            "the launcher went on:\n{}",
            fcc.log_text()
        );
        std::thread::sleep(Duration::from_millis(10));
    };
    (status, fcc.log_text())
}

#[test]
fn a_configuration_a_partition_refuses_stops_the_fcc_before_anything_starts() {
    let mut rig = Rig::new("supervise-config");
    // The FCC sends to the GCS's ports: the system cannot choose them.
    rig.config.links.gcs_direct = "127.0.0.1:0".parse().unwrap();
    let (status, text) = launcher_refusing(&rig);
    assert_eq!(status.code(), Some(2), "{text}");
    assert_eq!(
        lines_with(
            &text,
            &[
                "the FCC cannot come up",
                "voting-monitoring",
                "links.gcs_direct"
            ]
        ),
        1,
        "{text}"
    );
    assert_eq!(
        lines_with(&text, &["started"]),
        0,
        "nothing started:\n{text}"
    );
    assert!(
        text.lines().count() <= 3,
        "one clear error, not a storm:\n{text}"
    );
}

#[test]
fn a_partition_that_keeps_dying_is_given_up_after_its_start_limit() {
    let mut rig = Rig::new("supervise-limit");
    rig.config.launcher.restart_delay_ms = 20;
    rig.config.launcher.restart_delay_max_ms = 80;
    rig.config.launcher.start_limit_burst = 3;
    rig.config.launcher.start_limit_interval_ms = 60_000;
    // The real partitions, but a guidance that dies as soon as it starts.
    let bins = rig.dir.join("bin");
    std::fs::create_dir_all(&bins).unwrap();
    for name in PARTITIONS.iter().chain(&["fcc"]) {
        let target = bins.join(name);
        if *name == "guidance-stub" {
            std::fs::write(&target, "#!/bin/sh\nexit 1\n").unwrap();
            std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o755)).unwrap();
        } else {
            std::os::unix::fs::symlink(bin_dir().join(name), &target).unwrap();
        }
    }
    let log = rig.dir.join("fcc.log");
    let mut command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    command.arg("--bin-dir").arg(&bins);
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&log)).unwrap();
    let given_up = [
        "partition not started again",
        "guidance-stub",
        "start limit reached",
    ];
    let start = Instant::now();
    while lines_with(&fcc.log_text(), &given_up) == 0 {
        assert!(
            start.elapsed() < LIMIT,
            "never given up:\n{}",
            fcc.log_text()
        );
        assert!(fcc.try_wait().unwrap().is_none(), "{}", fcc.log_text());
        std::thread::sleep(Duration::from_millis(20));
    }
    // Time for a fourth start, were there one: the pause is at most 80 ms.
    std::thread::sleep(Duration::from_millis(1000));
    let text = fcc.log_text();
    assert_eq!(lines_with(&text, &given_up), 1, "said once:\n{text}");
    assert_eq!(
        lines_with(&text, &["launcher: started partition=\"guidance-stub\""]),
        3,
        "started as often as the limit allows:\n{text}"
    );
    // The pause grew: 20 ms, then 40 ms.
    assert_eq!(
        lines_with(&text, &["restarting in 20 ms", "guidance-stub"]),
        1,
        "{text}"
    );
    assert_eq!(
        lines_with(&text, &["restarting in 40 ms", "guidance-stub"]),
        1,
        "{text}"
    );
    // The others run on; the FCC is not announced up.
    assert!(
        fcc.try_wait().unwrap().is_none(),
        "the launcher runs on:\n{text}"
    );
    let state_dir = rig.config.ipc.state_dir();
    for name in [
        "voting-monitoring",
        "mission-data-handling",
        "system-automation",
    ] {
        let start = Instant::now();
        while !state::is_ready(&state_dir, name) {
            assert!(
                start.elapsed() < LIMIT,
                "{name} never came up:\n{}",
                fcc.log_text()
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
    assert!(
        !state::is_ready(&state_dir, "fcc"),
        "degraded, not up:\n{text}"
    );
    fcc.stop().unwrap();
}

/// Signing is required by default (ICD §9): an FCC without a key stops before any partition
/// starts, with one line that says how to make one.
#[test]
fn an_fcc_without_a_key_under_the_default_policy_exits_at_once_saying_how_to_make_one() {
    let mut rig = Rig::new("supervise-no-key");
    rig.config.signing = Signing::default();
    let (status, text) = launcher_refusing(&rig);
    assert_eq!(status.code(), Some(2), "{text}");
    assert_eq!(
        lines_with(
            &text,
            &[
                "the FCC cannot come up",
                "the link signing policy is require",
                "gcs keygen",
                "policy = \"off\""
            ]
        ),
        1,
        "{text}"
    );
    assert!(!text.contains("started"), "a partition started:\n{text}");
}

/// `policy = "off"` is a person's decision in writing, said at every start.
#[test]
fn voting_monitoring_warns_at_every_start_while_signing_is_off() {
    let mut rig = Rig::new("supervise-unsigned");
    rig.config.signing = Signing {
        policy: SigningPolicy::Off,
        key_files: Vec::new(),
        send_key_id: None,
    };
    let mut fcc = rig.start_fcc();
    let warning = ["the links are not authenticated", "signing is off"];
    assert_eq!(
        lines_with(&fcc.log_text(), &warning),
        1,
        "{}",
        fcc.log_text()
    );
    // Killed and started again: said again.
    signal_partition(&fcc, "voting-monitoring", rustix::process::Signal::KILL);
    let start = Instant::now();
    while lines_with(&fcc.log_text(), &warning) < 2 {
        assert!(start.elapsed() < LIMIT, "{}", fcc.log_text());
        std::thread::sleep(Duration::from_millis(20));
    }
    fcc.stop().unwrap();
}

/// A bridge that refuses its configuration (exit status 2) is given up, and the FCC it was to
/// connect to the other host is degraded: the launcher says so and never announces the FCC up,
/// though every partition of this host is.
#[test]
fn a_bridge_that_refuses_its_configuration_leaves_the_fcc_degraded_not_up() {
    let mut rig = Rig::new("supervise-bridge");
    rig.config.bridge.enabled = true;
    // The real partitions, and a bridge that refuses its configuration as the real one does.
    let bins = rig.dir.join("bin");
    std::fs::create_dir_all(&bins).unwrap();
    for name in PARTITIONS.iter().chain(&["fcc"]) {
        std::os::unix::fs::symlink(bin_dir().join(name), bins.join(name)).unwrap();
    }
    let bridge = bins.join(missionlink_partitions::bridge_config::BINARY);
    std::fs::write(
        &bridge,
        "#!/bin/sh\necho 'bridge: configuration refused' >&2\nexit 2\n",
    )
    .unwrap();
    std::fs::set_permissions(&bridge, std::fs::Permissions::from_mode(0o755)).unwrap();
    let log = rig.dir.join("fcc.log");
    let mut command = FccProcess::command(&bin_dir(), "fcc", &rig.config).unwrap();
    command.arg("--bin-dir").arg(&bins);
    let mut fcc = FccProcess::spawn(command, &rig.config, Some(&log)).unwrap();
    let given_up = ["bridge not started again", "the FCC is degraded"];
    let state_dir = rig.config.ipc.state_dir();
    let start = Instant::now();
    while lines_with(&fcc.log_text(), &given_up) == 0
        || !PARTITIONS.iter().all(|p| state::is_ready(&state_dir, p))
    {
        assert!(
            start.elapsed() < LIMIT,
            "never given up, or the partitions never came up:\n{}",
            fcc.log_text()
        );
        assert!(fcc.try_wait().unwrap().is_none(), "{}", fcc.log_text());
        std::thread::sleep(Duration::from_millis(20));
    }
    // A supervision round or two more, were the launcher to announce the FCC up after all.
    std::thread::sleep(Duration::from_millis(500));
    let text = fcc.log_text();
    assert_eq!(lines_with(&text, &given_up), 1, "said once:\n{text}");
    assert_eq!(lines_with(&text, &["all partitions up"]), 0, "{text}");
    assert!(
        !state::is_ready(&state_dir, "fcc"),
        "degraded, not up:\n{text}"
    );
    fcc.stop().unwrap();
}
