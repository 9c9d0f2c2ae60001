//! Each partition's loop in one process, on `iceoryx2::prelude::local::Service`: the partition
//! runs on a thread of the test, the test plays its neighbours through its own node, and a
//! `Control` stops it. Every test has its own service prefix and state directory. The
//! cross-process tests of the real binaries are in the root package's `tests/`.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::net::UdpSocket;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::prelude::local;
use missionlink_ground::ground_station::{
    GcsConfig, GcsEvent, GroundStation, MissionPlan, ValidatedPlan, WithoutGateway,
};
use missionlink_ground::testkit;
use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationCommandPayload, AutomationStatePayload, FccService, FlightPhase,
    FramePayload, GuidanceProgressPayload, HeartbeatPayload, Link, Partition, WaypointListPayload,
};
use missionlink_interfaces::wire::{
    AreaType, ExecuteCommand, LegType, MAX_FRAME_LEN, MissionPlanMode,
};
use missionlink_partitions::config::{Config, SigningPolicy};
use missionlink_partitions::ipc::{Ipc, Publisher, Subscriber};
use missionlink_partitions::runtime::{self, Control, PartitionError};
use missionlink_partitions::{
    guidance_stub, mission_data_handling, state, system_automation, voting_monitoring,
};
use missionlink_platform::clock::DriverClock;
use missionlink_protocol::transfer::sender::mission_command;

type S = local::Service;
type Loop = fn(&Config, &Control) -> Result<(), PartitionError>;

/// How long any condition may take before the test fails (generous: the machine is shared).
const LIMIT: Duration = Duration::from_secs(20);

/// A configuration no other test shares: prefix and state directory, the directory removed
/// when the returned guard is dropped.
fn config(test: &str) -> (Config, tempfile::TempDir) {
    let dir = tempfile::Builder::new()
        .prefix(&format!("missionlink-inproc-{test}-"))
        .tempdir()
        .unwrap();
    let mut c = Config::default();
    c.ipc.service_prefix = format!("inproc-{test}-{}", std::process::id());
    c.ipc.state_dir = Some(dir.path().join("state"));
    (c, dir)
}

/// A partition loop on a thread of the test.
struct Running {
    control: Control,
    thread: Option<JoinHandle<Result<(), PartitionError>>>,
}

impl Running {
    fn start(run: Loop, config: &Config) -> Self {
        let control = Control::new();
        let (c, config) = (control.clone(), config.clone());
        let thread = std::thread::spawn(move || run(&config, &c));
        assert!(control.wait_ready(LIMIT), "the partition did not start");
        Self {
            control,
            thread: Some(thread),
        }
    }

    /// Stops the loop and checks that it ended without an error.
    fn stop(mut self) {
        self.control.stop();
        if let Some(thread) = self.thread.take() {
            thread.join().unwrap().unwrap();
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.control.stop();
    }
}

/// Waits for `f` to give a value, sleeping in a WaitSet on `subscriber`'s listener; fails the
/// test after [`LIMIT`].
fn next<T: std::fmt::Debug + Copy + iceoryx2::prelude::ZeroCopySend + 'static, R>(
    subscriber: &Subscriber<S, T>,
    f: impl FnMut(&T) -> Option<R>,
) -> R {
    within(subscriber, LIMIT, f).unwrap_or_else(|| panic!("nothing came on {subscriber:?}"))
}

/// As [`next`], `None` after `limit`.
/// Every sample `subscriber` holds once one arrives within `limit` (a window of answers comes
/// at once, ICD §10: none may be dropped).
fn all_within<T: std::fmt::Debug + Copy + iceoryx2::prelude::ZeroCopySend + 'static>(
    subscriber: &Subscriber<S, T>,
    limit: Duration,
) -> Vec<T> {
    let waitset = runtime::waitset::<S>().unwrap();
    let _guard = waitset.attach_notification(subscriber.listener()).unwrap();
    let control = Control::new();
    let end = Instant::now() + limit;
    let mut all = Vec::new();
    loop {
        subscriber.take_all(|v| all.push(*v));
        if !all.is_empty() || Instant::now() >= end {
            return all;
        }
        control
            .wait(&waitset, false, Duration::from_millis(20))
            .unwrap();
    }
}

fn within<T: std::fmt::Debug + Copy + iceoryx2::prelude::ZeroCopySend + 'static, R>(
    subscriber: &Subscriber<S, T>,
    limit: Duration,
    mut f: impl FnMut(&T) -> Option<R>,
) -> Option<R> {
    let waitset = runtime::waitset::<S>().unwrap();
    let _guard = waitset.attach_notification(subscriber.listener()).unwrap();
    let control = Control::new();
    let end = Instant::now() + limit;
    loop {
        let mut found = None;
        subscriber.take_all(|v| {
            if found.is_none() {
                found = f(v);
            }
        });
        if found.is_some() || Instant::now() >= end {
            return found;
        }
        control
            .wait(&waitset, false, Duration::from_millis(20))
            .unwrap();
    }
}

