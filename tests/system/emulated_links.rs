//! The real GCS and the real FCC through the link emulator (`missionlink::link_emulator`):
//! windowed transfers (ICD §10) over an LTE link with its delay, jitter and loss on both links,
//! and over one link when the other is cut.

use std::time::Instant;

use missionlink::harness::*;
use missionlink::link_emulator::{Emulator, Flow, Profile};

const SEED: u64 = 15;

/// An FCC and a GCS talking through an emulator with `profile` on every flow.
fn through(test: &str, profile: Profile) -> (Rig, Process, Link, Emulator) {
    let mut rig = Rig::new(test);
    let (fcc, link, emulator) = rig.start_through(profile.flows(), SEED);
    (rig, fcc, link, emulator)
}

#[test]
fn an_upload_and_a_download_over_lte_on_both_links() {
    let (_rig, mut fcc, mut link, emulator) = through("emulated-lte", Profile::Lte);
    let plan = plan("mission-2.toml");
    let valid = link.station().validate(&plan).unwrap();
    let started = Instant::now();
    upload(&mut link, &plan).unwrap();
    let took = started.elapsed();
    assert_eq!(download(&mut link).unwrap(), valid);
    let stats = emulator.stats();
    println!("mission 2 over lte: upload {took:?}; per flow {stats:?}");
    // Everything went through the emulator, both ways, both links.
    assert!(stats.iter().all(|s| s.offered > 0), "{stats:?}");
    fcc.stop().unwrap();
}

#[test]
fn with_the_direct_link_cut_the_lte_link_carries_everything() {
    let (_rig, mut fcc, mut link, emulator) = through("emulated-cut", Profile::Lte);
    emulator.set(Flow::UpDirect, Profile::Lte.up().cut());
    emulator.set(Flow::DownDirect, Profile::Lte.down().cut());
    let plan = plan("mission-2.toml");
    let valid = link.station().validate(&plan).unwrap();
    upload(&mut link, &plan).unwrap();
    assert_eq!(download(&mut link).unwrap(), valid);
    let stats = emulator.stats();
    assert_eq!(
        stats[Flow::UpDirect as usize].lost,
        stats[Flow::UpDirect as usize].offered
    );
    assert!(stats[Flow::UpLte as usize].offered > 0);
    fcc.stop().unwrap();
}
