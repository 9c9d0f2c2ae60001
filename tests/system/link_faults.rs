//! The cross-process fault test: the real FCC (launcher and partitions) and the real
//! GCS through the link emulator, with seeded loss, duplication, reordering and corruption on
//! one link or both, and `kill -9` of a random partition in the middle of an atomic upload
//! (ICD §8). After every trial the FCC's active lists are the mission uploaded, whole, or the
//! ones active before it, whole; never a mix of the two and never part of one. What the GCS
//! said (its upload report) agrees with what the FCC holds whenever it said something, and the
//! next trial runs on the same FCC with nothing cleaned up by hand.
//!
//! Each trial draws from the seed: which links are impaired and how, which partition dies (or
//! none), after which of the GCS's messages, and whether the GCS may attempt the upload a second
//! time (`upload_attempts`). Uploads go round the demo's two missions and
//! one of 100 waypoints with 11 areas, so every trial changes the active lists.
//!
//! The test runs [`DEFAULT_TRIALS`] trials, some 30 s. The soak runs more:
//! `MISSIONLINK_FAULT_TRIALS=300 cargo test --release --test system link_faults:: -- --nocapture`
//! (`MISSIONLINK_FAULT_SEED` changes the seed); it prints what happened in every trial and a
//! summary.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use missionlink::harness::*;
use missionlink::link_emulator::{Flow, Impairments};
use missionlink_gcs::gcs_link::{Direction, Finished};
use missionlink_ground::ground_station::outcome::Held;
use missionlink_ground::ground_station::{GcsError, MissionPlan, Sequence, ValidatedPlan};
use missionlink_linksim::Rng;
use missionlink_protocol::testkit::{area_buffer, eleven_areas, generated_plan};

/// Trials in an ordinary test run: bounded so that CI spends well under two minutes here.
const DEFAULT_TRIALS: usize = 48;
/// The default seed.
const SEED: u64 = 1515;
/// The FCC's partitions, any of which may die.
const PARTITIONS: [&str; 4] = missionlink_interfaces::contracts::Partition::BINARIES;
/// Attempts at finding out what the FCC holds after a trial: a partition that died may still
/// be restarting, and on a lossy link a question may go unanswered twice.
const ATTEMPTS: usize = 10;

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// An impaired link: a short delay (the test is about faults, not about round trips), jitter
/// that reorders, and up to 10 % loss, 5 % duplication, 5 % reordering, 3 % corruption.
fn impaired(rng: &mut Rng) -> Impairments {
    Impairments {
        delay: Duration::from_millis(rng.range(1, 20)),
        jitter: Duration::from_millis(rng.range(0, 10)),
        loss: rng.unit() * 0.10,
        duplicate: rng.unit() * 0.05,
        reorder: rng.unit() * 0.05,
        corrupt: rng.unit() * 0.03,
        ..Impairments::NONE
    }
}

/// A clean link: 1 ms one way.
const CLEAN: Impairments = Impairments {
    delay: Duration::from_millis(1),
    ..Impairments::NONE
};

/// What the GCS said the upload left active: `Some(true)` the new lists, `Some(false)` the
/// previous ones, `None` it could not tell (or said nothing that an atomic upload would leave
/// half: the test checks the FCC either way).
fn claim(outcome: &Result<Finished, Error>, trial: usize) -> Option<bool> {
    let report = match outcome {
        Ok(Finished::Uploaded(report)) => report,
        Err(GcsError::Upload(report)) => report,
        // The report before the upload went unanswered, or a request found no room: nothing that
        // changes a list was sent.
        Err(e) if e.in_report() => return Some(false),
        Err(GcsError::Capacity { .. }) => return Some(false),
        other => panic!("trial {trial}: an upload ended with {other:?}"),
    };
    let said = |held: Held| match held {
        Held::New => Some(true),
        Held::Previous | Held::NotNew => Some(false),
        Held::Unknown => None,
        Held::Foreign => panic!("trial {trial}: lists neither old nor new: {report}"),
        // Only the paper's sequence clears; these uploads are atomic.
        Held::Cleared => panic!("trial {trial}: an atomic upload said it cleared: {report}"),
    };
    let (mission, areas) = (said(report.mission.held), said(report.areas.held));
    assert!(
        mission.is_none() || areas.is_none() || mission == areas,
        "trial {trial}: the GCS says the atomic upload left a mix: {report}"
    );
    mission.or(areas)
}

