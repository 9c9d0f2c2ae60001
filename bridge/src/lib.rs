//! The bridge: a process of its own that forwards chosen iceoryx2 services of this host to
//! Zenoh key expressions and takes others from Zenoh into iceoryx2, so that partitions run on
//! two hosts (docs/two-hosts.md; docs/design.md "Across hosts"; the key expressions and the
//! header in ICD §14, docs/icd.md).
//!
//! - Samples cross as their raw fixed-layout bytes ([`raw`]) with a [`header`] as the Zenoh
//!   attachment: the contract's type name, size and version, checked on arrival. A mismatch is
//!   refused, counted and logged once per service, never published.
//! - A sample from Zenoh is published with the service's own publisher, which notifies the
//!   service's event (and rings the doorbells of the partitions the configuration has wait on
//!   them, `doorbell::waits`), so a sleeping subscriber wakes.
//! - History-1 services (lists, automation state, progress): the sending bridge keeps the last
//!   sample of each and answers Zenoh queries with it (a queryable per key); the receiving
//!   bridge queries at start and whenever another bridge's liveliness token appears (a start,
//!   or a link that came back), so a late joiner on the far side gets the current sample.
//!   Duplicates (a sample heard live and again as an answer) are left out by sequence number.
//! - No loops: a service goes either out or in, never both; the outgoing side leaves out the
//!   samples of the bridge's own iceoryx2 publishers (the publisher ID in each sample), and the
//!   incoming side the Zenoh samples whose header carries its own bridge ID.
//! - Per service and direction, counters (forwarded, refused, dropped, own) go to the summary
//!   (`<summary_dir>/bridge.toml`, as the partitions write theirs).
//!
//! - The bridges authenticate each other by mutual TLS ([`credentials`]; ICD §14): with the
//!   defaults a bridge without its credentials refuses to start (exit status 2). A peer that
//!   cannot present a certificate of the deployment's authority gets no Zenoh session, so
//!   nothing is forwarded to it and nothing it sends is published. `authentication = "none"`
//!   (plain TCP) must be written in the configuration and is logged as a warning at every
//!   start.
//! - The bridge fences itself as a partition does (`missionlink_partitions::isolation`,
//!   [`Profile::Bridge`](missionlink_partitions::isolation::Profile::Bridge)) before it opens
//!   the Zenoh session, while it has one thread: every thread of Zenoh's runtime inherits the
//!   fence.
//!
//! The bridge runs two threads of its own: the outgoing one sleeps in an iceoryx2 WaitSet on the
//! services' events, the incoming one on a channel fed by Zenoh's callbacks; Zenoh's runtime
//! runs its own.

// No unsafe code in the bridge: payload bytes go through zerocopy ([`raw`]) and type names
// through iceoryx2's safe `TypeDetail` ([`ports::Contract`]). `forbid`, not the workspace's
// `deny`, so that no `allow` further down can bring it back.
#![forbid(unsafe_code)]

pub mod credentials;
pub mod header;
pub mod ports;
pub mod raw;

use std::collections::HashMap;
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::prelude::{CallbackProgression, ipc};
use missionlink_interfaces::contracts::{CONTRACT_VERSION, FccService};
use missionlink_partitions::bridge_config::{Authentication, Bridge, BridgeConfigError, Mode};
use missionlink_partitions::config::{Config, ConfigError, FccArgs};
use missionlink_partitions::ipc::{Ipc, IpcError};
use missionlink_partitions::isolation::IsolationError;
use missionlink_partitions::runtime::{CONFIG_EXIT_CODE, Control, PartitionError};
use zenoh::Wait;
use zenoh::sample::SampleKind;

use crate::credentials::{CredentialError, Credentials};
use crate::header::{Header, Refusal};
use crate::ports::Incoming;

/// The process's name (its summary, its readiness announcement, its log lines).
pub const NAME: &str = missionlink_partitions::bridge_config::BINARY;

/// How often the loops look at a stop request and reconnect late iceoryx2 subscribers.
const TICK: Duration = Duration::from_millis(100);

