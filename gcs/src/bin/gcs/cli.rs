//! The command line of `gcs`: every command, its arguments and its exit statuses, as `--help`
//! shows them.

use super::*;

/// Ground control station of missionlink: STANAG 4586 mission and area transfer.
#[derive(Debug, Parser)]
#[command(name = "gcs", version)]
pub(crate) struct Cli {
    #[command(flatten)]
    pub(crate) config: LinkArgs,
    /// Write every datagram sent and received on both links to FILE (pcap, UDP over IPv4 with
    /// the real addresses and ports): open it in Wireshark with tools/wireshark/missionlink.lua.
    #[arg(long, global = true, value_name = "FILE")]
    pub(crate) pcap: Option<PathBuf>,
    /// The vehicle, by its name in the fleet (needed when the fleet holds several). Through
    /// the ground service when one runs; alone, from the fleet file of `--fleet`. `upload` and
    /// `stage` take several, `a,b,c`: the plan goes to each at once, each vehicle's outcome
    /// printed after its name, the exit status the highest of theirs.
    #[arg(long, global = true, value_name = "NAME")]
    pub(crate) vehicle: Option<String>,
    /// The fleet file (TOML, see docs/gcs.md): for `gcs serve`, and for a command that runs
    /// alone for a vehicle of the fleet.
    #[arg(long, global = true, value_name = "FILE", env = "MISSIONLINK_FLEET")]
    pub(crate) fleet: Option<PathBuf>,
    /// The ground service's socket (default: $XDG_RUNTIME_DIR/missionlink/gcs.sock, else
    /// gcs.sock in the state directory). When a service runs there, every link command asks
    /// it; when none does, the command opens the links itself.
    #[arg(
        long,
        global = true,
        value_name = "PATH",
        env = "MISSIONLINK_GCS_SOCKET"
    )]
    pub(crate) service_socket: Option<PathBuf>,
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Check a mission file: assemble the waypoint and area lists (ICD §7), then run the safety
    /// gateway, flying from the plan's take-off position, and print every violation.
    ///
    /// A .plan or GeoJSON file is imported exactly or not at all: an element the ICD cannot carry
    /// or the FCC cannot hold (a return-to-launch or other unsupported item, a second inclusion
    /// polygon, an inclusion circle, an eleventh no-fly-zone, a polygon of more than 60
    /// vertices, ...) refuses the file, naming the element's path and the reason, unless
    /// `--drop unsupported` is given.
    #[command(after_help = "Exit status:\n  \
        0  feasible: the lists assemble (ICD §7) and every check of the safety gateway passes\n  \
        1  infeasible: a violation of the safety gateway, or the lists refused by the ICD §7 \
           assembly\n  \
        2  unreadable input: a file missing or unreadable, a syntax error or a bad value, an \
           import refused for what it cannot carry, bad flags")]
    Validate {
        /// Mission file: our TOML (.toml) or a QGroundControl plan (.plan).
        file: PathBuf,
        /// One JSON object instead of text.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Validate (the safety gateway included), then upload mission and areas. An infeasible
    /// mission is refused with the report; nothing is sent.
    ///
    /// Toward an edition-2 FCC the upload is atomic (ICD §8): the mission and areas are staged
    /// under the file's Mission ID (a fresh one, `gcs-` and the mission's checksum, when the
    /// file has none or the FCC holds a staged mission of that name), activated in one step
    /// (#50000 command 4) and the staged copy deleted, so the FCC holds the mission under the
    /// file's Mission ID; any failure before the activation leaves
    /// the active mission and areas as they were. Toward an edition-1 FCC, or with
    /// `--paper-sequence`, the paper's sequence (Figure 11): the waypoints, then the areas, each
    /// list active at its own closer, one after the other (the message says so).
    ///
    /// The checksums of both lists (ICD §11) go with the closers toward edition 2. When the
    /// transfer fails, the GCS asks the FCC what is active (its report, or a download from an
    /// edition-1 FCC) and says so, list by list, with the checksums.
    ///
    /// With `--edit` the file is compared with the active mission on the FCC (from the state
    /// directory when the FCC's checksum confirms it, else downloaded) and only what changed is
    /// sent: toward edition 2 #13000 mode 10 (load the buffer from the active list), the
    /// waypoints that changed or are new, the take-off height and route if changed, and the
    /// transmit (mode 2); if the areas changed too, the edit is staged and activated in one step.
    /// An edit that removes waypoints is sent as a full upload (the message says why). It prints
    /// "sent N messages (a full upload: M)".
    #[command(after_help = "Exit status:\n  \
        0  complete: the new mission and areas are active (also when an answer was lost and the \
           GCS confirmed it by asking)\n  \
        1  nothing sent: the plan is infeasible or invalid; or the FCC did not answer at all\n  \
        2  unreadable input\n  \
        3  failed: the previous mission and areas are still active, whole (also: the FCC holds \
           8 staged missions and an atomic upload needs one more; nothing was staged)\n  \
        4  failed half way: one list is the new one, the other the previous one (the message \
           says which; only the paper's sequence can end so)\n  \
        5  failed, and what the FCC holds is unknown: it did not answer the question\n  \
        6  failed: the FCC holds a list that is neither the new one nor the previous one\n  \
        7  failed after the clear of the paper's sequence (ICD §5.1): the FCC holds no mission \
           (only the paper's sequence can end so)")]
    Upload {
        /// Mission file (.toml or .plan).
        file: PathBuf,
        /// Send only what changed from the active mission on the FCC.
        #[arg(long)]
        edit: bool,
        /// The paper's sequence even toward an edition-2 FCC: the waypoint list, then the area
        /// list, each active at its own closer (not atomic).
        #[arg(long)]
        paper_sequence: bool,
        #[command(flatten)]
        state: StateArgs,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Validate, then stage mission and areas under a Mission ID on an edition-2 FCC (ICD §8):
    /// the active lists are untouched; `gcs activate ID` makes it active later.
    ///
    /// The FCC holds up to 8 staged missions; an ID already staged is replaced. With `--edit`
    /// the file is compared with the staged mission of that ID (from the state directory when
    /// the FCC's checksum confirms it, else downloaded) and only what changed is sent (#13000
    /// mode 10 with the ID, the changes, mode 8), the areas only if they changed.
    #[command(after_help = "Exit status:\n  \
        0  staged: the FCC holds the mission and areas under the ID\n  \
        1  nothing staged: the plan is infeasible or invalid, the FCC speaks edition 1, or it \
           did not answer at all\n  \
        2  unreadable input, or a bad Mission ID (nothing is sent)\n  \
        3  failed: the staged mission of the ID is as it was (or still absent); also: the FCC \
           holds 8 other staged missions\n  \
        4  failed half way: one list of the staged mission is the new one\n  \
        5  failed, and what the FCC holds under the ID is unknown\n  \
        6  failed: the FCC holds lists under the ID that it was not sent")]
    Stage {
        /// Mission file (.toml or .plan).
        file: PathBuf,
        /// The Mission ID: printable ASCII, 1 to 19 characters.
        #[arg(long, value_parser = parse_mission_id)]
        id: MissionId,
        /// Send only what changed from the staged mission of that ID.
        #[arg(long)]
        edit: bool,
        #[command(flatten)]
        state: StateArgs,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Make a staged mission the active mission and areas, both in one step (#50000 command 4,
    /// ICD §8). The FCC refuses while airborne, when the mission lacks a list, or when its
    /// onboard geofence check fails; then nothing changes. The staged copy stays staged.
    #[command(after_help = "Exit status:\n  \
        0  active: the staged mission's lists are the active ones\n  \
        1  refused or unanswered (the message gives the reason); nothing changed if refused\n  \
        2  a bad Mission ID (nothing is sent)")]
    Activate {
        /// The Mission ID of the staged mission.
        #[arg(value_parser = parse_mission_id)]
        id: MissionId,
    },
    /// Delete a staged mission (#13000 mode 6, ICD §8). The active lists are untouched.
    #[command(after_help = "Exit status:\n  \
        0  deleted\n  \
        1  refused (no such staged mission) or unanswered\n  \
        2  a bad Mission ID (nothing is sent)")]
    Delete {
        /// The Mission ID of the staged mission.
        #[arg(value_parser = parse_mission_id)]
        id: MissionId,
    },
    /// Draw the mission as SVG: areas with their safety offsets, waypoints, legs and arcs, the
    /// take-off, and every violation of the safety gateway in red.
    Map {
        /// Mission file (.toml or .plan).
        file: PathBuf,
        /// Where to write the SVG.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Convert a mission between formats, by extension: .toml (ours), .plan (QGroundControl),
    /// .geojson (the areas only, as output).
    Convert {
        /// Mission file to read (.toml or .plan).
        input: PathBuf,
        /// File to write (.toml, .plan or .geojson).
        output: PathBuf,
        #[command(flatten)]
        safety: SafetyArgs,
    },
    /// Download the active mission and areas (or with `--id` a staged mission's, ICD §8);
    /// print them, or write a mission file.
    #[command(after_help = "Exit status:\n  \
        0  downloaded\n  \
        1  refused (no such list), aborted or unanswered\n  \
        2  a bad Mission ID (nothing is sent), or the output cannot be written")]
    Download {
        /// Write the mission file here (upload it again for a round trip).
        #[arg(short, long, value_name = "FILE")]
        output: Option<PathBuf>,
        /// Download the staged mission of this Mission ID instead of the active lists.
        #[arg(long, value_parser = parse_mission_id)]
        id: Option<MissionId>,
    },
    /// Print what the FCC holds (ICD §8 report, #50001): for the active lists (and each staged
    /// mission) the waypoint and area counts, the onboard geofence check and the checksums of
    /// ICD §11, to compare with what `gcs validate` and `gcs upload` print. An edition-1 FCC
    /// gives no report (exit status 1).
    Missions,
    /// Clear the active mission: #13000 mode 1 deletes the waypoint buffer and the active
    /// waypoint list (ICD §5.1); refused while trajectory generation is active.
    Clear,
    /// Clear the active areas (#2011 mode 6).
    ClearAreas,
    /// Take off and fly the active mission (#50000 execute).
    Execute,
    /// Fly the route backwards to its start (#50000 return to home, bidirectional routes).
    Rth,
    /// Land at the next waypoint (#50000 land).
    Land,
    /// Print FROM-TO-NEXT (#4001) as it changes and the position (#101, 2 Hz by default) with
    /// the FROM-TO-NEXT it flies.
    Monitor {
        /// Stop after this many seconds (default: until interrupted).
        #[arg(long, value_name = "S")]
        seconds: Option<u64>,
    },
    /// Run the ground service: own the links of every vehicle of the fleet (`--fleet`, else the
    /// one vehicle of the link flags and file), keep each vehicle's state, and serve the other
    /// gcs commands, which then ask it instead of opening the links themselves. Runs until
    /// SIGINT or SIGTERM. See docs/gcs.md.
    #[command(after_help = "Exit status:\n  \
        0  stopped by SIGINT or SIGTERM\n  \
        1  a link cannot be opened (a port in use, an unusable key), or a service already runs \
           on the socket\n  \
        2  an unusable fleet file or configuration")]
    Serve {
        #[command(flatten)]
        state: StateArgs,
        /// The safety gateway of the MAVLink side's commits (a command brings its own).
        #[command(flatten)]
        safety: SafetyArgs,
        /// Present every vehicle to MAVLink 2 clients (QGroundControl, MAVSDK, pymavlink) on one
        /// UDP endpoint, each as its fleet's MAVLink system ID, as `gcs mavlink` presents one.
        #[arg(long)]
        mavlink: bool,
        /// Where the MAVLink side sends (QGroundControl listens on 14550); a client that talks
        /// to it is answered too.
        #[arg(long, default_value = "127.0.0.1:14550", value_name = "HOST:PORT")]
        mavlink_to: std::net::SocketAddr,
        /// The MAVLink side's own UDP address (port 0: the system chooses; printed at start).
        #[arg(long, default_value = "0.0.0.0:0", value_name = "HOST:PORT")]
        mavlink_bind: std::net::SocketAddr,
        /// Speed of waypoints before any DO_CHANGE_SPEED item, m/s.
        #[arg(long, default_value_t = 25.0, value_name = "M/S")]
        cruise_speed: f64,
        /// How long an accepted mission waits for a fence upload before it is committed with
        /// the areas held, milliseconds.
        #[arg(long, default_value_t = 3000, value_name = "MS")]
        fence_wait_ms: u64,
        /// Capture every MAVLink message sent and received into FILE (`.tlog`).
        #[arg(long, value_name = "FILE")]
        tlog: Option<std::path::PathBuf>,
        /// Serve without the fence the service puts around itself once its links and socket
        /// are open (no new privileges, Landlock: writing beneath its state and socket
        /// directories alone, seccomp: the calls it needs alone). For finding a fault; say why
        /// in the deployment.
        #[arg(long)]
        no_isolation: bool,
        /// End when the process that started this one ends (a test or a benchmark passes it,
        /// so that the service does not outlive them).
        #[arg(long, hide = true)]
        exit_with_parent: bool,
    },
    /// One row per vehicle of the ground service: each link's last frame and loss, the
    /// position and its age, FROM-TO-NEXT, the active lists' checksums and whether they are
    /// the ones this ground uploaded last, the staged missions, what is heard of the FCC.
    #[command(after_help = "Exit status:\n  \
        0  printed\n  \
        1  no ground service runs")]
    Status {
        /// Print it again every this many seconds, until interrupted.
        #[arg(long, value_name = "S")]
        watch: Option<f64>,
        /// The rows as one JSON array.
        #[arg(long)]
        json: bool,
    },
    /// Present the vehicle to MAVLink 2 clients (QGroundControl, MAVSDK, pymavlink) over UDP:
    /// heartbeat, position and mission progress from the downlink, the mission protocol for
    /// mission and fence items (committed to the FCC as one atomic upload through the safety
    /// gateway), MAV_CMD_MISSION_START as execute. See docs/qgroundcontrol.md.
    Mavlink {
        /// Where to send (QGroundControl listens on 14550); a client that talks to the bridge
        /// is answered too.
        #[arg(long, default_value = "127.0.0.1:14550", value_name = "HOST:PORT")]
        to: std::net::SocketAddr,
        /// The bridge's own UDP address (port 0: the system chooses; printed at start).
        #[arg(long, default_value = "0.0.0.0:0", value_name = "HOST:PORT")]
        bind: std::net::SocketAddr,
        /// Speed of waypoints before any DO_CHANGE_SPEED item, m/s (MAVLink items carry no
        /// planning speed; a `.plan` calls it cruiseSpeed).
        #[arg(long, default_value_t = 25.0, value_name = "M/S")]
        cruise_speed: f64,
        /// How long an accepted mission waits for a fence upload before it is committed with
        /// the areas held, milliseconds.
        #[arg(long, default_value_t = 3000, value_name = "MS")]
        fence_wait_ms: u64,
        /// Capture every MAVLink message sent and received into FILE, a telemetry log
        /// (`.tlog`, the format QGroundControl and MAVProxy write; pymavlink reads it).
        #[arg(long, value_name = "FILE")]
        tlog: Option<std::path::PathBuf>,
        #[command(flatten)]
        safety: SafetyArgs,
        /// The items the client uploaded and the vehicle's home are kept in
        /// DIR/mavlink-memory, so a download after a restart returns what was uploaded.
        #[command(flatten)]
        state: StateArgs,
    },
    /// Decode captured frames: every message with every field in readable units.
    ///
    /// Each argument is one datagram in hex (spaces, colons and a 0x prefix are ignored); with no
    /// argument, one datagram per line of stdin (blank lines and lines starting with # are
    /// skipped). A datagram may hold several messages back to back. Exits 1 if any frame or
    /// message is rejected, printing the ICD rule it breaks.
    Inspect {
        /// One JSON object per message instead of text (the input format of `gcs encode`).
        #[arg(long)]
        json: bool,
        /// Apply the addressing rules of ICD §2 as the node with this ID (needs --peer-id).
        #[arg(long, value_parser = parse_id, requires = "peer_id")]
        local_id: Option<u32>,
        /// The configured peer whose frames are accepted (needs --local-id).
        #[arg(long, value_parser = parse_id, requires = "local_id")]
        peer_id: Option<u32>,
        /// A link key file (ICD §9): say whether each signed frame verifies with it. Repeat for
        /// several keys.
        #[arg(long = "key", value_name = "FILE")]
        keys: Vec<PathBuf>,
        /// Datagrams in hex.
        hex: Vec<String>,
    },
    /// Make a link key (ICD §9) and write it to the FCC's key file and the ground's: 32 random
    /// bytes with a Key ID, each file readable by its owner only (mode 0600, its directory made
    /// 0700 when missing). An existing file is never overwritten; both files are written, or
    /// neither.
    ///
    /// Link signing is required by default on both sides: name each side's file in its
    /// `[signing] key_files` (or `--key-file`). On the FCC under systemd the key is
    /// /etc/missionlink/link.key, owned by the FCC's user (docs/deployment.md). The same path for both
    /// writes one file (an FCC and a ground on one machine).
    #[command(after_help = "Example:\n  \
        gcs keygen --fcc /etc/missionlink/link.key --ground ~/.config/missionlink/link.key")]
    Keygen {
        /// The FCC's key file to write.
        #[arg(long, value_name = "FILE")]
        fcc: PathBuf,
        /// The ground's key file to write.
        #[arg(long, value_name = "FILE")]
        ground: PathBuf,
        /// Its Key ID (0-255): keys in rotation differ by it.
        #[arg(long, default_value_t = 1)]
        key_id: u8,
    },
    /// Encode messages given as JSON (the objects `gcs inspect --json` prints) into hex frames.
    ///
    /// Each argument is one JSON object; with no argument, one object per line of stdin. Absent
    /// wrapper fields take the ICD defaults (source GCS 0x0A000001, destination FCC 0x0B000001,
    /// no ack, IDD 40, 4-byte checksum).
    Encode {
        /// Messages in JSON.
        json: Vec<String>,
    },
}

/// A Mission ID as ICD §8 defines it (one rule, `MissionId::new`): a bad one is refused by
/// the argument parser, before anything is sent (exit status 2).
pub(crate) fn parse_mission_id(s: &str) -> Result<MissionId, String> {
    MissionId::new(s).map_err(|e| e.to_string())
}
