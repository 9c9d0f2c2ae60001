//! The conversation between a `gcs` command and the ground service, over a Unix stream socket
//! that only the service's user can open: the command sends one [`Call`] as a line of JSON, the
//! service answers with [`Reply`] lines, the last a [`Reply::Finished`] or [`Reply::Failed`]
//! (a monitor's replies go on until the command hangs up).
//!
//! Where the socket is: `--service-socket`, else `$MISSIONLINK_GCS_SOCKET`, else
//! `$XDG_RUNTIME_DIR/missionlink/gcs.sock`, else `gcs.sock` in the state directory. No socket
//! file: no service runs, and a command works alone. A socket file nobody answers on: the
//! service died without removing it, and the command says so rather than fight a restarting
//! service for the links.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::time::Duration;

use missionlink_interfaces::wire::Message;
use serde::{Deserialize, Serialize};

use super::request::{Answer, Failure, Progress, Request};
use super::status::VehicleStatus;

/// What a command asks of the service.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Call {
    /// The vehicle, by its name in the fleet; `None` with a fleet of one.
    pub vehicle: Option<String>,
    /// What.
    pub what: What,
}

/// What a call asks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum What {
    /// A request to the vehicle's ground station.
    Request(Request),
    /// The vehicle's FROM-TO-NEXT and position now, then every report.
    Monitor,
    /// Every vehicle's row (the vehicle of the call is not used).
    Status,
}

/// One line of the service's answer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reply {
    /// A transfer's progress.
    Progress(Progress),
    /// For a monitor: a FROM-TO-NEXT (#4001) or a position (#101). Boxed: a message is the
    /// largest variant by far.
    Event(Box<Message>),
    /// For a status: the rows.
    Status(Vec<VehicleStatus>),
    /// The request ended well.
    Finished(Answer),
    /// The request failed, or the call could not be served.
    Failed(Failure),
}

/// The environment variable naming the service's socket.
pub const SOCKET_ENV: &str = "MISSIONLINK_GCS_SOCKET";

/// Where the service's socket is (see the module documentation); `explicit` first.
pub fn socket_path(explicit: Option<&Path>) -> Option<PathBuf> {
    explicit
        .map(Path::to_owned)
        .or_else(|| {
            std::env::var_os(SOCKET_ENV)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        })
        .or_else(|| {
            std::env::var_os("XDG_RUNTIME_DIR")
                .filter(|v| !v.is_empty())
                .map(|d| PathBuf::from(d).join("missionlink").join("gcs.sock"))
        })
        .or_else(|| Some(super::state_base(None)?.join("gcs.sock")))
}

/// A connection to a running service.
#[derive(Debug)]
pub struct Connection {
    stream: UnixStream,
    path: PathBuf,
}

/// Why a command cannot talk to a service whose socket is there.
pub fn unreachable(path: &Path, why: &dyn std::fmt::Display) -> Failure {
    Failure::other(format!(
        "the ground service's socket {} is there, but no service answers on it ({why}): it \
         stopped without removing it, or is restarting. Start it again (gcs serve), or remove \
         the socket to run commands alone",
        path.display()
    ))
}

impl Connection {
    /// Connects to the service at `path`: `Ok(None)` when no socket file is there (no service
    /// runs); an error when one is, but no service of this user answers.
    pub fn open(path: &Path) -> Result<Option<Self>, Failure> {
        if std::fs::symlink_metadata(path).is_err() {
            return Ok(None);
        }
        let stream = UnixStream::connect(path).map_err(|e| unreachable(path, &e))?;
        // The service must be this user's: another user's process that put a socket there
        // would be handed the mission and the commands.
        let peer =
            rustix::net::sockopt::socket_peercred(&stream).map_err(|e| unreachable(path, &e))?;
        let me = rustix::process::geteuid();
        if peer.uid != me {
            return Err(Failure::other(format!(
                "the ground service's socket {} belongs to a process of user {}, not to this \
                 user ({}): refused",
                path.display(),
                peer.uid.as_raw(),
                me.as_raw()
            )));
        }
        Ok(Some(Self {
            stream,
            path: path.to_owned(),
        }))
    }

    /// Sends `call`; then every reply goes to `on_reply` until one ends the call, which is
    /// returned, or `on_reply` returns false (a monitor that stops: it is also called with
    /// `None` whenever the read timeout passes without a reply). A service that hangs up first
    /// is the error, with `lost_status` as its exit status (what the FCC holds after an upload
    /// the service did not finish is unknown: 5).
    pub fn call(
        self,
        call: &Call,
        lost_status: u8,
        mut on_reply: impl FnMut(Option<&Reply>) -> bool,
    ) -> Result<Option<Reply>, Failure> {
        let Self { mut stream, path } = self;
        let mut line = serde_json::to_string(call).map_err(|e| Failure::other(e.to_string()))?;
        line.push('\n');
        stream
            .write_all(line.as_bytes())
            .map_err(|e| unreachable(&path, &e))?;
        let mut reader = BufReader::new(stream);
        let mut text = String::new();
        loop {
            // A timeout may leave part of a line in `text`: it is kept, and the rest appended.
            match reader.read_line(&mut text) {
                Ok(0) => {
                    return Err(Failure {
                        status: lost_status,
                        message: "the ground service ended before the request did (stopped or \
                                  killed): ask it again once the service is back"
                            .to_owned(),
                    });
                }
                Ok(_) => {}
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) =>
                {
                    if !on_reply(None) {
                        return Ok(None);
                    }
                    continue;
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => {
                    return Err(Failure {
                        status: lost_status,
                        message: format!("the ground service's answer was lost: {e}"),
                    });
                }
            }
            let reply: Reply = serde_json::from_str(&text).map_err(|e| {
                Failure::other(format!("the ground service's answer does not read: {e}"))
            })?;
            text.clear();
            match reply {
                Reply::Finished(_) | Reply::Failed(_) | Reply::Status(_) => return Ok(Some(reply)),
                other => {
                    if !on_reply(Some(&other)) {
                        return Ok(Some(other));
                    }
                }
            }
        }
    }

    /// Bounds how long a read of the service's answer may wait (a monitor wakes to look at its
    /// clock and at Ctrl-C).
    pub fn set_read_timeout(&self, timeout: Option<Duration>) -> std::io::Result<()> {
        self.stream.set_read_timeout(timeout)
    }
}