/// Why the bridge cannot run.
#[derive(Debug, thiserror::Error)]
pub enum BridgeError {
    /// `[bridge]` is wrong (a service that does not exist, one both ways, a bad key prefix,
    /// endpoints that do not fit the authentication, mutual TLS without credentials).
    #[error("configuration: {0}")]
    Config(#[from] BridgeConfigError),
    /// A setting Zenoh's configuration refuses.
    #[error("configuration: {0}")]
    ZenohConfig(String),
    /// The credentials cannot be used (missing, readable by others, not PEM).
    #[error("credentials: {0}")]
    Credentials(#[from] CredentialError),
    /// The bridge could not fence itself as configured (`[isolation]`).
    #[error("isolation: {0}")]
    Isolation(IsolationError),
    /// The Zenoh session, a subscriber, queryable or liveliness token could not be opened.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// iceoryx2 refused a node or a port.
    #[error("iceoryx2: {0}")]
    Ipc(#[from] IpcError),
    /// The WaitSet could not be created, attached to or waited on.
    #[error("WaitSet: {0}")]
    WaitSet(String),
    /// The incoming thread ended before it opened its ports.
    #[error("incoming thread: {0}")]
    Thread(String),
}

fn zenoh_err(what: &str) -> impl Fn(zenoh::Error) -> BridgeError + '_ {
    move |e| BridgeError::Zenoh(format!("{what}: {e}"))
}

/// The key expression of `service`: `<key_prefix>/<service path>`.
pub fn key(bridge: &Bridge, service: FccService) -> String {
    format!(
        "{}/{}",
        bridge.key_prefix.trim_end_matches('/'),
        service.path()
    )
}

/// The key expression of a bridge's liveliness token: `<key_prefix>/bridge/<id>`.
fn token_key(bridge: &Bridge, id: u64) -> String {
    format!(
        "{}/bridge/{id:016x}",
        bridge.key_prefix.trim_end_matches('/')
    )
}

/// Whether a service is history-1 (`contracts::Qos`) and so answers late joiners; heartbeats
/// are left out: an old heartbeat must never make a silent partition look alive.
fn answers_late_joiners(service: FccService) -> bool {
    service.qos().history_size > 0 && !matches!(service, FccService::Heartbeat(_))
}

/// Block for every service whose samples must all arrive (frames, commands, lists, the
/// automation state: a list dropped on a busy queue would leave the far side on the old one);
/// drop for the periodic ones (heartbeats, progress), where the next sample replaces a lost one
/// and a cut link must not stall the bridge.
fn congestion_control(service: FccService) -> zenoh::qos::CongestionControl {
    match service {
        FccService::Heartbeat(_) | FccService::GuidanceProgress => {
            zenoh::qos::CongestionControl::Drop
        }
        _ => zenoh::qos::CongestionControl::Block,
    }
}

/// The Zenoh configuration of `[bridge]`: the mode, the explicit endpoints, multicast
/// scouting off (no traffic to any address but the endpoints), a short lease so a cut link is
/// noticed and the session re-opened within seconds, and with `credentials` mutual TLS
/// ([`Credentials::zenoh_settings`]).
pub fn zenoh_config(
    bridge: &Bridge,
    credentials: Option<&Credentials>,
) -> Result<zenoh::Config, BridgeError> {
    let mut config = zenoh::Config::default();
    let json = |v: &[String]| {
        let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
        format!("[{}]", quoted.join(","))
    };
    let mode = match bridge.mode {
        Mode::Peer => "\"peer\"",
        Mode::Client => "\"client\"",
    };
    for (key, value) in [
        ("mode", mode.to_owned()),
        ("listen/endpoints", json(&bridge.listen)),
        ("connect/endpoints", json(&bridge.connect)),
        ("scouting/multicast/enabled", "false".to_owned()),
        // Peers learn of no other peers than their endpoints.
        ("scouting/gossip/enabled", "false".to_owned()),
        // Open the session without waiting for the connect endpoints, and never give up on
        // one: with no global timeout (-1) and no exit on failure, Zenoh tries each in the
        // background at the retry period until it answers, and again after a cut. (A timeout of
        // 0 would try each once only: a bridge started before the other would never connect.)
        ("connect/timeout_ms", "-1".to_owned()),
        ("connect/exit_on_failure", "false".to_owned()),
        (
            "connect/retry",
            "{period_init_ms: 250, period_max_ms: 1000, period_increase_factor: 2}".to_owned(),
        ),
        ("transport/link/tx/lease", "2000".to_owned()),
    ] {
        config
            .insert_json5(key, &value)
            .map_err(|e| BridgeError::ZenohConfig(format!("zenoh {key} = {value}: {e}")))?;
    }
    for (key, value) in credentials
        .map(Credentials::zenoh_settings)
        .unwrap_or_default()
    {
        // The value may be a key: only the setting's name goes into the message.
        config
            .insert_json5(key, &value)
            .map_err(|e| BridgeError::ZenohConfig(format!("zenoh {key}: {e}")))?;
    }
    Ok(config)
}

/// The counters of one service in one direction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Samples forwarded (to Zenoh, or published on this host).
    pub forwarded: u64,
    /// Samples refused: a header or payload that does not match the contract.
    pub refused: u64,
    /// Samples lost: a Zenoh put that failed, an iceoryx2 send that failed, or a gap in the
    /// sending bridge's sequence numbers.
    pub dropped: u64,
    /// Samples left out as the bridge's own (no loops).
    pub own: u64,
}

impl Counters {
    fn push_into(&self, direction: &str, service: FccService, out: &mut Vec<(String, u64)>) {
        for (what, v) in [
            ("forwarded", self.forwarded),
            ("refused", self.refused),
            ("dropped", self.dropped),
            ("own", self.own),
        ] {
            out.push((format!("{direction} {service} {what}"), v));
        }
    }
}

/// The last sample of each history-1 service going out, by key: (payload, header).
type LastSamples = Arc<Mutex<HashMap<String, (Vec<u8>, Vec<u8>)>>>;

/// What [`run`] needs checked before it starts: the services, and the credentials read (none
/// without authentication). The check refuses a configuration that cannot work, and warns of
/// one without authentication, before anything is opened ([`prepare`]).
#[derive(Debug)]
pub struct Prepared {
    out: Vec<FccService>,
    inbound: Vec<FccService>,
    credentials: Option<Credentials>,
}

/// Checks `[bridge]` and reads the credentials it names: a configuration that cannot work is an
/// error (exit status 2 in [`main`]); `authentication = "none"` is a warning, at every start.
pub fn prepare(bridge: &Bridge) -> Result<Prepared, BridgeError> {
    let (out, inbound) = bridge.services()?;
    bridge.endpoints()?;
    let credentials = match (bridge.authentication, &bridge.credentials) {
        (Authentication::Mtls, Some(dir)) => Some(Credentials::read(dir)?),
        (Authentication::Mtls, None) => return Err(BridgeConfigError::NoCredentials.into()),
        (Authentication::None, _) => {
            tracing::warn!(
                listen = ?bridge.listen,
                connect = ?bridge.connect,
                "the bridge does not authenticate its peers ([bridge] authentication = \"none\"): \
                 any host that reaches its endpoints is taken as the other bridge"
            );
            None
        }
    };
    Ok(Prepared {
        out,
        inbound,
        credentials,
    })
}

/// Runs the bridge of `config` until `control` stops it: [`prepare`], the fence of `control`
/// (`Control::fencing`; before Zenoh starts any thread), then the Zenoh session and the two
/// loops.
pub fn run(config: &Config, control: &Control) -> Result<(), BridgeError> {
    let bridge = &config.bridge;
    let Prepared {
        out,
        inbound,
        credentials,
    } = prepare(bridge)?;
    let zenoh_config = zenoh_config(bridge, credentials.as_ref())?;
    drop(credentials);
    // Zenoh's runtime starts its threads when the session opens: fenced from here on, they
    // all inherit the fence (Landlock acts on the calling thread and those it starts).
    control.fence.apply().map_err(|e| match e {
        PartitionError::Isolation(e) => BridgeError::Isolation(e),
        // `Fencing::apply` fails with `Isolation` only; anything else is said as it is.
        other => BridgeError::Thread(format!("fencing: {other}")),
    })?;
    let id = bridge_id();
    let session = zenoh::open(zenoh_config)
        .wait()
        .map_err(zenoh_err("opening the session"))?;
    tracing::info!(
        id = format_args!("{id:016x}"),
        zid = %session.zid(),
        prefix = %config.ipc.service_prefix,
        key_prefix = %bridge.key_prefix,
        authentication = ?bridge.authentication,
        listen = ?bridge.listen,
        connect = ?bridge.connect,
        out = ?bridge.out,
        inbound = ?bridge.inbound,
        "bridge up"
    );
    let _token = session
        .liveliness()
        .declare_token(token_key(bridge, id))
        .wait()
        .map_err(zenoh_err("liveliness token"))?;

    let (ids_tx, ids_rx) = mpsc::channel();
    let incoming = {
        let session = session.clone();
        let config = config.clone();
        let control = control.clone();
        std::thread::Builder::new()
            .name("bridge-in".to_owned())
            .spawn(move || run_incoming(&session, &config, &inbound, id, &ids_tx, &control))
            .map_err(|e| BridgeError::Thread(e.to_string()))?
    };
    let own = match ids_rx.recv() {
        Ok(own) => own,
        Err(_) => {
            let why = match incoming.join() {
                Ok(Err(e)) => e.to_string(),
                Ok(Ok(_)) => "ended".to_owned(),
                Err(_) => "panicked".to_owned(),
            };
            return Err(BridgeError::Thread(why));
        }
    };
    let outgoing = run_outgoing(&session, config, &out, id, &own, control);
    control.requests.stop();
    let incoming = incoming
        .join()
        .map_err(|_| BridgeError::Thread("panicked".to_owned()))?;
    let (out_counters, in_counters) = (outgoing?, incoming?);
    let mut counters = Vec::new();
    for (service, c) in &out_counters {
        c.push_into("out", *service, &mut counters);
    }
    for (service, c) in &in_counters {
        c.push_into("in", *service, &mut counters);
    }
    for (name, v) in &counters {
        tracing::info!(counter = %name, value = v, "bridge summary");
    }
    if let Some(dir) = &config.latency.summary_dir {
        let refs: Vec<(&str, u64)> = counters.iter().map(|(k, v)| (k.as_str(), *v)).collect();
        missionlink_partitions::latency::write_summary(dir, NAME, &[], &refs);
    }
    if let Err(e) = session.close().wait() {
        tracing::warn!(%e, "closing the Zenoh session");
    }
    Ok(())
}

/// A bridge ID that differs between processes and between starts of one.
fn bridge_id() -> u64 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64);
    (u64::from(std::process::id()) << 32) ^ nanos
}

