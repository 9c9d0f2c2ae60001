//! The layers of the house hold (docs/design.md, "Module map"): what flies and what stays on the
//! ground share only what both ends of the link need. The flight binaries, built as
//! docs/deployment.md builds them (`cargo build --release -p missionlink-partitions --bins`),
//! link no ground logic, no ground tooling and no harness; the gcs tool links no FCC logic and no
//! iceoryx2; and neither turns on a crate's test fixtures (the feature `testkit`). Read from
//! `cargo tree`, the dependency graph cargo builds from (normal edges only: what a release
//! binary contains). And no product crate runs cargo: building binaries is the harness's
//! (`src/harness/binaries.rs`).
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

/// Every package in the normal dependency tree of `package`, with the features it is built with.
fn tree(package: &str) -> BTreeMap<String, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = Command::new(env!("CARGO"))
        .current_dir(root)
        .args([
            "tree",
            "--offline",
            "--locked",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .args(["-p", package, "-f", "{p} [{f}]"])
        .output()
        .expect("cargo tree runs");
    assert!(
        out.status.success(),
        "cargo tree -p {package}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .filter_map(|line| {
            let name = line.split_whitespace().next()?;
            let features = line.rsplit_once('[')?.1.split(']').next()?;
            Some((name.to_owned(), features.to_owned()))
        })
        .collect()
}

fn assert_absent(package: &str, tree: &BTreeMap<String, String>, forbidden: &[&str]) {
    let found: Vec<&&str> = forbidden
        .iter()
        .filter(|f| tree.contains_key(**f))
        .collect();
    assert!(
        found.is_empty(),
        "{package} links {found:?}: {:?}",
        tree.keys()
    );
    let fixtures: Vec<&String> = tree
        .iter()
        .filter(|(_, features)| features.split(',').any(|f| f == "testkit"))
        .map(|(name, _)| name)
        .collect();
    assert!(
        fixtures.is_empty(),
        "{package} builds {fixtures:?} with its test fixtures"
    );
}

#[test]
fn the_flight_binaries_link_no_ground_logic_and_no_harness() {
    let flight = tree("missionlink-partitions");
    assert!(flight.contains_key("missionlink-flight"));
    assert!(flight.contains_key("missionlink-protocol"));
    assert_absent(
        "missionlink-partitions",
        &flight,
        &[
            "missionlink-ground",
            "missionlink-gcs",
            "missionlink-linksim",
            "missionlink",
            "serde_json",
        ],
    );
}

#[test]
fn the_ground_tooling_links_no_fcc_logic_and_no_harness() {
    let ground = tree("missionlink-gcs");
    assert!(ground.contains_key("missionlink-ground"));
    assert!(ground.contains_key("missionlink-protocol"));
    assert_absent(
        "missionlink-gcs",
        &ground,
        &[
            "missionlink-flight",
            "missionlink-partitions",
            "missionlink-linksim",
            "missionlink",
            "iceoryx2",
        ],
    );
}

#[test]
fn the_shared_crates_link_neither_side() {
    for shared in ["missionlink-protocol", "missionlink-platform"] {
        let tree = tree(shared);
        assert_absent(
            shared,
            &tree,
            &[
                "missionlink-flight",
                "missionlink-ground",
                "missionlink-partitions",
                "missionlink-gcs",
                "missionlink-linksim",
            ],
        );
    }
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

#[test]
fn no_product_crate_runs_cargo() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let product = [
        "interfaces/src",
        "services/protocol/src",
        "services/flight/src",
        "services/ground/src",
        "platform/src",
        "partitions/src",
        "gcs/src",
        "bridge/src",
        "clib/src",
    ];
    let running_cargo: Vec<String> = product
        .iter()
        .flat_map(|dir| sources(&root.join(dir)))
        .filter(|file| {
            let text = std::fs::read_to_string(file).unwrap();
            text.contains("env::var(\"CARGO\")")
                || text.contains("env!(\"CARGO\")")
                || text.contains("Command::new(\"cargo\")")
        })
        .map(|file| file.display().to_string())
        .collect();
    assert!(
        running_cargo.is_empty(),
        "product code that runs cargo (harness code belongs in src/harness): {running_cargo:?}"
    );
}
