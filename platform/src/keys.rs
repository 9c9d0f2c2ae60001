//! Link key files (ICD §9): one 32-byte key with its Key ID per file, readable by its owner
//! only, and the signing of one node as its configuration says (`[signing]`).
//!
//! A key file is TOML, so an operator can tell keys apart without a tool:
//!
//! ```toml
//! # missionlink link key (ICD §9): secret, mode 0600
//! key_id = 1
//! key = "<64 hexadecimal digits>"
//! ```
//!
//! A file that group or others may read or write is refused, as ssh refuses such a private key:
//! the key is the only thing between a stranger on the LTE network and the mission. No error
//! message, log line or `Debug` output carries key material.

use std::io::Write;
use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use missionlink_interfaces::wire::Timestamp;
use missionlink_protocol::link::signing::{
    KEY_LEN, Keyring, KeyringError, LinkKey, Policy, SignatureCheck, Signer,
};
use missionlink_protocol::link::time::Instant;
use serde::Deserialize;

use crate::config::Signing;

/// A key file or a signing configuration that cannot be used. Never holds key material.
#[derive(Debug, thiserror::Error)]
pub enum KeyError {
    /// The file cannot be read or written.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// Group or others may read or write the file.
    #[error(
        "{path}: a link key must be readable by its owner only, and this file has mode {:04o}; \
         run `chmod 600 {path}`",
        .mode & 0o7777
    )]
    Exposed {
        /// The file.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
    },
    /// The file is not a key file: what is wrong (never the key's value).
    #[error("{path}: not a link key file: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Two key files, or more than the keyring holds.
    #[error("{path}: {error}")]
    Keyring {
        /// The file that did not fit.
        path: PathBuf,
        /// Why.
        error: KeyringError,
    },
    /// The signing configuration contradicts itself.
    #[error("signing: {0}")]
    Config(String),
    /// The policy checks signatures (`require`, the default, or `accept`) and no key file is
    /// configured: the one line says how to make a key and how to run unsigned on purpose.
    #[error(
        "the link signing policy is {policy} (ICD §9) and no key file is configured: make a key with \
         `gcs keygen --fcc /etc/missionlink/link.key --ground ~/.config/missionlink/link.key` and \
         name each side's file in [signing] key_files (or --key-file); only for a peer that \
         cannot sign, write policy = \"off\" in [signing] (or --signing off)"
    )]
    NoKey {
        /// The policy configured.
        policy: Policy,
    },
}

/// The fields of a key file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyFile {
    key_id: u8,
    key: String,
}

/// Reads the key file at `path`.
pub fn read_key_file(path: &Path) -> Result<LinkKey, KeyError> {
    let io = |error| KeyError::Io {
        path: path.to_owned(),
        error,
    };
    let mode = std::fs::metadata(path).map_err(io)?.permissions().mode();
    if mode & 0o077 != 0 {
        return Err(KeyError::Exposed {
            path: path.to_owned(),
            mode,
        });
    }
    let text = std::fs::read_to_string(path).map_err(io)?;
    let format = |message: String| KeyError::Format {
        path: path.to_owned(),
        message,
    };
    // The parser's message only: its rendering would quote the line, which may be the key.
    let file: KeyFile = toml::from_str(&text).map_err(|e| {
        let (line, _) = e
            .span()
            .map_or((0, 0), |s| crate::config::line_column(&text, s.start));
        format(format!("line {line}: {}", e.message()))
    })?;
    let secret = parse_secret(&file.key).ok_or_else(|| {
        format(format!(
            "`key` must be {} hexadecimal digits ({KEY_LEN} bytes)",
            2 * KEY_LEN
        ))
    })?;
    Ok(LinkKey::new(file.key_id, &secret))
}

fn parse_secret(hex: &str) -> Option<[u8; KEY_LEN]> {
    let digits = hex.as_bytes();
    if digits.len() != 2 * KEY_LEN {
        return None;
    }
    let mut secret = [0u8; KEY_LEN];
    for (byte, pair) in secret.iter_mut().zip(digits.chunks_exact(2)) {
        let text = std::str::from_utf8(pair).ok()?;
        *byte = u8::from_str_radix(text, 16).ok()?;
    }
    Some(secret)
}

/// Writes a new key file at `path` with Key ID `key_id` and a key from the operating system's
/// random source, readable by its owner only. An existing file is never overwritten.
pub fn generate_key_file(path: &Path, key_id: u8) -> Result<(), KeyError> {
    generate_key_files(&[path], key_id)
}