/// What the FCC holds active (its checksums and lists) and how many staged missions it holds:
/// a report, then a download of the active lists, each asked again until the FCC answers over
/// the impaired links (one report may well be lost on both).
fn what_is_active(
    link: &mut Link,
    trial: usize,
) -> ((Option<u32>, Option<u32>), ValidatedPlan, usize) {
    for _ in 0..ATTEMPTS {
        let now = link.now();
        link.station().report(now).unwrap();
        let entries = match finish(link) {
            Ok(Finished::Reported(entries)) => entries,
            other => {
                eprintln!("trial {trial}: no report: {other:?}");
                continue;
            }
        };
        let active = &entries[0];
        let checksums = (
            active.mission_checksum.map(|c| c.value()),
            active.area_checksum.map(|c| c.value()),
        );
        for _ in 0..ATTEMPTS {
            match download(link) {
                Ok(lists) => return (checksums, lists, entries.len() - 1),
                Err(e) => eprintln!("trial {trial}: no download: {e}"),
            }
        }
    }
    panic!("trial {trial}: the FCC did not answer {ATTEMPTS} reports and downloads");
}

/// 100 waypoints zig-zagging inside the demo fly-zone ([`generated_plan`]'s mission) with that
/// fly-zone alone: its ten no-fly-zones fill a benchmark's transfer, and some of its legs pass
/// one closer than the safety offset, which the onboard check (ICD §7) refuses at activation.
fn hundred_waypoints() -> MissionPlan {
    MissionPlan {
        areas: area_buffer(&eleven_areas()[..1]),
        ..generated_plan(100)
    }
}

/// The lists without the Mission ID an atomic upload gives its staged copy (ICD §8), which the
/// activated lists keep: the lists themselves are compared.
fn whole(mut lists: ValidatedPlan) -> ValidatedPlan {
    lists.mission.mission_id = None;
    lists
}

