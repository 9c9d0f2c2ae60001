//! `[bridge]` of the configuration: the bridge process that forwards chosen iceoryx2 services to
//! Zenoh and back, so that partitions run on two hosts (docs/two-hosts.md). The bridge itself
//! is the crate `missionlink-bridge`; only its settings live here, because every partition
//! reads the same file and refuses a section it does not know. Off by default.
//!
//! An enabled bridge authenticates the other bridge by mutual TLS unless the configuration says
//! `authentication = "none"` in so many words: with the defaults it needs its credentials
//! (`credentials`, made by `bridge credentials`) and `tls/` endpoints, and refuses to start
//! without them ([`Bridge::endpoints`]).

use std::path::PathBuf;
use std::time::Duration;

use missionlink_interfaces::contracts::FccService;
use serde::{Deserialize, Serialize};

/// The binary the launcher starts when the bridge is enabled (in the partitions' directory).
pub const BINARY: &str = "bridge";

/// Zenoh's session mode.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Connects to the other bridges directly (listen on one side, connect on the other).
    #[default]
    Peer,
    /// Connects to a Zenoh router only.
    Client,
}

/// How the two bridges know each other.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Authentication {
    /// Mutual TLS (Zenoh's `tls/` endpoints): each bridge presents the certificate of its host,
    /// signed by the deployment's own certificate authority, and takes as its peer only a bridge
    /// that presents one too; a peer that does not gets no Zenoh session at all.
    #[default]
    Mtls,
    /// None (Zenoh's `tcp/` endpoints): any host that reaches an endpoint is taken as the other
    /// bridge. Only for a closed bench; the bridge says so in a warning at every start.
    None,
}

/// The bridge's settings.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Bridge {
    /// The launcher starts the bridge (and restarts it when it dies).
    pub enabled: bool,
    /// Peer or client.
    pub mode: Mode,
    /// Zenoh endpoints to listen on, such as `tcp/169.254.77.1:7447`.
    pub listen: Vec<String>,
    /// Zenoh endpoints to connect to (retried until they answer, and after a cut).
    pub connect: Vec<String>,
    /// The first part of every key expression (`<key_prefix>/fcc/...`): it separates vehicles
    /// on the Zenoh side, as the service prefix separates them on the host (the two hosts of a
    /// vehicle may use different service prefixes).
    pub key_prefix: String,
    /// Service paths (`fcc/guidance/progress`, ...) forwarded from this host to Zenoh.
    pub out: Vec<String>,
    /// Service paths taken from Zenoh and published on this host.
    #[serde(rename = "in")]
    pub inbound: Vec<String>,
    /// How long the bridge waits for Zenoh's answers to its queries of the current samples
    /// (history-1 services), milliseconds.
    pub query_timeout_ms: u64,
    /// How the bridges know each other: `"mtls"` (the default) or `"none"`.
    pub authentication: Authentication,
    /// The directory of this host's credentials for mutual TLS (`ca.pem`, `certificate.pem`,
    /// `private-key.pem`, each readable by its owner only), one of the directories
    /// `bridge credentials --out DIR` makes (`DIR/<host>`); none by default.
    pub credentials: Option<PathBuf>,
}

impl Default for Bridge {
    fn default() -> Self {
        Self {
            enabled: false,
            mode: Mode::Peer,
            listen: Vec::new(),
            connect: Vec::new(),
            key_prefix: "missionlink".to_owned(),
            out: Vec::new(),
            inbound: Vec::new(),
            query_timeout_ms: 1_000,
            authentication: Authentication::Mtls,
            credentials: None,
        }
    }
}

/// The command that makes the credentials, as the refusal of a bridge without them names it.
pub const MAKE_CREDENTIALS: &str = "bridge credentials --out DIR --host NAME=ADDRESS --host NAME";

