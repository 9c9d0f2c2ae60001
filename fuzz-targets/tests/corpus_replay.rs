//! Every file of every corpus (`fuzz/corpus/<target>/`) and every kept crash or hang input
//! (`fuzz/artifacts/<target>/`) through its target's entry point, on stable: an input that once
//! broke an invariant, or that reached code no other input reached, keeps being checked by
//! `cargo test --workspace` without nightly or cargo-fuzz.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::path::{Path, PathBuf};

use missionlink_fuzz::TARGETS;

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz")
}

/// The files of `dir`, sorted (none when it does not exist).
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

#[test]
fn every_corpus_and_artifact_replays() {
    let fuzz = fuzz_dir();
    for (name, run) in TARGETS {
        let corpus = files(&fuzz.join("corpus").join(name));
        assert!(
            !corpus.is_empty(),
            "{name}: no corpus in fuzz/corpus/{name}"
        );
        for file in corpus
            .iter()
            .chain(&files(&fuzz.join("artifacts").join(name)))
        {
            let bytes = std::fs::read(file).unwrap();
            // The file's name comes first if the target panics on it.
            eprintln!("replaying {}", file.display());
            run(&bytes);
        }
    }
}

/// Every corpus directory belongs to a target (a renamed target leaves no corpus behind that
/// nothing replays).
#[test]
fn every_corpus_has_a_target() {
    for sub in ["corpus", "artifacts"] {
        let Ok(entries) = std::fs::read_dir(fuzz_dir().join(sub)) else {
            continue;
        };
        for entry in entries {
            let name = entry.unwrap().file_name();
            let name = name.to_string_lossy();
            assert!(
                TARGETS.iter().any(|(t, _)| *t == name),
                "fuzz/{sub}/{name} belongs to no target"
            );
        }
    }
}
