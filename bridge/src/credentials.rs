//! The bridges' credentials for mutual TLS (docs/two-hosts.md, "Credentials"): how they are made
//! ([`generate`], the `bridge credentials` command), how a bridge reads and checks its own
//! ([`Credentials::read`]), and how they reach Zenoh ([`Credentials::zenoh_settings`]).
//!
//! One command makes a certificate authority of the deployment's own and one certificate per
//! host, signed by it, with the addresses the host listens on as its names (the connecting
//! bridge checks the listening one's address against them). Each host gets a directory of
//! three files:
//!
//! | file | what |
//! |---|---|
//! | `ca.pem` | the authority's certificate: a peer is taken only with a certificate it signed |
//! | `certificate.pem` | this host's certificate (server and client use), presented to the peer |
//! | `private-key.pem` | this host's private key (ECDSA P-256, PKCS #8) |
//!
//! The authority's private key is never written: nobody, not even whoever holds a host's
//! directory, can sign another certificate the bridges accept. Adding a host or renewing (after
//! ten years) means making a new set for every host.
//!
//! A bridge refuses a credential file that group or others may read or write, as ssh refuses
//! such a private key (and `platform`'s link keys refuse such a file), and a file that holds no
//! PEM block of its kind. It reads the files once, before it fences itself, and hands Zenoh
//! their contents (base64, Zenoh's `*_base64` settings), so what Zenoh uses is what was checked.
//! No error message, log line or `Debug` output carries the private key.

use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime};

use base64::Engine;

/// The authority's certificate in a host's directory.
pub const CA_FILE: &str = "ca.pem";
/// The host's certificate.
pub const CERTIFICATE_FILE: &str = "certificate.pem";
/// The host's private key.
pub const PRIVATE_KEY_FILE: &str = "private-key.pem";

/// How long the certificates are valid: ten years, from an hour before they were made (a peer
/// whose clock is a little behind still takes them).
const VALIDITY: Duration = Duration::from_secs(3_650 * 24 * 3_600);
const CLOCK_SLACK: Duration = Duration::from_secs(3_600);

/// Why credentials cannot be read or made. Never holds key material.
#[derive(Debug, thiserror::Error)]
pub enum CredentialError {
    /// A file or directory cannot be read or written (an existing one is never overwritten).
    #[error("{path}: {error}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// Group or others may read or write a credential file.
    #[error(
        "{path}: a bridge credential must be readable by its owner only, and this file has mode {:04o}; \
         run `chmod 600 {path}`",
        .mode & 0o7777
    )]
    Exposed {
        /// The file.
        path: PathBuf,
        /// Its permission bits.
        mode: u32,
    },
    /// A file that holds no PEM block of its kind (a certificate, a private key).
    #[error("{path}: not a {expected} in PEM: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What it should hold.
        expected: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A `--host` that is not `NAME` or `NAME=ADDRESS[,ADDRESS...]`.
    #[error(
        "--host {0:?}: not NAME or NAME=ADDRESS[,ADDRESS...] (NAME of letters, digits, '-' and '_')"
    )]
    Host(String),
    /// Two `--host` with the same name.
    #[error("--host {0:?} is given twice")]
    HostTwice(String),
    /// No `--host` at all.
    #[error("no --host: name at least the two hosts whose bridges meet")]
    NoHosts,
    /// The certificate generator refused (an address that is not an IP address or DNS name).
    #[error("making the certificate of {host}: {message}")]
    Generate {
        /// The host, or "the certificate authority".
        host: String,
        /// rcgen's message.
        message: String,
    },
}

/// One host of `bridge credentials --host NAME[=ADDRESS,...]`: its name (its directory, the
/// certificate's common name) and the addresses or DNS names it listens on (the certificate's
/// subject alternative names; none for a host that only connects).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Host {
    /// The host's name.
    pub name: String,
    /// The addresses or names other bridges reach it by (`tls/<address>:<port>`).
    pub addresses: Vec<String>,
}

