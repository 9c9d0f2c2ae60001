//! The FCC's per-frame path allocates nothing (docs/design.md, "The sans-IO core"): a counting
//! global allocator around every call into voting and mission data handling, while the GCS uploads
//! and then downloads demo mission 2 with its areas, and guidance reports progress. The links are
//! signed (ICD §9): the voter requires signatures and the FCC's answers are signed, inside the
//! count.

use std::time::Duration;

use crate::support::*;
use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_ground::ground_station::{GcsEvent, GroundStation, WithoutGateway};
use missionlink_interfaces::contracts::{GuidanceProgressPayload, Link};
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::{MAX_FRAME_LEN, MAX_SIGNED_FRAME_LEN};
use missionlink_protocol::link::signing::{Policy, Signer};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::testkit::counted;
use missionlink_protocol::voting::Voter;

#[test]
fn the_fcc_frame_path_allocates_nothing() {
    // Prove the counter counts.
    let ((), n) = counted(|| drop(std::hint::black_box(vec![1u8; 16])));
    assert_eq!(n, 1);

    let mut gcs = GroundStation::new(gcs_config(), WithoutGateway);
    let mut fcc = MissionDataHandling::new(fcc_config());
    let mut voter = Voter::new(defaults::FCC_ID, defaults::GCS_ID, TRANSFER_TIMEOUT)
        .with_signatures(signature_check(Policy::Require));
    let signer = Signer::new(link_key());
    let mut signed_direct = [0u8; MAX_SIGNED_FRAME_LEN];
    let mut signed_lte = [0u8; MAX_SIGNED_FRAME_LEN];
    let mut signed_down = [0u8; MAX_SIGNED_FRAME_LEN];
    let mut now = Instant::ZERO;
    let mut frames = 0u64;
    let mut total = 0u64;
    let mut up = [0u8; MAX_FRAME_LEN];
    let mut down = [0u8; MAX_FRAME_LEN];

    gcs.upload(now, &mission_2(), true).unwrap();
    let mut downloading = false;
    loop {
        now = now + Duration::from_millis(2);
        while let Some(len) = gcs.poll_transmit(&mut up) {
            let len = len.unwrap();
            // The GCS signs each link's copy.
            let direct = signer
                .sign(Link::Direct, &up[..len], &mut signed_direct)
                .unwrap();
            let lte = signer.sign(Link::Lte, &up[..len], &mut signed_lte).unwrap();
            // The FCC side: voting of both links' copies, mission data handling, the answers.
            let ((), n) = counted(|| {
                let arrivals = [
                    (Link::Direct, &signed_direct[..direct]),
                    (Link::Lte, &signed_lte[..lte]),
                ];
                voter.vote_step(now, &arrivals, |_, _, frame| {
                    let _ = fcc.handle_frame(now, frame);
                });
                while fcc.poll_event().is_some() {}
            });
            total += n;
            frames += 1;
            loop {
                let (out, n) = counted(|| {
                    let len = fcc.poll_transmit(&mut down)?.unwrap();
                    Some(
                        signer
                            .sign(Link::Direct, &down[..len], &mut signed_down)
                            .unwrap()
                            - 16,
                    )
                });
                total += n;
                let Some(len) = out else { break };
                gcs.handle_frame(now, &down[..len]).unwrap();
            }
        }
        let ((), n) = counted(|| {
            fcc.handle_timeout(now);
            let progress = GuidanceProgressPayload {
                from: 1,
                to: 2,
                next: 3,
                ..GuidanceProgressPayload::IDLE
            };
            fcc.handle_progress(now, &progress);
        });
        total += n;
        while let Some(len) = fcc.poll_transmit(&mut down) {
            gcs.handle_frame(now, &down[..len.unwrap()]).unwrap();
        }
        match gcs.poll_event() {
            Some(GcsEvent::Uploaded(report)) if !downloading => {
                assert!(report.is_complete(), "{report}");
                downloading = true;
                gcs.download(now).unwrap();
            }
            Some(GcsEvent::DownloadComplete(_)) => break,
            Some(GcsEvent::Failed(e)) => panic!("{e}"),
            _ => {}
        }
        assert!(now < Instant::from_millis(60_000), "did not finish");
    }
    assert!(frames > 20, "only {frames} frames");
    assert_eq!(total, 0, "{total} allocations over {frames} uplink frames");
}

/// Guidance's step allocates nothing either: the zone test runs on the geofence built when the
/// area list arrived (mission 2 flown from CCP to ROLE2 across the fly-zone, past both
/// no-fly-zones).
#[test]
fn guidance_steps_allocate_nothing() {
    use missionlink_flight::guidance::{Guidance, GuidanceConfig};

    let plan = mission_2().assemble().unwrap();
    let mut guidance = Guidance::new(GuidanceConfig {
        start_latitude_deg: 48.275,
        start_longitude_deg: 11.645,
        ..GuidanceConfig::default()
    });
    guidance.set_waypoint_list(&plan.mission.to_payload(1));
    guidance.set_area_list(&plan.areas.to_payload(1));
    guidance.set_automation(&flying());
    let mut now = Instant::ZERO;
    let mut total = 0u64;
    let mut last = GuidanceProgressPayload::IDLE;
    for _ in 0..2_000 {
        now = now + Duration::from_millis(100);
        let (progress, n) = counted(|| guidance.step(now));
        total += n;
        last = progress;
        if last.route_complete {
            break;
        }
    }
    assert!(last.route_complete && last.inside_fly_zone, "{last:?}");
    assert_eq!(total, 0, "{total} allocations over the flight");
}
