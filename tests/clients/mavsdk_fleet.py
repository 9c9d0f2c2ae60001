"""MAVSDK (its PyPI package, the C library bundled) against the ground service's MAVLink side
(`gcs serve --mavlink`, started by tests/system/ground_service.rs with a fleet of FCCs).

Connects, waits until MAVSDK's systems() lists every system named, each an autopilot; then
takes the one of TARGET_SYSTEM and uploads to it with MissionRaw a mission (a take-off and two
waypoints) and its geofence (the demo fly-zone as an inclusion polygon), and downloads the
mission back from it.

Usage: python3 mavsdk_fleet.py PORT TARGET_SYSTEM SYSTEM... Exit status 0 when every check
passes.
"""

import asyncio
import sys

from mavsdk.asyncio import ComponentType, Configuration, Mavsdk
from mavsdk.asyncio.plugins.mission_raw import MissionRawAsync
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
    port, target = int(sys.argv[1]), int(sys.argv[2])
    wanted = {int(s) for s in sys.argv[3:]}
    config = Configuration.create_with_component_type(ComponentType.GROUND_STATION)
    async with Mavsdk(config) as mavsdk:
        await mavsdk.add_any_connection(f"udpout://127.0.0.1:{port}")
        seen = {}
        for _ in range(300):
            for system in await mavsdk.get_systems():
                if await system.has_autopilot():
                    seen[await system.get_system_id()] = system
            if wanted <= set(seen):
                break
            await asyncio.sleep(0.1)
        if not wanted <= set(seen):
            fail(f"systems() lists autopilots {sorted(seen)}, not every one of {sorted(wanted)}")
        print(f"systems: {sorted(seen)}", flush=True)
        mission = MissionRawAsync(seen[target])
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
        print(f"uploaded to system {target}", flush=True)
        back = await mission.download_mission()
        if len(back) != len(items):
            fail(f"system {target} holds {len(back)} items, not {len(items)}")
        print(f"system {target} holds the {len(back)} items uploaded", flush=True)


if __name__ == "__main__":
    asyncio.run(main())
