//! A test-only partition for tests/system/isolation.rs, never deployed: it fences itself exactly as
//! the partition named by `MISSIONLINK_PROBE_AS` (default guidance-stub) does under the
//! configuration handed to it (`MISSIONLINK_CONFIG_TOML`, as the launcher hands it to every
//! partition), then tries one thing that partition must never do, named by
//! `MISSIONLINK_PROBE_TRY`:
//!
//! - `inet`: open a UDP socket (only voting-monitoring may);
//! - `write`: create a file in `MISSIONLINK_PROBE_OUTSIDE`, a directory outside its own;
//! - `exec`: run `/bin/true`;
//! - `whoami`: print the user and group it runs as (after `[isolation.<partition>] user`).
//!
//! It prints what the kernel answered (`refused: ...` or `allowed`) and exits 0 when refused,
//! 3 when allowed; a call the seccomp filter forbids kills it with SIGSYS before it can print.
//! Started by the launcher in place of a partition (the test's bin directory), it shows that
//! the launcher names the partition the kernel killed.
// A test helper: it stops at its first failure.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::process::ExitCode;

use missionlink_partitions::config::{Config, FccArgs};
use missionlink_partitions::isolation::fence_of;

fn main() -> ExitCode {
    missionlink_platform::init_logging();
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    let args = FccArgs {
        link: missionlink_platform::config::LinkArgs {
            config_toml: std::env::var("MISSIONLINK_CONFIG_TOML").ok(),
            ..Default::default()
        },
        ..FccArgs::default()
    };
    let config = Config::resolve(&args).expect("configuration");
    let role = std::env::var("MISSIONLINK_PROBE_AS").unwrap_or_else(|_| "guidance-stub".into());
    let attempt = std::env::var("MISSIONLINK_PROBE_TRY").expect("MISSIONLINK_PROBE_TRY");
    let partition = missionlink_interfaces::contracts::Partition::from_binary(&role)
        .unwrap_or_else(|| panic!("no partition {role:?}"));
    let fence = fence_of(partition, &config).expect("isolation is on");
    fence.apply().expect("fenced");
    println!("fenced as {role}");
    let answer = match attempt.as_str() {
        "inet" => std::net::UdpSocket::bind("127.0.0.1:0").map(drop),
        "write" => {
            let outside = std::env::var("MISSIONLINK_PROBE_OUTSIDE").expect("outside dir");
            std::fs::write(std::path::Path::new(&outside).join("written"), b"x")
        }
        "exec" => std::process::Command::new("/bin/true").status().map(drop),
        "whoami" => {
            let (uid, gid) = (rustix::process::geteuid(), rustix::process::getegid());
            println!("uid={} gid={}", uid.as_raw(), gid.as_raw());
            return ExitCode::SUCCESS;
        }
        other => panic!("nothing to try called {other:?}"),
    };
    match answer {
        Ok(()) => {
            println!("{attempt}: allowed");
            ExitCode::from(3)
        }
        Err(e) => {
            println!("{attempt}: refused: {e}");
            ExitCode::SUCCESS
        }
    }
}
