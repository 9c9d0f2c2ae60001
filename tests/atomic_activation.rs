//! Activation replaces the waypoint list and the area list in one step (ICD §8): two staged
//! missions (ICD §8) activated alternately many times on the real FCC, while a watcher on the
//! list services, using the pairing the partitions use (`ipc::ListPairing`), records every pair
//! it is handed. Every pair is a whole mission, the waypoint list and the area list of the same
//! staged mission: never the new waypoints with the old areas or the reverse (docs/design.md
//! "Activation is atomic"). How often the newest samples of the two services were of different
//! activations is printed, not asserted: it depends on timing, and shows what the pairing
//! prevented.
//!
//! The ground is played here, message by message (stop and wait, one retry, ICD §3): the GCS
//! logic's staging commands are not what is under test.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use common::*;
use iceoryx2::prelude::{CallbackProgression, ipc};
use missionlink_interfaces::contracts::{AreaListPayload, WaypointListPayload};
use missionlink_interfaces::wire::{
    AckType, AreaListStatus, AreaTransferMode, AreaTransmissionCommand, ExecuteCommand,
    MAX_FRAME_LEN, Message, MissionExecuteCommand, MissionPlanMode, Text, Timestamp,
};
use missionlink_partitions::ipc::{Ipc, ListPairing};
use missionlink_partitions::runtime;
use missionlink_platform::clock::DriverClock;
use missionlink_platform::udp::LinkPair;
use missionlink_services::ground_station::ValidatedPlan;
use missionlink_services::link::endpoint::{Endpoint, Inbound};
use missionlink_services::transfer::sender::mission_command;

/// Activations of the two staged missions, alternately.
const ACTIVATIONS: usize = 50;

/// How long anything the FCC does may take before the test gives up on it.
const LIMIT: Duration = Duration::from_secs(20);

/// The ground, played message by message over the rig's links.
struct Ground {
    endpoint: Endpoint,
    links: LinkPair,
    clock: DriverClock,
    ack_timeout: Duration,
}

impl Ground {
    fn new(config: &missionlink_partitions::config::Config, links: LinkPair) -> Self {
        let clock = DriverClock::start();
        let core = config.link().gcs_core(clock.utc_at_zero());
        // Answers come on both links; the direct one is read, with a timeout.
        let direct = links.sockets()[0];
        direct.set_nonblocking(false).unwrap();
        Self {
            endpoint: Endpoint::new(core.endpoint),
            links,
            clock,
            ack_timeout: core.ack_timeout,
        }
    }

    /// Sends `message` with "acknowledgement requested" and returns its answer: the #17000 of
    /// the same type and time stamp, or the #3012 to an area closer. After the ack timeout the
    /// message goes once more with a new time stamp (ICD §3).
    fn exchange(&mut self, message: Message) -> Message {
        let closes_areas = matches!(&message, Message::AreaTransmissionCommand(c)
            if c.mode == AreaTransferMode::UploadCompleteStaged);
        for _attempt in 0..2 {
            let stamp = self.endpoint.send(self.clock.now(), message.clone(), true);
            let mut buf = [0u8; MAX_FRAME_LEN];
            while let Some(frame) = self.endpoint.poll_transmit(&mut buf) {
                self.links.send_both(&buf[..frame.unwrap()]);
            }
            let deadline = std::time::Instant::now() + self.ack_timeout;
            while let Some(answer) = self.receive_until(deadline) {
                let is_answer = match &answer {
                    Message::MessageAcknowledgement(ack) => {
                        ack.original_message_type == message.message_type() as u16
                            && ack.original_time_stamp == stamp
                    }
                    Message::AreaStatusAlert(_) => closes_areas,
                    _ => false,
                };
                if is_answer {
                    return answer;
                }
            }
        }
        panic!("no answer to {message}");
    }

    /// The next fresh message from the FCC, until `deadline`.
    fn receive_until(&mut self, deadline: std::time::Instant) -> Option<Message> {
        let direct = self.links.sockets()[0];
        let mut buf = [0u8; 2048];
        loop {
            let left = deadline.checked_duration_since(std::time::Instant::now())?;
            direct
                .set_read_timeout(Some(left.max(Duration::from_millis(1))))
                .unwrap();
            let Ok((len, _)) = direct.recv_from(&mut buf) else {
                continue;
            };
            if let Ok(Inbound::Message { message, .. }) =
                self.endpoint.receive(self.clock.now(), &buf[..len])
            {
                return Some(message);
            }
        }
    }

    /// Sends `message` and expects it accepted (#17000 type 2, or #3012 valid).
    fn accepted(&mut self, message: Message) {
        let what = message.to_string();
        match self.exchange(message) {
            Message::MessageAcknowledgement(ack) => assert_eq!(
                ack.ack_type,
                AckType::Completed,
                "{what}: refused, {:?}",
                ack.reject_reason
            ),
            Message::AreaStatusAlert(alert) => assert_eq!(
                alert.status,
                AreaListStatus::Valid,
                "{what}: refused, {:?}",
                alert.reason
            ),
            other => panic!("{what}: answered by {other}"),
        }
    }

    /// Stages `plan` under `id` (ICD §8): #13000 mode 10 (a new mission: the buffer emptied),
    /// the waypoint messages, #13000 mode 8; #2011 mode 1, the #2012 areas, #2011 mode 7.
    fn stage(&mut self, id: &str, plan: &ValidatedPlan) {
        let id = Some(Text::new(id).unwrap());
        self.accepted(mission_command(
            MissionPlanMode::LoadWaypointBuffer,
            None,
            id,
        ));
        for m in plan.mission.messages() {
            self.accepted(m);
        }
        let count = plan.mission.waypoints.len() as u16;
        self.accepted(mission_command(
            MissionPlanMode::StageMission,
            Some(count),
            id,
        ));
        let areas = |mode, mission_id| {
            Message::from(AreaTransmissionCommand {
                time_stamp: Timestamp::default(),
                mode,
                loop_count: Some(plan.areas.areas.len() as u8),
                area_id: None,
                safety_offset: Some(plan.areas.safety_offset),
                activity_id: None,
                mission_id,
                window_or_checksum: None,
            })
        };
        self.accepted(areas(AreaTransferMode::InitiateUpload, None));
        for a in &plan.areas.areas {
            self.accepted(a.clone().into());
        }
        self.accepted(areas(AreaTransferMode::UploadCompleteStaged, id));
    }

    /// Activates staged mission `id` (#50000 command 4).
    fn activate(&mut self, id: &str) {
        self.accepted(
            MissionExecuteCommand {
                time_stamp: Timestamp::default(),
                command: ExecuteCommand::ActivateStaged,
                mission_id: Some(Text::new(id).unwrap()),
            }
            .into(),
        );
    }
}

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
    let node = Ipc::<ipc::Service>::open("activation-watcher", &prefix).unwrap();
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
    let late = Ipc::<ipc::Service>::open("activation-late", &rig.config.ipc.service_prefix)
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
