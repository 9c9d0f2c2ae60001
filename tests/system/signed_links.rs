//! Signed links (ICD §9) through the real binaries: the FCC's voting-monitoring requires the
//! key, the operator's GCS holds it, and a stranger on the network who knows the IDs, the ports
//! and the message formats cannot clear or replace the mission.

use std::net::{SocketAddr, UdpSocket};
use std::path::PathBuf;
use std::time::{SystemTime, UNIX_EPOCH};

use missionlink::harness::*;
use missionlink_interfaces::contracts::Link as LinkId;
use missionlink_interfaces::wire::{
    self, Envelope, MAX_FRAME_LEN, MAX_SIGNED_FRAME_LEN, Timestamp,
};
use missionlink_partitions::config::{Signing, SigningPolicy};
use missionlink_platform::keys;
use missionlink_protocol::link::signing::{LinkKey, SignatureCause, Signer};

/// A new key file with `key_id` in the rig's directory.
fn key_file(rig: &Rig, name: &str, key_id: u8) -> PathBuf {
    let path = rig.dir.join(name);
    keys::generate_key_file(&path, key_id).unwrap();
    path
}

fn require(key_files: Vec<PathBuf>) -> Signing {
    Signing {
        policy: SigningPolicy::Require,
        key_files,
        send_key_id: None,
    }
}

/// The attack that link signing (ICD §9) stops: a well-formed #13000 clear, then a #13000 transmit
/// with Waypoint Number 0, with the GCS's ID and the current time, sent from a foreign socket to
/// both of the FCC's ports; each frame as `disguise` makes it for the link it goes to.
fn attack(
    rig: &Rig,
    socket: &UdpSocket,
    first_ms: u64,
    disguise: impl Fn(LinkId, &[u8]) -> Vec<u8>,
) {
    let config = &rig.config;
    let now = SystemTime::now().duration_since(UNIX_EPOCH).unwrap();
    let mut buf = [0u8; MAX_FRAME_LEN];
    for (j, m) in clearing_commands().into_iter().enumerate() {
        let mut m = m;
        let ms = now.as_millis() as u64 + first_ms + j as u64;
        m.set_time_stamp(Timestamp::from_unix_millis(ms).unwrap());
        let envelope = Envelope::new(config.ids.gcs, config.ids.fcc).with_ack(true);
        let len = wire::encode(&envelope, &m, &mut buf).unwrap();
        let ports: [(LinkId, SocketAddr); 2] = [
            (LinkId::Direct, config.links.fcc_direct),
            (LinkId::Lte, config.links.fcc_lte),
        ];
        for (link, port) in ports {
            socket.send_to(&disguise(link, &buf[..len]), port).unwrap();
        }
    }
}

/// The defaults (ICD §9: policy `require`), with the key the rig made as an operator makes it.
#[test]
fn with_the_default_policy_a_stranger_changes_nothing_and_the_signed_operator_works() {
    let mut rig = Rig::new("signed");
    assert_eq!(
        rig.config.signing.policy,
        SigningPolicy::Require,
        "the default"
    );
    let mut fcc = rig.start_fcc();
    let mut link = rig.gcs(&mut fcc);
    assert_eq!(link.signing_key_id(), Some(1));
    let mission_1 = plan("mission-1.toml");
    let valid_1 = link.station().validate(&mission_1).unwrap();
    upload(&mut link, &mission_1).unwrap();
    // The FCC's position downlink (ICD §5.8) runs from its start: what it sent before this GCS
    // started is refused as a replay (older than the GCS's start, ICD §9). From here on, every
    // frame of the FCC verifies.
    let stale = link.voter().stats().rejected_signatures;

    let stranger = UdpSocket::bind("127.0.0.1:0").unwrap();
    // Unsigned, as an attacker without the key sends them.
    attack(&rig, &stranger, 0, |_, f| f.to_vec());
    // Signed with the right Key ID and a key of the stranger's own.
    let guessed = Signer::new(LinkKey::new(1, &[0x11; 32]));
    attack(&rig, &stranger, 10, |link, f| {
        let mut out = [0u8; MAX_SIGNED_FRAME_LEN];
        let len = guessed.sign(link, f, &mut out).unwrap();
        out[..len].to_vec()
    });
    // The download's frames reach the sockets after these (loopback queues a datagram when
    // send_to returns; voting-monitoring reads each socket in order), so it sees whatever the
    // stranger's frames did.
    assert_eq!(download(&mut link).unwrap(), valid_1, "nothing changed");

    // The operator still replaces the mission.
    let mission_2 = plan("mission-2.toml");
    let valid_2 = link.station().validate(&mission_2).unwrap();
    upload(&mut link, &mission_2).unwrap();
    assert_eq!(download(&mut link).unwrap(), valid_2);
    let rejected = link.voter().stats().rejected_signatures;
    assert_eq!(rejected, stale, "{rejected:?}");
    assert_eq!(
        stale.total(),
        stale.get(SignatureCause::Replay),
        "{stale:?}"
    );
    assert!(link.voter().signatures().stats().verified > 0);

    fcc.stop().unwrap();
    let counters = rig.counters("voting-monitoring");
    // Two frames, each on both links, per disguise.
    assert_eq!(counters["signature_no_trailer"], 4, "{counters:?}");
    assert_eq!(counters["signature_bad"], 4, "{counters:?}");
    assert_eq!(counters["rejected_signatures"], 8, "{counters:?}");
    // Counted, not logged per frame.
    let lines = fcc
        .log_text()
        .matches("failing the signature check")
        .count();
    assert!(lines <= 2, "{lines} log lines:\n{}", fcc.log_text());
    // No key material in any log.
    let secret = std::fs::read_to_string(rig.dir.join("link.key")).unwrap();
    let hex = secret.split('"').nth(1).unwrap();
    assert!(!fcc.log_text().contains(&hex[..16]));
}

#[test]
fn a_gcs_whose_key_the_fcc_does_not_hold_hears_nothing_and_says_why() {
    let mut rig = Rig::new("signed-unknown");
    let fcc_key = key_file(&rig, "fcc.key", 1);
    let gcs_key = key_file(&rig, "gcs.key", 2);
    rig.config.signing = require(vec![fcc_key]);
    let mut fcc = rig.start_fcc();
    rig.config.signing = require(vec![gcs_key]);
    let mut link = rig.gcs(&mut fcc);
    let error = upload(&mut link, &plan("mission-1.toml")).unwrap_err();
    let why = link.unheard().expect("an explanation");
    assert!(why.contains("key 2"), "{why}");
    assert!(why.contains("does not fall back"), "{why}");
    // Nothing unsigned went out after the silence: the FCC saw only frames with key 2.
    fcc.stop().unwrap();
    let counters = rig.counters("voting-monitoring");
    assert!(
        counters["signature_unknown_key"] > 0,
        "{error}: {counters:?}"
    );
    assert_eq!(counters["signature_no_trailer"], 0, "{counters:?}");
    assert_eq!(counters["forwarded_direct"] + counters["forwarded_lte"], 0);
}
