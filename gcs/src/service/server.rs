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

use std::collections::{HashMap, VecDeque};
use std::io::{BufRead, BufReader, Write};
use std::net::SocketAddr;
use std::os::fd::{AsFd, OwnedFd};
use std::os::unix::fs::{DirBuilderExt, PermissionsExt};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use missionlink_ground::ground_station::{GcsEvent, GroundStation, ValidatedPlan};
use missionlink_ground::safety_gateway::SafetyGateway;
use missionlink_interfaces::wire::{Checksum, GeoPoint, Message};
use missionlink_platform::udp::LinkPair;
use missionlink_protocol::transfer::integrity;
use missionlink_protocol::transfer::mission::Mission;
use missionlink_protocol::transfer::sender::Target;
use missionlink_protocol::transfer::staged::MissionId;

use super::client::{Call, Reply, What};
use super::fleet::{Fleet, Vehicle};
use super::request::{self, Answer, Event, Failure, Link, Listener, Progress, Request};
use super::status::{Snapshot, VehicleStatus};
use crate::gcs_link::GcsLink;
use crate::mavlink::driver::{self, MavlinkSocket};
use crate::mavlink::vehicle::{self as mav, Vehicle as MavVehicle, VehicleConfig};
use crate::mission_file::MissionFile;
use crate::pcap::PcapWriter;
use mavlink::MavHeader;
use mavlink::dialects::common::MavMessage;
use missionlink_platform::clock::DriverClock;
use missionlink_platform::fence::{Fence, IsolationError, Profile, TcpPorts, Violation};

/// How the service runs.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// The socket the clients connect to.
    pub socket: PathBuf,
    /// The state directory: per vehicle `vehicles/<name>/`.
    pub state_dir: Option<PathBuf>,
    /// Every datagram of every link into this capture, if given.
    pub capture: Option<Arc<PcapWriter>>,
    /// The safety gateway of what the MAVLink side commits (a command's request brings its
    /// own).
    pub gateway: SafetyGateway,
    /// The MAVLink side, if asked for.
    pub mavlink: Option<MavlinkOptions>,
    /// The fence the service puts around itself once its links and socket are open
    /// (`missionlink_platform::fence`, [`service_fence`]); `None`: none.
    pub fence: Option<Fence>,
    /// The process the service ends with (`--exit-with-parent`: the one that started it, as
    /// it was at start), watched once the fence is up: the fence needs the process's one
    /// thread.
    pub parent: Option<rustix::process::Pid>,
}

/// The fence of the ground service: it writes beneath its state directory and its socket's
/// directory alone (the captures it writes are open already), executes nothing, binds and
/// connects no TCP port, and makes only the calls of [`Profile::GroundService`].
pub fn service_fence(socket: &Path, state_dir: Option<&Path>) -> Fence {
    let writable = socket
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .into_iter()
        .chain(state_dir)
        .map(Path::to_owned)
        .collect();
    Fence::new(
        "gcs serve",
        Profile::GroundService,
        None,
        Violation::Kill,
        writable,
        TcpPorts::default(),
    )
}