struct OutPort {
    service: FccService,
    key: String,
    /// How Zenoh treats the sample when its transmission queue is full.
    congestion: zenoh::qos::CongestionControl,
    sequence: u64,
    history: bool,
    counters: Counters,
}

fn run_outgoing(
    session: &zenoh::Session,
    config: &Config,
    services: &[FccService],
    id: u64,
    own: &[UniquePublisherId],
    control: &Control,
) -> Result<Vec<(FccService, Counters)>, BridgeError> {
    let bridge = &config.bridge;
    let ipc = Ipc::<ipc::Service>::open("bridge-out", &config.ipc)?;
    let subscribers = services
        .iter()
        .map(|&service| ports::outgoing(&ipc, service))
        .collect::<Result<Vec<_>, _>>()?;
    let mut ports = services
        .iter()
        .map(|&service| {
            Ok(OutPort {
                service,
                congestion: congestion_control(service),
                key: key(bridge, service),
                sequence: 0,
                history: answers_late_joiners(service),
                counters: Counters::default(),
            })
        })
        .collect::<Result<Vec<_>, BridgeError>>()?;
    let last: LastSamples = Arc::default();
    let mut queryables = Vec::new();
    for p in ports.iter().filter(|p| p.history) {
        let last = Arc::clone(&last);
        let key = p.key.clone();
        let queryable = session
            .declare_queryable(&p.key)
            .callback(move |query| {
                let sample = last
                    .lock()
                    .ok()
                    .and_then(|l| l.get(&key).map(|(p, h)| (p.clone(), h.clone())));
                if let Some((payload, header)) = sample {
                    if let Err(e) = query.reply(&key, payload).attachment(header).wait() {
                        tracing::debug!(%e, key, "cannot answer a query");
                    }
                }
            })
            .wait()
            .map_err(zenoh_err("queryable"))?;
        queryables.push(queryable);
    }
    let waitset = missionlink_partitions::runtime::waitset::<ipc::Service>()
        .map_err(|e| BridgeError::WaitSet(e.to_string()))?;
    let _guards = subscribers
        .iter()
        .map(|s| waitset.attach_notification(s.listener()))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| BridgeError::WaitSet(format!("{e:?}")))?;
    // The stop request is looked at every tick, also with no service going out.
    let _tick = waitset
        .attach_interval(TICK)
        .map_err(|e| BridgeError::WaitSet(format!("{e:?}")))?;
    let mut header = Vec::with_capacity(header::FIXED_LEN + 64);
    control.ready.set();
    while !control.requests.stop_requested() {
        waitset
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, TICK)
            .map_err(|e| BridgeError::WaitSet(format!("{e:?}")))?;
        for (p, subscriber) in ports.iter_mut().zip(&subscribers) {
            let contract = subscriber.contract();
            subscriber.take_all(own, &mut |bytes, is_own| {
                if is_own {
                    p.counters.own += 1;
                    return;
                }
                p.sequence += 1;
                Header {
                    contract_version: CONTRACT_VERSION,
                    payload_size: u32::try_from(contract.size).unwrap_or(u32::MAX),
                    bridge_id: id,
                    sequence: p.sequence,
                    type_name: contract.type_name(),
                }
                .emit(&mut header);
                if p.history {
                    if let Ok(mut l) = last.lock() {
                        l.insert(p.key.clone(), (bytes.to_vec(), header.clone()));
                    }
                }
                let put = session
                    .put(&p.key, bytes.to_vec())
                    .attachment(header.clone())
                    .congestion_control(p.congestion)
                    .express(true)
                    .wait();
                match put {
                    Ok(()) => p.counters.forwarded += 1,
                    Err(e) => {
                        if p.counters.dropped == 0 {
                            tracing::warn!(%e, service = %p.service, "cannot put to Zenoh (logged once)");
                        }
                        p.counters.dropped += 1;
                    }
                }
            });
        }
    }
    drop(queryables);
    Ok(ports.into_iter().map(|p| (p.service, p.counters)).collect())
}

