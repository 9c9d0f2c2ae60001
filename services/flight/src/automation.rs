//! System automation (paper §2.5): the flight phases (on ground, take-off, cruise, landing,
//! landed), which functions they allow, and the #50000 Mission Execute Command of ICD §4.
//!
//! | phase | left when | to |
//! |---|---|---|
//! | on ground, landed | execute accepted | take-off |
//! | take-off (ATOL climb to the take-off height) | guidance reports the climb complete | cruise |
//! | cruise (trajectory generation flies the list) | guidance reports the route complete | landing |
//! | landing | guidance reports touchdown | landed |
//!
//! Trajectory generation counts as active from take-off to touchdown: guidance uses the active
//! lists in every airborne phase, so a clear is refused in all of them (`GuidanceActive`).
//!
//! [`check_command`] is the one rule for #50000: mission data handling applies it to answer the
//! command (type 2 or type 3 with the reason), system automation applies it again when it
//! carries the command out. Part of it is the onboard geofence check of ICD §7 (ext), and part
//! guidance's heartbeat (docs/design.md "Health"): system automation watches it and says in its
//! state whether guidance is alive; without it nothing flies.

use core::time::Duration;

use missionlink_interfaces::contracts::{
    AreaListPayload, AutomationStatePayload, DEFAULT_HEARTBEAT_PERIOD, FlightPhase,
    GuidanceProgressPayload, HeartbeatPayload, WaypointListPayload,
};
use missionlink_interfaces::wire::{ExecuteCommand, GeofenceCheck, Reason};

use crate::guidance::GuidanceConfig;
use crate::health::Liveness;
use crate::onboard;
use missionlink_protocol::geofence::earth::Site;
use missionlink_protocol::geofence::flown_route::{self, RouteView, RouteWaypoint};
use missionlink_protocol::geofence::zone::Fence;
use missionlink_protocol::link::time::Instant;

/// Whether system automation accepts `command` now (ICD §4, #50000). Execute, return to home
/// and land need guidance alive (its heartbeat within the limit, docs/design.md "Health"): nothing
/// would fly them, so they are refused with `WrongState`, the ICD's reason for "not now" (our
/// choice: the ICD has no reason of its own for it, and a new one would be unknown to an
/// edition-1 GCS). Then: execute needs a valid
/// waypoint and area list and the aircraft on the ground (`WrongState`); return to home needs a
/// bidirectional route (`Unsupported`), the aircraft in the air and flying the active list
/// (`WrongState`); landing at
/// the next waypoint needs the aircraft in the air (`WrongState`).
///
/// Execute and return to home then pass the onboard geofence check of ICD §7 (ext) or are
/// refused with `GeofenceViolation`: what the aircraft would fly from where navigation (guidance's
/// progress) says it is, against the active area list ([`onboard`]). Without a position from
/// navigation yet, or with one off the globe (not a number), there is nothing to check from:
/// `WrongState` (our choice; the ICD does not say).
pub fn check_command(
    state: &AutomationStatePayload,
    waypoints: &WaypointListPayload,
    areas: &AreaListPayload,
    fence: &Fence,
    navigation: &GuidanceProgressPayload,
    command: ExecuteCommand,
) -> Result<(), Reason> {
    let flies = matches!(
        command,
        ExecuteCommand::Execute | ExecuteCommand::ReturnToHome | ExecuteCommand::Land
    );
    if flies && !state.guidance_alive {
        return Err(Reason::WrongState);
    }
    let phase = state.flight_phase();
    let airborne = matches!(phase, Some(FlightPhase::TakeOff | FlightPhase::Cruise));
    let here = navigation_position(navigation);
    match command {
        ExecuteCommand::Execute => {
            let on_ground = matches!(phase, Some(FlightPhase::OnGround | FlightPhase::Landed));
            if !on_ground {
                return Err(Reason::WrongState);
            }
            take_off_check(waypoints, areas, fence, here)
        }
        ExecuteCommand::ReturnToHome => {
            if !waypoints.bidirectional {
                return Err(Reason::Unsupported);
            }
            if !airborne {
                return Err(Reason::WrongState);
            }
            let here = here.ok_or(Reason::WrongState)?;
            // Guidance flies home over the list it flies, which in the air stays the one it
            // started with until automation names another (guidance/mod.rs "New waypoint lists");
            // the check is of that list, so an edited active list it does not fly yet is
            // refused rather than checked in its place (our choice).
            if navigation.waypoint_list != waypoints.generation {
                return Err(Reason::WrongState);
            }
            geofence(
                fence,
                flown_route::return_route(
                    RouteView::from(waypoints),
                    here,
                    navigation.to,
                    Some(fcc_turns()),
                ),
            )
        }
        ExecuteCommand::Land => {
            if !airborne {
                return Err(Reason::WrongState);
            }
            Ok(())
        }
        // Mission data handling activates a staged mission itself ([`check_activation`]);
        // system automation has nothing to carry out.
        ExecuteCommand::ActivateStaged => Err(Reason::Unsupported),
    }
}