/// The MAVLink side of the service: every vehicle of the fleet on one endpoint, each its own
/// system ID (the fleet file's), so that QGroundControl shows every vehicle and a client's
/// traffic reaches the vehicle it addresses.
#[derive(Debug, Clone)]
pub struct MavlinkOptions {
    /// The endpoint, bound.
    pub socket: Arc<MavlinkSocket>,
    /// Speed of waypoints before any DO_CHANGE_SPEED item, m/s.
    pub cruise_speed_mps: f64,
    /// How long an accepted mission waits for a fence upload before it is committed.
    pub fence_wait: Duration,
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
    /// The fence could not be put up (the service starts with all of it or not at all).
    #[error("the fence: {0}")]
    Fence(#[from] IsolationError),
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
/// How long an idle vehicle's thread waits at most: it wakes for a datagram, a call (its
/// [`JobSender`] rings), a deadline of its ground station or of its MAVLink side, and at the
/// latest after this to look whether the service stops.
const IDLE_WAIT: Duration = Duration::from_millis(500);
/// How long a write to a client may block the vehicle's thread: a monitor that stopped reading
/// is dropped, not waited for.
const CLIENT_WRITE: Duration = Duration::from_millis(200);
/// How long a client may take to send its call.
const CLIENT_CALL: Duration = Duration::from_secs(5);

/// The service's socket and every vehicle's links, bound ([`open`]): what [`serve`] serves.
pub struct Opened {
    listener: UnixListener,
    links: Vec<Link>,
}

/// Binds the service's socket and every vehicle's links of `fleet`. Called before anything of
/// the service binds a port the system picks (the MAVLink endpoint's `127.0.0.1:0`): such a
/// port could be one the fleet file names, and that vehicle could not start.
pub fn open(fleet: &Fleet, options: &ServeOptions) -> Result<Opened, ServeError> {
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
    Ok(Opened { listener, links })
}

/// Runs the service for `fleet` on what [`open`] bound until `stop` is set: calls `ready` with
/// the bound links, serves, and on stop removes the socket.
pub fn serve(
    fleet: &Fleet,
    opened: Opened,
    options: &ServeOptions,
    stop: &Arc<AtomicBool>,
    ready: impl FnOnce(&[Bound]),
) -> Result<(), ServeError> {
    let Opened { listener, links } = opened;
    let mut bound = Vec::new();
    let mut routes = Vec::new();
    let mut workers = Vec::new();
    let fleet_missions = Arc::new(FleetMissions::default());
    let mut mavlink_routes = Vec::new();
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
        let bell = Arc::new(
            rustix::event::eventfd(
                0,
                rustix::event::EventfdFlags::CLOEXEC | rustix::event::EventfdFlags::NONBLOCK,
            )
            .map_err(|e| ServeError::Links {
                name: vehicle.name.clone(),
                error: format!("cannot make the thread's bell (eventfd): {e}"),
            })?,
        );
        let jobs = JobSender {
            queue: jobs,
            bell: bell.clone(),
        };
        let shared = Arc::new(Mutex::new(Snapshot::default()));
        let dir = vehicle_dir(options, &vehicle.name);
        let clock = link.clock();
        let mav = options.mavlink.as_ref().map(|m| MavSide {
            vehicle: MavVehicle::new(VehicleConfig::standard(
                vehicle.mavlink_system_id,
                m.fence_wait,
                m.cruise_speed_mps,
            )),
            socket: m.socket.clone(),
            memory: dir.as_ref().map(|d| d.join("mavlink-memory")),
        });
        if mav.is_some() {
            mavlink_routes.push((vehicle.mavlink_system_id, jobs.clone()));
        }
        let worker = Worker {
            name: vehicle.name.clone(),
            fleet: fleet_missions.clone(),
            separation: fleet.separation,
            gateway: options.gateway,
            link,
            queue,
            bell,
            deferred: VecDeque::new(),
            shared: shared.clone(),
            state: VehicleState {
                snapshot: Snapshot {
                    planned: dir.as_deref().and_then(read_planned),
                    // Until the FCC's report is asked and the copies a previous run left are
                    // deleted.
                    busy: Some("starting".to_owned()),
                    ..Snapshot::default()
                },
                monitors: Vec::new(),
                mav,
                clock,
                copies: Copies::new(dir.as_deref()),
            },
            dir,
        };
        workers.push((vehicle.name.clone(), worker));
        routes.push(Route {
            name: vehicle.name.clone(),
            vehicle_id: vehicle.link.ids.fcc,
            jobs,
            shared,
        });
    }
    // Everything is open: the fence goes up while this is the process's one thread, and every
    // thread started below inherits it.
    if let Some(fence) = &options.fence {
        fence.apply().map_err(|e| {
            let _ = std::fs::remove_file(&options.socket);
            ServeError::Fence(e)
        })?;
    }
    if let Some(parent) = options.parent {
        missionlink_platform::parent::watch_parent(parent);
    }
    for (name, mut worker) in workers {
        let stop = stop.clone();
        let thread = std::thread::Builder::new()
            .name(format!("vehicle {name}"))
            .stack_size(VEHICLE_STACK)
            .spawn(move || worker.run(&stop))
            .map_err(|e| ServeError::Links {
                name,
                error: e.to_string(),
            })?;
        threads.push(thread);
    }
    if let Some(m) = &options.mavlink {
        let socket = m.socket.clone();
        let stop = stop.clone();
        let thread = std::thread::Builder::new()
            .name("mavlink".to_owned())
            .spawn(move || route_mavlink(&socket, &mavlink_routes, &stop))
            .map_err(|e| ServeError::Links {
                name: "MAVLink".to_owned(),
                error: e.to_string(),
            })?;
        threads.push(thread);
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
            .map(|l| l.with_replay_lease(&super::replay_lease(dir, config.ids.fcc)))
            .map_err(|e| e.to_string()),
        None => Ok(link),
    }
}

/// The active mission of each vehicle of the fleet, as each vehicle's thread learns it (its own
/// uploads, else a download when the FCC's report shows another): what a mission for one
/// vehicle is checked against before it goes (the safety gateway's separation check,
/// `[fleet] separation_m`).
#[derive(Debug, Default)]
struct FleetMissions(Mutex<HashMap<String, Active>>);

/// A vehicle's active mission, by the checksum the FCC reports (ICD §11).
#[derive(Debug, Clone)]
struct Active {
    checksum: Checksum,
    mission: Arc<Mission>,
    /// Where it took off, when this ground uploaded it (the FCC does not hold it).
    take_off: Option<GeoPoint>,
}

impl FleetMissions {
    fn checksum(&self, vehicle: &str) -> Option<Checksum> {
        self.0.lock().ok()?.get(vehicle).map(|a| a.checksum)
    }