/// What Zenoh's callbacks hand to the incoming thread.
enum Message {
    /// A sample of the `usize`-th incoming service: payload, attachment.
    Sample(usize, Vec<u8>, Option<Vec<u8>>),
    /// Another bridge's liveliness token appeared: ask for the current samples.
    BridgeAppeared(String),
}

struct InPort {
    service: FccService,
    port: Box<dyn Incoming>,
    key: String,
    /// The sender and sequence number of the sample published last.
    last: Option<(u64, u64)>,
    refusal_logged: bool,
    counters: Counters,
}

impl InPort {
    fn handle(&mut self, payload: &[u8], attachment: Option<&[u8]>, id: u64) {
        let header = match attachment.ok_or(Refusal::Missing).and_then(Header::parse) {
            Ok(h) => h,
            Err(r) => return self.refuse(r, None),
        };
        let contract = self.port.contract();
        if let Err(r) = header.check(
            CONTRACT_VERSION,
            contract.type_name(),
            contract.size,
            payload.len(),
        ) {
            return self.refuse(r, Some(&header));
        }
        if header.bridge_id == id {
            self.counters.own += 1;
            return;
        }
        match self.last {
            // Heard already (live, then again as the answer to a query).
            Some((from, seq)) if from == header.bridge_id && header.sequence <= seq => return,
            Some((from, seq)) if from == header.bridge_id => {
                self.counters.dropped += header.sequence - seq - 1;
            }
            _ => {}
        }
        match self.port.publish(payload) {
            Ok(()) => {
                self.counters.forwarded += 1;
                self.last = Some((header.bridge_id, header.sequence));
            }
            Err(ports::PublishError::Refused(r)) => self.refuse(r, Some(&header)),
            Err(ports::PublishError::Ipc(e)) => {
                if self.counters.dropped == 0 {
                    tracing::warn!(%e, service = %self.service, "cannot publish (logged once)");
                }
                self.counters.dropped += 1;
            }
        }
    }