impl std::str::FromStr for Host {
    type Err = CredentialError;

    fn from_str(spec: &str) -> Result<Self, Self::Err> {
        let (name, addresses) = match spec.split_once('=') {
            Some((name, list)) => (name, list.split(',').map(str::to_owned).collect()),
            None => (spec, Vec::new()),
        };
        let name_ok = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        let addresses: Vec<String> = addresses;
        if !name_ok || addresses.iter().any(String::is_empty) {
            return Err(CredentialError::Host(spec.to_owned()));
        }
        Ok(Self {
            name: name.to_owned(),
            addresses,
        })
    }
}

/// A host's credentials, read and checked ([`Credentials::read`]).
pub struct Credentials {
    ca: Vec<u8>,
    certificate: Vec<u8>,
    private_key: Vec<u8>,
}

impl std::fmt::Debug for Credentials {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Credentials")
            .field("ca", &format_args!("{} bytes", self.ca.len()))
            .field(
                "certificate",
                &format_args!("{} bytes", self.certificate.len()),
            )
            .field("private_key", &format_args!("(secret)"))
            .finish()
    }
}

/// PEM labels of the kinds of file.
const CERTIFICATE_LABELS: &[&str] = &["CERTIFICATE"];
/// The private key forms Zenoh's TLS reads (PKCS #8, SEC 1, PKCS #1).
const KEY_LABELS: &[&str] = &["PRIVATE KEY", "EC PRIVATE KEY", "RSA PRIVATE KEY"];