/// Why `[bridge]` cannot work.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BridgeConfigError {
    /// A service path that names no service.
    #[error("[bridge]: no service {path:?} (the services: {known})")]
    NoService {
        /// The path as written.
        path: String,
        /// The known paths, comma-separated.
        known: String,
    },
    /// A service both in `out` and in `in` (a loop through two hosts).
    #[error("[bridge]: {0} is both in `out` and in `in`")]
    BothWays(FccService),
    /// A key prefix that is empty or holds a Zenoh wildcard.
    #[error("[bridge] key_prefix {0:?}: not a Zenoh key (empty or with a wildcard)")]
    KeyPrefix(String),
    /// Mutual TLS (the default) without `credentials`.
    #[error(
        "[bridge] authenticates by mutual TLS and has no credentials: make them with `{MAKE_CREDENTIALS}` \
         and set `credentials = \"DIR/NAME\"` on each host (docs/two-hosts.md, \"Credentials\"), \
         or write `authentication = \"none\"` to run unauthenticated"
    )]
    NoCredentials,
    /// An endpoint that is not `tls/` under mutual TLS: a `tcp/` listener would take anyone.
    #[error(
        "[bridge] endpoint {0:?}: with authentication \"mtls\" every endpoint is tls/<address>:<port>"
    )]
    NotTls(String),
    /// An endpoint that is not `tcp/` without authentication (TLS needs the credentials).
    #[error(
        "[bridge] endpoint {0:?}: with authentication \"none\" every endpoint is tcp/<address>:<port>"
    )]
    NotTcp(String),
    /// An endpoint without a port number after its address.
    #[error("[bridge] endpoint {0:?}: no port (<protocol>/<address>:<port>)")]
    NoPort(String),
}

/// The service of `path` (`fcc/...`).
pub fn service(path: &str) -> Result<FccService, BridgeConfigError> {
    FccService::ALL
        .into_iter()
        .find(|s| s.path() == path)
        .ok_or_else(|| {
            let known: Vec<&str> = FccService::ALL.iter().map(|s| s.path()).collect();
            BridgeConfigError::NoService {
                path: path.to_owned(),
                known: known.join(", "),
            }
        })
}

/// The TCP ports of the bridge's endpoints: what its Landlock rules let it bind and connect to.
pub use missionlink_platform::fence::TcpPorts as Ports;

/// The protocol (`tls`, `tcp`) and port of a Zenoh endpoint
/// `<protocol>/<address>:<port>[?<metadata>][#<config>]`.
fn protocol_and_port(endpoint: &str) -> Result<(&str, u16), BridgeConfigError> {
    let locator = endpoint.split(['?', '#']).next().unwrap_or(endpoint);
    let (protocol, address) = locator
        .split_once('/')
        .ok_or_else(|| BridgeConfigError::NoPort(endpoint.to_owned()))?;
    let port = address
        .rsplit_once(':')
        .and_then(|(_, port)| port.parse().ok())
        .ok_or_else(|| BridgeConfigError::NoPort(endpoint.to_owned()))?;
    Ok((protocol, port))
}

impl Bridge {
    /// The services going out and coming in, each checked; a service both ways is refused (a
    /// loop through two hosts).
    pub fn services(&self) -> Result<(Vec<FccService>, Vec<FccService>), BridgeConfigError> {
        let out = self
            .out
            .iter()
            .map(|p| service(p))
            .collect::<Result<Vec<_>, _>>()?;
        let inbound = self
            .inbound
            .iter()
            .map(|p| service(p))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(both) = out.iter().find(|s| inbound.contains(s)) {
            return Err(BridgeConfigError::BothWays(*both));
        }
        if self.key_prefix.is_empty() || self.key_prefix.contains(['*', '$', '?', '#']) {
            return Err(BridgeConfigError::KeyPrefix(self.key_prefix.clone()));
        }
        Ok((out, inbound))
    }

    /// The ports of the endpoints, once the endpoints and the credentials agree with
    /// `authentication`: under mutual TLS (the default) there must be credentials and every
    /// endpoint is `tls/`; without authentication every endpoint is `tcp/`.
    pub fn endpoints(&self) -> Result<Ports, BridgeConfigError> {
        if self.authentication == Authentication::Mtls && self.credentials.is_none() {
            return Err(BridgeConfigError::NoCredentials);
        }
        let ports = |endpoints: &[String]| {
            endpoints
                .iter()
                .map(|e| {
                    let (protocol, port) = protocol_and_port(e)?;
                    match (self.authentication, protocol) {
                        (Authentication::Mtls, "tls") | (Authentication::None, "tcp") => Ok(port),
                        (Authentication::Mtls, _) => Err(BridgeConfigError::NotTls(e.clone())),
                        (Authentication::None, _) => Err(BridgeConfigError::NotTcp(e.clone())),
                    }
                })
                .collect::<Result<Vec<u16>, _>>()
        };
        Ok(Ports {
            listen: ports(&self.listen)?,
            connect: ports(&self.connect)?,
        })
    }

