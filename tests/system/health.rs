//! Health across processes (docs/design.md "Health"): the launcher finds a partition that
//! hangs (SIGSTOP) by its heartbeat, logs it by name, kills and restarts it; one killed with
//! `kill -9` is restarted; system automation refuses execute while guidance is not alive, and
//! the GCS hears the reason (`WrongState`); and when the launcher gives up system automation
//! (its start limit), the FCC is degraded: mission data handling hears its heartbeat fall
//! silent and refuses execute. The limit itself (2.5 periods, found within 3) is
//! tested in simulated time in `missionlink_flight::health`; here the real processes, whose
//! timing on a loaded machine is printed, never asserted.

use std::time::{Duration, Instant};

use missionlink::harness::*;
use missionlink_ground::ground_station::GcsError;
use missionlink_ground::ground_station::GcsEvent;
use missionlink_interfaces::contracts::Partition;
use missionlink_interfaces::wire;
use rustix::process::Signal;

const LIMIT: Duration = Duration::from_secs(30);

/// The wall-clock seconds of the day now, as the log lines' UTC time stamps count them.
fn seconds_of_day_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs_f64()
        % 86_400.0
}

/// The seconds of the day of a log line's time stamp (`2026-11-26T02:43:35.060416Z ...`).
fn logged_at(line: &str) -> Option<f64> {
    let clock = line
        .split_whitespace()
        .next()?
        .split('T')
        .nth(1)?
        .strip_suffix('Z')?;
    let mut parts = clock.split(':');
    let (h, m, s) = (parts.next()?, parts.next()?, parts.next()?);
    Some(h.parse::<f64>().ok()? * 3600.0 + m.parse::<f64>().ok()? * 60.0 + s.parse::<f64>().ok()?)
}

#[test]
fn a_stopped_partition_is_found_by_its_heartbeat_killed_and_restarted() {
    let rig = Rig::new("health-stop");
    let mut fcc = rig.start_fcc();
    for partition in Partition::BINARIES {
        let tag = format!("partition=\"{partition}\"");
        let pid = partition_pid(&fcc, partition);
        let stopped_at = seconds_of_day_now();
        signal_partition(&fcc, partition, Signal::STOP);
        wait_for_line(&fcc, &["partition hung", &tag], 0, LIMIT);
        wait_for_starts(&fcc, partition, 2, LIMIT);
        assert!(!runs(pid), "the stopped {partition} ({pid}) was killed");
        let line = fcc
            .log_text()
            .lines()
            .find(|l| l.contains("partition hung") && l.contains(&tag))
            .map(str::to_owned)
            .unwrap();
        let found_ms = logged_at(&line)
            .map(|t| format!("{:.0}", (t - stopped_at).rem_euclid(86_400.0) * 1000.0))
            .unwrap_or_else(|| "?".to_owned());
        println!(
            "{partition}: the launcher logged it {found_ms} ms after the SIGSTOP: {}",
            line.split("silence=").nth(1).unwrap_or(&line)
        );
        rig.ready(&mut fcc);
    }
}

#[test]
fn a_killed_guidance_is_restarted_and_flies_again() {
    let (rig, mut fcc, mut link) = Rig::with_gcs("health-kill");
    upload(&mut link, &plan("mission-1.toml")).unwrap();
    wait_for_line(&fcc, &["guidance alive"], 0, LIMIT);
    signal_partition(&fcc, "guidance-stub", Signal::KILL);
    wait_for_line(
        &fcc,
        &["partition died", "guidance-stub", "killed by signal 9"],
        0,
        LIMIT,
    );
    wait_for_starts(&fcc, "guidance-stub", 2, LIMIT);
    rig.ready(&mut fcc);
    // The restarted guidance beats and reports its position: execute is accepted.
    assert_eq!(execute_when_ready(&mut link), None);
}

