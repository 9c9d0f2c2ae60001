//! `mission-data-handling`: the FCC partition of paper §3.1, a thin driver around
//! `missionlink_flight::mission_data_handling::MissionDataHandling`. It consumes voted uplink frames, the automation state
//! and guidance progress; it publishes downlink frames, the active waypoint and area lists
//! (history 1: late joiners get them) and accepted #50000 commands. After a restart it resumes
//! with the lists it published last, so guidance never sees them change.
//!
//! The loop is `missionlink_partitions::mission_data_handling::run`; `partition_binary!` runs it on
//! `ipc::Service` under `runtime::partition_main`, which parses the flags.

missionlink_partitions::partition_binary!(
    mission_data_handling,
    "Mission data handling of the FCC."
);