/// Whether the staged mission of `waypoints` and `areas` may be activated now (ICD §8, #50000
/// command 4): both lists there (the caller passes a staged list as active, generation not 0),
/// trajectory generation not active (`WrongState`), and the onboard geofence check of ICD §7
/// passed from where navigation says the aircraft is, as for execute (`GeofenceViolation`).
///
/// Without a position from navigation yet (an FCC just started, a guidance swapped in that has
/// not reported), the check starts at the mission's initial waypoint: the climb there and every
/// leg (our choice: the ICD does not say; refusing would make every upload fail until guidance
/// reports, and execute checks again from the position before anything flies).
pub fn check_activation(
    state: &AutomationStatePayload,
    waypoints: &WaypointListPayload,
    areas: &AreaListPayload,
    fence: &Fence,
    navigation: &GuidanceProgressPayload,
) -> Result<(), Reason> {
    if state.trajectory_generation_active {
        return Err(Reason::WrongState);
    }
    let initial = waypoints.waypoints().first().map(|w| {
        Site::new(
            w.position.latitude.degrees(),
            w.position.longitude.degrees(),
        )
    });
    take_off_check(
        waypoints,
        areas,
        fence,
        navigation_position(navigation).or(initial),
    )
}

/// The check before a take-off with `waypoints` and `areas` (execute, and the activation that
/// makes them the lists an execute would fly): both lists there and a position to start from
/// (`WrongState`), then the onboard geofence check of ICD §7 from there (`GeofenceViolation`).
fn take_off_check(
    waypoints: &WaypointListPayload,
    areas: &AreaListPayload,
    fence: &Fence,
    here: Option<Site>,
) -> Result<(), Reason> {
    if !waypoints.is_active() || areas.area_count() == 0 {
        return Err(Reason::WrongState);
    }
    let here = here.ok_or(Reason::WrongState)?;
    geofence(
        fence,
        flown_route::execute_route(RouteView::from(waypoints), here, Some(fcc_turns())),
    )
}

/// A position navigation has reported, on the globe (guidance may be another program).
fn navigation_position(navigation: &GuidanceProgressPayload) -> Option<Site> {
    (navigation.sequence != 0
        && (-90.0..=90.0).contains(&navigation.latitude_deg)
        && (-180.0..=180.0).contains(&navigation.longitude_deg))
    .then(|| Site::new(navigation.latitude_deg, navigation.longitude_deg))
}

/// The onboard geofence check of ICD §7 for a report entry (ICD §8, #50001 fields 6 and 7): the
/// check #50000 execute would run, from where navigation says the aircraft is, of `route`
/// against the `fence` of its area list (the active lists, or a staged mission's, read where
/// they are: no payload is built for it). Not run when a list is missing (`None`), and (our
/// choice, the ICD names only a missing list) when navigation has reported no position yet:
/// there is nothing to check from.
pub fn report_check<W: RouteWaypoint>(
    route: Option<RouteView<'_, W>>,
    fence: Option<&Fence>,
    navigation: &GuidanceProgressPayload,
) -> (GeofenceCheck, Option<Reason>) {
    let here = navigation_position(navigation);
    match (here, route, fence) {
        (Some(here), Some(route), Some(fence)) => {
            match geofence(
                fence,
                flown_route::execute_route(route, here, Some(fcc_turns())),
            ) {
                Ok(()) => (GeofenceCheck::Passed, None),
                Err(reason) => (GeofenceCheck::Failed, Some(reason)),
            }
        }
        _ => (GeofenceCheck::NotRun, None),
    }
}

