//! The README's main command, the demo (`src/bin/demo.rs`), runs to its end from the build the
//! tests made: both missions uploaded, mission 2 staged while mission 1 flies, activated after
//! the landing, flown waypoint by waypoint and downloaded equal to the upload.

use std::process::Command;

use missionlink::harness::*;

#[test]
fn the_demo_flies_both_missions_and_downloads_what_it_uploaded() {
    let bin = bin_dir();
    let out = Command::new(env!("CARGO_BIN_EXE_demo"))
        .arg("--bin-dir")
        .arg(&bin)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "the demo failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let wanted = [
        "1. Validate and upload mission 1",
        "upload complete: mission 0xFE2DA2DB and areas 0x5F20AB56 active on the FCC",
        "stage complete: mission 0x3A1E8E21 and areas 0x8B764BCB staged as \"MEDEVAC-2\"",
        "#50000 command 4 accepted",
        "FROM -, TO 1 (48.275000 N 11.645000 E), NEXT 2 (48.278000 N 11.658000 E)",
        "FROM 1 (48.275000 N 11.645000 E), TO 2 (48.278000 N 11.658000 E), NEXT 3 (48.280000 N 11.680000 E)",
        "FROM 2 (48.278000 N 11.658000 E), TO 3 (48.280000 N 11.680000 E), NEXT -",
        "FROM 3 (48.280000 N 11.680000 E), TO -, NEXT -",
        "3 waypoints, 3 areas: equal to the upload, every field",
        "demo complete in",
    ];
    let mut rest: &str = &stdout;
    for line in wanted {
        let at = rest
            .find(line)
            .unwrap_or_else(|| panic!("the demo did not print, in order, {line:?}:\n{stdout}"));
        rest = &rest[at + line.len()..];
    }
}
