"""Reads a telemetry log (`.tlog`, as `gcs mavlink --tlog` writes it) with pymavlink, as
MAVProxy and QGroundControl's log tools do: prints the message types the vehicle (system 1)
sent, and how many of its messages that name a target name system 0.

Usage: python3 tlog_messages.py FILE. Exit status 0 when the log reads.
"""

import os
import sys

os.environ["MAVLINK20"] = "1"
from pymavlink import mavutil  # noqa: E402


def main():
    log = mavutil.mavlink_connection(sys.argv[1], dialect="common")
    kinds, to_system_0, count = set(), 0, 0
    while True:
        msg = log.recv_match()
        if msg is None:
            break
        if msg.get_type() == "BAD_DATA" or msg.get_srcSystem() != 1:
            continue
        count += 1
        kinds.add(msg.get_type())
        if getattr(msg, "target_system", None) == 0:
            to_system_0 += 1
    print(f"{count} messages of the vehicle: {' '.join(sorted(kinds))}")
    print(f"addressed to system 0: {to_system_0}")


if __name__ == "__main__":
    main()
