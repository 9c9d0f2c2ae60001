//! The ground service's loop: a thread per vehicle that owns its links and its ground station
//! (nothing shared between vehicles but the acceptor), and the acceptor that hands each client's
//! call to its vehicle's thread. A request for one vehicle never waits on another's; two for one
//! vehicle go one after the other, as its ground station runs one at a time.
//!
//! Each vehicle's thread pumps its links all the time, so what the FCC sends while no command
//! runs is heard: the last position and FROM-TO-NEXT are there for a monitor that starts, and
//! the status ([`super::status`]) is always current. What must outlive the service (the lists
//! this ground uploaded last, the time stamps it used) is kept per vehicle in the state
//! directory.

use std::io::{BufRead, BufReader, Write};
use std::net::SocketAddr;
use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use missionlink_ground::ground_station::GcsEvent;
use missionlink_ground::safety_gateway::SafetyGateway;
use missionlink_interfaces::wire::{Checksum, Message};
use missionlink_platform::udp::LinkPair;
use missionlink_protocol::transfer::integrity;

use super::client::{Call, Reply, What};
use super::fleet::{Fleet, Vehicle};
use super::request::{self, Answer, Event, Failure, Link, Request};
use super::status::{Snapshot, VehicleStatus};
use crate::gcs_link::GcsLink;
use crate::mission_file::MissionFile;
use crate::pcap::PcapWriter;

/// How the service runs.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The socket the clients connect to.
    pub socket: PathBuf,
    /// The state directory: per vehicle `vehicles/<name>/`.
    pub state_dir: Option<PathBuf>,
    /// Every datagram of every link into this capture, if given.
    pub capture: Option<Arc<PcapWriter>>,
}

/// A vehicle's links as bound.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bound {
    /// Its name.
    pub name: String,
    /// Its Vehicle ID.
    pub vehicle_id: u32,
    /// Where the ground receives its direct link.
    pub direct: SocketAddr,
    /// Where the ground receives its LTE link.
    pub lte: SocketAddr,
}

/// Why the service cannot start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// Another service answers on the socket.
    #[error("a ground service already runs on {}", .0.display())]
    AlreadyRunning(PathBuf),
    /// The socket or its directory cannot be made.
    #[error("the socket {}: {error}", path.display())]
    Socket {
        /// The socket.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// The state directory cannot be made.
    #[error("the state directory {}: {error}", path.display())]
    StateDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// A vehicle's links cannot be opened (a port in use, an unusable key).
    #[error("vehicle {name:?}: {error}")]
    Links {
        /// The vehicle.
        name: String,
        /// Why.
        error: String,
    },
}

/// The stack of a vehicle's thread: requests hold plans and lists inline (tens of KB each, and
/// a debug build copies them into every frame), as the gcs command's thread does.
const VEHICLE_STACK: usize = 64 << 20;
/// How long a vehicle's thread waits on its links between looks at its queue of calls.
const PUMP: Duration = Duration::from_millis(20);
/// How long a write to a client may block the vehicle's thread: a monitor that stopped reading
/// is dropped, not waited for.
const CLIENT_WRITE: Duration = Duration::from_millis(200);
/// How long a client may take to send its call.
const CLIENT_CALL: Duration = Duration::from_secs(5);

/// Runs the service for `fleet` until `stop` is set: binds every vehicle's links and the
/// socket, calls `ready` with the bound links, serves, and on stop removes the socket.
pub fn serve(
    fleet: &Fleet,
    options: &ServeOptions,
    stop: &Arc<AtomicBool>,
    ready: impl FnOnce(&[Bound]),
) -> Result<(), ServeError> {
    if let Some(dir) = &options.state_dir
        && let Err(error) = std::fs::create_dir_all(dir)
    {
        return Err(ServeError::StateDir {
            path: dir.clone(),
            error,
        });
    }
    let listener = bind_socket(&options.socket)?;
    let mut links = Vec::with_capacity(fleet.vehicles.len());
    for vehicle in &fleet.vehicles {
        let link = open_link(vehicle, options).map_err(|error| {
            let _ = std::fs::remove_file(&options.socket);
            ServeError::Links {
                name: vehicle.name.clone(),
                error,
            }
        })?;
        links.push(link);
    }
    let mut bound = Vec::new();
    let mut routes = Vec::new();
    let mut threads = Vec::new();
    for (vehicle, link) in fleet.vehicles.iter().zip(links) {
        let [direct, lte] = link.local_addrs();
        bound.push(Bound {
            name: vehicle.name.clone(),
            vehicle_id: vehicle.link.ids.fcc,
            direct,
            lte,
        });
        let (jobs, queue) = channel();
        let shared = Arc::new(Mutex::new(Snapshot::default()));
        let dir = vehicle_dir(options, &vehicle.name);
        let mut worker = Worker {
            link,
            queue,
            shared: shared.clone(),
            state: VehicleState {
                snapshot: Snapshot {
                    planned: dir.as_deref().and_then(read_planned),
                    ..Snapshot::default()
                },
                monitors: Vec::new(),
            },
            dir,
        };
        let stop = stop.clone();
        let thread = std::thread::Builder::new()
            .name(format!("vehicle {}", vehicle.name))
            .stack_size(VEHICLE_STACK)
            .spawn(move || worker.run(&stop))
            .map_err(|e| ServeError::Links {
                name: vehicle.name.clone(),
                error: e.to_string(),
            })?;
        threads.push(thread);
        routes.push(Route {
            name: vehicle.name.clone(),
            vehicle_id: vehicle.link.ids.fcc,
            jobs,
            shared,
        });
    }
    ready(&bound);
    let routes = Arc::new(Routes {
        fleet: fleet.clone(),
        routes,
    });
    accept(&listener, &routes, stop);
    for thread in threads {
        let _ = thread.join();
    }
    let _ = std::fs::remove_file(&options.socket);
    Ok(())
}

