//! Activation replaces the waypoint list and the area list in one step (ICD §8): two staged
//! missions (ICD §8) activated alternately many times on the real FCC, while a watcher on the
//! list services, using the pairing the partitions use (`ipc::ListPairing`), records every pair
//! it is handed. Every pair is a whole mission, the waypoint list and the area list of the same
//! staged mission: never the new waypoints with the old areas or the reverse (docs/design.md
//! "Activation is atomic"). How often the newest samples of the two services were of different
//! activations is printed, not asserted: it depends on timing, and shows what the pairing
//! prevented.
//!
//! The ground is played message by message (`harness::ground`): the GCS logic's staging
//! commands are not what is under test.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use iceoryx2::prelude::{CallbackProgression, ipc};
use missionlink::harness::ground::Ground;
use missionlink::harness::*;
use missionlink_ground::ground_station::ValidatedPlan;
use missionlink_interfaces::contracts::{AreaListPayload, WaypointListPayload};
use missionlink_partitions::ipc::{Ipc, ListPairing};
use missionlink_partitions::runtime;

/// Activations of the two staged missions, alternately.
const ACTIVATIONS: usize = 50;

/// How long anything the FCC does may take before the test gives up on it.
const LIMIT: Duration = Duration::from_secs(20);

/// Which of `missions` a waypoint list is (by its content, not its counters).
fn which_waypoints(list: &WaypointListPayload, missions: &[ValidatedPlan]) -> Option<usize> {
    missions.iter().position(|m| {
        let e = m.mission.to_payload(0);
        list.take_off_height == e.take_off_height
            && list.initial_waypoint == e.initial_waypoint
            && list.bidirectional == e.bidirectional
            && list.waypoints() == e.waypoints()
    })
}

/// Which of `missions` an area list is (by its content, not its counters).
fn which_areas(list: &AreaListPayload, missions: &[ValidatedPlan]) -> Option<usize> {
    missions.iter().position(|m| {
        let e = m.areas.to_payload(0);
        list.safety_offset == e.safety_offset
            && list.fly_zone == e.fly_zone
            && list.no_fly_polygons() == e.no_fly_polygons()
            && list.no_fly_circles() == e.no_fly_circles()
    })
}

/// A pair the watcher was handed: its activation, and which mission each list is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Handed {
    activation: u64,
    waypoints: Option<usize>,
    areas: Option<usize>,
}

/// What the watcher saw so far.
#[derive(Debug, Default)]
struct Watched {
    handed: Vec<Handed>,
    /// Looks at which the newest waypoint list and area list were of different activations.
    mismatched: u64,
}

/// Watches the list services under `prefix` until `stop`, as guidance does: it sleeps in a
/// WaitSet on both lists' events and takes pairs from the same pairing code.
fn watch(
    prefix: String,
    missions: Vec<ValidatedPlan>,
    seen: Arc<(Mutex<Watched>, Condvar)>,
    stop: Arc<AtomicBool>,
) {
    let node = Ipc::<ipc::Service>::open(
        "activation-watcher",
        &missionlink_partitions::config::Ipc::with_prefix(&prefix),
    )
    .unwrap();
    let lists = node.active_lists().unwrap();
    let waitset = runtime::waitset::<ipc::Service>().unwrap();
    let _guards = [
        waitset
            .attach_notification(lists.waypoints.listener())
            .unwrap(),
        waitset.attach_notification(lists.areas.listener()).unwrap(),
    ];
    let mut pairing = ListPairing::new();
    while !stop.load(Ordering::Relaxed) {
        waitset
            .wait_and_process_once_with_timeout(
                |_| CallbackProgression::Continue,
                Duration::from_millis(100),
            )
            .unwrap();
        let handed = lists.receive(&mut pairing).map(|(w, a)| Handed {
            activation: w.activation,
            waypoints: which_waypoints(w, &missions),
            areas: which_areas(a, &missions),
        });
        let (lock, changed) = &*seen;
        let mut watched = lock.lock().unwrap();
        watched.mismatched = pairing.mismatched();
        if let Some(handed) = handed {
            watched.handed.push(handed);
            changed.notify_all();
        }
    }
}

#[test]
fn alternate_activations_of_two_staged_missions_hand_out_only_whole_pairs() {
    let mut rig = Rig::new("atomic-activation");
    // The subject is which lists are handed out together, not the FCC's answer time: each
    // activation writes the lists to disk before it is answered, and on a machine busy writing
    // (the whole suite, its builds) one took longer than two ack timeouts of 500 ms in CI.
    rig.config.timing.ack_timeout_ms = 2_000;
    let mut fcc = rig.start_fcc();
    let links = rig.gcs_links(&mut fcc);
    let mut ground = Ground::new(&rig.config, links);
    let missions: Vec<ValidatedPlan> = ["mission-1.toml", "mission-2.toml"]
        .iter()
        .map(|f| plan(f).assemble().unwrap())
        .collect();
    let ids = ["ALPHA", "BRAVO"];

    let seen = Arc::new((Mutex::new(Watched::default()), Condvar::new()));
    let stop = Arc::new(AtomicBool::new(false));
    let watcher = {
        let (prefix, missions) = (rig.config.ipc.service_prefix.clone(), missions.clone());
        let (seen, stop) = (Arc::clone(&seen), Arc::clone(&stop));
        std::thread::Builder::new()
            .name("watcher".into())
            // Payloads are copied onto the stack, as in a partition's main thread.
            .stack_size(8 << 20)
            .spawn(move || watch(prefix, missions, seen, stop))
            .unwrap()
    };

    for (id, mission) in ids.iter().zip(&missions) {
        ground.stage(id, mission);
    }
    for i in 0..ACTIVATIONS {
        ground.activate(ids[i % 2]);
    }
    let last = (ACTIVATIONS - 1) % 2;

    // The lists published last, as a late subscriber receives them from the history.
    let late = Ipc::<ipc::Service>::open("activation-late", &rig.config.ipc)
        .unwrap()
        .active_lists()
        .unwrap();
    let mut pairing = ListPairing::new();
    let deadline = std::time::Instant::now() + LIMIT;
    let final_activation = loop {
        if let Some((w, a)) = late.receive(&mut pairing) {
            assert_eq!(which_waypoints(w, &missions), Some(last));
            assert_eq!(which_areas(a, &missions), Some(last));
            break w.activation;
        }
        assert!(std::time::Instant::now() < deadline, "no pair published");
        std::thread::sleep(Duration::from_millis(10));
    };

    // The watcher is handed that pair too (it may have skipped some between: history 1).
    let (lock, changed) = &*seen;
    let (watched, timeout) = changed
        .wait_timeout_while(lock.lock().unwrap(), LIMIT, |w| {
            w.handed.last().map(|h| h.activation) != Some(final_activation)
        })
        .unwrap();
    assert!(
        !timeout.timed_out(),
        "the watcher never got activation {final_activation}: {watched:?}"
    );
    let handed = watched.handed.clone();
    let mismatched = watched.mismatched;
    drop(watched);
    stop.store(true, Ordering::Relaxed);
    watcher.join().unwrap();

    for h in &handed {
        assert!(
            h.waypoints.is_some() && h.waypoints == h.areas,
            "a pair that is not one staged mission: {h:?} in {handed:?}"
        );
    }
    assert!(
        handed.windows(2).all(|w| w[0].activation < w[1].activation),
        "{handed:?}"
    );
    eprintln!(
        "{ACTIVATIONS} activations: {} whole pairs handed out, none mixed; the newest samples \
         of the two services disagreed at {mismatched} looks (a partition without the pairing \
         would have held a mix then)",
        handed.len()
    );
}