    fn set(&self, vehicle: &str, active: Option<Active>) {
        if let Ok(mut map) = self.0.lock() {
            match active {
                Some(a) => map.insert(vehicle.to_owned(), a),
                None => map.remove(vehicle),
            };
        }
    }

    /// Every vehicle's but `vehicle`'s.
    fn others(&self, vehicle: &str) -> Vec<(String, Active)> {
        self.0.lock().map_or_else(
            |_| Vec::new(),
            |map| {
                map.iter()
                    .filter(|(name, _)| name.as_str() != vehicle)
                    .map(|(name, a)| (name.clone(), a.clone()))
                    .collect()
            },
        )
    }
}

/// The active mission of a mission file's text (the lists as the command validated them) and
/// its take-off position.
fn active_of(mission: &str) -> Option<Active> {
    let plan = MissionFile::parse(mission).ok()?.to_plan().ok()?;
    let lists = plan.assemble().ok()?;
    Some(lists_of(&lists, plan.take_off_position).0)
}

/// Validated lists as they become active when uploaded (ICD §8): the mission with its checksum
/// and take-off position, and the area list's checksum (ICD §11).
fn lists_of(lists: &ValidatedPlan, take_off: Option<GeoPoint>) -> (Active, Checksum) {
    (
        Active {
            checksum: integrity::mission_checksum(&lists.mission),
            mission: Arc::new(lists.mission.clone()),
            take_off,
        },
        integrity::areas_checksum(&lists.areas),
    )
}

/// The safety gateway's separation check (`[fleet] separation_m`): the mission `own` for
/// `vehicle` (validated, taking off at `take_off`), as it flies with `gateway`, against the
/// active missions of the fleet's other vehicles; every conflict, or why the check cannot run.
fn keeps_separation(
    fleet: &FleetMissions,
    vehicle: &str,
    separation: super::fleet::Separation,
    gateway: &SafetyGateway,
    own: &Mission,
    take_off: Option<GeoPoint>,
) -> Result<(), String> {
    use missionlink_ground::safety_gateway::separation::{self, Flight, Separation};
    if separation.separation_m <= 0.0 {
        return Ok(());
    }
    let others = fleet.others(vehicle);
    let flights: Vec<Flight<'_>> = others
        .iter()
        .map(|(name, a)| Flight {
            vehicle: name,
            mission: &a.mission,
            take_off: a.take_off,
        })
        .collect();
    let own = Flight {
        vehicle,
        mission: own,
        take_off,
    };
    let limits = Separation {
        horizontal_m: separation.separation_m,
        // 0: altitudes never separate two paths.
        vertical_m: separation.vertical_separation_m.max(f64::MIN_POSITIVE),
    };
    let found = separation::conflicts(gateway, own, &flights, limits)
        .map_err(|e| format!("the separation check: {e}"))?;
    if found.is_empty() {
        return Ok(());
    }
    let mut message = format!(
        "infeasible: {} separation conflict{} with the fleet's active missions",
        found.len(),
        if found.len() == 1 { "" } else { "s" }
    );
    for conflict in &found {
        message.push_str(&format!("\n  {}", conflict.violation()));
    }
    Err(message)
}

/// A vehicle as the acceptor reaches it.
struct Route {
    name: String,
    vehicle_id: u32,
    jobs: JobSender,
    shared: Arc<Mutex<Snapshot>>,
}

/// The sending end of a vehicle's queue of calls: each call rings the vehicle's bell (an
/// eventfd its thread waits on beside its links), so that an idle vehicle's thread sleeps until
/// something comes instead of looking at its queue every few milliseconds.
#[derive(Clone)]
struct JobSender {
    queue: Sender<Job>,
    bell: Arc<OwnedFd>,
}

impl JobSender {
    fn send(&self, job: Job) -> Result<(), std::sync::mpsc::SendError<Job>> {
        self.queue.send(job)?;
        // A full counter (2^64 - 2 rings) would only mean the thread is woken already.
        let _ = rustix::io::write(&*self.bell, &1u64.to_ne_bytes());
        Ok(())
    }
}

struct Routes {
    fleet: Fleet,
    routes: Vec<Route>,
}

/// A call handed to a vehicle's thread, with the client to answer, or a MAVLink client's
/// message for its vehicle.
enum Job {
    Request(Request, UnixStream),
    Monitor(UnixStream),
    Mavlink(Box<(MavHeader, MavMessage)>),
}

/// Receives the MAVLink clients' datagrams until `stop` and hands each message to the vehicle
/// it addresses (its target system); a message for every system (target 0, or none: a
/// client's HEARTBEAT) goes to every vehicle, but the mission protocol and commands addressed
/// to system 0 in a fleet of several, which would change every vehicle's lists at once: those
/// are counted and dropped. A message for a system the fleet does not hold is counted.
fn route_mavlink(socket: &MavlinkSocket, routes: &[(u8, JobSender)], stop: &AtomicBool) {
    let mut buf = [0u8; 2048];
    let (mut elsewhere, mut to_all_refused, mut unreadable) = (0u64, 0u64, 0u64);
    while !stop.load(Ordering::Relaxed) {
        let len = match socket.receive(&mut buf, Duration::from_millis(200)) {
            Ok(Some(len)) => len,
            Ok(None) => continue,
            Err(e) => {
                tracing::warn!(%e, "the MAVLink socket failed; the MAVLink side stops");
                return;
            }
        };
        let messages = mav::read_datagram(buf.get(..len).unwrap_or_default());
        if messages.is_empty() {
            unreadable += 1;
        }
        for (header, message) in messages {
            match mav::target(&message).map(|(system, _)| system) {
                Some(0) if routes.len() > 1 => {
                    to_all_refused += 1;
                    if to_all_refused == 1 {
                        tracing::warn!(
                            "a MAVLink client addressed a command or the mission protocol to \
                             every system (0): refused in a fleet, counted from now on"
                        );
                    }
                }
                Some(0) | None => {
                    for (_, jobs) in routes {
                        let _ = jobs.send(Job::Mavlink(Box::new((header, message.clone()))));
                    }
                }
                Some(system) => match routes.iter().find(|(id, _)| *id == system) {
                    Some((_, jobs)) => {
                        let _ = jobs.send(Job::Mavlink(Box::new((header, message))));
                    }
                    None => {
                        elsewhere += 1;
                        if elsewhere == 1 {
                            tracing::warn!(
                                system,
                                "a MAVLink client addressed a system the fleet does not hold: \
                                 ignored, counted from now on"
                            );
                        }
                    }
                },
            }
        }
    }
    if elsewhere + to_all_refused + unreadable > 0 {
        tracing::info!(
            elsewhere,
            to_all_refused,
            unreadable,
            "the MAVLink side stopped: messages for systems the fleet does not hold, to every \
             system refused, datagrams that did not read"
        );
    }
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
        if let Job::Request(_, mut stream) | Job::Monitor(mut stream) = unsent.0 {
            send(
                &mut stream,
                &Reply::Failed(Failure::other("the service is stopping")),
            );
        }
    }
}

