//! Where the partition binaries are, for the demo and the cross-process tests and benches.
//! `cargo run --bin demo` builds only the demo; on a fresh clone the partitions it starts are not
//! built yet, so this builds them with the cargo that built the caller (same profile). Harness
//! code: no product crate runs cargo.

use std::path::{Path, PathBuf};
use std::process::Command;

use missionlink_interfaces::contracts::Partition;
use missionlink_partitions::{bridge_config, launcher};

/// The workspace's root package (the demo, the cross-process tests and benches).
const ROOT_PACKAGE: &str = "missionlink";

/// The binaries the FCC needs: the launcher and the partitions it starts
/// (`Partition::ALL`, by `Partition::binary`).
pub const FCC_BINARIES: [&str; 5] = {
    let [a, b, c, d] = Partition::ALL;
    [
        launcher::NAME,
        a.binary(),
        b.binary(),
        c.binary(),
        d.binary(),
    ]
};

/// The directory of the binaries of this build: the caller's own directory, or for a test
/// binary (in `deps/`) the one above it.
pub fn build_dir() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let dir = exe.parent()?;
    if dir.file_name().is_some_and(|n| n == "deps") {
        dir.parent().map(Path::to_path_buf)
    } else {
        Some(dir.to_path_buf())
    }
}

/// Which of `names` are not in `dir` (what [`ensure`] would build).
pub fn missing(dir: &Path, names: &[&str]) -> Vec<String> {
    names
        .iter()
        .filter(|n| !dir.join(n).is_file())
        .map(|n| (*n).to_owned())
        .collect()
}

/// When [`ensure`] runs cargo.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Build {
    /// Only when a binary is missing (the tests: `cargo test` builds the workspace's binaries
    /// before it runs them, or CI builds them first).
    IfMissing,
    /// Always, when the caller was started by cargo (`cargo run`): a binary built before the
    /// last change of the sources would otherwise be started as it is, an FCC older than the
    /// GCS that talks to it. Cargo does nothing when they are up to date.
    UnderCargo,
}

/// `dir` holding every one of `names`, built with cargo first if some are missing (or, with
/// [`Build::UnderCargo`], to bring them up to date).
pub fn ensure(dir: &Path, names: &[&str], build: Build) -> Result<PathBuf, String> {
    ensure_of(dir, names, "missionlink-partitions", build)
}

/// `dir` holding the bridge binary ([`bridge_config::BINARY`]), built with cargo first
/// as [`ensure`] does. It is a package of its own (`missionlink-bridge`, with Zenoh), which
/// nothing else depends on: only a configuration with `[bridge]` or a test that uses it builds
/// it, never the demo.
pub fn ensure_bridge(dir: &Path, build: Build) -> Result<PathBuf, String> {
    ensure_of(dir, &[bridge_config::BINARY], "missionlink-bridge", build)
}

/// `dir` holding the ground tool `gcs`, built with cargo first as [`ensure`] does (the ground
/// service's tests run it as an operator does).
pub fn ensure_gcs(dir: &Path, build: Build) -> Result<PathBuf, String> {
    ensure_of(dir, &["gcs"], "missionlink-gcs", build)
}

fn ensure_of(dir: &Path, names: &[&str], package: &str, build: Build) -> Result<PathBuf, String> {
    let absent = missing(dir, names);
    let under_cargo = build == Build::UnderCargo && std::env::var_os("CARGO").is_some();
    if absent.is_empty() && !under_cargo {
        return Ok(dir.to_path_buf());
    }
    // The cargo and the workspace that built this binary.
    let cargo = std::env::var("CARGO")
        .ok()
        .or_else(|| option_env!("CARGO").map(str::to_owned))
        .unwrap_or_else(|| "cargo".to_owned());
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    if !absent.is_empty() {
        tracing::info!(binaries = %absent.join(", "), "building the missing binaries");
    }
    let mut command = Command::new(cargo);
    // With the workspace's root package beside it: cargo resolves the features of the shared
    // dependencies (iceoryx2 and the rest) over the packages it builds, and the callers (the
    // demo, the tests) were built with the root's resolution. The package alone would resolve
    // them otherwise and compile every shared dependency a second time.
    command
        .args(["build", "-q", "-p", package, "-p", ROOT_PACKAGE, "--bins"])
        .arg("--manifest-path")
        .arg(&manifest);
    if !cfg!(debug_assertions) {
        command.arg("--release");
    }
    let status = command
        .status()
        .map_err(|e| format!("cannot run cargo to build {}: {e}", names.join(", ")))?;
    let still = missing(dir, names);
    if !status.success() || !still.is_empty() {
        return Err(format!(
            "{} missing in {} (cargo build: {status})",
            still.join(", "),
            dir.display()
        ));
    }
    Ok(dir.to_path_buf())
}

/// The libraries the Rust standard library inside the C library's static library needs from the
/// system, to link a C program with it
/// (`cargo rustc -p missionlink-c --crate-type staticlib -- --print native-static-libs`).
pub const C_NATIVE_LIBS: [&str; 7] = [
    "-lgcc_s",
    "-lutil",
    "-lrt",
    "-lpthread",
    "-lm",
    "-ldl",
    "-lc",
];

/// `libmissionlink_c.a` of this build (the test's or bench's profile and features): the root
/// package's dev-dependency on the C library (`clib/`) makes cargo build it before any test or
/// bench runs, so none builds it while others run.
pub fn c_static_library() -> Result<PathBuf, String> {
    let dir = build_dir().ok_or("cannot find the build directory")?;
    let library = dir.join("deps/libmissionlink_c.a");
    if library.is_file() {
        Ok(library)
    } else {
        Err(format!(
            "{} missing: the tests' and benches' build makes it (missionlink-c, a \
             dev-dependency of the root package)",
            library.display()
        ))
    }
}
