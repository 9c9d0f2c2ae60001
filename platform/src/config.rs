//! The link configuration both sides read: node IDs, the UDP ports of the two links, timeouts
//! and link signing (ICD §1, §5, §9), each with a built-in default, so no file is needed to
//! start; a TOML file may override any of them, and command-line flags override the file. The
//! FCC and the gcs tool read the same file and take the same link flags ([`LinkArgs`]): the FCC's
//! own sections (`[ipc]`, `[guidance]`, `[latency]`, `[launcher]`, `[health]`, `[realtime]`)
//! are `missionlink_partitions::config`'s, and the ground's [`LinkConfig`] passes over them.
//!
//! ```toml
//! [ids]
//! gcs = 0x0A000001          # CUCS ID
//! fcc = 0x0B000001          # vehicle ID
//!
//! [links]
//! fcc_direct = "127.0.0.1:4586"   # the FCC receives the direct link here (port 0: the system
//!                                 # chooses; voting-monitoring announces it)
//! gcs_direct = "127.0.0.1:4587"
//! fcc_lte = "127.0.0.1:4588"
//! gcs_lte = "127.0.0.1:4589"
//!
//! [timing]
//! ack_timeout_ms = 500
//! transfer_timeout_ms = 3000
//! transfer_window = 128           # data messages in flight toward an edition-2 FCC (ICD §10);
//!                                 # 1: every message stop-and-wait (no §10.3)
//! upload_attempts = 2             # a GCS upload that failed with the lists as they were, again
//! uplink_rate_bps = 0             # the link's rate toward the FCC, bit/s, if known (0: not
//!                                 # known): the GCS's window keeps in flight at most what the
//!                                 # link carries in a round trip (ICD §10.4)
//!
//! [signing]                       # link signing, ICD §9 (see `keys`)
//! policy = "require"              # require (the default) | accept | off: what this node's
//!                                 # receiver checks; "off" only for a peer that cannot sign
//! key_files = ["/etc/missionlink/link-1.key"]   # 32-byte keys with their Key IDs, mode 0600
//! send_key_id = 1                 # sign with this key (optional with one key file)
//! ```

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::Args;
use missionlink_interfaces::defaults;
use missionlink_interfaces::wire::Timestamp;
use missionlink_protocol::link::endpoint::EndpointConfig;
use missionlink_protocol::transfer::window::MAX_WINDOW;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Node IDs (ICD §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ids {
    /// GCS (CUCS) ID.
    pub gcs: u32,
    /// FCC (vehicle) ID.
    pub fcc: u32,
}

impl Default for Ids {
    fn default() -> Self {
        Self {
            gcs: defaults::GCS_ID,
            fcc: defaults::FCC_ID,
        }
    }
}

impl Ids {
    /// The endpoint of the FCC (from the FCC to the GCS) whose instant zero is `utc_at_zero`.
    pub fn fcc_endpoint(&self, utc_at_zero: Timestamp) -> EndpointConfig {
        EndpointConfig {
            local_id: self.fcc,
            peer_id: self.gcs,
            utc_at_zero,
        }
    }

    /// The endpoint of the GCS (from the GCS to the FCC) whose instant zero is `utc_at_zero`.
    pub fn gcs_endpoint(&self, utc_at_zero: Timestamp) -> EndpointConfig {
        EndpointConfig {
            local_id: self.gcs,
            peer_id: self.fcc,
            utc_at_zero,
        }
    }
}

/// The UDP ports of the two links (ICD §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Links {
    /// The FCC receives the direct link here. Port 0: the system chooses one when
    /// voting-monitoring binds it, which announces it in the state directory
    /// (`missionlink_partitions::state::BoundLinks`) and binds it again after a restart.
    pub fcc_direct: SocketAddr,
    /// The GCS receives the direct link here.
    pub gcs_direct: SocketAddr,
    /// The FCC receives the LTE link here (port 0 as for `fcc_direct`).
    pub fcc_lte: SocketAddr,
    /// The GCS receives the LTE link here.
    pub gcs_lte: SocketAddr,
}

fn addr(s: &str) -> SocketAddr {
    // The defaults are literals of the ICD.
    s.parse().unwrap_or(SocketAddr::from(([127, 0, 0, 1], 0)))
}

