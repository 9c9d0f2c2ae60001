"""MAVSDK (its PyPI package, the C library bundled) against `gcs mavlink`
(tests/system/mavlink_clients.rs starts both).

Connects, uploads a mission with MissionRaw (a take-off and two waypoints) and its geofence (the
demo fly-zone as an inclusion polygon), starts it, and watches the mission progress and the
positions until the last item is reached, and the flight mode MAVSDK decodes from HEARTBEAT.

Usage: python3 mavsdk_mission.py BRIDGE_PORT. Exit status 0 when every check passes.
"""

import asyncio
import sys

from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
from mavsdk.asyncio.plugins.telemetry import TelemetryAsync
from mavsdk.plugins.mission_raw import MissionItem

TAKEOFF, WAYPOINT, POLYGON_INCLUSION = 22, 16, 5001
RELATIVE, GLOBAL = 3, 0
MISSION, FENCE = 0, 1


def fail(why):
    print(f"FAILED: {why}", flush=True)
    sys.exit(1)


def item(seq, frame, command, p1, lat, lon, alt, kind):
    return MissionItem(
        seq, frame, command, 1 if seq == 0 else 0, 1, p1, 0.0, 0.0, 0.0,
        int(round(lat * 1e7)), int(round(lon * 1e7)), alt, kind,
    )


async def main():
    port = int(sys.argv[1])
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpout://127.0.0.1:{port}")
        system = await mavsdk.first_autopilot(timeout_s=30.0)
        if system is None:
            fail("no autopilot found")
        print("connected", flush=True)
        mission = MissionRawAsync(system)
        telemetry = TelemetryAsync(system)
        items = [
            item(0, RELATIVE, TAKEOFF, 0.0, 48.26, 11.66, 30.0, MISSION),
            item(1, RELATIVE, WAYPOINT, 0.0, 48.265, 11.655, 120.0, MISSION),
            item(2, RELATIVE, WAYPOINT, 0.0, 48.275, 11.645, 120.0, MISSION),
        ]
        corners = [(48.255, 11.635), (48.255, 11.69), (48.285, 11.69), (48.285, 11.635)]
        fence = [
            item(i, GLOBAL, POLYGON_INCLUSION, 4.0, lat, lon, 0.0, FENCE)
            for i, (lat, lon) in enumerate(corners)
        ]
        await mission.upload_mission(items)
        await mission.upload_geofence(fence)
        print("uploaded", flush=True)
        await mission.start_mission()
        print("started", flush=True)

        positions = []
        progress = []
        modes = set()

        async def watch_modes():
            async for m in telemetry.subscribe_flight_mode():
                modes.add(getattr(m, "name", str(m)))

        async def watch_positions():
            async for p in telemetry.subscribe_position():
                positions.append((p.latitude_deg, p.longitude_deg, p.relative_altitude_m))

        async def watch_progress():
            async for p in mission.subscribe_mission_progress():
                progress.append((p.current, p.total))
                print(f"progress {p.current}/{p.total}", flush=True)
                if p.total > 0 and p.current >= p.total - 1 and len(progress) > 1:
                    return

        watcher = asyncio.ensure_future(watch_positions())
        mode_watcher = asyncio.ensure_future(watch_modes())
        try:
            await asyncio.wait_for(watch_progress(), timeout=60)
        except asyncio.TimeoutError:
            fail(f"the mission did not reach its last item: {progress}")
        watcher.cancel()
        mode_watcher.cancel()
        print(f"flight modes: {sorted(modes)}", flush=True)
        if "MISSION" not in modes:
            fail(f"MAVSDK decoded no mission flight mode: {modes}")
        moved = {(round(lat, 5), round(lon, 5)) for lat, lon, _ in positions}
        print(f"{len(positions)} positions, {len(moved)} distinct; progress {progress}", flush=True)
        if len(moved) < 3:
            fail("the aircraft was not seen moving")


if __name__ == "__main__":
    asyncio.run(main())
