//! `system-automation`: the FCC partition of paper §2.5, a thin driver around
//! `missionlink_flight::automation::SystemAutomation`. It follows the active lists and guidance's
//! progress, carries out the #50000 commands mission data handling accepted, and publishes the
//! flight phase and which functions are active (`fcc/automation/state`, history 1). A restarted
//! automation adopts the phase guidance's progress shows, so it never drops an aircraft in the
//! air back to "on ground".
//!
//! The loop is `missionlink_partitions::system_automation::run`; `partition_binary!` runs it on
//! `ipc::Service` under `runtime::partition_main`, which parses the flags.

missionlink_partitions::partition_binary!(system_automation, "System automation of the FCC.");
