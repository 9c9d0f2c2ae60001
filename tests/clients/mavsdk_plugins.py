"""MAVSDK-Python's Mission, Geofence, Telemetry and Action plugins (its PyPI package, the C
library bundled, unmodified) against `gcs mavlink` (tests/system/mavlink_clients.rs starts both), as
a script writer uses them.

1. Telemetry: the flight mode by name, the home (HOME_POSITION), the landed state.
2. Geofence: the demo's fly-zone as an inclusion polygon and a no-fly-zone as an exclusion
   circle, uploaded with `upload_geofence` (the bridge holds them for the next mission).
3. Mission: `MissionItem`s as MAVSDK's own examples write them but not fly-through (MAVSDK's
   default: it stops 0.5 s at each waypoint) are refused, and the reason reaches
   `telemetry.status_text`; the same items flown through are taken, the first one the take-off
   (`VehicleAction.TAKEOFF`), and `download_mission` gives them back.
4. Action: `hold` on the ground is accepted (it is what the vehicle does).
5. `start_mission`, `mission_progress` to the last item and `is_mission_finished`.
6. `clear_mission` and `clear_geofence` once the mission is over.

Usage: python3 mavsdk_plugins.py BRIDGE_PORT. Exit status 0 when every check passes.
"""

import asyncio
import math
import sys

from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.action import ActionAsync
from mavsdk.asyncio.plugins.geofence import GeofenceAsync
from mavsdk.asyncio.plugins.mission import MissionAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.geofence import Circle, FenceType, GeofenceData, Point, Polygon
from mavsdk.plugins.mission import MissionItem, MissionPlan

TIMEOUT = 60


def fail(why):
    print(f"FAILED: {why}", flush=True)
    sys.exit(1)


def item(lat, lon, alt, fly_through, action=MissionItem.VehicleAction.NONE):
    nan = float("nan")
    return MissionItem(
        lat, lon, alt, 25.0, fly_through, nan, nan, MissionItem.CameraAction.NONE, nan, nan,
        nan, nan, nan, action,
    )


def route(fly_through):
    return [
        item(48.26, 11.66, 30.0, fly_through, MissionItem.VehicleAction.TAKEOFF),
        item(48.265, 11.655, 120.0, fly_through),
        item(48.275, 11.645, 120.0, fly_through),
    ]


async def first(stream, timeout=TIMEOUT):
    async def take():
        async for value in stream:
            return value
    return await asyncio.wait_for(take(), timeout)