/// A small mission: take-off height, two waypoints, a bidirectional route, the demo fly-zone.
fn plan() -> MissionPlan {
    testkit::plan(
        &[
            testkit::take_off(30.0).into(),
            testkit::waypoint(1, 2, testkit::CCP, LegType::TrackToFix).into(),
            testkit::waypoint(2, 0, (48.278, 11.658), LegType::TrackToFix).into(),
            testkit::route(1, true).into(),
        ],
        &[testkit::polygon(1, AreaType::FlyZone, &testkit::FLY_ZONE)],
        "IN-PROCESS",
    )
}

fn valid() -> ValidatedPlan {
    plan().assemble().unwrap()
}

#[test]
fn mission_data_handling_fed_uplink_frames_publishes_the_lists_and_answers_on_the_downlink() {
    let (config, _dir) = config("mdh");
    let partition = Running::start(mission_data_handling::run::<S>, &config);
    let ipc = Ipc::<S>::open("gcs-side", &config.ipc.service_prefix).unwrap();
    let uplink: Publisher<S, FramePayload> = ipc.publisher(FccService::Uplink).unwrap();
    let downlink: Subscriber<S, FramePayload> = ipc.subscriber(FccService::Downlink).unwrap();
    let waypoints: Subscriber<S, WaypointListPayload> =
        ipc.subscriber(FccService::WaypointList).unwrap();
    let areas: Subscriber<S, AreaListPayload> = ipc.subscriber(FccService::AreaList).unwrap();

    // The GCS logic plays the ground, its frames carried over the uplink service.
    let clock = DriverClock::start();
    let gcs_config = GcsConfig {
        endpoint: config.link().ids.gcs_endpoint(clock.utc_at_zero()),
        ..testkit::gcs_config()
    };
    let mut gcs = GroundStation::new(gcs_config, WithoutGateway);
    gcs.upload(clock.now(), &plan(), true).unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    let mut answers = 0;
    let outcome = loop {
        while let Some(len) = gcs.poll_transmit(&mut buf) {
            let frame = buf.get(..len.unwrap()).unwrap();
            uplink
                .send(&FramePayload::new(Link::Direct, frame, 0).unwrap())
                .unwrap();
        }
        if let Some(event) = gcs.poll_event() {
            if !matches!(event, GcsEvent::Progress { .. }) {
                break event;
            }
            continue;
        }
        if gcs.poll_timeout().is_some_and(|t| t <= clock.now()) {
            gcs.handle_timeout(clock.now());
            continue;
        }
        // The next answer, or the GCS's next timer.
        let until_timer = gcs
            .poll_timeout()
            .map_or(LIMIT, |t| t.saturating_since(clock.now()));
        for frame in all_within(&downlink, until_timer) {
            answers += 1;
            assert_eq!(
                frame.link(),
                Some(Link::Both),
                "answers go out on both links"
            );
            gcs.handle_frame(clock.now(), frame.frame()).unwrap();
        }
    };
    assert!(
        matches!(&outcome, GcsEvent::Uploaded(r) if r.is_complete()),
        "{outcome:?}"
    );
    assert!(answers >= 6, "an answer per uplink message: {answers}");

    let valid = valid();
    let list = next(&waypoints, |l| (l.generation > 0).then_some(*l));
    let expected = valid.mission.to_payload(list.generation);
    assert_eq!(list.count, 2);
    assert_eq!(list.waypoints(), expected.waypoints());
    assert_eq!(list.take_off_height, expected.take_off_height);
    let area_list = next(&areas, |l| (l.generation > 0).then_some(*l));
    assert_eq!(area_list.area_count(), 1);
    assert_eq!(
        area_list.fly_zone,
        valid.areas.to_payload(area_list.generation).fly_zone
    );
    // Kept for a restart.
    let dir = config.ipc.state_dir();
    assert!(state::load_active(&dir).is_some_and(|a| a.mission == Some(valid.mission)));
    partition.stop();
}

