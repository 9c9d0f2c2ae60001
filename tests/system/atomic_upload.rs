//! The atomic upload survives its GCS: the GCS dies in the middle of an atomic upload (ICD §8:
//! stage under a fresh Mission ID, activate, delete the staged copy), after its k-th message, k
//! drawn with a seed over the whole upload, many times. Afterwards the FCC's active lists are the
//! old ones, whole, whenever the activation (#50000 command 4) had not been sent; the new ones,
//! whole, when it had (loopback loses nothing, so a sent activation arrives). Never a mix: the
//! FCC's report (its checksums, ICD §11) and the lists it publishes to guidance agree.
//!
//! "Dies" is the crash of the GCS process: it sends, answers and retries nothing more, and a new
//! GCS starts on the same ports ([`GcsLink::into_links`]), asks the report, deletes the staged
//! copies the dead one left, and uploads the old mission again for the next run.

use std::time::Duration;

use missionlink::harness::*;
use missionlink_gcs::gcs_link::{Direction, Finished};
use missionlink_ground::ground_station::{MissionPlan, Sequence};
use missionlink_interfaces::wire::Message;
use missionlink_linksim::Rng;
use missionlink_protocol::transfer::staged::MissionId;

/// Upload runs cut at a random message.
const RUNS: usize = 40;
/// The seed of the cuts: the same seed cuts at the same messages.
const SEED: u64 = 13;

/// Messages the GCS sent since log entry `from`.
fn sent(link: &Link, from: usize) -> Vec<&Message> {
    link.log
        .get(from..)
        .unwrap_or_default()
        .iter()
        .filter(|l| l.direction == Direction::Up)
        .map(|l| &l.message)
        .collect()
}

fn atomic(link: &mut Link, plan: &MissionPlan) {
    let now = link.now();
    link.station()
        .upload_with(now, plan, Sequence::Atomic)
        .unwrap();
    match finish(link) {
        Ok(Finished::Uploaded(_)) => {}
        other => panic!("the atomic upload did not complete: {other:?}"),
    }
}

/// Deletes every staged mission the report lists (what a dead GCS left).
fn delete_staged(link: &mut Link) {
    for e in report(link).iter().skip(1) {
        let id = MissionId::of_text(&e.mission_id.unwrap()).unwrap();
        let now = link.now();
        link.station().delete(now, id).unwrap();
        finish(link).unwrap();
    }
}

#[test]
fn a_gcs_that_dies_during_an_atomic_upload_leaves_the_old_lists_whole_until_it_activated() {
    let mut rig = Rig::new("atomic-upload-kill");
    // The subject is which lists survive the GCS, not the link's timing: over a thousand
    // exchanges, a GCS that gives up after 500 ms and one retry (ICD §1's default) fails the
    // test whenever a loaded machine starves the FCC for a second; 2 s per answer does not.
    rig.config.timing.ack_timeout_ms = 2_000;
    let mut fcc = rig.start_fcc();
    let mut link = rig.gcs(&mut fcc);
    link.enable_log();
    let (mission_1, mission_2) = (plan("mission-1.toml"), plan("mission-2.toml"));
    let old = plan_checksums(&link.station().validate(&mission_1).unwrap());
    let new = plan_checksums(&link.station().validate(&mission_2).unwrap());

    // An undisturbed atomic upload of mission 2 over mission 1: its messages, and which one is
    // the activation.
    atomic(&mut link, &mission_1);
    let from = link.log.len();
    atomic(&mut link, &mission_2);
    let messages = sent(&link, from);
    let total = messages.len();
    let activation = 1 + messages
        .iter()
        .position(|m| matches!(m, Message::MissionExecuteCommand(_)))
        .expect("the atomic upload activates");
    assert!(
        activation > 10 && activation < total,
        "{activation} of {total}"
    );

    let mut rng = Rng::new(SEED);
    let (mut before, mut after) = (0, 0);
    for run in 0..RUNS {
        atomic(&mut link, &mission_1);
        assert_eq!(active_checksums(&mut link), old, "run {run}: the old lists");
        let k = rng.range(1, total as u64) as usize;
        let from = link.log.len();
        let now = link.now();
        link.station()
            .upload_with(now, &mission_2, Sequence::Atomic)
            .unwrap();
        while sent(&link, from).len() < k && !link.station().is_standby() {
            link.pump(Duration::from_millis(1));
        }
        // One pump may send two messages (an acknowledgement and the next request): the cut
        // falls after the k-th or the one after it.
        let k = sent(&link, from).len();

        // The GCS dies; another starts on its ports.
        let links = link.into_links();
        link = rig.gcs_on(links);
        link.enable_log();
        let lists = active_checksums(&mut link);
        if k < activation {
            before += 1;
            assert_eq!(
                lists, old,
                "run {run}: cut after message {k} of {total}, before the activation ({activation}): the old lists, whole"
            );
        } else {
            after += 1;
            assert_eq!(
                lists, new,
                "run {run}: cut after message {k} of {total}, the activation ({activation}) sent: the new lists, whole"
            );
        }
        delete_staged(&mut link);
    }
    println!(
        "{RUNS} atomic uploads of {total} GCS messages cut by the GCS's death (seed {SEED}): {before} before the activation (message {activation}), old lists whole every time; {after} after it, new lists whole every time"
    );
    assert!(before > 0 && after > 0, "the seed cut on one side only");
}
