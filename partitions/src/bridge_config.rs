//! `[bridge]` of the configuration: the bridge process that forwards chosen iceoryx2 services to
//! Zenoh and back, so that partitions run on two hosts (docs/two-hosts.md). The bridge itself
//! is the crate `missionlink-bridge`; only its settings live here, because every partition
//! reads the same file and refuses a section it does not know. Off by default.

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
        }
    }
}

/// The service of `path` (`fcc/...`), or a message naming the known ones.
pub fn service(path: &str) -> Result<FccService, String> {
    FccService::ALL
        .into_iter()
        .find(|s| s.path() == path)
        .ok_or_else(|| {
            let known: Vec<&str> = FccService::ALL.iter().map(|s| s.path()).collect();
            format!(
                "[bridge]: no service {path:?} (the services: {})",
                known.join(", ")
            )
        })
}

impl Bridge {
    /// The services going out and coming in, each checked; a service both ways is refused (a
    /// loop through two hosts).
    pub fn services(&self) -> Result<(Vec<FccService>, Vec<FccService>), String> {
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
            return Err(format!("[bridge]: {both} is both in `out` and in `in`"));
        }
        if self.key_prefix.is_empty() || self.key_prefix.contains(['*', '$', '?', '#']) {
            return Err(format!(
                "[bridge] key_prefix {:?}: not a Zenoh key (empty or with a wildcard)",
                self.key_prefix
            ));
        }
        Ok((out, inbound))
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
        assert!(b.services().unwrap_err().contains("both"));
        b.inbound = vec!["fcc/nothing".to_owned()];
        assert!(b.services().unwrap_err().contains("no service"));
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
    }
}