/// How the FCC's guidance turns at fly-by waypoints: the guidance stub's, whose bank the
/// configuration does not change (`[guidance]` has none). A guidance partition swapped in
/// that turns otherwise is checked as if it turned like the stub.
pub fn fcc_turns() -> flown_route::FlyBy {
    GuidanceConfig::default().fly_by()
}

/// The onboard geofence check (ICD §7 ext): `GeofenceViolation` names no leg on the wire, so
/// the leg and the area go to the log.
fn geofence(
    fence: &Fence,
    route: impl Iterator<Item = flown_route::RouteLeg>,
) -> Result<(), Reason> {
    onboard::check(fence, route).map_err(|v| {
        tracing::warn!(
            element = %v.element,
            area = v.area_id,
            margin_m = v.clearance.metres(),
            "onboard geofence check failed"
        );
        Reason::GeofenceViolation
    })
}

/// System automation.
#[derive(Debug, Clone)]
pub struct SystemAutomation {
    state: AutomationStatePayload,
    waypoints: WaypointListPayload,
    areas: AreaListPayload,
    /// The active area list as the onboard geofence check takes it (built when it changes).
    fence: Box<Fence>,
    /// Guidance's last progress: the TO waypoint (where "land at the next waypoint" lands) and
    /// the position the onboard geofence check starts from.
    navigation: GuidanceProgressPayload,
    /// Guidance's heartbeats: whether it is alive (`state.guidance_alive`).
    guidance: Liveness,
    changed: bool,
}

impl Default for SystemAutomation {
    fn default() -> Self {
        Self::new()
    }
}

impl SystemAutomation {
    /// On the ground, no lists.
    pub fn new() -> Self {
        Self {
            state: AutomationStatePayload::ON_GROUND,
            waypoints: WaypointListPayload::EMPTY,
            areas: AreaListPayload::EMPTY,
            fence: Box::new(Fence::empty()),
            navigation: GuidanceProgressPayload::IDLE,
            guidance: Liveness::new(DEFAULT_HEARTBEAT_PERIOD),
            // The first state is published too.
            changed: true,
        }
    }

    /// As [`SystemAutomation::new`], with guidance expected to beat on `period`.
    pub fn with_heartbeat_period(period: Duration) -> Self {
        Self {
            guidance: Liveness::new(period),
            ..Self::new()
        }
    }

    /// Guidance's heartbeat arrived: guidance is alive (published if it was not).
    pub fn handle_guidance_heartbeat(&mut self, now: Instant, beat: &HeartbeatPayload) {
        self.guidance.handle_beat(now, beat);
        if !self.state.guidance_alive {
            self.state.guidance_alive = true;
            tracing::info!("guidance alive");
            self.touch(now);
        }
    }

    /// When guidance falls silent if no heartbeat comes first ([`SystemAutomation::handle_timeout`]).
    pub fn poll_timeout(&self) -> Option<Instant> {
        self.state
            .guidance_alive
            .then(|| self.guidance.deadline())
            .flatten()
    }

    /// Time passed: guidance silent for longer than the limit is no longer alive.
    pub fn handle_timeout(&mut self, now: Instant) {
        if let Some(silence) = self.guidance.poll(now) {
            if self.state.guidance_alive {
                self.state.guidance_alive = false;
                tracing::warn!(%silence, "guidance not alive: execute, return to home and land are refused");
                self.touch(now);
            }
        }
    }

    /// The state to publish.
    pub fn state(&self) -> &AutomationStatePayload {
        &self.state
    }

    /// Whether the state changed since the last call (publish it then).
    pub fn take_changed(&mut self) -> bool {
        core::mem::take(&mut self.changed)
    }

    fn set_phase(&mut self, now: Instant, phase: FlightPhase) {
        self.state.flight_phase = phase as u8;
        self.state.trajectory_generation_active = matches!(
            phase,
            FlightPhase::TakeOff | FlightPhase::Cruise | FlightPhase::Landing
        );
        self.touch(now);
        tracing::info!(?phase, "flight phase");
    }