    fn refuse(&mut self, reason: Refusal, header: Option<&Header<'_>>) {
        self.counters.refused += 1;
        if !self.refusal_logged {
            self.refusal_logged = true;
            let contract = self.port.contract();
            tracing::warn!(
                service = %self.service,
                %reason,
                received = %header.map_or_else(|| "-".to_owned(), ToString::to_string),
                expected = %format_args!("{} ({} B, contract v{CONTRACT_VERSION})", contract.type_name(), contract.size),
                "sample from Zenoh refused (logged once per service; the summary counts them)"
            );
        }
    }
}

fn run_incoming(
    session: &zenoh::Session,
    config: &Config,
    services: &[FccService],
    id: u64,
    ids: &mpsc::Sender<Vec<UniquePublisherId>>,
    control: &Control,
) -> Result<Vec<(FccService, Counters)>, BridgeError> {
    let bridge = &config.bridge;
    let ipc = Ipc::<ipc::Service>::open("bridge-in", &config.ipc)?;
    let mut ports = services
        .iter()
        .map(|&service| {
            Ok(InPort {
                service,
                port: ports::incoming(&ipc, service)?,
                key: key(bridge, service),
                last: None,
                refusal_logged: false,
                counters: Counters::default(),
            })
        })
        .collect::<Result<Vec<_>, BridgeError>>()?;
    if ids
        .send(ports.iter().map(|p| p.port.id()).collect())
        .is_err()
    {
        return Ok(Vec::new());
    }
    let (tx, rx) = mpsc::channel();
    let mut subscribers = Vec::new();
    for (i, p) in ports.iter().enumerate() {
        let tx = tx.clone();
        let subscriber = session
            .declare_subscriber(&p.key)
            .callback(move |sample| {
                let payload = sample.payload().to_bytes().into_owned();
                let attachment = sample.attachment().map(|a| a.to_bytes().into_owned());
                let _ = tx.send(Message::Sample(i, payload, attachment));
            })
            .wait()
            .map_err(zenoh_err("subscriber"))?;
        subscribers.push(subscriber);
    }
    let own_token = token_key(bridge, id);
    let liveliness = {
        let tx = tx.clone();
        session
            .liveliness()
            .declare_subscriber(format!(
                "{}/bridge/*",
                bridge.key_prefix.trim_end_matches('/')
            ))
            .callback(move |sample| {
                let key = sample.key_expr().as_str();
                if sample.kind() == SampleKind::Put && key != own_token {
                    let _ = tx.send(Message::BridgeAppeared(key.to_owned()));
                }
            })
            .wait()
            .map_err(zenoh_err("liveliness subscriber"))?
    };
    drop(tx);
    query_current(session, bridge, &mut ports, id);
    while !control.requests.stop_requested() {
        match rx.recv_timeout(TICK) {
            Ok(Message::Sample(i, payload, attachment)) => {
                if let Some(p) = ports.get_mut(i) {
                    p.handle(&payload, attachment.as_deref(), id);
                }
            }
            Ok(Message::BridgeAppeared(key)) => {
                tracing::info!(
                    token = key,
                    "another bridge appeared: asking for the current samples"
                );
                query_current(session, bridge, &mut ports, id);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {
                for p in &ports {
                    p.port.update_connections();
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    drop(liveliness);
    drop(subscribers);
    Ok(ports.into_iter().map(|p| (p.service, p.counters)).collect())
}

/// Asks Zenoh for the current sample of every history-1 incoming service and publishes the
/// answers (those already published are left out by their sequence numbers).
fn query_current(session: &zenoh::Session, bridge: &Bridge, ports: &mut [InPort], id: u64) {
    let mut pending = Vec::new();
    for (i, p) in ports.iter().enumerate() {
        if !answers_late_joiners(p.service) {
            continue;
        }
        match session.get(&p.key).timeout(bridge.query_timeout()).wait() {
            Ok(replies) => pending.push((i, replies)),
            Err(e) => tracing::warn!(%e, key = p.key, "cannot query"),
        }
    }
    for (i, replies) in pending {
        while let Ok(reply) = replies.recv() {
            if let (Ok(sample), Some(p)) = (reply.result(), ports.get_mut(i)) {
                let payload = sample.payload().to_bytes();
                let attachment = sample.attachment().map(|a| a.to_bytes());
                p.handle(&payload, attachment.as_deref(), id);
            }
        }
    }
}

/// The `main` of `bridge`: the configuration (exit status 2 when it is wrong), the signals
/// (SIGINT and SIGTERM stop it), then [`run`], which fences the process before Zenoh starts.
pub fn main(args: &FccArgs) -> std::process::ExitCode {
    missionlink_platform::init_logging();
    missionlink_partitions::ipc::quiet_iceoryx2_log();
    // The launcher at start; the watch that ends the bridge without it starts once the fence
    // is up (`Control::fencing`), so that its thread is fenced too.
    let parent = args
        .exit_with_parent
        .then(rustix::process::getppid)
        .flatten();
    let config = match Config::resolve(args) {
        Ok(c) => c,
        Err(e) => return config_error(&e),
    };
    let control = Control::new()
        .announcing_ready(config.ipc.state_dir(), NAME)
        .fencing(
            missionlink_partitions::isolation::bridge_fence(&config),
            parent,
        );
    if let Err(e) = control.requests.from_signals() {
        tracing::error!(%e, "bridge failed");
        return std::process::ExitCode::FAILURE;
    }
    let result = run(&config, &control);
    control.ready.forget();
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(
            e @ (BridgeError::Config(_)
            | BridgeError::ZenohConfig(_)
            | BridgeError::Credentials(_)
            | BridgeError::Isolation(
                IsolationError::NoSuchUser(_) | IsolationError::NotRoot { .. },
            )),
        ) => {
            // Starting it again cannot help: the launcher gives it up at once.
            tracing::error!("bridge refused to start: {e}");
            std::process::ExitCode::from(CONFIG_EXIT_CODE)
        }
        Err(e) => {
            tracing::error!(%e, "bridge failed");
            std::process::ExitCode::FAILURE
        }
    }
}

fn config_error(e: &ConfigError) -> std::process::ExitCode {
    missionlink_partitions::runtime::config_error(e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_the_key_prefix_and_the_service_path() {
        let b = Bridge {
            key_prefix: "uav7/".to_owned(),
            ..Bridge::default()
        };
        assert_eq!(
            key(&b, FccService::GuidanceProgress),
            "uav7/fcc/guidance/progress"
        );
        assert_eq!(token_key(&b, 0xab), "uav7/bridge/00000000000000ab");
    }

    #[test]
    fn the_zenoh_configuration_takes_the_endpoints() {
        let b = Bridge {
            listen: vec!["tcp/169.254.77.1:7447".to_owned()],
            ..Bridge::default()
        };
        assert!(zenoh_config(&b, None).is_ok());
        assert!(answers_late_joiners(FccService::WaypointList));
        assert!(!answers_late_joiners(FccService::Heartbeat(
            missionlink_interfaces::contracts::Partition::Guidance
        )));
        assert!(!answers_late_joiners(FccService::Uplink));
    }

    #[test]
    fn an_enabled_bridge_needs_its_credentials_unless_told_to_run_without() {
        let dir = tempfile::tempdir().unwrap();
        let made = credentials::generate(
            dir.path(),
            &["a=127.0.0.1".parse().unwrap(), "b".parse().unwrap()],
        )
        .unwrap();
        let mut b = Bridge {
            enabled: true,
            listen: vec!["tls/127.0.0.1:7447".to_owned()],
            ..Bridge::default()
        };
        // The defaults: mutual TLS, and no credentials named.
        assert!(matches!(
            prepare(&b),
            Err(BridgeError::Config(BridgeConfigError::NoCredentials))
        ));
        b.credentials = Some(made[0].clone());
        let prepared = prepare(&b).unwrap();
        let config = zenoh_config(&b, prepared.credentials.as_ref()).unwrap();
        assert_eq!(
            config.get_json("transport/link/tls/enable_mtls").unwrap(),
            "true"
        );
        assert_eq!(
            config
                .get_json("transport/link/tls/verify_name_on_connect")
                .unwrap(),
            "true"
        );
        // A key others may read: refused.
        let key = made[0].join(credentials::PRIVATE_KEY_FILE);
        std::fs::set_permissions(&key, std::os::unix::fs::PermissionsExt::from_mode(0o644))
            .unwrap();
        assert!(matches!(
            prepare(&b),
            Err(BridgeError::Credentials(CredentialError::Exposed { .. }))
        ));
        // Without authentication, in so many words: plain TCP, no credentials read.
        b.authentication = Authentication::None;
        assert!(matches!(
            prepare(&b),
            Err(BridgeError::Config(BridgeConfigError::NotTcp(_)))
        ));
        b.listen = vec!["tcp/127.0.0.1:7447".to_owned()];
        assert!(prepare(&b).unwrap().credentials.is_none());
    }

    /// A publisher that keeps what it was given.
    struct Fake {
        published: std::cell::RefCell<Vec<Vec<u8>>>,
    }

    impl Incoming for Fake {
        fn contract(&self) -> ports::Contract {
            ports::contract_of(FccService::Heartbeat(
                missionlink_interfaces::contracts::Partition::Guidance,
            ))
        }
        fn id(&self) -> UniquePublisherId {
            unreachable!("not asked in these tests")
        }
        fn publish(&self, bytes: &[u8]) -> Result<(), ports::PublishError> {
            if bytes.get(31) == Some(&0xff) {
                return Err(ports::PublishError::Refused(Refusal::Invalid));
            }
            self.published.borrow_mut().push(bytes.to_vec());
            Ok(())
        }
        fn update_connections(&self) {}
    }

    fn in_port() -> InPort {
        InPort {
            service: FccService::Heartbeat(missionlink_interfaces::contracts::Partition::Guidance),
            port: Box::new(Fake {
                published: std::cell::RefCell::default(),
            }),
            key: "k".to_owned(),
            last: None,
            refusal_logged: false,
            counters: Counters::default(),
        }
    }

    fn header_of(port: &InPort, bridge_id: u64, sequence: u64) -> Vec<u8> {
        let contract = port.port.contract();
        let mut out = Vec::new();
        Header {
            contract_version: CONTRACT_VERSION,
            payload_size: contract.size as u32,
            bridge_id,
            sequence,
            type_name: contract.type_name(),
        }
        .emit(&mut out);
        out
    }

    #[test]
    fn an_incoming_sample_is_published_once_refused_on_mismatch_and_never_from_itself() {
        const OWN: u64 = 1;
        const OTHER: u64 = 2;
        let mut p = in_port();
        let payload = [0u8; 32];
        // Published, then the same again (an answer to a query): published once.
        p.handle(&payload, Some(&header_of(&p, OTHER, 1)), OWN);
        p.handle(&payload, Some(&header_of(&p, OTHER, 1)), OWN);
        assert_eq!(p.counters.forwarded, 1);
        // Sequence 2 and 3 lost: counted as dropped when 4 arrives.
        p.handle(&payload, Some(&header_of(&p, OTHER, 4)), OWN);
        assert_eq!((p.counters.forwarded, p.counters.dropped), (2, 2));
        // The bridge's own sample is left out.
        p.handle(&payload, Some(&header_of(&p, OWN, 9)), OWN);
        assert_eq!((p.counters.forwarded, p.counters.own), (2, 1));
        // Refused: no header, another size, another type, invalid bytes.
        p.handle(&payload, None, OWN);
        p.handle(&payload[..31], Some(&header_of(&p, OTHER, 5)), OWN);
        let mut other_type = header_of(&p, OTHER, 5);
        let last = other_type.len() - 1;
        other_type[last] = b'x';
        p.handle(&payload, Some(&other_type), OWN);
        let mut invalid = payload;
        invalid[31] = 0xff;
        p.handle(&invalid, Some(&header_of(&p, OTHER, 5)), OWN);
        assert_eq!(p.counters.refused, 4);
        assert_eq!(p.counters.forwarded, 2, "nothing refused was published");
    }

    #[test]
    fn the_outgoing_side_knows_its_own_publishers_samples() {
        missionlink_partitions::ipc::quiet_iceoryx2_log();
        let prefix = format!("bridge-own-test-{}", std::process::id());
        let ipc = Ipc::<ipc::Service>::open(
            "bridge-own-test",
            &missionlink_partitions::config::Ipc::with_prefix(&prefix),
        )
        .unwrap();
        let service = FccService::Heartbeat(missionlink_interfaces::contracts::Partition::Guidance);
        let out = ports::outgoing(&ipc, service).unwrap();
        let own = ports::incoming(&ipc, service).unwrap();
        let other = ipc
            .publisher::<missionlink_interfaces::contracts::HeartbeatPayload>(service)
            .unwrap();
        let mut beat = [0u8; 32];
        beat[0] = 1;
        own.publish(&beat).unwrap();
        let mut seen = Vec::new();
        out.take_all(&[own.id()], &mut |bytes, is_own| {
            seen.push((bytes[0], is_own))
        });
        beat[0] = 2;
        let value =
            <missionlink_interfaces::contracts::HeartbeatPayload as zerocopy::TryFromBytes>::try_read_from_bytes(&beat)
                .unwrap();
        other.send(&value).unwrap();
        out.take_all(&[own.id()], &mut |bytes, is_own| {
            seen.push((bytes[0], is_own))
        });
        assert_eq!(seen, [(1, true), (2, false)]);
    }

    #[test]
    fn counters_are_named_by_direction_service_and_kind() {
        let mut out = Vec::new();
        Counters {
            forwarded: 3,
            ..Counters::default()
        }
        .push_into("in", FccService::GuidanceProgress, &mut out);
        assert_eq!(out[0], ("in fcc/guidance/progress forwarded".to_owned(), 3));
        assert_eq!(out.len(), 4);
    }
}
