//! The ground service (`gcs serve`) as an operator runs it, for the tests of the ground side:
//! the `gcs` binary of this build started on a fleet file, with a socket and a state directory
//! of the test's own, and `gcs` commands run against it as an operator types them.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

use super::binaries::{Build, build_dir, ensure_gcs};
use super::{Rig, eventually};

/// The `gcs` binary of this build.
pub fn gcs_binary() -> PathBuf {
    let dir = build_dir().expect("the build directory");
    ensure_gcs(&dir, Build::IfMissing).unwrap().join("gcs")
}

/// A vehicle of a fleet file: its name and the rig whose FCC it is.
pub struct FleetVehicle<'a> {
    pub name: &'a str,
    pub rig: &'a mut Rig,
}

/// One vehicle of a fleet file: its name, Vehicle ID, where the ground binds its direct and LTE
/// ends, where the FCC receives, and the link key both hold.
pub struct FleetEntry {
    pub name: String,
    pub vehicle_id: u32,
    pub ground: [std::net::SocketAddr; 2],
    pub fcc: [std::net::SocketAddr; 2],
    pub key_file: PathBuf,
}

/// The fleet file of CUCS `cucs` with `entries`, MAVLink system IDs 1, 2, ... in their order,
/// and no separation check (the tests and benches fly the demo missions on every vehicle at
/// once; a test about separation removes the `[fleet]` line).
pub fn fleet_text(cucs: u32, entries: &[FleetEntry]) -> String {
    let mut text = format!("cucs_id = {cucs:#010X}\n\n[fleet]\nseparation_m = 0.0\n");
    for (i, e) in entries.iter().enumerate() {
        text.push_str(&format!(
            "\n[[vehicle]]\nname = \"{}\"\nvehicle_id = {:#010X}\nmavlink_system_id = {}\n\
             direct = {{ ground = \"{}\", fcc = \"{}\" }}\n\
             lte = {{ ground = \"{}\", fcc = \"{}\" }}\nkey_files = [\"{}\"]\n",
            e.name,
            e.vehicle_id,
            i + 1,
            e.ground[0],
            e.fcc[0],
            e.ground[1],
            e.fcc[1],
            e.key_file.display(),
        ));
    }
    text
}