    fn touch(&mut self, now: Instant) {
        self.state.sequence += 1;
        self.state.changed_ns = now.micros().saturating_mul(1000);
        self.changed = true;
    }

    /// The active waypoint list changed.
    pub fn handle_waypoint_list(&mut self, list: &WaypointListPayload) {
        self.waypoints = *list;
    }

    /// The active area list changed.
    pub fn handle_area_list(&mut self, list: &AreaListPayload) {
        self.areas = *list;
        self.fence.set_payload(list);
    }

    /// Carries out a #50000 command.
    pub fn handle_command(&mut self, now: Instant, command: ExecuteCommand) -> Result<(), Reason> {
        check_command(
            &self.state,
            &self.waypoints,
            &self.areas,
            &self.fence,
            &self.navigation,
            command,
        )?;
        match command {
            ExecuteCommand::Execute => {
                self.state.flown_waypoint_list = self.waypoints.generation;
                self.state.route_reversed = false;
                self.state.land_at = 0;
                self.set_phase(now, FlightPhase::TakeOff);
            }
            ExecuteCommand::ReturnToHome => {
                self.state.route_reversed = true;
                self.state.land_at = 0;
                self.touch(now);
            }
            ExecuteCommand::Land => {
                self.state.land_at = self.navigation.to;
                self.touch(now);
            }
            // `check_command` refuses it (Unsupported): nothing to carry out.
            ExecuteCommand::ActivateStaged => {}
        }
        tracing::info!(?command, "command carried out");
        Ok(())
    }