/// Makes the socket's directory (mode 0700 when made here) and binds the socket (mode 0600),
/// replacing a socket file nobody answers on.
fn bind_socket(path: &Path) -> Result<UnixListener, ServeError> {
    let error = |error| ServeError::Socket {
        path: path.to_owned(),
        error,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(dir)
            .map_err(error)?;
    }
    if std::fs::symlink_metadata(path).is_ok() {
        if UnixStream::connect(path).is_ok() {
            return Err(ServeError::AlreadyRunning(path.to_owned()));
        }
        std::fs::remove_file(path).map_err(error)?;
    }
    let listener = UnixListener::bind(path).map_err(error)?;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o600)).map_err(error)?;
    listener.set_nonblocking(true).map_err(error)?;
    Ok(listener)
}

/// `vehicles/<name>` in the state directory, made if missing; `None` without a state directory.
fn vehicle_dir(options: &ServeOptions, name: &str) -> Option<PathBuf> {
    let dir = options.state_dir.as_ref()?.join("vehicles").join(name);
    match std::fs::create_dir_all(&dir) {
        Ok(()) => Some(dir),
        Err(e) => {
            tracing::warn!(dir = %dir.display(), %e, "no state directory for the vehicle: its state will not outlive the service");
            None
        }
    }
}

/// The vehicle's links, capturing if asked, their time stamps reserved in the state directory
/// (shared with `gcs` commands that run alone for this vehicle).
fn open_link(vehicle: &Vehicle, options: &ServeOptions) -> Result<Link, String> {
    let config = &vehicle.link;
    let links = LinkPair::bind(
        config.links.gcs_direct,
        config.links.gcs_lte,
        config.links.fcc_direct,
        config.links.fcc_lte,
    )
    .map_err(|e| e.to_string())?;
    let links = match &options.capture {
        Some(capture) => links.with_tap(capture.clone()).map_err(|e| e.to_string())?,
        None => links,
    };
    let link =
        GcsLink::with_links(config, links, SafetyGateway::default()).map_err(|e| e.to_string())?;
    match &options.state_dir {
        Some(dir) => link
            .with_stamp_lease(&super::stamp_lease(dir, config.ids.fcc))
            .map_err(|e| e.to_string()),
        None => Ok(link),
    }
}

/// A vehicle as the acceptor reaches it.
struct Route {
    name: String,
    vehicle_id: u32,
    jobs: Sender<Job>,
    shared: Arc<Mutex<Snapshot>>,
}

struct Routes {
    fleet: Fleet,
    routes: Vec<Route>,
}

/// A call handed to a vehicle's thread, with the client to answer.
enum Job {
    Request(Request, UnixStream),
    Monitor(UnixStream),
}