/// The vehicle's MAVLink side: its sans-IO vehicle, the shared endpoint, and the file of what
/// it remembers across restarts.
struct MavSide {
    vehicle: MavVehicle,
    socket: Arc<MavlinkSocket>,
    memory: Option<PathBuf>,
}

/// What a vehicle's thread keeps beside its link.
struct VehicleState {
    snapshot: Snapshot,
    /// The clients monitoring the vehicle.
    monitors: Vec<UnixStream>,
    mav: Option<MavSide>,
    /// The clock of the link's GCS logic, for the MAVLink side's time.
    clock: DriverClock,
    /// The staged copies this ground must delete, as kept on disk.
    copies: Copies,
}

/// The staged copies of this ground's atomic uploads that the FCC may hold and nobody else
/// will delete (`GroundStation::copies_to_delete`), kept in the vehicle's state directory as
/// they change, one Mission ID a line: the service killed in the middle of an upload deletes
/// them when it starts again.
struct Copies {
    kept: Vec<MissionId>,
    path: Option<PathBuf>,
}

impl Copies {
    const FILE: &'static str = "copies-to-delete";

    /// The copies a previous run kept in `dir`.
    fn new(dir: Option<&Path>) -> Self {
        let path = dir.map(|d| d.join(Self::FILE));
        let text = path
            .as_ref()
            .and_then(|p| std::fs::read_to_string(p).ok())
            .unwrap_or_default();
        Self {
            kept: text
                .lines()
                .filter(|l| !l.is_empty())
                .filter_map(|l| MissionId::new(l).ok())
                .collect(),
            path,
        }
    }

