//! Running the real binaries: an FCC (the launcher and its partitions) under a prefix, ports
//! and state directory of its own, so tests run in parallel; and the GCS over UDP in the test.
#![allow(dead_code)]

use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use missionlink_gcs::gcs_link::GcsLink;
use missionlink_gcs::mission_file::MissionFile;
use missionlink_partitions::binaries;
use missionlink_partitions::config::Config;
use missionlink_partitions::latency::Summary;
use missionlink_services::ground_station::{GcsError, MissionPlan, ValidatedPlan, WithoutGateway};

pub type Link = GcsLink<WithoutGateway>;
pub type Error = GcsError<core::convert::Infallible>;

/// The directory of the partition binaries, built if missing.
pub fn bin_dir() -> PathBuf {
    let dir = binaries::build_dir().expect("build directory");
    binaries::ensure(&dir, &binaries::FCC_BINARIES).expect("partition binaries")
}

fn free_ports() -> [SocketAddr; 4] {
    let sockets: Vec<UdpSocket> = (0..4)
        .map(|_| UdpSocket::bind("127.0.0.1:0").unwrap())
        .collect();
    let a: Vec<SocketAddr> = sockets.iter().map(|s| s.local_addr().unwrap()).collect();
    [a[0], a[1], a[2], a[3]]
}

/// A configuration no other test shares: prefix, ports, state and summary directories.
pub fn unique_config(test: &str) -> (Config, PathBuf) {
    let dir = std::env::temp_dir().join(format!("missionlink-test-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let [fcc_direct, gcs_direct, fcc_lte, gcs_lte] = free_ports();
    let mut c = Config::default();
    c.ipc.service_prefix = format!("test-{test}-{}", std::process::id());
    c.ipc.state_dir = Some(dir.join("state"));
    c.links.fcc_direct = fcc_direct;
    c.links.gcs_direct = gcs_direct;
    c.links.fcc_lte = fcc_lte;
    c.links.gcs_lte = gcs_lte;
    c.guidance.time_scale = 50.0;
    c.latency.summary_dir = Some(dir.join("latency"));
    c.launcher.restart_delay_ms = 100;
    std::fs::write(dir.join("fcc.toml"), c.to_toml()).unwrap();
    (c, dir)
}

/// A process of ours, stopped with SIGTERM when dropped.
pub struct Process {
    pub child: Child,
    pub log: PathBuf,
}

impl Process {
    /// Starts `binary --config <dir>/fcc.toml`, stderr into `<dir>/<binary>.log`.
    pub fn start(dir: &Path, binary: &str) -> Self {
        let log = dir.join(format!("{binary}.log"));
        let child = Command::new(bin_dir().join(binary))
            .args(["--config", &dir.join("fcc.toml").display().to_string()])
            .env("RUST_LOG", "info")
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .unwrap();
        Self { child, log }
    }

    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    pub fn stop(&mut self) {
        if let Some(pid) = rustix::process::Pid::from_raw(self.child.id() as i32) {
            let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
        }
        let _ = self.child.wait();
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            self.stop();
        }
    }
}

/// Waits until `log` says `text`, or panics after `limit`.
pub fn wait_for_log(process: &Process, text: &str, limit: Duration) {
    let end = Instant::now() + limit;
    while Instant::now() < end {
        if process.log_text().contains(text) {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    panic!(
        "{} never logged {text:?}:\n{}",
        process.log.display(),
        process.log_text()
    );
}

pub fn gcs(config: &Config) -> Link {
    GcsLink::open(config, WithoutGateway).unwrap()
}

pub fn plan(file: &str) -> MissionPlan {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("missions")
        .join(file);
    MissionFile::read(&path).unwrap().to_plan().unwrap()
}

/// Runs the link until the request ends.
pub fn finish(link: &mut Link) -> Result<Option<ValidatedPlan>, Error> {
    link.finish(|_| {})
}

pub fn upload(link: &mut Link, plan: &MissionPlan) -> Result<(), Error> {
    let now = link.now();
    link.station().upload(now, plan, true)?;
    finish(link).map(|_| ())
}

pub fn download(link: &mut Link) -> Result<ValidatedPlan, Error> {
    let now = link.now();
    link.station().download(now)?;
    finish(link).map(|p| p.expect("lists"))
}

/// The summaries the partitions wrote at shutdown.
pub fn summaries(dir: &Path) -> Vec<Summary> {
    missionlink_partitions::latency::read_summaries(&dir.join("latency"))
}