/// Reads `path` if only its owner may read or write it, and checks that it holds PEM blocks of
/// `labels` only (one, for a key).
fn read_checked(
    path: &Path,
    expected: &'static str,
    labels: &[&str],
    one: bool,
) -> Result<Vec<u8>, CredentialError> {
    let io = |error| CredentialError::Io {
        path: path.to_owned(),
        error,
    };
    let mode = std::fs::metadata(path).map_err(io)?.permissions().mode();
    if mode & 0o077 != 0 {
        return Err(CredentialError::Exposed {
            path: path.to_owned(),
            mode,
        });
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let format = |message: String| CredentialError::Format {
        path: path.to_owned(),
        expected,
        message,
    };
    // The parser's message names the block's label and position, never its contents.
    let blocks = pem::parse_many(&bytes).map_err(|e| format(e.to_string()))?;
    if blocks.is_empty() {
        return Err(format("no PEM block".to_owned()));
    }
    if let Some(other) = blocks.iter().find(|b| !labels.contains(&b.tag())) {
        return Err(format(format!("a block \"{}\"", other.tag())));
    }
    if one && blocks.len() > 1 {
        return Err(format(format!("{} blocks, one expected", blocks.len())));
    }
    Ok(bytes)
}

impl Credentials {
    /// Reads the three files of a host's directory `dir` ([`CA_FILE`], [`CERTIFICATE_FILE`],
    /// [`PRIVATE_KEY_FILE`]), refusing one that group or others may read or write, or that
    /// holds no PEM block of its kind.
    pub fn read(dir: &Path) -> Result<Self, CredentialError> {
        Ok(Self {
            ca: read_checked(&dir.join(CA_FILE), "certificate", CERTIFICATE_LABELS, false)?,
            certificate: read_checked(
                &dir.join(CERTIFICATE_FILE),
                "certificate",
                CERTIFICATE_LABELS,
                false,
            )?,
            private_key: read_checked(
                &dir.join(PRIVATE_KEY_FILE),
                "private key",
                KEY_LABELS,
                true,
            )?,
        })
    }

    /// Zenoh's settings (key, JSON5 value) for mutual TLS with these credentials: the authority
    /// as the only root it adds, this host's certificate and key both when it listens and when
    /// it connects, client certificates required (`enable_mtls`), and the listening peer's
    /// address checked against its certificate's names (`verify_name_on_connect`).
    pub fn zenoh_settings(&self) -> Vec<(&'static str, String)> {
        let b64 = |bytes: &[u8]| {
            // Base64 needs no escaping inside a JSON string.
            format!(
                "\"{}\"",
                base64::engine::general_purpose::STANDARD.encode(bytes)
            )
        };
        vec![
            (
                "transport/link/tls/root_ca_certificate_base64",
                b64(&self.ca),
            ),
            (
                "transport/link/tls/listen_certificate_base64",
                b64(&self.certificate),
            ),
            (
                "transport/link/tls/listen_private_key_base64",
                b64(&self.private_key),
            ),
            (
                "transport/link/tls/connect_certificate_base64",
                b64(&self.certificate),
            ),
            (
                "transport/link/tls/connect_private_key_base64",
                b64(&self.private_key),
            ),
            ("transport/link/tls/enable_mtls", "true".to_owned()),
            (
                "transport/link/tls/verify_name_on_connect",
                "true".to_owned(),
            ),
        ]
    }
}

/// Makes a certificate authority and a certificate per host of `hosts`, and writes each host's
/// directory `out/<name>` (mode 0700) with its three files (mode 0600). `out` is created if
/// missing; a host's directory that exists already is an error (nothing is overwritten). The
/// directories written, in the order of `hosts`.
pub fn generate(out: &Path, hosts: &[Host]) -> Result<Vec<PathBuf>, CredentialError> {
    if hosts.is_empty() {
        return Err(CredentialError::NoHosts);
    }
    for (i, host) in hosts.iter().enumerate() {
        if hosts.iter().skip(i + 1).any(|h| h.name == host.name) {
            return Err(CredentialError::HostTwice(host.name.clone()));
        }
    }
    let generate_err = |host: &str| {
        let host = host.to_owned();
        move |e: rcgen::Error| CredentialError::Generate {
            host: host.clone(),
            message: e.to_string(),
        }
    };
    let now = SystemTime::now();
    let not_before = now.checked_sub(CLOCK_SLACK).unwrap_or(now);
    let not_after = now.checked_add(VALIDITY).unwrap_or(now);
    let authority = "the certificate authority";

    let ca_key = rcgen::KeyPair::generate().map_err(generate_err(authority))?;
    let mut ca_params = rcgen::CertificateParams::default();
    ca_params.distinguished_name = rcgen::DistinguishedName::new();
    ca_params
        .distinguished_name
        .push(rcgen::DnType::OrganizationName, "missionlink");
    ca_params
        .distinguished_name
        .push(rcgen::DnType::CommonName, "missionlink bridge authority");
    // It signs host certificates only, never another authority.
    ca_params.is_ca = rcgen::IsCa::Ca(rcgen::BasicConstraints::Constrained(0));
    ca_params.key_usages = vec![
        rcgen::KeyUsagePurpose::KeyCertSign,
        rcgen::KeyUsagePurpose::CrlSign,
    ];
    ca_params.not_before = not_before.into();
    ca_params.not_after = not_after.into();
    let ca_certificate = ca_params
        .self_signed(&ca_key)
        .map_err(generate_err(authority))?;
    let issuer = rcgen::Issuer::new(ca_params, ca_key);

    // Every certificate first, then the files: an address rcgen refuses leaves nothing behind.
    let mut made = Vec::new();
    for host in hosts {
        let key = rcgen::KeyPair::generate().map_err(generate_err(&host.name))?;
        let mut params = rcgen::CertificateParams::new(host.addresses.clone())
            .map_err(generate_err(&host.name))?;
        params.distinguished_name = rcgen::DistinguishedName::new();
        params
            .distinguished_name
            .push(rcgen::DnType::OrganizationName, "missionlink");
        params
            .distinguished_name
            .push(rcgen::DnType::CommonName, format!("bridge {}", host.name));
        params.key_usages = vec![rcgen::KeyUsagePurpose::DigitalSignature];
        // A host's bridge may listen or connect, whichever its configuration says.
        params.extended_key_usages = vec![
            rcgen::ExtendedKeyUsagePurpose::ServerAuth,
            rcgen::ExtendedKeyUsagePurpose::ClientAuth,
        ];
        params.use_authority_key_identifier_extension = true;
        params.not_before = not_before.into();
        params.not_after = not_after.into();
        let certificate = params
            .signed_by(&key, &issuer)
            .map_err(generate_err(&host.name))?;
        made.push((host, certificate.pem(), key.serialize_pem()));
    }

    let io = |path: &Path| {
        let path = path.to_owned();
        move |error| CredentialError::Io {
            path: path.clone(),
            error,
        }
    };
    // A host's directory that exists already stops the command before anything is written.
    for (host, _, _) in &made {
        let dir = out.join(&host.name);
        if dir.exists() {
            return Err(CredentialError::Io {
                error: std::io::Error::from(std::io::ErrorKind::AlreadyExists),
                path: dir,
            });
        }
    }
    std::fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(out)
        .map_err(io(out))?;
    let ca_pem = ca_certificate.pem();
    let mut dirs = Vec::new();
    for (host, certificate, key) in made {
        let dir = out.join(&host.name);
        std::fs::DirBuilder::new()
            .mode(0o700)
            .create(&dir)
            .map_err(io(&dir))?;
        for (file, text) in [
            (CA_FILE, &ca_pem),
            (CERTIFICATE_FILE, &certificate),
            (PRIVATE_KEY_FILE, &key),
        ] {
            let path = dir.join(file);
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .mode(0o600)
                .open(&path)
                .map_err(io(&path))?;
            f.write_all(text.as_bytes())
                .and_then(|()| f.sync_all())
                .map_err(io(&path))?;
        }
        dirs.push(dir);
    }
    Ok(dirs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hosts() -> Vec<Host> {
        vec![
            "fcc=169.254.77.1".parse().unwrap(),
            "guidance".parse().unwrap(),
        ]
    }

    #[test]
    fn hosts_are_a_name_and_the_addresses_it_listens_on() {
        assert_eq!(
            "fcc=192.0.2.1,fcc.local".parse::<Host>().unwrap(),
            Host {
                name: "fcc".to_owned(),
                addresses: vec!["192.0.2.1".to_owned(), "fcc.local".to_owned()]
            }
        );
        assert!("guidance_b-2".parse::<Host>().unwrap().addresses.is_empty());
        for bad in [
            "",
            "=1.2.3.4",
            "a/b=1.2.3.4",
            "../x",
            "fcc=",
            "fcc=1.2.3.4,",
        ] {
            assert!(
                matches!(bad.parse::<Host>(), Err(CredentialError::Host(_))),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn made_credentials_are_owner_only_and_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("credentials");
        let made = generate(&out, &hosts()).unwrap();
        assert_eq!(made, [out.join("fcc"), out.join("guidance")]);
        for host in &made {
            let mode = std::fs::metadata(host).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o700, "{}", host.display());
            for file in [CA_FILE, CERTIFICATE_FILE, PRIVATE_KEY_FILE] {
                let mode = std::fs::metadata(host.join(file))
                    .unwrap()
                    .permissions()
                    .mode();
                assert_eq!(mode & 0o777, 0o600, "{file}");
            }
            let credentials = Credentials::read(host).unwrap();
            let settings = credentials.zenoh_settings();
            assert!(
                settings
                    .iter()
                    .any(|(k, v)| *k == "transport/link/tls/enable_mtls" && v == "true")
            );
            assert!(!format!("{credentials:?}").contains("PRIVATE"));
        }
        // Both hosts share the authority; each has its own key.
        let read = |host: &str, file: &str| std::fs::read(out.join(host).join(file)).unwrap();
        assert_eq!(read("fcc", CA_FILE), read("guidance", CA_FILE));
        assert_ne!(
            read("fcc", PRIVATE_KEY_FILE),
            read("guidance", PRIVATE_KEY_FILE)
        );
        // No file holds the authority's private key.
        let keys = std::fs::read_dir(out.join("fcc")).unwrap().count();
        assert_eq!(keys, 3);
        // Nothing is overwritten, and a set with a host that exists writes nothing at all.
        assert!(matches!(
            generate(&out, &hosts()[..1]),
            Err(CredentialError::Io { .. })
        ));
        let new_and_old = vec!["new".parse().unwrap(), hosts()[1].clone()];
        assert!(matches!(
            generate(&out, &new_and_old),
            Err(CredentialError::Io { path, .. }) if path == out.join("guidance")
        ));
        assert!(!out.join("new").exists());
    }

    #[test]
    fn a_credential_that_group_or_others_may_read_is_refused_with_the_chmod_hint() {
        let dir = tempfile::tempdir().unwrap();
        let made = generate(dir.path(), &hosts()).unwrap();
        let fcc = &made[0];
        for file in [PRIVATE_KEY_FILE, CERTIFICATE_FILE, CA_FILE] {
            let path = fcc.join(file);
            for mode in [0o640, 0o604, 0o620] {
                std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode)).unwrap();
                let refusal = Credentials::read(fcc).unwrap_err();
                assert!(
                    matches!(&refusal, CredentialError::Exposed { path: p, .. } if *p == path),
                    "{refusal}"
                );
                let message = refusal.to_string();
                assert!(
                    message.contains(&format!("chmod 600 {}", path.display())),
                    "{message}"
                );
                assert!(message.contains(&format!("{mode:04o}")), "{message}");
            }
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        }
        assert!(Credentials::read(fcc).is_ok());
    }

    #[test]
    fn a_missing_or_wrong_credential_file_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let made = generate(dir.path(), &hosts()).unwrap();
        let fcc = &made[0];
        let write = |file: &str, text: &str| {
            let path = fcc.join(file);
            std::fs::write(&path, text).unwrap();
            path
        };
        // The key where the certificate belongs: refused, and the message quotes no key.
        let key = std::fs::read_to_string(fcc.join(PRIVATE_KEY_FILE)).unwrap();
        let path = write(CERTIFICATE_FILE, &key);
        let refusal = Credentials::read(fcc).unwrap_err();
        assert!(
            matches!(&refusal, CredentialError::Format { path: p, .. } if *p == path),
            "{refusal}"
        );
        let secret_line = key.lines().nth(1).unwrap();
        assert!(!refusal.to_string().contains(secret_line), "{refusal}");
        // Not PEM at all.
        write(CERTIFICATE_FILE, "hello\n");
        assert!(matches!(
            Credentials::read(fcc),
            Err(CredentialError::Format { .. })
        ));
        // Missing.
        std::fs::remove_file(fcc.join(CERTIFICATE_FILE)).unwrap();
        assert!(matches!(
            Credentials::read(fcc),
            Err(CredentialError::Io { .. })
        ));
    }

    #[test]
    fn hosts_must_be_named_once() {
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(
            generate(dir.path(), &[]),
            Err(CredentialError::NoHosts)
        ));
        let twice = vec![hosts()[0].clone(), hosts()[0].clone()];
        assert!(matches!(
            generate(dir.path(), &twice),
            Err(CredentialError::HostTwice(_))
        ));
        let bad = vec![Host {
            name: "x".to_owned(),
            addresses: vec!["ünïcode".to_owned()],
        }];
        assert!(matches!(
            generate(&dir.path().join("bad"), &bad),
            Err(CredentialError::Generate { .. })
        ));
        assert!(!dir.path().join("bad").exists(), "nothing written");
    }
}