    /// What a previous run kept.
    fn read(&self) -> Vec<MissionId> {
        self.kept.clone()
    }

    /// Keeps `ids` on disk when they changed (whole: `missionlink_platform::files`).
    fn keep(&mut self, ids: Vec<MissionId>) {
        if ids == self.kept {
            return;
        }
        if let Some(path) = &self.path {
            let text: String = ids.iter().map(|id| format!("{}\n", id.as_str())).collect();
            if let Err(e) = missionlink_platform::files::replace(path, text.as_bytes()) {
                tracing::warn!(path = %path.display(), %e, "the staged copies to delete are not kept");
            }
        }
        self.kept = ids;
    }
}

impl VehicleState {
    /// An event of the GCS logic heard while no request or a request runs: the downlink's
    /// reports go to the snapshot, to every monitor and to the MAVLink side.
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
        if let Some(m) = &mut self.mav {
            driver::hear(self.clock.now(), &mut m.vehicle, event);
            driver::tick(self.clock.now(), &mut m.vehicle, &m.socket);
        }
        let reply = Reply::Event(Box::new(message));
        self.monitors.retain_mut(|m| send(m, &reply));
    }

    /// A monitor joins: the vehicle's FROM-TO-NEXT and position now, then every report.
    fn monitor(&mut self, mut stream: UnixStream) {
        let s = &self.snapshot;
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
            self.monitors.push(stream);
        }
    }

    /// A MAVLink client's message for the vehicle.
    fn mavlink(&mut self, header: MavHeader, message: &MavMessage) {
        if let Some(m) = &mut self.mav {
            m.vehicle.handle(self.clock.now(), header, message);
            driver::tick(self.clock.now(), &mut m.vehicle, &m.socket);
        }
    }

    /// The MAVLink side's deadlines and datagrams.
    fn tick(&mut self) {
        if let Some(m) = &mut self.mav {
            driver::tick(self.clock.now(), &mut m.vehicle, &m.socket);
        }
    }
}

