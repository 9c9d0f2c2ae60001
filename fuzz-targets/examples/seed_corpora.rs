//! Writes the seed inputs of every fuzz target into `fuzz/corpus/<target>/seed-*`
//! (docs/fuzzing.md): what the targets start from before the fuzzer finds its own inputs, built from
//! the project's one set of fixtures.
//!
//! - Frames: the golden frames of the `interfaces` tests (written beforehand into
//!   `fuzz/corpus/fuzz_datagram/` by `MISSIONLINK_GOLDEN_DIR=... cargo test -p
//!   missionlink-interfaces --lib`), and every message a GCS sends to a real FCC (and the
//!   answers) in the demo missions' uploads, downloads, report, clears and commands, in the
//!   record format of each target (`missionlink_fuzz::input`).
//! - Mission files: the demo missions (`missions/*.toml`), the real QGroundControl files
//!   (`missions/qgc/*.plan`), and the demo missions exported as `.plan` and their areas as
//!   GeoJSON by the gcs crate's own exporters.
//!
//! ```sh
//! cargo run -p missionlink-fuzz --example seed_corpora
//! ```
//!
//! Seeds are only a start: `cargo fuzz cmin` keeps those that add coverage.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::path::{Path, PathBuf};

use missionlink_flight::mission_data_handling::MissionDataHandling;
use missionlink_fuzz::input::{MessageBody, record};
use missionlink_fuzz::{fcc, gcs, signature, voting};
use missionlink_gcs::mission_file::MissionFile;
use missionlink_gcs::{geojson, qgc};
use missionlink_ground::ground_station::{
    GroundStation, MissionPlan, Sequence, ValidatedPlan, WithoutGateway,
};
use missionlink_interfaces::wire::{self, MAX_FRAME_LEN, Message};
use missionlink_protocol::link::time::Instant;
use missionlink_protocol::testkit;
use missionlink_protocol::transfer::staged::MissionId;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn write(target: &str, name: &str, bytes: &[u8]) {
    let dir = root().join("fuzz/corpus").join(target);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(format!("seed-{name}")), bytes).unwrap();
}