async def main():
    port = int(sys.argv[1])
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpout://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=30.0)
        if system is None:
            fail("no autopilot found")
        print("connected", flush=True)
        mission, geofence = MissionAsync(system), GeofenceAsync(system)
        telemetry, action = TelemetryAsync(system), ActionAsync(system)
        texts = []

        async def watch_texts():
            async for t in telemetry.subscribe_status_text():
                texts.append(t.text)
                print(f"status text ({t.type}): {t.text}", flush=True)

        text_watcher = asyncio.ensure_future(watch_texts())

        mode = await first(telemetry.subscribe_flight_mode())
        print(f"flight mode: {mode.name}", flush=True)
        home = await first(telemetry.subscribe_home())
        print(f"home: {home.latitude_deg:.6f} {home.longitude_deg:.6f}, "
              f"{home.absolute_altitude_m:.2f} m above mean sea level", flush=True)
        if math.isnan(home.absolute_altitude_m):
            fail("the home has no altitude")
        landed = await first(telemetry.subscribe_landed_state())
        print(f"landed state: {landed.name}", flush=True)

        fly_zone = Polygon(
            [Point(48.255, 11.635), Point(48.255, 11.69), Point(48.285, 11.69),
             Point(48.285, 11.635)],
            FenceType.INCLUSION,
        )
        no_fly = Circle(Point(48.268, 11.675), 200.0, FenceType.EXCLUSION)
        await geofence.upload_geofence(GeofenceData([fly_zone], [no_fly]))
        print("geofence uploaded", flush=True)

        # MAVSDK's default: not fly-through, a stop at every waypoint the FCC cannot make.
        texts.clear()
        try:
            await mission.upload_mission(MissionPlan(route(False)))
            fail("a mission that stops at its waypoints was accepted")
        except Exception as e:  # MissionError: its result says DENIED
            await asyncio.sleep(1.0)
            if not any("refused" in t for t in texts):
                fail(f"no status text says why ({e}): {texts}")
            print(f"stopping at waypoints refused: {e}; reason: {' '.join(texts)}", flush=True)

        plan = MissionPlan(route(True))
        await mission.upload_mission(plan)
        print("mission uploaded", flush=True)
        await asyncio.sleep(4.0)  # the bridge commits the mission with the fence held
        back = await mission.download_mission()
        if len(back.mission_items) != len(plan.mission_items):
            fail(f"downloaded {len(back.mission_items)} items, uploaded {len(plan.mission_items)}")
        for up, down in zip(plan.mission_items, back.mission_items):
            if (abs(up.latitude_deg - down.latitude_deg) > 1e-7
                    or abs(up.longitude_deg - down.longitude_deg) > 1e-7
                    or abs(up.relative_altitude_m - down.relative_altitude_m) > 1e-3
                    or up.vehicle_action != down.vehicle_action):
                fail(f"downloaded {down}, uploaded {up}")
        print("downloaded: equal to the upload", flush=True)

        await action.hold()
        print("hold on the ground: accepted", flush=True)

        modes = set()

        async def watch_modes():
            async for m in telemetry.subscribe_flight_mode():
                modes.add(m.name)

        mode_watcher = asyncio.ensure_future(watch_modes())
        await mission.start_mission()
        print("started", flush=True)
        # In the air: the attitude, the position above mean sea level and above home, and the
        # HUD's ground speed (its airspeed NaN: the FCC reports none).
        await asyncio.sleep(3.0)
        attitude = await first(telemetry.subscribe_attitude_euler())
        position = await first(telemetry.subscribe_position())
        hud = await first(telemetry.subscribe_fixedwing_metrics())
        print(f"attitude: roll {attitude.roll_deg:.1f} pitch {attitude.pitch_deg:.1f} "
              f"yaw {attitude.yaw_deg:.1f} deg; position {position.absolute_altitude_m:.1f} m "
              f"above mean sea level, {position.relative_altitude_m:.1f} m above home; "
              f"ground speed {hud.groundspeed_m_s:.1f} m/s, climb {hud.climb_rate_m_s:.1f} m/s",
              flush=True)
        if any(math.isnan(v) for v in (attitude.roll_deg, attitude.pitch_deg, attitude.yaw_deg,
                                       position.absolute_altitude_m,
                                       position.relative_altitude_m)):
            fail("attitude or altitudes unknown in flight")
        progress = []

        async def follow():
            async for p in mission.subscribe_mission_progress():
                progress.append((p.current, p.total))
                if await mission.is_mission_finished():
                    return

        try:
            await asyncio.wait_for(follow(), timeout=TIMEOUT)
        except asyncio.TimeoutError:
            fail(f"is_mission_finished never true: progress {progress}")
        print(f"mission finished: progress {progress}", flush=True)
        await asyncio.sleep(1.5)
        mode_watcher.cancel()
        print(f"flight modes: {sorted(modes)}", flush=True)
        if "MISSION" not in modes:
            fail(f"no mission flight mode: {modes}")

        # The FCC lands at the last waypoint; the clear waits until it is on the ground.
        for attempt in range(60):
            try:
                await mission.clear_mission()
                break
            except Exception as e:
                if attempt == 59:
                    fail(f"clear_mission: {e}, {texts}")
                await asyncio.sleep(1.0)
        await geofence.clear_geofence()
        back = await mission.download_mission()
        if back.mission_items:
            fail(f"after clear_mission the vehicle holds {len(back.mission_items)} items")
        print("clear_mission and clear_geofence: the FCC holds no mission", flush=True)
        text_watcher.cancel()


if __name__ == "__main__":
    asyncio.run(main())