impl Default for Links {
    fn default() -> Self {
        Self {
            fcc_direct: addr(defaults::FCC_DIRECT),
            gcs_direct: addr(defaults::GCS_DIRECT),
            fcc_lte: addr(defaults::FCC_LTE),
            gcs_lte: addr(defaults::GCS_LTE),
        }
    }
}

/// Timeouts (ICD §1, §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Timing {
    /// How long a sender waits for an answer before its one retry.
    pub ack_timeout_ms: u64,
    /// How long a receiver in a transfer waits for its peer.
    pub transfer_timeout_ms: u64,
    /// Data messages the GCS keeps in flight toward an edition-2 FCC, 1..=128 (ICD §10.2): its
    /// uploads' window, and the one its download requests ask for up to the 32 their field
    /// holds. Toward edition 1 it is 1. Toward an FCC built from the shared contract alone,
    /// whose receivers accept 32, at most 32 (ICD §13).
    /// Above 1 the GCS also sends what ICD §10.3 allows without waiting, and sizes its window
    /// to the link at or below this (ICD §10.4); 1 keeps every message stop-and-wait.
    pub transfer_window: u8,
    /// How often the GCS attempts an upload in all, at least 1: an attempt that failed with
    /// the lists as they were, for a cause that may pass (no answer, `Busy`, `WrongState`), is
    /// begun again once more by default.
    pub upload_attempts: u8,
    /// The rate of the link toward the FCC in bit/s, when the operator knows it (a satellite
    /// terminal's guaranteed rate, say); 0: not known. The GCS's window then keeps in flight at
    /// most what the link carries in its shortest round trip measured (ICD §10.4), so that a
    /// window does not only build a queue in the terminal.
    pub uplink_rate_bps: u64,
}

impl Default for Timing {
    fn default() -> Self {
        Self {
            ack_timeout_ms: defaults::ACK_TIMEOUT.as_millis() as u64,
            transfer_timeout_ms: defaults::TRANSFER_TIMEOUT.as_millis() as u64,
            transfer_window: MAX_WINDOW as u8,
            upload_attempts: 2,
            uplink_rate_bps: 0,
        }
    }
}

impl Timing {
    /// The ack timeout.
    pub fn ack_timeout(&self) -> Duration {
        Duration::from_millis(self.ack_timeout_ms)
    }
    /// The transfer timeout.
    pub fn transfer_timeout(&self) -> Duration {
        Duration::from_millis(self.transfer_timeout_ms)
    }
    /// The rate of the link toward the FCC, if known.
    pub fn uplink_rate(&self) -> Option<u64> {
        (self.uplink_rate_bps > 0).then_some(self.uplink_rate_bps)
    }

    /// The transfer window, clamped to 1..=128.
    pub fn transfer_window(&self) -> u8 {
        self.transfer_window.clamp(1, MAX_WINDOW as u8)
    }
}

/// What a receiver does with signature trailers (ICD §9); see
/// [`missionlink_protocol::link::signing::Policy`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum SigningPolicy {
    /// Trailers are ignored and not checked (edition 1): for a peer that cannot sign, written
    /// in the configuration or given as a flag, and warned about at every start.
    Off,
    /// A signed frame must verify; unsigned frames are still accepted.
    Accept,
    /// Only frames that verify are accepted: the default, so that with the defaults no stranger
    /// who reaches the links changes anything.
    #[default]
    Require,
}

impl From<SigningPolicy> for missionlink_protocol::link::signing::Policy {
    fn from(p: SigningPolicy) -> Self {
        match p {
            SigningPolicy::Off => Self::Off,
            SigningPolicy::Accept => Self::Accept,
            SigningPolicy::Require => Self::Require,
        }
    }
}

/// Link signing (ICD §9): the receiver's policy and the key files. The keys themselves never
/// enter the configuration (so `--print-config` and the hand-over to the partitions carry
/// paths only); [`crate::keys::LinkSigning::load`] reads them.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Signing {
    /// What this node's receiver does with signature trailers.
    pub policy: SigningPolicy,
    /// Key files (`keys`), one key with its Key ID each: the key in use and those a rotation
    /// brings or retires.
    pub key_files: Vec<PathBuf>,
    /// The Key ID to sign with; may be left out with one key file. No key file: frames go out
    /// unsigned.
    pub send_key_id: Option<u8>,
}