    /// The query timeout.
    pub fn query_timeout(&self) -> Duration {
        Duration::from_millis(self.query_timeout_ms.max(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn services_are_named_by_path_and_never_both_ways() {
        let mut b = Bridge {
            out: vec!["fcc/guidance/progress".to_owned()],
            inbound: vec!["fcc/mission/waypoint-list".to_owned()],
            ..Bridge::default()
        };
        assert_eq!(
            b.services().unwrap(),
            (
                vec![FccService::GuidanceProgress],
                vec![FccService::WaypointList]
            )
        );
        b.inbound.push("fcc/guidance/progress".to_owned());
        assert_eq!(
            b.services().unwrap_err(),
            BridgeConfigError::BothWays(FccService::GuidanceProgress)
        );
        assert!(b.services().unwrap_err().to_string().contains("both"));
        b.inbound = vec!["fcc/nothing".to_owned()];
        assert!(
            b.services()
                .unwrap_err()
                .to_string()
                .contains("no service \"fcc/nothing\"")
        );
        b.inbound = Vec::new();
        b.key_prefix = "uav/*".to_owned();
        assert_eq!(
            b.services().unwrap_err(),
            BridgeConfigError::KeyPrefix("uav/*".to_owned())
        );
    }

    #[test]
    fn by_default_the_bridge_needs_credentials_and_tls_endpoints() {
        let mut b = Bridge {
            enabled: true,
            listen: vec!["tls/169.254.77.1:7447".to_owned()],
            ..Bridge::default()
        };
        assert_eq!(b.authentication, Authentication::Mtls);
        let refusal = b.endpoints().unwrap_err();
        assert_eq!(refusal, BridgeConfigError::NoCredentials);
        let line = refusal.to_string();
        assert!(!line.contains('\n'), "one line: {line}");
        assert!(line.contains(MAKE_CREDENTIALS), "{line}");
        assert!(line.contains("authentication = \"none\""), "{line}");

        b.credentials = Some(PathBuf::from("/etc/missionlink/bridge"));
        b.connect = vec!["tls/[fd00::1]:7448?iface=eth0#so_sndbuf=65000".to_owned()];
        assert_eq!(
            b.endpoints().unwrap(),
            Ports {
                listen: vec![7447],
                connect: vec![7448]
            }
        );
        // A tcp/ listener under mutual TLS would take any peer.
        b.listen = vec!["tcp/169.254.77.1:7447".to_owned()];
        assert_eq!(
            b.endpoints().unwrap_err(),
            BridgeConfigError::NotTls("tcp/169.254.77.1:7447".to_owned())
        );
        b.listen = vec!["tls/169.254.77.1".to_owned()];
        assert_eq!(
            b.endpoints().unwrap_err(),
            BridgeConfigError::NoPort("tls/169.254.77.1".to_owned())
        );
    }

    #[test]
    fn without_authentication_in_so_many_words_the_endpoints_are_tcp() {
        let mut b: Bridge = toml::from_str(
            "enabled = true\nauthentication = \"none\"\nlisten = [\"tcp/127.0.0.1:7447\"]\n",
        )
        .unwrap();
        assert_eq!(b.authentication, Authentication::None);
        assert_eq!(b.endpoints().unwrap().listen, [7447]);
        b.connect = vec!["tls/127.0.0.1:7448".to_owned()];
        assert_eq!(
            b.endpoints().unwrap_err(),
            BridgeConfigError::NotTcp("tls/127.0.0.1:7448".to_owned())
        );
        assert!(toml::from_str::<Bridge>("authentication = \"password\"\n").is_err());
        assert!(toml::from_str::<Bridge>("certificate = \"x\"\n").is_err());
    }

    #[test]
    fn the_section_reads_from_toml_with_in_and_out() {
        let b: Bridge = toml::from_str(
            "enabled = true\nmode = \"client\"\nconnect = [\"tcp/169.254.77.1:7447\"]\n\
             in = [\"fcc/health/guidance\"]\n",
        )
        .unwrap();
        assert!(b.enabled);
        assert_eq!(b.mode, Mode::Client);
        assert_eq!(b.inbound, ["fcc/health/guidance"]);
        assert_eq!(b.key_prefix, "missionlink");
        assert_eq!(b.authentication, Authentication::Mtls);
        assert_eq!(b.credentials, None);
        let with: Bridge = toml::from_str("credentials = \"/etc/missionlink/bridge\"\n").unwrap();
        assert_eq!(
            with.credentials.as_deref(),
            Some(std::path::Path::new("/etc/missionlink/bridge"))
        );
    }
}