/// Writes one new key (Key ID `key_id`, from the operating system's random source) to every
/// path of `paths`, the same path once: the FCC's key file and the ground's, which hold the same
/// key (ICD §9). Each is readable by its owner only; a missing directory is made, readable by
/// its owner only. An existing file is never overwritten, and when one cannot be written, the
/// ones written before are removed: all of them are made, or none.
pub fn generate_key_files(paths: &[&Path], key_id: u8) -> Result<(), KeyError> {
    let mut secret = [0u8; KEY_LEN];
    getrandom::fill(&mut secret).map_err(|e| KeyError::Io {
        path: paths.first().map(|p| p.to_path_buf()).unwrap_or_default(),
        error: std::io::Error::other(format!("no random source: {e}")),
    })?;
    let mut written: Vec<&Path> = Vec::new();
    for path in paths {
        if written.contains(path) {
            continue;
        }
        if let Err(e) = write_key_file(path, key_id, &secret) {
            for done in written {
                let _ = std::fs::remove_file(done);
            }
            return Err(e);
        }
        written.push(path);
    }
    Ok(())
}

fn write_key_file(path: &Path, key_id: u8, secret: &[u8; KEY_LEN]) -> Result<(), KeyError> {
    use std::os::unix::fs::DirBuilderExt;
    let io = |error| KeyError::Io {
        path: path.to_owned(),
        error,
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(dir)
            .map_err(io)?;
    }
    let hex: String = secret.iter().map(|b| format!("{b:02x}")).collect();
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .open(path)
        .map_err(io)?;
    writeln!(
        file,
        "# missionlink link key (ICD §9): secret, readable by its owner only\n\
         key_id = {key_id}\n\
         key = \"{hex}\""
    )
    .and_then(|()| file.sync_all())
    .map_err(io)
}

/// The signing of one node, loaded: the keys, the policy of its receiver, and the signer of
/// what it sends (none: it sends unsigned, as edition 1).
#[derive(Debug, Clone)]
pub struct LinkSigning {
    /// The receiver's policy.
    pub policy: Policy,
    /// Every configured key.
    pub keys: Keyring,
    /// The sender's key.
    pub signer: Option<Signer>,
}

impl LinkSigning {
    /// Reads the key files `signing` names and checks that it holds together: a policy that
    /// checks needs a key, the sending key must be one of them, several keys need the sending
    /// one named.
    pub fn load(signing: &Signing) -> Result<Self, KeyError> {
        let mut keys = Keyring::new();
        for path in &signing.key_files {
            let key = read_key_file(path)?;
            keys.insert(key).map_err(|error| KeyError::Keyring {
                path: path.clone(),
                error,
            })?;
        }
        let policy = Policy::from(signing.policy);
        if policy != Policy::Off && keys.is_empty() {
            return Err(KeyError::NoKey { policy });
        }
        let ids: Vec<u8> = keys.ids().collect();
        let send_id = match (signing.send_key_id, ids.as_slice()) {
            (Some(id), _) => Some(id),
            (None, []) => None,
            (None, [only]) => Some(*only),
            (None, _) => {
                return Err(KeyError::Config(format!(
                    "keys {ids:?} are configured: name the one to sign with (send_key_id)"
                )));
            }
        };
        let signer = match send_id {
            None => None,
            Some(id) => Some(Signer::new(keys.get(id).cloned().ok_or_else(|| {
                KeyError::Config(format!(
                    "send_key_id = {id}, and no configured key file has that Key ID ({ids:?})"
                ))
            })?)),
        };
        Ok(Self {
            policy,
            keys,
            signer,
        })
    }

    /// The receiver's check, on a driver clock whose instant zero is `utc_at_zero`, started at
    /// `now`.
    pub fn check(&self, utc_at_zero: Timestamp, now: Instant) -> SignatureCheck {
        SignatureCheck::new(self.policy, self.keys.clone(), utc_at_zero, now)
    }

