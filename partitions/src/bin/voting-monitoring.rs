//! `voting-monitoring`: the FCC partition that owns the two data links (paper §2.4). It votes
//! every step's datagrams from the direct and the LTE link (integrity and validity checks of ICD
//! §2, newest by time stamp, the direct link on a tie, never waiting for the other link),
//! publishes the voted uplink frames on `fcc/link/uplink`, and sends every frame of
//! `fcc/link/downlink` on both links.
//!
//! The loop is `missionlink_partitions::voting_monitoring::run`; `partition_binary!` runs it on
//! `ipc::Service` under `runtime::partition_main`, which parses the flags.

missionlink_partitions::partition_binary!(
    voting_monitoring,
    "Voting and monitoring of the direct and LTE links."
);