/// Accepts clients until `stop`; each call is read on a thread of its own, so a slow client
/// holds up no other.
fn accept(listener: &UnixListener, routes: &Arc<Routes>, stop: &AtomicBool) {
    let me = rustix::process::geteuid();
    while !stop.load(Ordering::Relaxed) {
        let mut fds = [rustix::event::PollFd::new(
            listener,
            rustix::event::PollFlags::IN,
        )];
        let timeout = rustix::time::Timespec {
            tv_sec: 0,
            tv_nsec: 200_000_000,
        };
        if let Err(e) = rustix::event::poll(&mut fds, Some(&timeout))
            && e != rustix::io::Errno::INTR
        {
            tracing::warn!(%e, "poll of the service socket failed");
        }
        loop {
            match listener.accept() {
                Ok((stream, _)) => {
                    // Only this user's processes reach the socket (its directory is 0700); the
                    // credentials are checked all the same.
                    match rustix::net::sockopt::socket_peercred(&stream) {
                        Ok(cred) if cred.uid == me => {}
                        _ => continue,
                    }
                    let routes = routes.clone();
                    let spawned = std::thread::Builder::new()
                        .name("gcs client".to_owned())
                        .spawn(move || route(stream, &routes));
                    if let Err(e) = spawned {
                        tracing::warn!(%e, "cannot serve a client");
                    }
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break,
                Err(e) => {
                    tracing::warn!(%e, "accept failed");
                    break;
                }
            }
        }
    }
}

/// Writes one reply line; whether the client took it.
fn send(stream: &mut UnixStream, reply: &Reply) -> bool {
    let Ok(mut line) = serde_json::to_string(reply) else {
        return false;
    };
    line.push('\n');
    stream.write_all(line.as_bytes()).is_ok()
}

/// Reads a client's call and hands it to its vehicle (a status is answered here, from every
/// vehicle's snapshot, without waiting on any vehicle's thread).
fn route(stream: UnixStream, routes: &Routes) {
    let _ = stream.set_read_timeout(Some(CLIENT_CALL));
    let _ = stream.set_write_timeout(Some(CLIENT_WRITE));
    let mut line = String::new();
    let Ok(mut reply_to) = stream.try_clone() else {
        return;
    };
    if BufReader::new(stream).read_line(&mut line).is_err() {
        return;
    }
    let call: Call = match serde_json::from_str(&line) {
        Ok(call) => call,
        Err(e) => {
            send(
                &mut reply_to,
                &Reply::Failed(Failure::input(format!(
                    "a call the service cannot read: {e}"
                ))),
            );
            return;
        }
    };
    if call.what == What::Status {
        let now = Instant::now();
        let rows: Vec<VehicleStatus> = routes
            .routes
            .iter()
            .map(|r| {
                let snapshot = r.shared.lock().map(|s| s.clone()).unwrap_or_default();
                snapshot.status(&r.name, r.vehicle_id, now)
            })
            .collect();
        send(&mut reply_to, &Reply::Status(rows));
        return;
    }
    let vehicle = match routes.fleet.vehicle(call.vehicle.as_deref()) {
        Ok(v) => v.name.clone(),
        Err(e) => {
            send(&mut reply_to, &Reply::Failed(Failure::input(e.to_string())));
            return;
        }
    };
    let Some(route) = routes.routes.iter().find(|r| r.name == vehicle) else {
        return;
    };
    let job = match call.what {
        What::Request(request) => Job::Request(request, reply_to),
        What::Monitor => Job::Monitor(reply_to),
        What::Status => return,
    };
    if let Err(unsent) = route.jobs.send(job) {
        let (Job::Request(_, mut stream) | Job::Monitor(mut stream)) = unsent.0;
        send(
            &mut stream,
            &Reply::Failed(Failure::other("the service is stopping")),
        );
    }
}

/// What a vehicle's thread keeps beside its link.
struct VehicleState {
    snapshot: Snapshot,
    /// The clients monitoring the vehicle.
    monitors: Vec<UnixStream>,
}

impl VehicleState {
    /// An event of the GCS logic heard while no request or a request runs: the downlink's
    /// reports go to the snapshot and to every monitor.
    fn heard(&mut self, event: &Event) {
        let message = match event {
            GcsEvent::Position(p) => {
                self.snapshot.position = Some((*p, Instant::now()));
                Message::from(*p)
            }
            GcsEvent::FromToNext(f) => {
                self.snapshot.from_to_next = Some(*f);
                Message::from(*f)
            }
            _ => return,
        };
        let reply = Reply::Event(Box::new(message));
        self.monitors.retain_mut(|m| send(m, &reply));
    }
}

struct Worker {
    link: Link,
    queue: Receiver<Job>,
    shared: Arc<Mutex<Snapshot>>,
    state: VehicleState,
    dir: Option<PathBuf>,
}

impl Worker {
    fn run(&mut self, stop: &AtomicBool) {
        self.refresh_report();
        while !stop.load(Ordering::Relaxed) {
            self.link.pump(PUMP);
            while let Some(event) = self.link.station().poll_event() {
                self.state.heard(&event);
            }
            while let Ok(job) = self.queue.try_recv() {
                match job {
                    Job::Request(request, stream) => self.request(request, stream),
                    Job::Monitor(stream) => self.monitor(stream),
                }
            }
            self.publish();
        }
    }

    /// Hands the current state to the acceptor's status.
    fn publish(&mut self) {
        let s = &mut self.state.snapshot;
        s.links = self.link.activity();
        let stats = self.link.voter().stats();
        s.messages = stats.forwarded.iter().sum();
        if let Ok(mut shared) = self.shared.lock() {
            shared.clone_from(s);
        }
    }

    fn monitor(&mut self, mut stream: UnixStream) {
        let s = &self.state.snapshot;
        let now: Vec<Message> = s
            .from_to_next
            .map(Message::from)
            .into_iter()
            .chain(s.position.map(|(p, _)| Message::from(p)))
            .collect();
        if now
            .into_iter()
            .all(|m| send(&mut stream, &Reply::Event(Box::new(m))))
        {
            self.state.monitors.push(stream);
        }
    }

    fn request(&mut self, request: Request, mut stream: UnixStream) {
        let planned = match &request {
            Request::Upload(u) if u.stage.is_none() => checksums(&u.mission),
            _ => None,
        };
        let changes = !matches!(request, Request::Report | Request::Download { .. });
        let name = request_name(&request);
        self.state.snapshot.busy = Some(name.to_owned());
        self.publish();
        let Self { link, state, .. } = self;
        let mut progress = |p| {
            let _ = send(&mut stream, &Reply::Progress(p));
        };
        let outcome = request::carry_out(link, request, &mut progress, &mut |e| state.heard(e));
        if let Ok(Answer::Reported { entries }) = &outcome {
            self.state.snapshot.report = Some(reports(entries));
            self.state.snapshot.report_failed = None;
        }
        if let (Ok(Answer::Uploaded { .. }), Some(planned)) = (&outcome, planned) {
            self.state.snapshot.planned = Some(planned);
            if let Some(dir) = &self.dir {
                write_planned(dir, planned);
            }
        }
        let reply = match outcome {
            Ok(answer) => Reply::Finished(answer),
            Err(failure) => Reply::Failed(failure),
        };
        // The client may have gone: the request ran to its end all the same.
        let _ = send(&mut stream, &reply);
        drop(stream);
        if changes {
            self.refresh_report();
        }
        self.state.snapshot.busy = None;
        self.publish();
    }

    /// Asks the FCC for its report (ICD §8) for the status.
    fn refresh_report(&mut self) {
        let Self { link, state, .. } = self;
        let outcome =
            request::carry_out(link, Request::Report, &mut |_| {}, &mut |e| state.heard(e));
        match outcome {
            Ok(Answer::Reported { entries }) => {
                state.snapshot.report = Some(reports(&entries));
                state.snapshot.report_failed = None;
            }
            Ok(_) => {}
            Err(f) => {
                state.snapshot.report = None;
                state.snapshot.report_failed =
                    Some(f.message.lines().next().unwrap_or_default().to_owned());
            }
        }
    }
}

fn reports(entries: &[Message]) -> Vec<missionlink_interfaces::wire::MissionReport> {
    entries
        .iter()
        .filter_map(|m| match m {
            Message::MissionReport(r) => Some(*r),
            _ => None,
        })
        .collect()
}

/// What the request is, for the status.
fn request_name(request: &Request) -> &'static str {
    match request {
        Request::Upload(u) if u.stage.is_some() => "stage",
        Request::Upload(_) => "upload",
        Request::Activate { .. } => "activate",
        Request::Delete { .. } => "delete",
        Request::Download { .. } => "download",
        Request::Report => "report",
        Request::ClearMission => "clear",
        Request::ClearAreas => "clear areas",
        Request::Execute { .. } => "execute",
    }
}