    /// One line for the start-up log: the policy and Key IDs, never a key.
    pub fn summary(&self) -> String {
        let ids: Vec<u8> = self.keys.ids().collect();
        match &self.signer {
            Some(s) => format!(
                "policy {}, keys {ids:?}, signing with key {}",
                self.policy,
                s.key_id()
            ),
            None => format!("policy {}, keys {ids:?}, sending unsigned", self.policy),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SigningPolicy;

    fn write(dir: &Path, name: &str, text: &str, mode: u32) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode)).unwrap();
        path
    }

    const HEX: &str = "000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f";

    #[test]
    fn a_generated_key_file_is_private_and_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("link.key");
        generate_key_file(&path, 7).unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
        assert_eq!(read_key_file(&path).unwrap().id(), 7);
        // Never overwritten.
        assert!(matches!(
            generate_key_file(&path, 8),
            Err(KeyError::Io { .. })
        ));
        // Two generated keys differ.
        let other = dir.path().join("other.key");
        generate_key_file(&other, 7).unwrap();
        assert_ne!(
            std::fs::read_to_string(&path).unwrap(),
            std::fs::read_to_string(&other).unwrap()
        );
    }

    #[test]
    fn one_key_is_written_to_the_fccs_and_the_grounds_file_or_to_none() {
        let dir = tempfile::tempdir().unwrap();
        let fcc = dir.path().join("fcc/etc/link.key");
        let ground = dir.path().join("ground.key");
        generate_key_files(&[&fcc, &ground], 3).unwrap();
        for path in [&fcc, &ground] {
            let mode = std::fs::metadata(path).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o600, "{path:?}");
        }
        let dir_mode = std::fs::metadata(fcc.parent().unwrap())
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(dir_mode & 0o777, 0o700);
        assert_eq!(
            std::fs::read_to_string(&fcc).unwrap(),
            std::fs::read_to_string(&ground).unwrap()
        );
        assert_eq!(read_key_file(&fcc).unwrap().id(), 3);
        // The same path twice is one file.
        let same = dir.path().join("same.key");
        generate_key_files(&[&same, &same], 1).unwrap();
        // The second file exists: the first is not left behind.
        let first = dir.path().join("first.key");
        assert!(matches!(
            generate_key_files(&[&first, &ground], 1),
            Err(KeyError::Io { .. })
        ));
        assert!(!first.exists());
    }

    #[test]
    fn a_key_file_others_can_read_is_refused_and_the_message_says_how_to_fix_it() {
        let dir = tempfile::tempdir().unwrap();
        let text = format!("key_id = 1\nkey = \"{HEX}\"\n");
        for mode in [0o644, 0o640, 0o604, 0o620] {
            let path = write(dir.path(), "k", &text, mode);
            let error = read_key_file(&path).unwrap_err();
            let message = error.to_string();
            assert!(matches!(error, KeyError::Exposed { .. }), "{message}");
            assert!(message.contains("chmod 600"), "{message}");
            assert!(message.contains(&format!("{mode:04o}")), "{message}");
        }
        let path = write(dir.path(), "k", &text, 0o400);
        assert_eq!(read_key_file(&path).unwrap().id(), 1);
    }

    #[test]
    fn a_malformed_key_file_is_refused_without_quoting_the_key() {
        let dir = tempfile::tempdir().unwrap();
        for (text, expected) in [
            (
                format!("key_id = 1\nkey = \"{}\"\n", &HEX[..62]),
                "64 hexadecimal",
            ),
            (
                format!("key_id = 1\nkey = \"{}zz\"\n", &HEX[..62]),
                "64 hexadecimal",
            ),
            (format!("key_id = 300\nkey = \"{HEX}\"\n"), "line 1"),
            (format!("key = \"{HEX}\"\n"), "key_id"),
            (format!("key_id = 1\nkey = {HEX}\n"), "line 2"),
        ] {
            let path = write(dir.path(), "k", &text, 0o600);
            let message = read_key_file(&path).unwrap_err().to_string();
            assert!(message.contains(expected), "{text:?}: {message}");
            assert!(!message.contains(&HEX[..16]), "the key leaked: {message}");
        }
    }

    #[test]
    fn the_signing_configuration_must_hold_together() {
        let dir = tempfile::tempdir().unwrap();
        let one = write(
            dir.path(),
            "1",
            &format!("key_id = 1\nkey = \"{HEX}\"\n"),
            0o600,
        );
        let two = write(
            dir.path(),
            "2",
            &format!("key_id = 2\nkey = \"{HEX}\"\n"),
            0o600,
        );
        let dup = write(
            dir.path(),
            "3",
            &format!("key_id = 2\nkey = \"{HEX}\"\n"),
            0o600,
        );
        let signing = |policy, key_files: &[&PathBuf], send_key_id| Signing {
            policy,
            key_files: key_files.iter().map(|p| (*p).clone()).collect(),
            send_key_id,
        };
        let off = LinkSigning::load(&signing(SigningPolicy::Off, &[], None)).unwrap();
        assert_eq!(off.policy, Policy::Off);
        assert!(off.signer.is_none());
        // The default requires a key, and says in one line how to make one.
        let message = LinkSigning::load(&Signing::default())
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("the link signing policy is require"),
            "{message}"
        );
        assert!(message.contains("gcs keygen"), "{message}");
        assert!(message.contains("policy = \"off\""), "{message}");
        assert!(!message.contains('\n'), "{message}");
        let only = LinkSigning::load(&signing(SigningPolicy::Require, &[&one], None)).unwrap();
        assert_eq!(only.signer.unwrap().key_id(), 1);
        let named =
            LinkSigning::load(&signing(SigningPolicy::Accept, &[&one, &two], Some(2))).unwrap();
        assert_eq!(named.signer.as_ref().unwrap().key_id(), 2);
        assert_eq!(
            named.summary(),
            "policy accept, keys [1, 2], signing with key 2"
        );
        for (bad, expected) in [
            (signing(SigningPolicy::Require, &[], None), "no key file"),
            (
                signing(SigningPolicy::Accept, &[], None),
                "policy is accept",
            ),
            (
                signing(SigningPolicy::Off, &[&one, &two], None),
                "send_key_id",
            ),
            (
                signing(SigningPolicy::Off, &[&one], Some(5)),
                "send_key_id = 5",
            ),
            (
                signing(SigningPolicy::Off, &[&two, &dup], Some(2)),
                "Key ID 2",
            ),
        ] {
            let message = LinkSigning::load(&bad).unwrap_err().to_string();
            assert!(message.contains(expected), "{message}");
        }
    }
}
