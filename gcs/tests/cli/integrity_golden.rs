//! ICD §11 golden values: the canonical forms and CRC-32 checksums of the demo missions and
//! their areas (and of mission 2 planned in wind), as `services/protocol/tests/data/integrity_reference.py` computes them from the ICD text
//! alone (a third party can rerun it), against services' `transfer::integrity` on the same
//! mission files read by the gcs.

use std::path::Path;

use missionlink_gcs::mission_file::MissionFile;
use missionlink_interfaces::wire::Speed;
use missionlink_protocol::transfer::integrity::{
    areas_checksum, mission_checksum, write_areas, write_mission,
};

const GOLDEN: &str = include_str!("../../../services/protocol/tests/data/integrity_golden.txt");

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn the_demo_missions_canonical_forms_and_checksums_are_the_icds() {
    let mut rows = 0;
    for line in GOLDEN.lines().filter(|l| !l.starts_with('#')) {
        let [name, bytes, crc] = line.split(' ').collect::<Vec<_>>()[..] else {
            panic!("a row of three fields: {line}");
        };
        let (file, kind) = name.split_once('.').unwrap();
        // "mission-2@wind12": the file planned in a wind of 12 m/s (#13001 field 5).
        let (file, wind) = match file.split_once("@wind") {
            Some((file, mps)) => (file, Some(Speed::from_mps(mps.parse().unwrap()).unwrap())),
            None => (file, None),
        };
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../missions")
            .join(format!("{file}.toml"));
        let mut lists = MissionFile::read(&path)
            .unwrap()
            .to_plan()
            .unwrap()
            .assemble()
            .unwrap();
        lists.mission.route.planning_wind = wind;
        let mut canonical = Vec::new();
        let checksum = match kind {
            "mission" => {
                write_mission(&lists.mission, &mut canonical);
                mission_checksum(&lists.mission)
            }
            "areas" => {
                write_areas(&lists.areas, &mut canonical);
                areas_checksum(&lists.areas)
            }
            other => panic!("kind {other}"),
        };
        assert_eq!(hex(&canonical), bytes, "{name}: canonical form");
        assert_eq!(format!("{:08x}", checksum.value()), crc, "{name}: checksum");
        rows += 1;
    }
    assert_eq!(rows, 5);
}