/// What hears a request run in a vehicle's thread: the client's progress, the downlink, and the
/// vehicle's queue, whose monitors and MAVLink messages are served at once while calls that
/// need the link wait their turn.
struct Running<'a> {
    client: Option<&'a mut UnixStream>,
    state: &'a mut VehicleState,
    queue: &'a mut Receiver<Job>,
    deferred: &'a mut VecDeque<Job>,
    /// The fleet an upload keeps its separation from, this vehicle's name and the separation.
    fleet: (&'a FleetMissions, &'a str, super::fleet::Separation),
    /// The lists an upload to the active lists makes active, once validated and separated.
    uploading: Option<(Active, Checksum)>,
}

impl Listener for Running<'_> {
    fn progress(&mut self, progress: Progress) {
        if let Some(client) = self.client.as_deref_mut() {
            let _ = send(client, &Reply::Progress(progress));
        }
    }

    fn event(&mut self, event: &Event) {
        self.state.heard(event);
    }

    fn validated(
        &mut self,
        lists: &ValidatedPlan,
        take_off: Option<GeoPoint>,
        target: Target,
        gateway: &SafetyGateway,
    ) -> Result<(), String> {
        let (fleet, vehicle, separation) = self.fleet;
        keeps_separation(
            fleet,
            vehicle,
            separation,
            gateway,
            &lists.mission,
            take_off,
        )?;
        self.uploading = (target == Target::Active).then(|| lists_of(lists, take_off));
        Ok(())
    }

    fn tick(&mut self, station: &GroundStation<SafetyGateway>) {
        self.state.copies.keep(station.copies_to_delete());
        while let Ok(job) = self.queue.try_recv() {
            match job {
                Job::Monitor(stream) => self.state.monitor(stream),
                Job::Mavlink(m) => self.state.mavlink(m.0, &m.1),
                request @ Job::Request(..) => self.deferred.push_back(request),
            }
        }
        self.state.tick();
    }
}

struct Worker {
    /// The vehicle's name in the fleet.
    name: String,
    /// The fleet's active missions, shared by every vehicle's thread.
    fleet: Arc<FleetMissions>,
    /// The separation kept from them.
    separation: super::fleet::Separation,
    /// The safety gateway of what the MAVLink side commits.
    gateway: SafetyGateway,
    link: Link,
    queue: Receiver<Job>,
    /// Rung with every call put in `queue`.
    bell: Arc<OwnedFd>,
    /// Calls that came while a request ran, in their order.
    deferred: VecDeque<Job>,
    shared: Arc<Mutex<Snapshot>>,
    state: VehicleState,
    dir: Option<PathBuf>,
}

impl Worker {
    fn run(&mut self, stop: &AtomicBool) {
        let name = self.name.clone();
        on_request_thread(&name, || self.start());
        while !stop.load(Ordering::Relaxed) {
            // Until a datagram, a call, or the next deadline of the MAVLink side (the ground
            // station's own the pump adds).
            let now = self.state.clock.now();
            let wait = self
                .state
                .mav
                .as_ref()
                .and_then(|m| m.vehicle.poll_timeout())
                .map_or(IDLE_WAIT, |t| t.saturating_since(now))
                .min(IDLE_WAIT);
            self.link.pump_or_bell(wait, Some(self.bell.as_fd()));
            // Reset before the queue is read: a call put after this rings again.
            let _ = rustix::io::read(&*self.bell, &mut [0u8; 8]);
            while let Some(event) = self.link.station().poll_event() {
                self.state.heard(&event);
            }
            while let Some(job) = self
                .deferred
                .pop_front()
                .or_else(|| self.queue.try_recv().ok())
            {
                match job {
                    Job::Request(request, stream) => {
                        on_request_thread(&name, || self.request(request, stream));
                    }
                    Job::Monitor(stream) => self.state.monitor(stream),
                    Job::Mavlink(m) => self.state.mavlink(m.0, &m.1),
                }
            }
            // What a MAVLink client asked (a commit, an execute, a clear) is a request.
            if self
                .state
                .mav
                .as_ref()
                .is_some_and(|m| m.vehicle.has_event())
            {
                on_request_thread(&name, || self.mavlink_requests());
            } else {
                self.mavlink_requests();
            }
            self.state.tick();
            self.publish();
        }
    }