/// The checksums (ICD §11) of the lists of a mission file.
fn checksums(mission: &str) -> Option<(Checksum, Checksum)> {
    let plan = MissionFile::parse(mission)
        .ok()?
        .to_plan()
        .ok()?
        .assemble()
        .ok()?;
    Some((
        integrity::mission_checksum(&plan.mission),
        integrity::areas_checksum(&plan.areas),
    ))
}

const PLANNED: &str = "planned";

/// The lists this ground uploaded last to the vehicle, as written by [`write_planned`].
fn read_planned(dir: &Path) -> Option<(Checksum, Checksum)> {
    let text = std::fs::read_to_string(dir.join(PLANNED)).ok()?;
    let mut words = text.split_whitespace();
    let mut next = || -> Option<Checksum> {
        let word = words.next()?;
        u32::from_str_radix(word.trim_start_matches("0x"), 16)
            .ok()
            .map(Checksum::new)
    };
    Some((next()?, next()?))
}

fn write_planned(dir: &Path, (mission, areas): (Checksum, Checksum)) {
    let path = dir.join(PLANNED);
    let tmp = path.with_extension("tmp");
    let written = std::fs::write(
        &tmp,
        format!("{:#010x} {:#010x}\n", mission.value(), areas.value()),
    )
    .and_then(|()| std::fs::rename(&tmp, &path));
    if let Err(e) = written {
        tracing::warn!(path = %path.display(), %e, "the lists uploaded last are not kept");
    }
}
