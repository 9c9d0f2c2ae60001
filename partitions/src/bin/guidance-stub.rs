//! `guidance-stub`: the FCC partition that stands in for flight guidance in the rig, a thin
//! driver around `missionlink_flight::guidance::Guidance`. It flies the active waypoint and area lists
//! with a simple kinematic model when system automation says so, time-scaled for demos, and
//! publishes FROM / TO / NEXT and the position on `fcc/guidance/progress`. It reports when the
//! position leaves the fly-zone or enters a no-fly-zone.
//!
//! The loop is `missionlink_partitions::guidance_stub::run`; `partition_binary!` runs it on
//! `ipc::Service` under `runtime::partition_main`, which parses the flags.

missionlink_partitions::partition_binary!(guidance_stub, "Guidance stub of the FCC.");
