//! Running the real `gcs` binary in the tests: arguments and stdin in, exit status and output
//! out; and the paths and text the tests of the `gcs` tool share.

use std::io::Write;
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// `gcs` with `args`, run to its end (stdin empty).
pub fn gcs(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gcs"))
        .args(args)
        .env("RUST_LOG", "warn")
        .stdin(Stdio::null())
        .output()
        .expect("gcs runs")
}

/// Output bytes as text.
pub fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Standard output and standard error as one text.
pub fn text_of(o: &Output) -> String {
    format!("{}{}", text(&o.stdout), text(&o.stderr))
}

/// The repository's top directory.
pub fn repo_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A path of the repository, from its top.
pub fn repo(path: &str) -> String {
    repo_dir().join(path).display().to_string()
}

/// A directory of the test's own, named after the test (and unique to this process and run),
/// removed when dropped: tests run in parallel, so no two may share a file name.
pub fn scratch(test: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gcs-{test}-{}-", std::process::id()))
        .tempdir()
        .expect("a temporary directory")
}

/// Two sockets standing in for the FCC's links, for the commands that must send nothing.
pub struct SilentFcc {
    direct: UdpSocket,
    lte: UdpSocket,
    /// The link key the ground signs with (ICD §9: signing is required by default).
    key: tempfile::TempDir,
}

impl SilentFcc {
    /// Binds both on loopback, ports the system chooses, and makes a link key.
    pub fn bind() -> Self {
        let key = scratch("silent-fcc-key");
        let made = gcs(&[
            "keygen",
            "--fcc",
            &key.path().join("link.key").display().to_string(),
            "--ground",
            &key.path().join("link.key").display().to_string(),
        ]);
        assert!(made.status.success(), "{}", text_of(&made));
        Self {
            direct: UdpSocket::bind("127.0.0.1:0").expect("direct bound"),
            lte: UdpSocket::bind("127.0.0.1:0").expect("LTE bound"),
            key,
        }
    }

    /// The `gcs` flags that point both links at these sockets (the GCS's own ends: port 0),
    /// with the link key.
    pub fn args(&self) -> Vec<String> {
        let addr = |s: &UdpSocket| s.local_addr().expect("bound").to_string();
        vec![
            "--key-file".to_owned(),
            self.key.path().join("link.key").display().to_string(),
            "--fcc-direct".to_owned(),
            addr(&self.direct),
            "--fcc-lte".to_owned(),
            addr(&self.lte),
            "--gcs-direct".to_owned(),
            "127.0.0.1:0".to_owned(),
            "--gcs-lte".to_owned(),
            "127.0.0.1:0".to_owned(),
        ]
    }

    /// Fails the test if a datagram arrived on either socket (waiting 200 ms on each).
    pub fn assert_nothing_sent(&self) {
        for s in [&self.direct, &self.lte] {
            s.set_read_timeout(Some(Duration::from_millis(200)))
                .expect("timeout set");
            let mut buf = [0u8; 600];
            assert!(s.recv_from(&mut buf).is_err(), "a frame was sent");
        }
    }
}

/// `gcs` with `args`, `stdin` written to it, run to its end.
pub fn gcs_with_input(args: &[&str], stdin: &str) -> Output {
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