/// The settings of the ground: the link sections of the configuration file. The FCC's own
/// sections may stand in the same file (one file serves both sides); the ground passes over
/// them. Any other section is refused
/// with its line and column, as the FCC refuses it: a misspelt `[signin]` must not leave the
/// ground unsigned without a word. (`missionlink_partitions::config` tests that every section of
/// the FCC's configuration is one the ground passes over.)
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LinkConfig {
    /// Node IDs.
    pub ids: Ids,
    /// UDP links.
    pub links: Links,
    /// Timeouts.
    pub timing: Timing,
    /// Link signing.
    pub signing: Signing,
    /// The FCC's sections, passed over (never read, never written).
    #[serde(skip_serializing)]
    ipc: Option<toml::Value>,
    #[serde(skip_serializing)]
    guidance: Option<toml::Value>,
    #[serde(skip_serializing)]
    latency: Option<toml::Value>,
    #[serde(skip_serializing)]
    launcher: Option<toml::Value>,
    #[serde(skip_serializing)]
    health: Option<toml::Value>,
    #[serde(skip_serializing)]
    realtime: Option<toml::Value>,
    #[serde(skip_serializing)]
    isolation: Option<toml::Value>,
    #[serde(skip_serializing)]
    bridge: Option<toml::Value>,
    #[serde(skip_serializing)]
    downlink: Option<toml::Value>,
}

impl LinkConfig {
    /// The link sections, without the FCC's.
    pub fn new(ids: Ids, links: Links, timing: Timing, signing: Signing) -> Self {
        Self {
            ids,
            links,
            timing,
            signing,
            ..Self::default()
        }
    }

    /// The configuration `args` name (handed over as TOML, a file or the defaults) with the
    /// link flags applied.
    pub fn resolve(args: &LinkArgs) -> Result<Self, ConfigError> {
        let mut c: Self = args.load()?;
        args.apply_link(&mut c.ids, &mut c.links, &mut c.timing, &mut c.signing);
        Ok(c)
    }
}

/// A configuration file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The file cannot be read.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// The TOML is wrong: line, column and what.
    #[error("{path}:{line}:{column}: {message}")]
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The resolved configuration cannot be written as TOML (a path that is not UTF-8, say), so
    /// it could not be handed to the partitions: refused, rather than let them start with the
    /// defaults.
    #[error("the configuration cannot be written as TOML: {message}")]
    Unrepresentable {
        /// What TOML could not represent.
        message: String,
    },
}

/// 1-based line and column of byte `offset` in `text`.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// Parses the configuration `text` as `C` (the ground's [`LinkConfig`] or the FCC's whole
/// configuration); `path` names it in errors, which give its line and column.
pub fn parse<C: DeserializeOwned>(text: &str, path: &Path) -> Result<C, ConfigError> {
    toml::from_str(text).map_err(|e| {
        let (line, column) = e
            .span()
            .map_or((0, 0), |span| line_column(text, span.start));
        ConfigError::Syntax {
            path: path.to_owned(),
            line,
            column,
            message: e.message().to_owned(),
        }
    })
}

/// The configuration of `path` as `C`, or `C`'s defaults without one.
pub fn load<C: DeserializeOwned + Default>(path: Option<&Path>) -> Result<C, ConfigError> {
    match path {
        None => Ok(C::default()),
        Some(p) => {
            let text = std::fs::read_to_string(p).map_err(|error| ConfigError::Io {
                path: p.to_owned(),
                error,
            })?;
            parse(&text, p)
        }
    }
}

/// A 32-bit node ID, decimal or `0x` hexadecimal.
pub fn parse_id(s: &str) -> Result<u32, String> {
    let t = s.trim();
    match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16),
        None => t.parse(),
    }
    .map_err(|e| format!("{s:?} is not a 32-bit ID: {e}"))
}

