//! Running the real `gcs` binary in the tests: arguments and stdin in, exit status and output
//! out.

use std::io::Write;
use std::process::{Command, Output, Stdio};

/// `gcs` with `args`, `stdin` written to it, run to its end.
pub fn gcs(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_gcs"))
        .args(args)
        .env("RUST_LOG", "warn")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("gcs starts");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(stdin.as_bytes())
        .expect("stdin written");
    child.wait_with_output().expect("gcs ends")
}