#[test]
fn voting_monitoring_votes_udp_onto_the_uplink_sends_the_downlink_on_both_links_and_keeps_its_ports()
 {
    let (mut config, _dir) = config("vm");
    // The voting of unsigned frames, as from a GCS that cannot sign, written in the
    // configuration as a deployment would have to (the signed links: tests/system/signed_links.rs).
    config.signing.policy = SigningPolicy::Off;
    let gcs_direct = UdpSocket::bind("127.0.0.1:0").unwrap();
    let gcs_lte = UdpSocket::bind("127.0.0.1:0").unwrap();
    for s in [&gcs_direct, &gcs_lte] {
        s.set_read_timeout(Some(LIMIT)).unwrap();
    }
    config.links.gcs_direct = gcs_direct.local_addr().unwrap();
    config.links.gcs_lte = gcs_lte.local_addr().unwrap();
    config.links.fcc_direct = "127.0.0.1:0".parse().unwrap();
    config.links.fcc_lte = "127.0.0.1:0".parse().unwrap();

    let ipc = Ipc::<S>::open("neighbours", &config.ipc.service_prefix).unwrap();
    let uplink: Subscriber<S, FramePayload> = ipc.subscriber(FccService::Uplink).unwrap();
    let downlink: Publisher<S, FramePayload> = ipc.publisher(FccService::Downlink).unwrap();
    let partition = Running::start(voting_monitoring::run::<S>, &config);
    let dir = config.ipc.state_dir();
    let links = state::load_links(&dir).expect("the bound ports are announced");
    assert_ne!(links.fcc_direct.port(), 0);
    assert_ne!(links.fcc_lte.port(), 0);

    // The same message on both links, then a newer one on LTE: the duplicate is dropped, so
    // the newer one is the next frame on the uplink.
    let frame = |ms: u64| {
        let mut m = mission_command(MissionPlanMode::ClearMission, None, None);
        m.set_time_stamp(testkit::ts(900_000_000_000 + ms));
        // The configuration keeps the IDs of ICD §1, the testkit's.
        testkit::uplink(&m)
    };
    let (first, second) = (frame(1), frame(2));
    let from_gcs = UdpSocket::bind("127.0.0.1:0").unwrap();
    from_gcs.send_to(&first, links.fcc_direct).unwrap();
    let voted = next(&uplink, |f| Some(*f));
    assert_eq!(voted.frame(), &first[..]);
    assert_eq!(voted.link(), Some(Link::Direct));
    from_gcs.send_to(&first, links.fcc_lte).unwrap();
    from_gcs.send_to(&second, links.fcc_lte).unwrap();
    let voted = next(&uplink, |f| Some(*f));
    assert_eq!(
        voted.frame(),
        &second[..],
        "the duplicate was not forwarded"
    );
    assert_eq!(voted.link(), Some(Link::Lte));

    // A downlink frame goes out on both links.
    downlink
        .send(&FramePayload::new(Link::Both, &second, 0).unwrap())
        .unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    for socket in [&gcs_direct, &gcs_lte] {
        let (len, from) = socket.recv_from(&mut buf).unwrap();
        assert_eq!(&buf[..len], &second[..]);
        assert!(from == links.fcc_direct || from == links.fcc_lte, "{from}");
    }

    // Restarted, it binds the announced ports again.
    partition.stop();
    let partition = Running::start(voting_monitoring::run::<S>, &config);
    assert_eq!(state::load_links(&dir), Some(links));
    partition.stop();
}