/// The environment variable naming the configuration file (`--config`).
pub const CONFIG_FILE_ENV: &str = "MISSIONLINK_CONFIG";
/// The environment variable of the service-name prefix (`--prefix`).
pub const PREFIX_ENV: &str = "MISSIONLINK_PREFIX";
/// The environment variable carrying a whole configuration as TOML text: how the launcher, the
/// demo and the tests hand a resolved configuration to a child process, with no file that a
/// `kill -9` could leave behind.
pub const CONFIG_TOML_ENV: &str = "MISSIONLINK_CONFIG_TOML";

/// The flags of the link, which the FCC's binaries and the gcs tool alike take: a configuration
/// file and overrides of the link sections' most used settings ([`LinkConfig::resolve`]). The
/// FCC's own flags are its binaries' alone (`missionlink_partitions::config::FccArgs`): the
/// ground neither takes nor shows them.
#[derive(Debug, Clone, Default, Args)]
pub struct LinkArgs {
    /// Configuration file (TOML); every setting has a built-in default.
    #[arg(long, value_name = "FILE", env = CONFIG_FILE_ENV)]
    pub config: Option<PathBuf>,
    /// A whole configuration as TOML text, in place of `--config` (see
    /// `missionlink_partitions::config::hand_to`).
    #[arg(long, hide = true, value_name = "TOML", env = CONFIG_TOML_ENV)]
    pub config_toml: Option<String>,
    /// GCS (CUCS) ID.
    #[arg(long, value_parser = parse_id)]
    pub gcs_id: Option<u32>,
    /// FCC (vehicle) ID.
    #[arg(long, value_parser = parse_id)]
    pub fcc_id: Option<u32>,
    /// Where the FCC receives the direct link.
    #[arg(long, value_name = "ADDR")]
    pub fcc_direct: Option<SocketAddr>,
    /// Where the FCC receives the LTE link.
    #[arg(long, value_name = "ADDR")]
    pub fcc_lte: Option<SocketAddr>,
    /// Where the GCS receives the direct link.
    #[arg(long, value_name = "ADDR")]
    pub gcs_direct: Option<SocketAddr>,
    /// Where the GCS receives the LTE link.
    #[arg(long, value_name = "ADDR")]
    pub gcs_lte: Option<SocketAddr>,
    /// Ack timeout in ms.
    #[arg(long, value_name = "MS")]
    pub ack_timeout_ms: Option<u64>,
    /// Transfer timeout in ms.
    #[arg(long, value_name = "MS")]
    pub transfer_timeout_ms: Option<u64>,
    /// Data messages in flight toward an edition-2 FCC, 1..=32 (ICD §10).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=32))]
    pub transfer_window: Option<u8>,
    /// How often the GCS attempts an upload in all (a failed attempt that left the lists as
    /// they were is begun again).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..))]
    pub upload_attempts: Option<u8>,
    /// The link's rate toward the FCC in bit/s, if known (0: not known): the GCS's window keeps
    /// in flight at most what the link carries in a round trip (ICD §10.4).
    #[arg(long, value_name = "BPS")]
    pub uplink_rate_bps: Option<u64>,
    /// What this node's receiver does with link signatures (ICD §9).
    #[arg(long, value_name = "POLICY")]
    pub signing: Option<SigningPolicy>,
    /// A link key file (ICD §9; `gcs keygen` writes one); repeat for several keys. Replaces the
    /// configuration's key files.
    #[arg(long = "key-file", value_name = "FILE")]
    pub key_files: Vec<PathBuf>,
    /// The Key ID to sign with (needed with several key files).
    #[arg(long, value_name = "ID")]
    pub send_key_id: Option<u8>,
}

impl LinkArgs {
    /// The configuration handed over as TOML ([`CONFIG_TOML_ENV`]), else the file's, else the
    /// defaults, as `C`; no flag applied yet.
    pub fn load<C: DeserializeOwned + Default>(&self) -> Result<C, ConfigError> {
        match &self.config_toml {
            Some(text) => parse(text, Path::new(CONFIG_TOML_ENV)),
            None => load(self.config.as_deref()),
        }
    }

