"""MAVProxy (its PyPI package, unmodified) against `gcs mavlink` (tests/system/mavlink_clients.rs
starts both), driven as a person types at its prompt.

MAVProxy runs with its own system and component IDs (255, 230 by default) and takes a mission
request only when it is addressed to itself, so an upload succeeds only when the vehicle
answers the system and component that asked. The script writes a mission and a fence as
QGC WPL 110 files (the mission with its home row), then types `wp load`, `fence load`, `wp
list`, `long DO_SET_MODE` (Hold), `long MISSION_START` and `wp clear` (refused while the aircraft flies,
taken after it landed), and reads MAVProxy's own output for each step's outcome.

Usage: python3 mavproxy_mission.py BRIDGE_PORT. Exit status 0 when every check passes.
"""

import os
import queue
import re
import subprocess
import sys
import tempfile
import threading
import time

TIMEOUT = 30

# QGC WPL 110 rows: seq, current, frame, command, p1..p4, lat, lon, alt, autocontinue.
# Row 0 is the home, as MAVProxy's `wp save` and Mission Planner write it (a waypoint in the
# global frame, altitude above mean sea level); the take-off follows.
MISSION = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t48.26\t11.66\t520\t1
1\t0\t3\t22\t0\t0\t0\t0\t48.26\t11.66\t30\t1
2\t0\t3\t16\t0\t0\t0\t0\t48.265\t11.655\t120\t1
3\t0\t3\t16\t0\t0\t0\t0\t48.275\t11.645\t120\t1
"""

# The fly-zone (an inclusion polygon of 4 vertices) and a no-fly-zone (an exclusion circle of
# 200 m), as MAVProxy's `fence save` writes them.
FENCE = """QGC WPL 110
0\t0\t0\t5001\t4\t0\t0\t0\t48.255\t11.635\t0\t1
1\t0\t0\t5001\t4\t0\t0\t0\t48.255\t11.69\t0\t1
2\t0\t0\t5001\t4\t0\t0\t0\t48.285\t11.69\t0\t1
3\t0\t0\t5001\t4\t0\t0\t0\t48.285\t11.635\t0\t1
4\t0\t0\t5004\t200\t0\t0\t0\t48.268\t11.675\t0\t1
"""


def fail(why):
    print(f"FAILED: {why}", flush=True)
    sys.exit(1)


class Proxy:
    """MAVProxy in a child process: lines typed on its stdin, its output read line by line."""

    def __init__(self, port, state):
        mavproxy = os.path.join(os.path.dirname(sys.executable), "mavproxy.py")
        self.child = subprocess.Popen(
            [sys.executable, mavproxy, f"--master=udpout:127.0.0.1:{port}",
             f"--state-basedir={state}", "--default-modules=link,wp,fence,mode,cmdlong"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, bufsize=1, cwd=state,
            # Its start-up scripts and state files in the test's directory, not the user's.
            env={**os.environ, "HOME": state},
        )
        self.lines = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.child.stdout:
            self.lines.put(line.rstrip("\n"))

    def type(self, command):
        print(f"> {command}", flush=True)
        self.child.stdin.write(command + "\n")
        self.child.stdin.flush()

    def wait_for(self, pattern, what):
        """The first line matching `pattern` within the deadline; lines before it are echoed."""
        deadline = time.monotonic() + TIMEOUT
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                fail(f"MAVProxy did not say {what} ({pattern!r})")
            try:
                line = self.lines.get(timeout=left)
            except queue.Empty:
                continue
            print(f"  {line}", flush=True)
            match = re.search(pattern, line)
            if match:
                return match

    def close(self):
        try:
            self.child.stdin.write("exit\n")
            self.child.stdin.flush()
        except OSError:
            pass
        try:
            self.child.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.child.kill()


def main():
    port = int(sys.argv[1])
    with tempfile.TemporaryDirectory() as state:
        mission, fence = os.path.join(state, "mission.txt"), os.path.join(state, "fence.txt")
        with open(mission, "w") as f:
            f.write(MISSION)
        with open(fence, "w") as f:
            f.write(FENCE)
        proxy = Proxy(port, state)
        try:
            proxy.wait_for(r"Detected vehicle 1:1", "that it sees the vehicle")

            proxy.type(f"wp load {mission}")
            proxy.wait_for(r"Sent all 4 waypoints", "the mission sent")
            ack = proxy.wait_for(r"Got MISSION_ACK: TYPE_MISSION: (\w+)", "the mission's ack")
            if ack.group(1) != "ACCEPTED":
                fail(f"mission upload: {ack.group(1)}")
            print("mission uploaded, its home row the planned home", flush=True)

            proxy.type(f"fence load {fence}")
            proxy.wait_for(r"Sent all 5 fence items", "the fence sent")
            ack = proxy.wait_for(r"Got MISSION_ACK: TYPE_FENCE: (\w+)", "the fence's ack")
            if ack.group(1) != "ACCEPTED":
                fail(f"fence upload: {ack.group(1)}")
            print("fence uploaded: mission and fence active on the FCC", flush=True)

            proxy.type("wp list")
            proxy.wait_for(r"Requesting 4 waypoints", "the mission's count")
            rows = [proxy.wait_for(r"^(\d+) (\d+) ([-\d.]+) ([-\d.]+) ([-\d.]+) p1=", "an item")
                    for _ in range(4)]
            got = [(int(r.group(1)), float(r.group(3)), float(r.group(4)), float(r.group(5)))
                   for r in rows]
            want = [(16, 48.26, 11.66, 520.0), (22, 48.26, 11.66, 30.0),
                    (16, 48.265, 11.655, 120.0), (16, 48.275, 11.645, 120.0)]
            if any(g[0] != w[0] or any(abs(a - b) > 1e-6 for a, b in zip(g[1:], w[1:]))
                   for g, w in zip(got, want)):
                fail(f"wp list: {got}, uploaded {want}")
            print("wp list: equal to the upload, home row included", flush=True)

            # Hold (PX4's AUTO.LOITER) is what the vehicle does on the ground. MAVProxy
            # 1.8.75's `mode LOITER` cannot send a PX4 mode (it passes the mode table's tuple
            # as a float: "required argument is not a float"), so the operator types the
            # command: base mode 29 (custom, auto, guided, stabilised), main mode 4 (AUTO),
            # sub mode 3 (LOITER).
            proxy.type("long DO_SET_MODE 29 4 3")
            ack = proxy.wait_for(r"Got COMMAND_ACK: DO_SET_MODE: (\w+)", "the mode's ack")
            if ack.group(1) != "ACCEPTED":
                fail(f"DO_SET_MODE LOITER: {ack.group(1)}")
            print("mode LOITER (DO_SET_MODE): accepted", flush=True)

            proxy.type("long MISSION_START")
            ack = proxy.wait_for(r"Got COMMAND_ACK: MISSION_START: (\w+)", "the start's ack")
            if ack.group(1) != "ACCEPTED":
                fail(f"long MISSION_START: {ack.group(1)}")
            proxy.wait_for(r"\bMISSION>|Mode MISSION|mode MISSION", "the mission mode")
            print("long MISSION_START: the mission flies, MAVProxy shows mode MISSION", flush=True)

            # While it flies, the FCC refuses the clear, and says why.
            proxy.type("wp clear")
            ack = proxy.wait_for(r"Got MISSION_ACK: TYPE_MISSION: (\w+)", "the clear's ack")
            if ack.group(1) == "ACCEPTED":
                fail("wp clear while flying: accepted")
            print(f"wp clear while flying: {ack.group(1)}", flush=True)

            # After the landing at the last waypoint, the clear is taken.
            deadline = time.monotonic() + 90
            while True:
                time.sleep(2)
                proxy.type("wp clear")
                ack = proxy.wait_for(r"Got MISSION_ACK: TYPE_MISSION: (\w+)", "the clear's ack")
                if ack.group(1) == "ACCEPTED":
                    break
                if time.monotonic() > deadline:
                    fail(f"wp clear after the flight: {ack.group(1)}")
            proxy.type("wp list")
            proxy.wait_for(r"Requesting 0 waypoints", "an empty mission")
            print("wp clear: the FCC holds no mission", flush=True)
        finally:
            proxy.close()


if __name__ == "__main__":
    main()
