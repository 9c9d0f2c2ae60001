//! The onboard geofence check allocates nothing (docs/design.md, "The sans-IO
//! core"): under a counting global allocator, in the worst case of
//! `testkit::geofence_worst_case` (and its radius-to-fix variant), building the fence from the
//! published area list (`Fence::of_payload`) and checking the execute route and the return
//! route against it make no allocation, and neither does a check that fails. The fixtures are
//! built before counting (they are test code; building them initialises the geodesic solver's
//! coefficients once, as the FCC's first check would).
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

use missionlink_protocol::geofence::flown_route;
use std::hint::black_box;

use missionlink_flight::automation::fcc_turns;
use missionlink_flight::onboard;
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::testkit::{CountingAllocator, counted};
use missionlink_protocol::testkit::{
    geofence_worst_case, geofence_worst_case_rf, published_lists, worst_case_areas,
    worst_case_messages,
};

#[test]
fn the_onboard_check_allocates_nothing_in_its_worst_case() {
    // Prove the counter counts.
    let ((), n) = counted(|| drop(black_box(vec![1u8; 16])));
    assert_eq!(n, 1);

    for (waypoints, areas, take_off) in [geofence_worst_case(), geofence_worst_case_rf()] {
        let site = Site::of(take_off);
        let (verdicts, n) = counted(|| {
            let fence = Fence::of_payload(black_box(&areas));
            let execute = onboard::check(
                &fence,
                flown_route::execute_route(
                    flown_route::RouteView::from(&waypoints),
                    site,
                    Some(fcc_turns()),
                ),
            );
            let back = onboard::check(
                &fence,
                flown_route::return_route(
                    flown_route::RouteView::from(&waypoints),
                    site,
                    0,
                    Some(fcc_turns()),
                ),
            );
            let halfway = onboard::check(
                &fence,
                flown_route::return_route(
                    flown_route::RouteView::from(&waypoints),
                    site,
                    128,
                    Some(fcc_turns()),
                ),
            );
            (execute, back, halfway)
        });
        assert_eq!(verdicts, (Ok(()), Ok(()), Ok(())));
        assert_eq!(n, 0, "{n} allocations");
    }
}

#[test]
fn a_failing_onboard_check_allocates_nothing() {
    let mut shifts = [0.0; 10];
    shifts[4] = 200.0;
    let (waypoints, areas) =
        published_lists(&worst_case_messages(false), &worst_case_areas(shifts));
    let (_, _, take_off) = geofence_worst_case();
    let site = Site::of(take_off);
    let (verdict, n) = counted(|| {
        let fence = Fence::of_payload(black_box(&areas));
        onboard::check(
            &fence,
            flown_route::execute_route(
                flown_route::RouteView::from(&waypoints),
                site,
                Some(fcc_turns()),
            ),
        )
    });
    assert_eq!(verdict.map_err(|v| v.area_id), Err(6));
    assert_eq!(n, 0, "{n} allocations");
}
