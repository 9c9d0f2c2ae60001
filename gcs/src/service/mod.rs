//! The ground service (`gcs serve`): one long-running process that owns the links of every
//! vehicle of a fleet ([`fleet`]), keeps each vehicle's state ([`status`]), and serves the `gcs`
//! commands as its clients ([`client`]); a command carries out the same [`request`] alone when
//! no service runs. STANAG 4586's control station (CUCS) is such a process: it holds the links
//! and every vehicle's state, and everything else talks to it.
//!
//! - [`fleet`]: the fleet file.
//! - [`request`]: what a command asks of a vehicle's ground station, and [`request::carry_out`].
//! - [`client`]: the socket, the call and its replies.
//! - `server`: the acceptor and a thread per vehicle.
//! - [`status`]: what `gcs status` shows.

use std::path::{Path, PathBuf};

pub mod client;
pub mod fleet;
pub mod request;
mod server;
pub mod status;

pub use server::{
    Bound, MavlinkOptions, Opened, ServeError, ServeOptions, open, serve, service_fence,
};

/// The state directory: `dir`, else `$XDG_STATE_HOME/missionlink`, else
/// `$HOME/.local/state/missionlink`.
pub fn state_base(dir: Option<PathBuf>) -> Option<PathBuf> {
    dir.or_else(|| {
        std::env::var_os("XDG_STATE_HOME")
            .filter(|v| !v.is_empty())
            .map(|v| PathBuf::from(v).join("missionlink"))
            .or_else(|| {
                std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/state/missionlink"))
            })
    })
}

/// The file in the state directory `dir` that reserves the time stamps of this ground toward
/// the FCC of Vehicle ID `fcc` (`GcsLink::with_stamp_lease`): one per vehicle, shared by the
/// service and the commands that run alone, so that neither reuses the other's stamps.
pub fn stamp_lease(dir: &Path, fcc: u32) -> PathBuf {
    dir.join(format!("time-stamps-{fcc:08X}"))
}

/// The file in the state directory `dir` that keeps the replay window of the downlink of the FCC
/// of Vehicle ID `fcc` (`GcsLink::with_replay_lease`), shared as [`stamp_lease`] is.
pub fn replay_lease(dir: &Path, fcc: u32) -> PathBuf {
    dir.join(format!("replay-window-{fcc:08X}"))
}