/// The fleet file of `vehicles` ([`fleet_text`]), each rig's FCC with its links learnt
/// (`Rig::learn_links`) and its GCS ends released for the service to bind.
pub fn fleet_file(vehicles: &mut [FleetVehicle<'_>]) -> String {
    let cucs = vehicles.first().map_or(0, |v| v.rig.config.ids.gcs);
    let entries: Vec<FleetEntry> = vehicles
        .iter_mut()
        .map(|v| {
            let ground = v.rig.release_gcs_ends();
            let config = &v.rig.config;
            FleetEntry {
                name: v.name.to_owned(),
                vehicle_id: config.ids.fcc,
                ground,
                fcc: [config.links.fcc_direct, config.links.fcc_lte],
                key_file: v.rig.dir.join("link.key"),
            }
        })
        .collect();
    fleet_text(cucs, &entries)
}

/// A running ground service; stopped with SIGTERM when dropped.
pub struct GroundService {
    child: Child,
    /// Its socket.
    pub socket: PathBuf,
    /// Its state directory.
    pub state_dir: PathBuf,
    fleet: PathBuf,
    log: PathBuf,
    args: Vec<String>,
    /// What it printed as it started: a line for the service, one per vehicle, one for the
    /// MAVLink side if it has one.
    pub banner: Vec<String>,
}

impl GroundService {
    /// Starts `gcs serve ARGS` on the fleet file `fleet` (written to `dir`), its socket, state
    /// and log in `dir`, and waits until it serves.
    pub fn start(dir: &Path, fleet: &str, args: &[&str]) -> Self {
        Self::start_with_state(
            dir,
            fleet,
            &dir.join("ground-state"),
            &dir.join("run").join("gcs.sock"),
            args,
        )
    }

    /// As [`GroundService::start`], with the state directory and the socket given.
    pub fn start_with_state(
        dir: &Path,
        fleet: &str,
        state_dir: &Path,
        socket: &Path,
        args: &[&str],
    ) -> Self {
        let path = dir.join("fleet.toml");
        std::fs::write(&path, fleet).unwrap();
        Self::start_on(
            path,
            socket.to_owned(),
            state_dir.to_owned(),
            dir.join("gcs-serve.log"),
            args.iter().map(|a| (*a).to_owned()).collect(),
        )
    }

    fn start_on(
        fleet: PathBuf,
        socket: PathBuf,
        state_dir: PathBuf,
        log: PathBuf,
        args: Vec<String>,
    ) -> Self {
        let mut child = Command::new(gcs_binary())
            .arg("--fleet")
            .arg(&fleet)
            .arg("--service-socket")
            .arg(&socket)
            .arg("serve")
            // The service ends with whatever started it, even a test or a bench killed.
            .arg("--exit-with-parent")
            .arg("--state-dir")
            .arg(&state_dir)
            .args(&args)
            .env("RUST_LOG", "info")
            .stdout(Stdio::piped())
            .stderr(std::fs::File::create(&log).unwrap())
            .spawn()
            .unwrap();
        // Serving once it said so: every vehicle's links bound, the socket listening.
        let stdout = child.stdout.take().unwrap();
        let mut lines = BufReader::new(stdout).lines();
        let mut next = || lines.next().and_then(Result::ok).unwrap_or_default();
        let first = next();
        let vehicles: usize = first
            .strip_prefix("ground service for ")
            .and_then(|rest| rest.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| {
                panic!(
                    "gcs serve did not start: {first:?}\n{}",
                    std::fs::read_to_string(&log).unwrap_or_default()
                )
            });
        let mut banner = vec![first];
        let more = vehicles + usize::from(args.iter().any(|a| a == "--mavlink"));
        banner.extend((0..more).map(|_| next()));
        // The rest of its output is not read: drained, so that it never blocks on a full pipe.
        std::thread::spawn(move || lines.for_each(drop));
        Self {
            child,
            socket,
            state_dir,
            fleet,
            log,
            args,
            banner,
        }
    }

    /// The port of its MAVLink side, from its banner.
    pub fn mavlink_port(&self) -> Option<u16> {
        self.banner.iter().find_map(|l| {
            let addr = l.strip_prefix("MAVLink vehicles on ")?.split(',').next()?;
            addr.parse::<std::net::SocketAddr>().ok().map(|a| a.port())
        })
    }

    /// `gcs ARGS` against the service, as an operator types it, to run to its end with
    /// [`GroundService::gcs`] or to start and watch (its output piped).
    pub fn gcs_command(&self, args: &[&str]) -> Command {
        let mut command = Command::new(gcs_binary());
        command
            .args(args)
            .env("MISSIONLINK_GCS_SOCKET", &self.socket)
            .env("XDG_STATE_HOME", self.state_dir.join("client"))
            .env_remove("MISSIONLINK_FLEET")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        command
    }

    /// `gcs ARGS` run against the service to its end, as an operator runs it.
    pub fn gcs(&self, args: &[&str]) -> Output {
        self.gcs_command(args).output().unwrap()
    }

    /// Kills the service as a crash would (its socket file stays behind).
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// Starts the service again as it was (same fleet, socket and state directory).
    pub fn restart(&mut self) {
        self.stop();
        let next = Self::start_on(
            self.fleet.clone(),
            self.socket.clone(),
            self.state_dir.clone(),
            self.log.with_extension("2.log"),
            self.args.clone(),
        );
        *self = next;
    }

    /// Its process ID.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Its log (stderr).
    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }

    fn stop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let pid = rustix::process::Pid::from_raw(self.child.id() as i32);
            if let Some(pid) = pid {
                let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
            }
            let stopped = eventually(Duration::from_secs(5), || {
                self.child.try_wait().ok().flatten()
            });
            if stopped.is_none() {
                let _ = self.child.kill();
                let _ = self.child.wait();
            }
        }
    }
}

impl Drop for GroundService {
    fn drop(&mut self) {
        self.stop();
    }
}