#[test]
fn faulty_links_and_a_dying_partition_leave_the_uploaded_lists_or_the_previous_ones_whole() {
    let trials = env_or("MISSIONLINK_FAULT_TRIALS", DEFAULT_TRIALS);
    let seed = env_or("MISSIONLINK_FAULT_SEED", SEED);
    let mut rig = Rig::new("link-faults");
    let (mut fcc, mut link, emulator) = rig.start_through([CLEAN; 4], seed);
    link.enable_log();
    let plans = [
        plan("mission-1.toml"),
        plan("mission-2.toml"),
        hundred_waypoints(),
    ];
    let valid = plans
        .each_ref()
        .map(|p| whole(link.station().validate(p).unwrap()));
    let sums = valid.each_ref().map(plan_checksums);

    // Each plan uploaded once, undisturbed, in the order of the trials: how many messages its
    // atomic upload sends. The last one, mission 1, stays active.
    let mut total = [0; 3];
    for next in [0, 1, 2, 0] {
        let from = link.log.len();
        let now = link.now();
        link.station()
            .upload_with(now, &plans[next], Sequence::Atomic)
            .unwrap();
        finish(&mut link).unwrap();
        total[next] = logged_since(&link, from, Direction::Up) as u64;
    }
    let mut active = 0;

    let mut rng = Rng::new(seed);
    let mut kills: BTreeMap<&str, usize> = BTreeMap::new();
    let mut tally: BTreeMap<String, usize> = BTreeMap::new();
    let started = Instant::now();
    for trial in 0..trials {
        let which = rng.range(0, 2);
        let [direct, lte] = match which {
            0 => [impaired(&mut rng), CLEAN],
            1 => [CLEAN, impaired(&mut rng)],
            _ => [impaired(&mut rng), impaired(&mut rng)],
        };
        for (flow, impairments) in Flow::ALL.into_iter().zip([direct, lte, direct, lte]) {
            emulator.set(flow, impairments);
        }
        let victim = PARTITIONS.get(rng.range(0, PARTITIONS.len() as u64) as usize);
        // One attempt or two (the default): a failed attempt shows the clean abort, a second one
        // that the upload completes anyway.
        let attempts = rng.range(1, 2) as u8;
        link.station().set_upload_attempts(attempts);
        let next = (active + 1) % plans.len();
        let cut_after = rng.range(1, total[next]) as usize;

        let from = link.log.len();
        let now = link.now();
        link.station()
            .upload_with(now, &plans[next], Sequence::Atomic)
            .unwrap();
        if let Some(victim) = victim {
            while logged_since(&link, from, Direction::Up) < cut_after
                && !link.station().is_standby()
            {
                link.pump(Duration::from_millis(1));
            }
            // The one before must have been restarted: a partition dies once at a time.
            let killed = kills.entry(victim).or_default();
            wait_for_starts(&fcc, victim, *killed + 1, Duration::from_secs(20));
            signal_partition(&fcc, victim, rustix::process::Signal::KILL);
            *killed += 1;
        }
        let outcome = finish(&mut link);
        eprintln!(
            "trial {trial}: plan {next}, links {which}, {victim:?} killed after GCS message {cut_after}: {:?}",
            outcome
                .as_ref()
                .map(|_| "uploaded")
                .map_err(|e| e.to_string())
        );
        let said_new = claim(&outcome, trial);

        let (checksums, lists, staged) = what_is_active(&mut link, trial);
        let is_new = if checksums == sums[next] {
            true
        } else if checksums == sums[active] {
            false
        } else {
            panic!(
                "trial {trial}: the FCC reports checksums {checksums:?}, neither the new {:?} nor the previous {:?}",
                sums[next], sums[active]
            );
        };
        let expected = if is_new { &valid[next] } else { &valid[active] };
        assert_eq!(
            &whole(lists),
            expected,
            "trial {trial}: the active lists are not whole"
        );
        if let Some(said_new) = said_new {
            assert_eq!(
                said_new,
                is_new,
                "trial {trial}: the GCS said {} but the FCC holds the {} lists: {outcome:?}",
                if said_new { "new" } else { "previous" },
                if is_new { "new" } else { "previous" }
            );
        }
        let made = match &outcome {
            Ok(Finished::Uploaded(report)) => report.attempts,
            Err(GcsError::Upload(report)) => report.attempts,
            _ => 1,
        };
        let line = format!(
            "plan {next}, {} links impaired, {} killed{}, {} active",
            ["direct", "lte", "both"][which as usize],
            victim.unwrap_or(&"none"),
            victim.map_or_else(String::new, |_| format!(
                " after GCS message {cut_after} of {}",
                total[next]
            )),
            if is_new { "new" } else { "previous" },
        );
        println!(
            "trial {trial}: {line}; GCS said {said_new:?} after {made} of {attempts} attempt(s); {staged} staged left; {:?}",
            outcome
                .as_ref()
                .map(|_| "uploaded")
                .map_err(|e| e.to_string())
        );
        *tally
            .entry(format!(
                "{} active{}",
                if is_new { "new" } else { "previous" },
                if victim.is_some() {
                    " after a kill"
                } else {
                    ""
                },
            ))
            .or_default() += 1;
        *tally
            .entry(format!("{made} of {attempts} attempt(s) made"))
            .or_default() += 1;
        if is_new {
            active = next;
        }
    }

    // Afterwards, on clean links, the FCC works as before: no cleanup by hand. Every partition
    // killed was started again, once per death.
    for (partition, killed) in &kills {
        wait_for_starts(&fcc, partition, killed + 1, Duration::from_secs(20));
    }
    for flow in Flow::ALL {
        emulator.set(flow, CLEAN);
    }
    let next = (active + 1) % plans.len();
    let _ = what_is_active(&mut link, trials);
    let now = link.now();
    link.station()
        .upload_with(now, &plans[next], Sequence::Atomic)
        .unwrap();
    finish(&mut link).unwrap();
    assert_eq!(whole(download(&mut link).unwrap()), valid[next]);
    assert_eq!(report(&mut link).len(), 1, "staged copies were left");
    println!(
        "{trials} trials (seed {seed}) in {:.1} s: {tally:?}; kills {kills:?}; emulator {:?}",
        started.elapsed().as_secs_f64(),
        emulator.stats()
    );
    fcc.stop().unwrap();
}