    /// Applies the flags of the link sections, the ones both sides take.
    pub fn apply_link(
        &self,
        ids: &mut Ids,
        links: &mut Links,
        timing: &mut Timing,
        signing: &mut Signing,
    ) {
        if let Some(v) = self.gcs_id {
            ids.gcs = v;
        }
        if let Some(v) = self.fcc_id {
            ids.fcc = v;
        }
        if let Some(v) = self.fcc_direct {
            links.fcc_direct = v;
        }
        if let Some(v) = self.fcc_lte {
            links.fcc_lte = v;
        }
        if let Some(v) = self.gcs_direct {
            links.gcs_direct = v;
        }
        if let Some(v) = self.gcs_lte {
            links.gcs_lte = v;
        }
        if let Some(v) = self.ack_timeout_ms {
            timing.ack_timeout_ms = v;
        }
        if let Some(v) = self.transfer_timeout_ms {
            timing.transfer_timeout_ms = v;
        }
        if let Some(v) = self.transfer_window {
            timing.transfer_window = v;
        }
        if let Some(v) = self.upload_attempts {
            timing.upload_attempts = v;
        }
        if let Some(v) = self.uplink_rate_bps {
            timing.uplink_rate_bps = v;
        }
        if let Some(p) = self.signing {
            signing.policy = p;
        }
        if !self.key_files.is_empty() {
            signing.key_files = self.key_files.clone();
        }
        if let Some(id) = self.send_key_id {
            signing.send_key_id = Some(id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ground_reads_the_link_sections_of_an_fcc_file_and_passes_over_the_rest() {
        let text = "[ids]\ngcs = 0x0A000009\n\n[ipc]\nservice_prefix = \"x\"\n\n\
                    [launcher]\nwithout = [\"guidance-stub\"]\n\n[signing]\npolicy = \"accept\"\n";
        let c: LinkConfig = parse(text, Path::new("fcc.toml")).unwrap();
        assert_eq!(c.ids.gcs, 0x0A00_0009);
        assert_eq!(c.ids.fcc, defaults::FCC_ID);
        assert_eq!(c.signing.policy, SigningPolicy::Accept);
        assert_eq!(c.timing, Timing::default());
    }

    #[test]
    fn a_section_neither_side_reads_is_refused_with_its_line() {
        let e = parse::<LinkConfig>(
            "[ids]\ngcs = 1\n\n[signin]\npolicy = \"require\"\n",
            Path::new("gcs.toml"),
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("gcs.toml:4:"), "{e}");
        assert!(e.to_string().contains("signin"), "{e}");
    }

    #[test]
    fn a_wrong_link_setting_names_file_line_and_column() {
        let e = parse::<LinkConfig>("[ids]\ngcs = 1\nfcc = \"x\"\n", Path::new("gcs.toml"))
            .unwrap_err();
        assert!(e.to_string().starts_with("gcs.toml:3:7: "), "{e}");
        let e = parse::<LinkConfig>("[timing]\nack_timeout = 5\n", Path::new("f")).unwrap_err();
        assert!(e.to_string().starts_with("f:2:1: "), "{e}");
    }

    #[test]
    fn the_link_flags_override_the_handed_over_configuration() {
        let args = LinkArgs {
            config_toml: Some("[timing]\nack_timeout_ms = 900\nuplink_rate_bps = 64000\n".into()),
            fcc_id: Some(7),
            transfer_window: Some(4),
            signing: Some(SigningPolicy::Require),
            ..LinkArgs::default()
        };
        let c = LinkConfig::resolve(&args).unwrap();
        assert_eq!(c.timing.ack_timeout(), Duration::from_millis(900));
        assert_eq!(c.ids.fcc, 7);
        assert_eq!(c.timing.transfer_window, 4);
        assert_eq!(c.timing.uplink_rate(), Some(64_000));
        assert_eq!(
            LinkConfig::default().timing.uplink_rate(),
            None,
            "not known"
        );
        assert_eq!(c.signing.policy, SigningPolicy::Require);
    }

    #[test]
    fn line_column_counts_from_one_in_characters() {
        let text = "a\nbé c";
        assert_eq!(line_column(text, 0), (1, 1));
        assert_eq!(line_column(text, 2), (2, 1));
        assert_eq!(line_column(text, text.len()), (2, 5));
        assert_eq!(parse_id("0x0B000001"), Ok(0x0B00_0001));
        assert!(parse_id("x").is_err());
    }
}