/// The golden frames the interfaces tests wrote.
fn golden() -> Vec<Vec<u8>> {
    let dir = root().join("fuzz/corpus/fuzz_datagram");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    files.retain(|p| {
        p.file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("golden-")
    });
    files.sort();
    assert!(
        !files.is_empty(),
        "no golden frames in {}: run MISSIONLINK_GOLDEN_DIR=$PWD/fuzz/corpus/fuzz_datagram \
         cargo test -p missionlink-interfaces --lib first",
        dir.display()
    );
    files.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// One message of an exchange: who sent it, the frame, and the message.
struct Sent {
    by_gcs: bool,
    frame: Vec<u8>,
    message: Message,
    ack_requested: bool,
}

/// A GCS and a real FCC, every frame delivered, 1 ms per message, until the GCS is in standby.
struct Exchange {
    gcs: GroundStation<WithoutGateway>,
    fcc: MissionDataHandling,
    now: Instant,
    log: Vec<Sent>,
}

impl Exchange {
    fn new() -> Self {
        let mut fcc = MissionDataHandling::new(missionlink_flight::testkit::fcc_config());
        // As the FCC target starts: on the ground at TROL.
        fcc.handle_progress(
            Instant::ZERO,
            &missionlink_interfaces::contracts::GuidanceProgressPayload {
                sequence: 1,
                latitude_deg: testkit::TROL.0,
                longitude_deg: testkit::TROL.1,
                on_ground: true,
                ..missionlink_interfaces::contracts::GuidanceProgressPayload::IDLE
            },
        );
        let mut buf = [0u8; MAX_FRAME_LEN];
        while fcc.poll_transmit(&mut buf).is_some() {}
        Self {
            gcs: GroundStation::new(missionlink_ground::testkit::gcs_config(), WithoutGateway),
            fcc,
            now: Instant::from_millis(1),
            log: Vec::new(),
        }
    }

    fn run(&mut self) {
        let mut buf = [0u8; MAX_FRAME_LEN];
        for _ in 0..100_000 {
            let mut moved = false;
            while let Some(len) = self.gcs.poll_transmit(&mut buf) {
                let frame = buf[..len.unwrap()].to_vec();
                self.now = self.now + core::time::Duration::from_millis(1);
                let _ = self.fcc.handle_frame(self.now, &frame);
                self.log(true, frame);
                moved = true;
            }
            while let Some(len) = self.fcc.poll_transmit(&mut buf) {
                let frame = buf[..len.unwrap()].to_vec();
                self.now = self.now + core::time::Duration::from_millis(1);
                let _ = self.gcs.handle_frame(self.now, &frame);
                self.log(false, frame);
                moved = true;
            }
            while self.gcs.poll_event().is_some() {}
            while self.fcc.poll_event().is_some() {}
            if moved {
                continue;
            }
            if self.gcs.is_standby() {
                return;
            }
            let next = [self.gcs.poll_timeout(), self.fcc.poll_timeout()]
                .into_iter()
                .flatten()
                .min();
            let Some(next) = next else { return };
            self.now = self.now.max(next);
            self.gcs.handle_timeout(self.now);
            self.fcc.handle_timeout(self.now);
        }
        panic!("an exchange that does not end");
    }

    fn log(&mut self, by_gcs: bool, frame: Vec<u8>) {
        let (envelope, message) = wire::decode(&frame).unwrap();
        self.log.push(Sent {
            by_gcs,
            frame,
            message,
            ack_requested: envelope.ack_requested,
        });
    }

    /// The FCC target's records of what the GCS sent: its acknowledgements as answers, every
    /// other message sent again by the target's GCS endpoint.
    fn fcc_records(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for sent in self.log.iter().filter(|s| s.by_gcs) {
            match &sent.message {
                Message::MessageAcknowledgement(a) => {
                    let reason = match a.ack_type {
                        wire::AckType::Rejected => a.reject_reason.map_or(1, |r| r as u8),
                        _ => 0,
                    };
                    out.extend(record(fcc::tag::ANSWER, &[reason]));
                }
                m => out.extend(record(
                    fcc::tag::SEND,
                    &MessageBody::of(m, u8::from(sent.ack_requested)),
                )),
            }
        }
        out
    }
}

fn plans() -> [(&'static str, MissionPlan); 3] {
    [
        ("mission-1", testkit::mission_1()),
        ("mission-2", testkit::mission_2()),
        ("generated-256", testkit::generated_plan(256)),
    ]
}

fn staged() -> MissionId {
    MissionId::new("MEDEVAC-2").unwrap()
}

/// Each scenario on a fresh pair: its exchange.
fn scenarios() -> Vec<(String, Exchange)> {
    let mut out = Vec::new();
    for (name, plan) in plans() {
        for (sequence, label) in [
            (Sequence::Paper { clear: true }, "paper"),
            (Sequence::Atomic, "atomic"),
        ] {
            let mut x = Exchange::new();
            if name == "generated-256" {
                x.gcs.set_transfer_window(32);
            }
            x.gcs.upload_with(x.now, &plan, sequence).unwrap();
            x.run();
            x.gcs.download(x.now).unwrap();
            x.run();
            out.push((format!("{name}-{label}-upload-download"), x));
        }
    }
    let mission_2 = testkit::mission_2();
    let mut x = Exchange::new();
    x.gcs.stage(x.now, staged(), &mission_2).unwrap();
    x.run();
    x.gcs.report(x.now).unwrap();
    x.run();
    x.gcs.download_of(x.now, Some(staged())).unwrap();
    x.run();
    x.gcs.activate(x.now, staged()).unwrap();
    x.run();
    x.gcs.delete(x.now, staged()).unwrap();
    x.run();
    out.push(("mission-2-staged".into(), x));
    let mut x = Exchange::new();
    x.gcs
        .upload_with(
            x.now,
            &testkit::mission_1(),
            Sequence::Paper { clear: true },
        )
        .unwrap();
    x.run();
    x.gcs.execute(x.now, wire::ExecuteCommand::Execute).unwrap();
    x.run();
    x.gcs.clear_areas(x.now).unwrap();
    x.run();
    x.gcs.clear_mission(x.now).unwrap();
    x.run();
    out.push(("mission-1-execute-clear".into(), x));
    out
}

fn datagram_seeds(exchanges: &[(String, Exchange)]) {
    // Every frame of the demo mission 2 upload back to back in one datagram (ICD §1), and one
    // signed frame with its trailer followed by an unsigned one.
    let (_, x) = exchanges
        .iter()
        .find(|(n, _)| n == "mission-2-atomic-upload-download")
        .unwrap();
    let all: Vec<u8> = x.log.iter().flat_map(|s| s.frame.clone()).collect();
    write(
        "fuzz_datagram",
        "mission-2-back-to-back",
        &all[..all.len().min(4096)],
    );
    let first = &x.log[1].frame;
    let mut signed = voting::signed(
        &voting::keys().0,
        missionlink_interfaces::contracts::Link::Direct,
        first,
    )
    .unwrap();
    signed.extend_from_slice(&x.log[2].frame);
    write("fuzz_datagram", "signed-then-unsigned", &signed);
}

fn fcc_seeds(exchanges: &[(String, Exchange)], golden: &[Vec<u8>]) {
    for (name, x) in exchanges {
        write("fuzz_fcc", name, &x.fcc_records());
    }
    // The golden frames as they are, and their data in fresh GCS frames.
    let mut raw = Vec::new();
    let mut sent = Vec::new();
    for frame in golden {
        raw.extend(record(fcc::tag::RAW, frame));
        if let Ok((envelope, message)) = wire::decode(frame) {
            sent.extend(record(
                fcc::tag::SEND,
                &MessageBody::of(&message, u8::from(envelope.ack_requested)),
            ));
        }
    }
    write("fuzz_fcc", "golden-raw", &raw);
    write("fuzz_fcc", "golden-sent", &sent);
}

fn gcs_seeds(golden: &[Vec<u8>]) {
    let pump = record(gcs::tag::PUMP, &[15]);
    let request = |which: u8, argument: u8| record(gcs::tag::REQUEST, &[which, argument]);
    // Each request alone, answered by the FCC; then the upload of mission 2 with answers lost.
    for which in 0..gcs::REQUESTS {
        let mut seed = Vec::new();
        if which >= 9 {
            // Staged requests and commands find a mission staged and active first.
            seed.extend(request(12, 0));
            for _ in 0..8 {
                seed.extend(&pump);
            }
        }
        seed.extend(request(which, 1));
        for _ in 0..8 {
            seed.extend(&pump);
        }
        seed.extend(request(4, 0));
        for _ in 0..8 {
            seed.extend(&pump);
        }
        write("fuzz_gcs", &format!("request-{which}"), &seed);
    }
    let mut lossy = Vec::new();
    lossy.extend(request(13, 32));
    lossy.extend(request(1, 0));
    for i in 0..24u8 {
        lossy.extend(record(gcs::tag::PUMP, &[0, 0x41 << (i % 2), i]));
        lossy.extend(record(gcs::tag::TIME, &[0x01, 0xf4]));
    }
    write("fuzz_gcs", "mission-2-lossy", &lossy);
    // The golden frames put in front of a GCS in the middle of a download.
    let mut seed = Vec::new();
    seed.extend(request(4, 0));
    seed.extend(&pump);
    for frame in golden {
        seed.extend(record(gcs::tag::RAW, frame));
        if let Ok((envelope, message)) = wire::decode(frame) {
            seed.extend(record(
                gcs::tag::SEND,
                &MessageBody::of(&message, u8::from(envelope.ack_requested)),
            ));
        }
    }
    write("fuzz_gcs", "golden-during-download", &seed);
}

fn voting_seeds(exchanges: &[(String, Exchange)]) {
    let (_, x) = exchanges
        .iter()
        .find(|(n, _)| n == "mission-2-paper-upload-download")
        .unwrap();
    let from_gcs: Vec<&Sent> = x.log.iter().filter(|s| s.by_gcs).collect();
    for policy in 0..3u8 {
        let mut seed = vec![policy];
        for (i, sent) in from_gcs.iter().enumerate() {
            let mut body = (i as u16).to_be_bytes().to_vec();
            body.extend(MessageBody::of(&sent.message, u8::from(sent.ack_requested)));
            let sign = if policy == 0 { 0 } else { voting::tag::SIGN };
            seed.extend(record(voting::tag::FRAME | sign, &body));
            // The LTE copy of the same message, in this step or the next.
            seed.extend(record(voting::tag::COPY | voting::tag::LTE, &[]));
            if i % 3 == 0 {
                seed.extend(record(voting::tag::VOTE, &[0, 2]));
            }
            if i % 5 == 0 {
                seed.extend(record(
                    voting::tag::FRAME | sign | voting::tag::APPEND,
                    &body,
                ));
            }
        }
        seed.extend(record(voting::tag::VOTE, &[0x0b, 0xb8]));
        for frame in x.log.iter().take(4) {
            seed.extend(record(voting::tag::RAW, &frame.frame));
        }
        write("fuzz_voting", &format!("mission-2-policy-{policy}"), &seed);
    }
}

fn signature_seeds(exchanges: &[(String, Exchange)]) {
    let (_, x) = exchanges
        .iter()
        .find(|(n, _)| n == "mission-1-paper-upload-download")
        .unwrap();
    for policy in 0..3u8 {
        let mut seed = vec![policy];
        for (i, sent) in x.log.iter().filter(|s| s.by_gcs).enumerate().take(12) {
            let mut body = ((i as i16 - 3) as u16).to_be_bytes().to_vec();
            body.extend(MessageBody::of(&sent.message, u8::from(sent.ack_requested)));
            let lte = if i % 2 == 0 { 0 } else { signature::tag::LTE };
            seed.extend(record(signature::tag::SIGN | lte, &body));
            seed.extend(record(signature::tag::VERIFY | lte, &[]));
            seed.extend(record(signature::tag::VERIFY | lte, &[]));
            seed.extend(record(
                signature::tag::VERIFY | (lte ^ signature::tag::LTE),
                &[],
            ));
            if i % 4 == 1 {
                seed.extend(record(signature::tag::MUTATE, &[0, 20, 1]));
                seed.extend(record(signature::tag::VERIFY | lte, &[]));
            }
            seed.extend(record(
                signature::tag::ADMIT | lte,
                &[0, i as u8, 0x32, 0xca],
            ));
            seed.extend(record(signature::tag::TIME, &[0, 100]));
            seed.extend(record(signature::tag::RAW, &sent.frame));
        }
        write(
            "fuzz_signature",
            &format!("mission-1-policy-{policy}"),
            &seed,
        );
    }
}

fn file_seeds() {
    let missions = root().join("missions");
    for entry in std::fs::read_dir(&missions).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            write("fuzz_mission_toml", &name, &std::fs::read(&path).unwrap());
        }
    }
    for entry in std::fs::read_dir(missions.join("qgc")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "plan") {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read(&path).unwrap();
            write("fuzz_qgc_plan", &name, &text);
            // A .plan's geofence is GeoJSON-like too: a start for the GeoJSON target's
            // syntax.
            write("fuzz_geojson", &name, &text);
        }
    }
    // The demo missions only: the 256-waypoint plan would make files of 100 KB, and a
    // fuzzer's inputs as long as its longest seed.
    for (name, plan) in plans().into_iter().take(2) {
        let valid: ValidatedPlan = plan.assemble().unwrap();
        let options = qgc::ExportOptions {
            take_off_position: plan.take_off_position,
            ..Default::default()
        };
        let (text, _) = qgc::export_plan(&valid, &options);
        write("fuzz_qgc_plan", &format!("{name}.plan"), text.as_bytes());
        write(
            "fuzz_geojson",
            &format!("{name}.geojson"),
            geojson::export_areas(&valid.areas).as_bytes(),
        );
        // As `gcs convert` writes it (every optional key it has).
        let toml = MissionFile::from_plan(&valid, plan.take_off_position).to_toml();
        write(
            "fuzz_mission_toml",
            &format!("{name}-written.toml"),
            toml.as_bytes(),
        );
    }
}

fn main() {
    let golden = golden();
    let exchanges = scenarios();
    datagram_seeds(&exchanges);
    fcc_seeds(&exchanges, &golden);
    gcs_seeds(&golden);
    voting_seeds(&exchanges);
    signature_seeds(&exchanges);
    file_seeds();
}
