//! The `bridge` binary as an operator runs it: `bridge credentials` makes a deployment's
//! credentials once and never overwrites them, and a bridge enabled with the defaults but no
//! credentials refuses to start with the one line that says how to make them (exit status 2,
//! which the launcher does not retry). Being an integration test of this package, it also makes
//! `cargo test` build the `bridge` binary with the rest of the workspace, which the two-host
//! tests start.
// A test stops at its first failure: it may unwrap, expect, panic and index.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![allow(clippy::panic, clippy::indexing_slicing)]

use std::os::unix::fs::PermissionsExt;
use std::process::{Command, Output};

fn bridge(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bridge"))
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn mode(path: &std::path::Path) -> u32 {
    std::fs::metadata(path).unwrap().permissions().mode() & 0o777
}

#[test]
fn credentials_are_made_owner_only_once_and_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("set");
    let out_arg = out.display().to_string();
    let args = [
        "credentials",
        "--out",
        &out_arg,
        "--host",
        "fcc=127.0.0.1",
        "--host",
        "guidance",
    ];
    let made = bridge(&args);
    assert!(made.status.success(), "{}", text(&made));
    for host in ["fcc", "guidance"] {
        let host_dir = out.join(host);
        assert_eq!(mode(&host_dir), 0o700, "{host_dir:?}");
        for file in ["ca.pem", "certificate.pem", "private-key.pem"] {
            assert_eq!(mode(&host_dir.join(file)), 0o600, "{host}/{file}");
        }
    }
    let key = std::fs::read(out.join("fcc/private-key.pem")).unwrap();
    // Made again into the same place: refused, nothing changed.
    let again = bridge(&args);
    assert_eq!(again.status.code(), Some(2), "{}", text(&again));
    assert_eq!(std::fs::read(out.join("fcc/private-key.pem")).unwrap(), key);
}

#[test]
fn an_enabled_bridge_without_credentials_refuses_to_start_saying_how_to_make_them() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("bridge.toml");
    std::fs::write(
        &config,
        "[bridge]\nenabled = true\nlisten = [\"tls/127.0.0.1:0\"]\nout = [\"fcc/guidance/progress\"]\n",
    )
    .unwrap();
    let o = bridge(&["--config", &config.display().to_string()]);
    let said = text(&o);
    assert_eq!(o.status.code(), Some(2), "{said}");
    assert!(said.contains("has no credentials"), "{said}");
    assert!(said.contains("bridge credentials"), "{said}");
}