#[test]
fn system_automation_executes_only_when_its_rules_allow_and_follows_guidance() {
    let (mut config, _dir) = config("sa");
    // One beat keeps guidance alive through the test, however slowly the machine runs it: the
    // state changes counted below are the commands' alone.
    config.health.period_ms = 10_000;
    let ipc = Ipc::<S>::open("neighbours", &config.ipc.service_prefix).unwrap();
    let state: Subscriber<S, AutomationStatePayload> =
        ipc.subscriber(FccService::AutomationState).unwrap();
    let waypoints: Publisher<S, WaypointListPayload> =
        ipc.publisher(FccService::WaypointList).unwrap();
    let areas: Publisher<S, AreaListPayload> = ipc.publisher(FccService::AreaList).unwrap();
    let commands: Publisher<S, AutomationCommandPayload> =
        ipc.publisher(FccService::AutomationCommand).unwrap();
    let progress: Publisher<S, GuidanceProgressPayload> =
        ipc.publisher(FccService::GuidanceProgress).unwrap();
    let heartbeat: Publisher<S, HeartbeatPayload> = ipc
        .publisher(FccService::Heartbeat(Partition::Guidance))
        .unwrap();
    let partition = Running::start(system_automation::run::<S>, &config);
    // Guidance beats before every command: nothing flies without it (docs/design.md "Health").
    let command = |sequence, command: ExecuteCommand| {
        heartbeat
            .send(&HeartbeatPayload {
                sequence,
                time_ns: 0,
                period_ns: 100_000_000,
                pid: 1,
                reserved: [0; 4],
            })
            .unwrap();
        commands
            .send(&AutomationCommandPayload {
                sequence,
                accepted_ns: 0,
                command: command as u8,
                reserved: [0; 7],
            })
            .unwrap();
    };
    let phase = |s: &AutomationStatePayload| s.flight_phase();

    let first = next(&state, |s| Some(*s));
    assert_eq!(phase(&first), Some(FlightPhase::OnGround));
    assert!(!first.guidance_alive, "no heartbeat yet");
    let valid = valid();
    waypoints.send(&valid.mission.to_payload(1)).unwrap();
    areas.send(&valid.areas.to_payload(1)).unwrap();
    // Navigation: on the ground at TROL, where the onboard geofence check starts (ICD §7).
    let (lat, lon) = testkit::TROL;
    progress
        .send(&GuidanceProgressPayload {
            sequence: 1,
            waypoint_list: 1,
            latitude_deg: lat,
            longitude_deg: lon,
            ..GuidanceProgressPayload::IDLE
        })
        .unwrap();
    // Until automation has seen the lists and the position an execute is refused; it is sent
    // again until taken.
    let end = Instant::now() + LIMIT;
    let mut sequence = 0;
    let take_off = loop {
        assert!(Instant::now() < end, "execute never carried out");
        sequence += 1;
        command(sequence, ExecuteCommand::Execute);
        let taken = within(&state, Duration::from_millis(200), |s| {
            (phase(s) == Some(FlightPhase::TakeOff)).then_some(*s)
        });
        if let Some(state_now) = taken {
            break state_now;
        }
    };
    assert_eq!(take_off.flown_waypoint_list, 1);
    assert!(take_off.trajectory_generation_active && take_off.guidance_alive);

    // In the air an execute is refused and a return to home carried out, in queue order: one
    // state change, not two.
    command(sequence + 1, ExecuteCommand::Execute);
    command(sequence + 2, ExecuteCommand::ReturnToHome);
    let home = next(&state, |s| s.route_reversed.then_some(*s));
    assert_eq!(home.sequence, take_off.sequence + 1, "{home:?}");
    assert_eq!(phase(&home), Some(FlightPhase::TakeOff));

    // Guidance reports the climb complete: cruise.
    let mut climbed = GuidanceProgressPayload::IDLE;
    climbed.on_ground = false;
    climbed.climb_complete = true;
    climbed.waypoint_list = 1;
    progress.send(&climbed).unwrap();
    let cruise = next(&state, |s| {
        (phase(s) == Some(FlightPhase::Cruise)).then_some(*s)
    });
    assert!(cruise.trajectory_generation_active);
    partition.stop();
}

#[test]
fn guidance_stub_flies_the_list_and_publishes_its_progress() {
    let (mut config, _dir) = config("guidance");
    config.guidance.time_scale = 50.0;
    let ipc = Ipc::<S>::open("neighbours", &config.ipc.service_prefix).unwrap();
    let waypoints: Publisher<S, WaypointListPayload> =
        ipc.publisher(FccService::WaypointList).unwrap();
    let areas: Publisher<S, AreaListPayload> = ipc.publisher(FccService::AreaList).unwrap();
    let automation: Publisher<S, AutomationStatePayload> =
        ipc.publisher(FccService::AutomationState).unwrap();
    let progress: Subscriber<S, GuidanceProgressPayload> =
        ipc.subscriber(FccService::GuidanceProgress).unwrap();
    let partition = Running::start(guidance_stub::run::<S>, &config);

    let idle = next(&progress, |p| Some(*p));
    assert!(idle.on_ground);
    let valid = valid();
    waypoints.send(&valid.mission.to_payload(1)).unwrap();
    areas.send(&valid.areas.to_payload(1)).unwrap();
    let mut state = AutomationStatePayload::ON_GROUND;
    state.sequence = 1;
    state.flown_waypoint_list = 1;
    state.flight_phase = FlightPhase::TakeOff as u8;
    state.trajectory_generation_active = true;
    automation.send(&state).unwrap();
    let climbed = next(&progress, |p| p.climb_complete.then_some(*p));
    assert!(!climbed.on_ground);
    assert_eq!(climbed.waypoint_list, 1);

    state.sequence = 2;
    state.flight_phase = FlightPhase::Cruise as u8;
    automation.send(&state).unwrap();
    // FROM-TO-NEXT along the route 1 -> 2, then the end of the route.
    let on_route = next(&progress, |p| (p.to == 1).then_some(*p));
    assert_eq!(on_route.next, 2);
    assert!(on_route.inside_fly_zone);
    let second_leg = next(&progress, |p| (p.from == 1 && p.to == 2).then_some(*p));
    assert_eq!(second_leg.next, 0);
    next(&progress, |p| p.route_complete.then_some(()));
    partition.stop();
}