    /// Guidance reported progress: moves to the next phase when the current one is complete.
    ///
    /// A restarted automation (nothing published yet) that meets an aircraft in the air adopts
    /// the phase guidance's progress shows, instead of claiming "on ground" under a flying
    /// aircraft. What it cannot see (a return to home, a landing waypoint) is lost.
    pub fn handle_progress(&mut self, now: Instant, progress: &GuidanceProgressPayload) {
        // The TO waypoint is kept through updates that have none (on the ground, climbing).
        let to = if progress.to != 0 {
            progress.to
        } else {
            self.navigation.to
        };
        self.navigation = GuidanceProgressPayload { to, ..*progress };
        if self.state.sequence == 0 && !progress.on_ground {
            let phase = if !progress.climb_complete {
                FlightPhase::TakeOff
            } else if progress.route_complete {
                FlightPhase::Landing
            } else {
                FlightPhase::Cruise
            };
            self.state.flown_waypoint_list = progress.waypoint_list;
            tracing::warn!(?phase, "resuming under an aircraft in the air");
            self.set_phase(now, phase);
            return;
        }
        match self.state.flight_phase() {
            Some(FlightPhase::TakeOff) if progress.climb_complete => {
                self.set_phase(now, FlightPhase::Cruise);
            }
            Some(FlightPhase::Cruise) if progress.route_complete => {
                self.set_phase(now, FlightPhase::Landing);
            }
            Some(FlightPhase::Landing) if progress.on_ground => {
                self.set_phase(now, FlightPhase::Landed);
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testkit;

    /// Demo mission 2 (bidirectional) or 1 (one-way) with its areas, as published.
    fn lists(bidirectional: bool) -> (WaypointListPayload, AreaListPayload) {
        let plan = if bidirectional {
            testkit::mission_2()
        } else {
            testkit::mission_1()
        };
        let valid = plan.assemble().unwrap();
        (valid.mission.to_payload(1), valid.areas.to_payload(1))
    }

    /// Automation that has carried out execute of demo mission 2 from TROL (take-off phase).
    fn taken_off() -> SystemAutomation {
        let mut sa = alive();
        let (w, a) = lists(true);
        sa.handle_waypoint_list(&w);
        sa.handle_area_list(&a);
        sa.handle_progress(Instant::ZERO, &progress(|_| {}));
        sa.handle_command(Instant::ZERO, ExecuteCommand::Execute)
            .unwrap();
        sa
    }

    /// Automation with guidance's heartbeat heard at instant zero.
    fn alive() -> SystemAutomation {
        let mut sa = SystemAutomation::new();
        sa.handle_guidance_heartbeat(Instant::ZERO, &beat());
        sa
    }

    fn beat() -> HeartbeatPayload {
        HeartbeatPayload {
            sequence: 1,
            time_ns: 0,
            period_ns: 100_000_000,
            pid: 1,
            reserved: [0; 4],
        }
    }

    /// Guidance's progress with the aircraft at TROL, changed by `f`.
    fn progress(f: impl FnOnce(&mut GuidanceProgressPayload)) -> GuidanceProgressPayload {
        let mut p = GuidanceProgressPayload {
            sequence: 1,
            waypoint_list: 1,
            latitude_deg: testkit::TROL.0,
            longitude_deg: testkit::TROL.1,
            ..GuidanceProgressPayload::IDLE
        };
        f(&mut p);
        p
    }

    #[test]
    fn a_mission_goes_through_every_phase() {
        let mut sa = alive();
        assert!(sa.take_changed(), "the first state is published");
        let (w, a) = lists(false);
        sa.handle_waypoint_list(&w);
        sa.handle_area_list(&a);
        let t = Instant::from_millis(5);
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::Execute),
            Err(Reason::WrongState),
            "no position from navigation yet"
        );
        sa.handle_progress(t, &progress(|_| {}));
        sa.handle_command(t, ExecuteCommand::Execute).unwrap();
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::TakeOff));
        assert!(sa.state().trajectory_generation_active);
        assert_eq!(sa.state().flown_waypoint_list, 1);
        assert!(sa.take_changed());
        sa.handle_progress(t, &progress(|_| {}));
        assert!(!sa.take_changed(), "nothing changed");
        sa.handle_progress(t, &progress(|p| p.climb_complete = true));
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::Cruise));
        sa.handle_progress(t, &progress(|p| p.route_complete = true));
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::Landing));
        assert!(sa.state().trajectory_generation_active);
        sa.handle_progress(t, &progress(|p| p.on_ground = true));
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::Landed));
        assert!(!sa.state().trajectory_generation_active);
        assert_eq!(sa.state().sequence, 5, "guidance alive, then four phases");
        // A landed aircraft can fly the next mission.
        assert_eq!(sa.handle_command(t, ExecuteCommand::Execute), Ok(()));
    }

    #[test]
    fn commands_are_checked_against_lists_and_phase() {
        let mut sa = alive();
        let t = Instant::ZERO;
        // No lists.
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::Execute),
            Err(Reason::WrongState)
        );
        let (w, a) = lists(false);
        sa.handle_waypoint_list(&w);
        sa.handle_area_list(&a);
        sa.handle_progress(t, &progress(|_| {}));
        // On the ground: nothing to return from or land.
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::Land),
            Err(Reason::WrongState)
        );
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::ReturnToHome),
            Err(Reason::Unsupported),
            "one-way route"
        );
        sa.handle_command(t, ExecuteCommand::Execute).unwrap();
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::Execute),
            Err(Reason::WrongState)
        );
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::ReturnToHome),
            Err(Reason::Unsupported)
        );
    }

    #[test]
    fn a_restarted_automation_adopts_the_phase_of_an_aircraft_in_the_air() {
        let mut sa = SystemAutomation::new();
        let t = Instant::ZERO;
        sa.handle_progress(
            t,
            &progress(|p| {
                p.on_ground = false;
                p.climb_complete = true;
                p.waypoint_list = 7;
            }),
        );
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::Cruise));
        assert_eq!(sa.state().flown_waypoint_list, 7);
        assert!(sa.state().trajectory_generation_active);
        // A fresh automation with the aircraft on the ground stays on the ground.
        let mut sa = SystemAutomation::new();
        sa.handle_progress(t, &progress(|_| {}));
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::OnGround));
    }

    #[test]
    fn return_to_home_and_land_at_the_next_waypoint() {
        let t = Instant::ZERO;
        let mut sa = taken_off();
        sa.handle_progress(t, &progress(|p| p.climb_complete = true));
        sa.handle_progress(
            t,
            &progress(|p| {
                p.from = 1;
                p.to = 2;
            }),
        );
        sa.handle_command(t, ExecuteCommand::ReturnToHome).unwrap();
        assert!(sa.state().route_reversed);
        sa.handle_command(t, ExecuteCommand::Land).unwrap();
        assert_eq!(sa.state().land_at, 2);
        assert_eq!(sa.state().flight_phase(), Some(FlightPhase::Cruise));
    }

    /// The onboard check (ICD §7 ext): return to home from south of the polygonal no-fly-zone
    /// with CCP the TO waypoint would cross it; refused, and nothing changes.
    #[test]
    fn return_to_home_across_a_no_fly_zone_is_refused() {
        let t = Instant::ZERO;
        let mut sa = taken_off();
        sa.handle_progress(
            t,
            &progress(|p| {
                p.on_ground = false;
                p.latitude_deg = 48.258;
                p.longitude_deg = 11.643;
                p.to = 1;
            }),
        );
        let before = *sa.state();
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::ReturnToHome),
            Err(Reason::GeofenceViolation)
        );
        assert_eq!(sa.state(), &before);
    }

    /// A position that is not on the globe (guidance may be another program) is no position:
    /// nothing to check from, so nothing is flown.
    #[test]
    fn a_position_off_the_globe_is_no_position() {
        let (w, a) = lists(false);
        for (lat, lon) in [(f64::NAN, 11.66), (48.26, f64::INFINITY), (91.0, 11.66)] {
            let mut sa = alive();
            sa.handle_waypoint_list(&w);
            sa.handle_area_list(&a);
            let t = Instant::ZERO;
            sa.handle_progress(
                t,
                &progress(|p| {
                    p.latitude_deg = lat;
                    p.longitude_deg = lon;
                }),
            );
            assert_eq!(
                sa.handle_command(t, ExecuteCommand::Execute),
                Err(Reason::WrongState),
                "{lat} {lon}"
            );
        }
    }

    /// Review finding: after an edit in the air, the active list is not the one guidance flies
    /// home over; return to home is refused rather than checked against the wrong list.
    #[test]
    fn return_to_home_over_a_list_guidance_does_not_fly_is_refused() {
        let t = Instant::ZERO;
        let mut sa = taken_off();
        sa.handle_progress(t, &progress(|p| p.on_ground = false));
        let edited = WaypointListPayload {
            generation: 2,
            ..lists(true).0
        };
        sa.handle_waypoint_list(&edited);
        assert_eq!(
            sa.handle_command(t, ExecuteCommand::ReturnToHome),
            Err(Reason::WrongState)
        );
        sa.handle_progress(t, &progress(|p| p.waypoint_list = 2));
        assert_eq!(sa.handle_command(t, ExecuteCommand::ReturnToHome), Ok(()));
    }

    /// docs/design.md "Health": no heartbeat from guidance, nothing flies; a silence of the limit
    /// makes it not alive again, and the state says so.
    #[test]
    fn flight_commands_are_refused_while_guidance_is_not_alive() {
        let mut sa = SystemAutomation::new();
        let (w, a) = lists(true);
        sa.handle_waypoint_list(&w);
        sa.handle_area_list(&a);
        let t = Instant::ZERO;
        sa.handle_progress(t, &progress(|_| {}));
        assert!(!sa.state().guidance_alive);
        assert_eq!(sa.poll_timeout(), None);
        for command in [
            ExecuteCommand::Execute,
            ExecuteCommand::ReturnToHome,
            ExecuteCommand::Land,
        ] {
            assert_eq!(
                sa.handle_command(t, command),
                Err(Reason::WrongState),
                "{command:?}"
            );
        }
        sa.take_changed();
        sa.handle_guidance_heartbeat(t, &beat());
        assert!(sa.state().guidance_alive && sa.take_changed());
        let limit = crate::health::silence_limit(DEFAULT_HEARTBEAT_PERIOD);
        assert_eq!(sa.poll_timeout(), Some(t + limit));
        sa.handle_command(t, ExecuteCommand::Execute).unwrap();
        sa.take_changed();
        // Silent: at the deadline, not before.
        sa.handle_timeout(Instant::from_micros(limit.as_micros() as u64 - 1));
        assert!(sa.state().guidance_alive && !sa.take_changed());
        sa.handle_timeout(t + limit);
        assert!(!sa.state().guidance_alive && sa.take_changed());
        assert_eq!(sa.poll_timeout(), None);
        assert_eq!(
            sa.handle_command(t + limit, ExecuteCommand::Land),
            Err(Reason::WrongState)
        );
    }
}