/// Execute, asked again (bounded) while it is refused with `WrongState` because guidance has
/// not beaten or reported its position yet; the reason of the last refusal, `None` when
/// accepted.
fn execute_when_ready(link: &mut Link) -> Option<wire::Reason> {
    let start = Instant::now();
    loop {
        match execute(link) {
            Some(wire::Reason::WrongState) if start.elapsed() < LIMIT => {
                std::thread::sleep(Duration::from_millis(100));
            }
            outcome => return outcome,
        }
    }
}

/// Execute of `link`'s station once; the reason of a refusal, `None` when accepted.
fn execute(link: &mut Link) -> Option<wire::Reason> {
    let now = link.now();
    link.station()
        .execute(now, wire::ExecuteCommand::Execute)
        .unwrap();
    match finish(link) {
        Ok(_) => None,
        Err(GcsError::Transfer { error, .. }) => {
            Some(error.reason().expect("a refusal with a reason"))
        }
        Err(other) => panic!("execute: {other}"),
    }
}

#[test]
fn execute_is_refused_while_guidance_is_not_alive_and_the_gcs_hears_why() {
    let mut rig = Rig::new("health-gate");
    rig.config.launcher.without = vec!["guidance-stub".to_owned()];
    let mut fcc = rig.start_fcc();
    // Guidance runs as a process of its own, as a replacement in a rig would.
    let mut guidance = rig.start("guidance-stub");
    rig.ready(&mut guidance);
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-1.toml")).unwrap();
    wait_for_line(&fcc, &["alive (not started by the launcher)"], 0, LIMIT);
    assert!(
        !fcc.log_text()
            .contains("started partition=\"guidance-stub\""),
        "left out"
    );

    // Guidance has published its position; now it stops beating.
    rustix::process::kill_process(
        rustix::process::Pid::from_raw(guidance.id() as i32).unwrap(),
        Signal::STOP,
    )
    .unwrap();
    wait_for_line(&fcc, &["guidance not alive"], 0, LIMIT);
    wait_for_line(&fcc, &["not alive (not started by the launcher"], 0, LIMIT);
    assert_eq!(execute(&mut link), Some(wire::Reason::WrongState));

    // It beats again: execute is accepted, and FROM-TO-NEXT reaches the GCS.
    rustix::process::kill_process(
        rustix::process::Pid::from_raw(guidance.id() as i32).unwrap(),
        Signal::CONT,
    )
    .unwrap();
    wait_for_line(&fcc, &["guidance alive"], 1, LIMIT);
    assert_eq!(execute_when_ready(&mut link), None);
    let flying = link.run_until(LIMIT, |event| {
        matches!(event, GcsEvent::FromToNext(f) if f.to.waypoint_number.is_some_and(|n| n != 0))
    });
    assert!(flying, "no FROM-TO-NEXT with a TO waypoint");
}

#[test]
fn when_the_launcher_gives_up_system_automation_the_fcc_is_degraded_and_refuses_execute() {
    let mut rig = Rig::new("health-degraded");
    // One start only: the first death is the start limit.
    rig.config.launcher.start_limit_burst = 1;
    let mut fcc = rig.start("fcc");
    rig.ready(&mut fcc);
    let mut link = rig.gcs(&mut fcc);
    upload(&mut link, &plan("mission-1.toml")).unwrap();
    wait_for_line(&fcc, &["system automation alive"], 0, LIMIT);

    signal_partition(&fcc, "system-automation", Signal::KILL);
    wait_for_line(
        &fcc,
        &[
            "start limit reached",
            "the FCC is degraded",
            "system-automation",
        ],
        0,
        LIMIT,
    );
    // Mission data handling hears system automation fall silent and refuses what it would
    // carry out; its last published state ("on ground") no longer counts.
    wait_for_line(&fcc, &["system automation not alive"], 0, LIMIT);
    assert_eq!(execute(&mut link), Some(wire::Reason::WrongState));
    let text = fcc.log_text();
    assert_eq!(
        text.lines()
            .filter(|l| l.contains("started partition=\"system-automation\""))
            .count(),
        1,
        "not started again:\n{text}"
    );
}
