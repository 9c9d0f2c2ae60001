"""pymavlink against the ground service's MAVLink side (`gcs serve --mavlink`, started by
tests/system/ground_service.rs with a fleet of FCCs).

Listens until it has a HEARTBEAT from each of the systems named, each from component 1
(MAV_COMP_ID_AUTOPILOT1); then uploads a mission (a take-off and two waypoints) and a fence (an
inclusion polygon and an exclusion circle) to one system in QGroundControl's order (mission,
fence, rally points, each after the previous MISSION_ACK), every message addressed to that
system, and downloads the mission back from it. A mission upload addressed to every system (0)
must be refused by a fleet: no MISSION_REQUEST answers it.

With `--refused` first, the upload must be refused instead: the fence's MISSION_ACK an error
and a STATUSTEXT naming the separation conflict (the service checks a plan against the other
vehicles' active missions).

Usage: python3 pymavlink_fleet.py [--refused] PORT TARGET_SYSTEM SYSTEM... Exit status 0 when
every check passes; each check that fails is printed.
"""

import os
import sys
import time

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402

MISSION, FENCE, RALLY = 0, 1, 2
TAKEOFF, WAYPOINT = 22, 16
POLYGON_INCLUSION, CIRCLE_EXCLUSION = 5001, 5004
RELATIVE, GLOBAL = 3, 0
TIMEOUT = 30


def fail(why):
    print(f"FAILED: {why}", flush=True)
    sys.exit(1)


def main():
    args = sys.argv[1:]
    refused = args[:1] == ["--refused"]
    if refused:
        args = args[1:]
    port, target = int(args[0]), int(args[1])
    systems = {int(s) for s in args[2:]}
    m = mavutil.mavlink_connection(
        f"udpout:127.0.0.1:{port}", source_system=255, source_component=190
    )
    seen = set()
    end = time.time() + TIMEOUT
    while seen != systems:
        m.mav.heartbeat_send(6, 8, 0, 0, 0)  # MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID
        msg = m.recv_match(type="HEARTBEAT", blocking=True, timeout=1)
        if msg is not None:
            if msg.get_srcComponent() != 1:
                fail(f"HEARTBEAT of system {msg.get_srcSystem()} from component {msg.get_srcComponent()}")
            seen.add(msg.get_srcSystem())
        if time.time() > end:
            fail(f"HEARTBEATs from {sorted(seen)}, not from every one of {sorted(systems)}")
    print(f"heartbeats from systems {sorted(seen)}", flush=True)

    texts = []

    def recv(types):
        while True:
            msg = m.recv_match(type=types + ["STATUSTEXT"], blocking=True, timeout=TIMEOUT)
            if msg is None:
                fail(f"no {types}")
            if msg.get_type() == "STATUSTEXT":
                print(f"STATUSTEXT from {msg.get_srcSystem()}: {msg.text}", flush=True)
                if msg.get_srcSystem() == target:
                    texts.append(msg.text)
                continue
            if msg.get_srcSystem() != target:
                continue
            return msg

    def upload(kind, items):
        m.mav.mission_count_send(target, 1, len(items), kind)
        while True:
            msg = recv(["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"])
            if msg.get_type() == "MISSION_ACK":
                return msg.type
            command, frame, p1, lat, lon, alt = items[msg.seq]
            m.mav.mission_item_int_send(
                target, 1, msg.seq, frame, command, 0, 1, p1, 0, 0, 0,
                int(round(lat * 1e7)), int(round(lon * 1e7)), alt, kind,
            )

    # To every system at once: a fleet refuses it, no vehicle asks for an item.
    m.mav.mission_count_send(0, 0, 3, MISSION)
    asked = m.recv_match(type=["MISSION_REQUEST_INT", "MISSION_REQUEST"], blocking=True, timeout=2)
    if asked is not None:
        fail(f"a mission upload to system 0 was answered by system {asked.get_srcSystem()}")
    print("a mission upload to every system: refused", flush=True)

    mission = [
        (TAKEOFF, RELATIVE, 0.0, 48.26, 11.66, 30.0),
        (WAYPOINT, RELATIVE, 0.0, 48.265, 11.655, 120.0),
        (WAYPOINT, RELATIVE, 0.0, 48.275, 11.645, 120.0),
    ]
    corners = [(48.255, 11.635), (48.255, 11.69), (48.285, 11.69), (48.285, 11.635)]
    fence = [(POLYGON_INCLUSION, GLOBAL, 4.0, lat, lon, 0.0) for lat, lon in corners]
    fence.append((CIRCLE_EXCLUSION, GLOBAL, 200.0, 48.268, 11.675, 0.0))
    if refused:
        result = upload(MISSION, mission)
        if result == 0:
            result = upload(FENCE, fence)
        if result == 0:
            fail(f"system {target} accepted a plan that breaks the fleet's separation")
        said = "".join(texts)
        if "separation" not in said:
            fail(f"no STATUSTEXT names the separation conflict: {texts}")
        print(f"refused by system {target}: MISSION_ACK {result}: {said}", flush=True)
        return
    for kind, items, name in [(MISSION, mission, "mission"), (FENCE, fence, "fence"),
                              (RALLY, [], "rally points")]:
        result = upload(kind, items)
        if result != 0:
            fail(f"{name} upload to system {target}: MISSION_ACK {result}")
    print(f"uploaded to system {target}: mission and fence active on its FCC", flush=True)

    m.mav.mission_request_list_send(target, 1, MISSION)
    count = recv(["MISSION_COUNT"]).count
    if count != len(mission):
        fail(f"system {target} holds {count} mission items, not {len(mission)}")
    m.mav.mission_ack_send(target, 1, 0, MISSION)
    print(f"system {target} holds the {count} items uploaded", flush=True)


main()
