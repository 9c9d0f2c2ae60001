"""pymavlink against `gcs mavlink` (tests/system/mavlink_clients.rs starts both).

Uploads a mission (a take-off and two waypoints) with a fence (an inclusion polygon and an
exclusion circle) in QGroundControl's order (mission, then fence, then rally points, each after
the previous MISSION_ACK), downloads both back and compares them with the upload, then uploads
an infeasible mission (a waypoint inside the exclusion circle) with the same fence and expects
it refused, the reason in a STATUSTEXT, and the lists as they were. Then it starts the mission
and follows it as a ground station does: the flight mode by name from HEARTBEAT (pymavlink's
decoding, MAVProxy's), the landed state, a clear refused while the aircraft flies with the
reason, MISSION_ITEM_REACHED for every item and MISSION_CURRENT to MISSION_STATE_COMPLETE on
the last item, with the plan's checksums as mission_id and fence_id. The client has its own
system and component (255, 190, a ground station's): every reply of the vehicle that names a
target must name it, never system 0.

With a second argument it plays one side of a restart of the bridge: `upload` uploads the
mission and fence and ends; `download` (to the bridge started again) downloads both and compares
them with the same upload: a restarted bridge returns what the client uploaded.

Usage: python3 pymavlink_mission.py BRIDGE_PORT [upload|download]. Exit status 0 when every
check passes; each check that fails is printed.
"""

import os
import struct
import sys

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
    port = int(sys.argv[1])
    m = mavutil.mavlink_connection(
        f"udpout:127.0.0.1:{port}", source_system=255, source_component=190
    )
    m.mav.heartbeat_send(6, 8, 0, 0, 0)  # MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID
    hb = m.wait_heartbeat(timeout=TIMEOUT)
    if hb is None:
        fail("no HEARTBEAT")
    print(f"heartbeat from system {m.target_system}: type {hb.type}, autopilot {hb.autopilot}")
    texts = []
    replies = []

    def recv(types):
        while True:
            msg = m.recv_match(type=types + ["STATUSTEXT"], blocking=True, timeout=TIMEOUT)
            if msg is None:
                fail(f"no {types}")
            target = getattr(msg, "target_system", None)
            if target is not None:
                replies.append(msg.get_type())
                if (target, msg.target_component) != (255, 190):
                    fail(f"{msg.get_type()} addressed to {target}/{msg.target_component}")
            if msg.get_type() == "STATUSTEXT":
                texts.append(msg.text)
                print(f"STATUSTEXT: {msg.text}", flush=True)
                continue
            return msg

    def upload(kind, items):
        m.mav.mission_count_send(1, 1, len(items), kind)
        while True:
            msg = recv(["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"])
            if msg.get_type() == "MISSION_ACK":
                return msg.type
            command, frame, p1, lat, lon, alt = items[msg.seq]
            m.mav.mission_item_int_send(
                1, 1, msg.seq, frame, command, 0, 1, p1, 0, 0, 0,
                int(round(lat * 1e7)), int(round(lon * 1e7)), alt, kind,
            )

    def download(kind):
        m.mav.mission_request_list_send(1, 1, kind)
        count = recv(["MISSION_COUNT"]).count
        items = []
        for seq in range(count):
            m.mav.mission_request_int_send(1, 1, seq, kind)
            it = recv(["MISSION_ITEM_INT"])
            items.append((it.command, it.frame, it.param1, it.x / 1e7, it.y / 1e7, it.z))
        m.mav.mission_ack_send(1, 1, 0, kind)
        return items

    def same(a, b):
        return len(a) == len(b) and all(
            x[0] == y[0] and x[1] == y[1] and abs(x[2] - y[2]) < 1e-3
            and abs(x[3] - y[3]) < 1e-7 and abs(x[4] - y[4]) < 1e-7 and abs(x[5] - y[5]) < 1e-3
            for x, y in zip(a, b)
        )

    mission = [
        (TAKEOFF, RELATIVE, 0.0, 48.26, 11.66, 30.0),
        (WAYPOINT, RELATIVE, 0.0, 48.265, 11.655, 120.0),
        (WAYPOINT, RELATIVE, 0.0, 48.275, 11.645, 120.0),
    ]
    corners = [(48.255, 11.635), (48.255, 11.69), (48.285, 11.69), (48.285, 11.635)]
    fence = [(POLYGON_INCLUSION, GLOBAL, 4.0, lat, lon, 0.0) for lat, lon in corners]
    fence.append((CIRCLE_EXCLUSION, GLOBAL, 200.0, 48.268, 11.675, 0.0))

    phase = sys.argv[2] if len(sys.argv) > 2 else None
    if phase == "download":
        if not same(download(MISSION), mission):
            fail("after the restart, the mission downloaded differs from the upload")
        if not same(download(FENCE), fence):
            fail("after the restart, the fence downloaded differs from the upload")
        print("after the restart, downloaded: equal to the upload", flush=True)
        return
    result = upload(MISSION, mission)
    if result != 0:
        fail(f"mission upload: MISSION_ACK {result}")
    result = upload(FENCE, fence)
    if result != 0:
        fail(f"fence upload: MISSION_ACK {result}, {texts}")
    result = upload(RALLY, [])
    if result != 0:
        fail(f"rally upload: MISSION_ACK {result}")
    print("uploaded: mission and fence active on the FCC", flush=True)
    if phase == "upload":
        return

    if not same(download(MISSION), mission):
        fail("the mission downloaded differs from the upload")
    if not same(download(FENCE), fence):
        fail("the fence downloaded differs from the upload")
    print("downloaded: equal to the upload", flush=True)

    # Infeasible: the second waypoint inside the exclusion circle.
    infeasible = list(mission)
    infeasible[1] = (WAYPOINT, RELATIVE, 0.0, 48.268, 11.675, 120.0)
    texts.clear()
    result = upload(MISSION, infeasible)
    if result != 0:
        print(f"infeasible mission refused at once: MISSION_ACK {result}", flush=True)
    else:
        result = upload(FENCE, fence)
    if result == 0:
        fail("the infeasible mission was accepted")
    if not texts:
        fail("no STATUSTEXT says why the infeasible mission was refused")
    print(f"infeasible mission refused: MISSION_ACK {result}: {''.join(texts)}", flush=True)
    if not same(download(MISSION), mission) or not same(download(FENCE), fence):
        fail("the refusal changed the lists")
    print("the lists are as they were", flush=True)
    fly(m, recv, texts)
    print(f"{len(replies)} replies, every one addressed to 255/190", flush=True)