    /// What the thread does before its loop: the FCC's report for the status, the staged
    /// copies a previous run left deleted, the MAVLink side's lists read.
    fn start(&mut self) {
        let left = self.state.copies.read();
        self.link.station().set_copies_to_delete(&left);
        self.publish();
        self.refresh_report();
        self.delete_copies_left();
        if let Some(m) = &mut self.state.mav {
            driver::read_lists(&mut self.link, &mut m.vehicle, m.memory.as_deref());
            m.vehicle.start(self.link.now());
        }
        self.state.snapshot.busy = None;
    }

    /// Carries out what the MAVLink client asked, and asks the FCC's report after what may
    /// have changed its lists.
    fn mavlink_requests(&mut self) {
        let Some(m) = &mut self.state.mav else {
            return;
        };
        let (fleet, name, separation, gateway) =
            (&self.fleet, &self.name, self.separation, &self.gateway);
        let changed = driver::carry_out_events(
            &mut self.link,
            &mut m.vehicle,
            m.memory.as_deref(),
            &mut |own, take_off| keeps_separation(fleet, name, separation, gateway, own, take_off),
        );
        if changed {
            self.refresh_report();
        }
    }

    /// The FCC's active mission has checksum `active` (`None`: it holds none): downloaded when
    /// the fleet's record of it is another.
    fn learn_active(&mut self, active: Option<Checksum>) {
        if self.separation.separation_m <= 0.0 {
            return;
        }
        let Some(checksum) = active else {
            self.fleet.set(&self.name, None);
            return;
        };
        if self.fleet.checksum(&self.name) == Some(checksum) {
            return;
        }
        match self.carry_out(Request::Download { id: None }, None).0 {
            Ok(Answer::Downloaded { mission }) => {
                let learnt = active_of(&mission).filter(|a| a.checksum == checksum);
                if learnt.is_none() {
                    tracing::warn!(vehicle = %self.name, "the active mission downloaded is not the one reported: the separation check does not know it");
                }
                self.fleet.set(&self.name, learnt);
            }
            _ => {
                tracing::warn!(vehicle = %self.name, "the active mission could not be downloaded: the separation check does not know it");
                self.fleet.set(&self.name, None);
            }
        }
    }

    /// Deletes the staged copies a previous run left (those the FCC's report lists); those
    /// whose delete fails are kept for the next upload to delete.
    fn delete_copies_left(&mut self) {
        let left = self.state.copies.read();
        let listed: Vec<MissionId> = left
            .into_iter()
            .filter(|id| self.state.snapshot.staged_ids().any(|s| s == id.as_str()))
            .collect();
        let mut failed = Vec::new();
        let attempted = !listed.is_empty();
        for id in listed {
            let request = Request::Delete {
                id: id.as_str().to_owned(),
            };
            match self.carry_out(request, None).0 {
                Ok(_) => {
                    tracing::info!(copy = %id.as_str(), "a staged copy a previous run left is deleted")
                }
                Err(f) => {
                    tracing::warn!(copy = %id.as_str(), why = %f.message, "a staged copy a previous run left is not deleted: the next upload tries again");
                    failed.push(id);
                }
            }
        }
        self.link.station().set_copies_to_delete(&failed);
        self.state.copies.keep(failed);
        if attempted {
            self.refresh_report();
        }
    }

    /// Hands the current state to the acceptor's status.
    fn publish(&mut self) {
        let copies = self.link.station().copies_to_delete();
        self.state.copies.keep(copies);
        let s = &mut self.state.snapshot;
        s.links = self.link.activity();
        let stats = self.link.voter().stats();
        s.messages = stats.forwarded.iter().sum();
        if let Ok(mut shared) = self.shared.lock() {
            shared.clone_from(s);
        }
    }

