//! The worst case of the onboard geofence check (ICD §7; the fixture is
//! `testkit::geofence_worst_case`, measured in BENCHMARKS.md section 4) is what it says: the check
//! passes, so it looks at every leg against every zone; every one of the 11 zones comes within 40 m
//! of the route, 15 m beyond the safety offset; and the fixture is tight, so a no-fly-zone moved
//! 16 m onto the route fails the check naming that zone while one moved 14 m still passes. The
//! benchmark (`benches/geofence.rs`) and the allocation test (`tests/geofence_no_allocation.rs`)
//! run it.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use missionlink_flight::automation::fcc_turns;
use missionlink_flight::onboard;
use missionlink_interfaces::capacity::{MAX_AREAS, MAX_POLYGON_VERTICES, MAX_WAYPOINTS};
use missionlink_interfaces::contracts::{AreaListPayload, WaypointListPayload};
use missionlink_interfaces::wire::{GeoPoint, LegType};
use missionlink_protocol::geofence::clearance::clearance;
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::flown_route::{self, RouteElement};
use missionlink_protocol::geofence::path::Track;
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::testkit::{
    WORST_CASE_CLOSEST_M, geofence_worst_case, geofence_worst_case_rf, published_lists,
    worst_case_areas, worst_case_messages, worst_case_take_off,
};

/// The smallest margin of the execute route to each zone, in the fence's order.
fn closest_per_zone(fence: &Fence, list: &WaypointListPayload, take_off: GeoPoint) -> Vec<f64> {
    let tracks: Vec<Track> = flown_route::execute_route(
        flown_route::RouteView::from(list),
        Site::of(take_off),
        Some(fcc_turns()),
    )
    .map(|leg| Track::new(leg.path))
    .collect();
    fence
        .zones
        .iter()
        .map(|zone| {
            tracks
                .iter()
                .map(|t| clearance(t, zone, 10_000.0, true).metres())
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

fn shape_is_the_largest(waypoints: &WaypointListPayload, areas: &AreaListPayload) {
    assert_eq!(usize::from(waypoints.count), MAX_WAYPOINTS);
    assert_eq!(areas.area_count(), MAX_AREAS);
    assert_eq!(areas.fly_zone.vertices().len(), MAX_POLYGON_VERTICES);
    assert_eq!(areas.no_fly_polygons().len(), MAX_AREAS - 1);
    for p in areas.no_fly_polygons() {
        assert_eq!(p.vertices().len(), MAX_POLYGON_VERTICES);
    }
    assert_eq!(areas.safety_offset.metres(), 25.0);
}

#[test]
fn the_worst_case_passes_with_every_zone_40_m_from_the_route() {
    for (name, (waypoints, areas, take_off)) in [
        ("track-to-fix", geofence_worst_case()),
        ("radius-to-fix", geofence_worst_case_rf()),
    ] {
        shape_is_the_largest(&waypoints, &areas);
        let fence = Fence::of_payload(&areas);
        let site = Site::of(take_off);
        assert_eq!(
            onboard::check(
                &fence,
                flown_route::execute_route(
                    flown_route::RouteView::from(&waypoints),
                    site,
                    Some(fcc_turns())
                )
            ),
            Ok(()),
            "{name}"
        );
        assert_eq!(
            onboard::check(
                &fence,
                flown_route::return_route(
                    flown_route::RouteView::from(&waypoints),
                    site,
                    0,
                    Some(fcc_turns())
                )
            ),
            Ok(()),
            "{name}"
        );
        let closest = closest_per_zone(&fence, &waypoints, take_off);
        assert_eq!(closest.len(), MAX_AREAS);
        for (zone, m) in fence.zones.iter().zip(&closest) {
            assert!(
                (m - WORST_CASE_CLOSEST_M).abs() < 0.5,
                "{name}: area {} is {m} m from the route",
                zone.id
            );
        }
    }
}

#[test]
fn the_radius_to_fix_variant_flies_every_fourth_leg_as_an_arc() {
    let (rf, ..) = geofence_worst_case_rf();
    let arcs = rf
        .waypoints()
        .iter()
        .filter(|w| w.leg_type() == Some(LegType::RadiusToFix))
        .count();
    // 127 legs between lanes, the north ones arcs but for the turns between passes.
    assert!((55..=64).contains(&arcs), "{arcs} arcs");
    let (tf, ..) = geofence_worst_case();
    assert!(
        tf.waypoints()
            .iter()
            .all(|w| w.leg_type() == Some(LegType::TrackToFix))
    );
}

#[test]
fn a_no_fly_zone_moved_onto_the_route_fails_the_check() {
    let messages = worst_case_messages(false);
    let take_off = Site::of(worst_case_take_off());
    // No-fly-zone 4 (area 6) moved east: the first pass flies 40 m east of it, up corridor 5
    // (lane 5, waypoints 11 -> 12).
    let check = |shift: f64| {
        let mut shifts = [0.0; 10];
        shifts[4] = shift;
        let (waypoints, areas) = published_lists(&messages, &worst_case_areas(shifts));
        let fence = Fence::of_payload(&areas);
        onboard::check(
            &fence,
            flown_route::execute_route(
                flown_route::RouteView::from(&waypoints),
                take_off,
                Some(fcc_turns()),
            ),
        )
    };
    assert_eq!(check(14.0), Ok(()));
    let near = check(16.0).unwrap_err();
    assert_eq!(near.area_id, 6);
    assert_eq!(
        near.element,
        RouteElement::Leg { from: 11, to: 12 },
        "{near:?}"
    );
    assert!((near.clearance.metres() - 24.0).abs() < 0.5, "{near:?}");
    // Onto the route: the lane crosses it.
    let across = check(200.0).unwrap_err();
    assert_eq!(across.area_id, 6);
    assert!(across.clearance.metres() < 0.0, "{across:?}");
}