def fly(m, recv, texts):
    m.mav.command_long_send(1, 1, 300, 0, 0, 0, 0, 0, 0, 0, 0)  # MAV_CMD_MISSION_START
    ack = recv(["COMMAND_ACK"])
    if ack.result != 0:
        fail(f"MISSION_START: COMMAND_ACK {ack.result}, {texts}")
    print("mission started", flush=True)
    modes, landed, reached, refused = set(), set(), [], None
    while True:
        msg = recv(["HEARTBEAT", "EXTENDED_SYS_STATE", "MISSION_ITEM_REACHED",
                    "MISSION_CURRENT", "MISSION_ACK"])
        kind = msg.get_type()
        if kind == "HEARTBEAT":
            modes.add(mavutil.mode_string_v10(msg))
        elif kind == "EXTENDED_SYS_STATE":
            landed.add(msg.landed_state)
        elif kind == "MISSION_ITEM_REACHED":
            reached.append(msg.seq)
        elif kind == "MISSION_ACK":
            refused = msg.type
        elif kind == "MISSION_CURRENT":
            if msg.mission_state == 3 and msg.seq >= 1 and refused is None:
                texts.clear()
                m.mav.mission_clear_all_send(1, 1, MISSION)
                refused = -1
            if msg.mission_state == 5:
                break
    if refused in (None, -1, 0):
        fail(f"the clear while flying was not refused: {refused}")
    if not any("refused" in t for t in texts):
        fail(f"no STATUSTEXT says why the clear was refused: {texts}")
    # The essence in the first chunk (50 characters), where a ground station shows it first.
    first = next(t for t in texts if "refused" in t)
    if "refused while" not in first:
        fail(f"the first 50 characters do not say why: {first!r}")
    print(f"first 50 characters: {first!r}", flush=True)
    print(f"clear while flying refused: MISSION_ACK {refused}: {''.join(texts)}", flush=True)
    if msg.seq != 2 or msg.total != 3:
        fail(f"the end: MISSION_CURRENT seq {msg.seq} of {msg.total}")
    # pymavlink 2.4.50's dialect stops at mission_mode: mission_id and fence_id are read from
    # the payload (MAVLink 2 trims its trailing zeros; they are the 4-byte fields at offset 6).
    buf = msg.get_msgbuf()
    payload = bytes(buf[10:10 + buf[1]]).ljust(18, b"\0")
    mission_id, fence_id = struct.unpack_from("<II", payload, 6)
    if mission_id == 0 or fence_id == 0:
        fail(f"no plan checksums: mission_id {mission_id}, fence_id {fence_id}")
    print(f"mission complete on item {msg.seq} of {msg.total}, "
          f"mission_id {mission_id:#010x}, fence_id {fence_id:#010x}", flush=True)
    if reached != [0, 1, 2]:
        fail(f"MISSION_ITEM_REACHED {reached}")
    print(f"reached {reached}", flush=True)
    if "MISSION" not in modes:
        fail(f"flight modes {modes}")
    print(f"flight modes by name: {sorted(modes)}", flush=True)
    if 2 not in landed:  # MAV_LANDED_STATE_IN_AIR
        fail(f"landed states {landed}")
    print(f"landed states {sorted(landed)}", flush=True)


if __name__ == "__main__":
    main()