    /// Carries `request` out, `client` hearing its progress (none: the service's own), and,
    /// for an upload to the active lists that went, the lists it made active. Called on a
    /// request's thread ([`on_request_thread`]).
    fn carry_out(
        &mut self,
        request: Request,
        client: Option<&mut UnixStream>,
    ) -> (Result<Answer, Failure>, Option<(Active, Checksum)>) {
        let Self {
            link,
            state,
            queue,
            deferred,
            fleet,
            name,
            separation,
            ..
        } = self;
        let mut running = Running {
            client,
            state,
            queue,
            deferred,
            fleet: (fleet, name, *separation),
            uploading: None,
        };
        let outcome = request::carry_out(link, request, &mut running);
        (outcome, running.uploading)
    }

    fn request(&mut self, request: Request, mut stream: UnixStream) {
        let changes = !matches!(request, Request::Report | Request::Download { .. });
        self.state.snapshot.busy = Some(request_name(&request).to_owned());
        self.publish();
        let (outcome, uploaded) = self.carry_out(request, Some(&mut stream));
        if let Ok(Answer::Reported { entries }) = &outcome {
            self.state.snapshot.report = Some(reports(entries));
            self.state.snapshot.report_failed = None;
        }
        if let (Ok(Answer::Uploaded { .. }), Some((active, areas))) = (&outcome, uploaded) {
            let planned = (active.checksum, areas);
            self.fleet.set(&self.name, Some(active));
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

    /// Asks the FCC for its report (ICD §8) for the status, and learns its active mission for
    /// the fleet's separation check when the report shows one this ground does not know.
    fn refresh_report(&mut self) {
        match self.carry_out(Request::Report, None).0 {
            Ok(Answer::Reported { entries }) => {
                let reports = reports(&entries);
                let active = reports.first().and_then(|e| e.mission_checksum);
                self.state.snapshot.report = Some(reports);
                self.state.snapshot.report_failed = None;
                self.learn_active(active);
            }
            Ok(_) => {}
            Err(f) => {
                self.state.snapshot.report = None;
                self.state.snapshot.report_failed =
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

/// Runs `work` (a request, a MAVLink client's commit, the start's report and downloads) on a
/// thread of its own and waits for it.
/// A request goes deep into the GCS logic with mission plans on the stack, some 500 KB at an
/// upload's deepest, and a thread keeps every page of stack it touched: run on the vehicle's
/// own thread, that would stay resident for every vehicle of the fleet, idle or not. A
/// thread's stack this large is unmapped when the thread ends (the C library caches smaller
/// ones for the next thread). Where no thread can be started, `work` runs on this one.
fn on_request_thread<T: Send>(vehicle: &str, work: impl FnOnce() -> T + Send) -> Option<T> {
    // Taken once, by the thread or, if none starts, here.
    let work = Mutex::new(Some(work));
    let run = || work.lock().ok().and_then(|mut w| w.take()).map(|w| w());
    std::thread::scope(|scope| {
        let spawned = std::thread::Builder::new()
            .name(format!("{vehicle} request"))
            .stack_size(VEHICLE_STACK)
            .spawn_scoped(scope, run);
        match spawned {
            Ok(thread) => match thread.join() {
                Ok(done) => done,
                Err(panic) => std::panic::resume_unwind(panic),
            },
            Err(e) => {
                tracing::warn!(%e, "cannot start a request's thread: it runs on the vehicle's");
                run()
            }
        }
    })
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

/// Keeps the lists of an upload that completed: one line of fixed width overwritten in place
/// (`missionlink_platform::files::LineFile`), no file made per upload.
fn write_planned(dir: &Path, (mission, areas): (Checksum, Checksum)) {
    let path = dir.join(PLANNED);
    let line = format!("{:#010x} {:#010x}", mission.value(), areas.value());
    let written =
        missionlink_platform::files::LineFile::open(&path).and_then(|mut f| f.write(&line));
    if let Err(e) = written {
        tracing::warn!(path = %path.display(), %e, "the lists uploaded last are not kept");
    }
}
