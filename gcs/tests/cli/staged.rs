//! The staged-mission commands of `gcs` (ICD §8) as the operator meets their arguments: a bad
//! Mission ID is refused with the rule it breaks before anything is sent, and every command
//! documents its exit statuses.

use crate::support::{SilentFcc, gcs, repo, text};

#[test]
fn a_bad_mission_id_is_refused_before_anything_is_sent() {
    // Nothing may arrive on the FCC's links.
    let fcc = SilentFcc::bind();
    let links = fcc.args();
    let mission = repo("missions/mission-1.toml");
    let long = "a".repeat(20);
    let cases: [(Vec<&str>, &str); 5] = [
        (
            vec!["stage", &mission, "--id", ""],
            "the Mission ID is empty",
        ),
        (
            vec!["activate", &long],
            "the Mission ID has 20 characters, at most 19 fit",
        ),
        (vec!["delete", "tab\there"], "not printable ASCII at byte 3"),
        (
            vec!["download", "--id", "né"],
            "not printable ASCII at byte 1",
        ),
        (
            vec!["stage", &mission, "--edit", "--id", &long],
            "at most 19 fit",
        ),
    ];
    for (args, rule) in cases {
        let mut all: Vec<&str> = links.iter().map(String::as_str).collect();
        all.extend(&args);
        let o = gcs(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = text(&o.stderr);
        assert!(err.contains(rule), "{args:?}: {err}");
    }
    fcc.assert_nothing_sent();
}

#[test]
fn every_staged_command_documents_its_exit_statuses() {
    for command in ["upload", "stage", "activate", "delete", "download"] {
        let o = gcs(&[command, "--help"]);
        assert!(o.status.success(), "{command}");
        let help = text(&o.stdout);
        assert!(help.contains("Exit status:"), "{command}: {help}");
        assert!(help.contains("  0  "), "{command}: {help}");
    }
    let upload = text(&gcs(&["upload", "--help"]).stdout);
    for flag in ["--edit", "--paper-sequence", "--state-dir"] {
        assert!(upload.contains(flag), "{flag}: {upload}");
    }
    let stage = text(&gcs(&["stage", "--help"]).stdout);
    assert!(stage.contains("--id <ID>"), "{stage}");
}

/// The ground takes the link's flags and none of the FCC's own: a flag it would accept and
/// ignore is one an operator believes did something.
#[test]
fn the_gcs_takes_the_link_flags_and_none_of_the_fccs() {
    let top = text(&gcs(&["--help"]).stdout);
    for link in ["--config", "--fcc-direct", "--ack-timeout-ms", "--key-file"] {
        assert!(top.contains(link), "{link}: {top}");
    }
    for command in ["", "upload", "download", "monitor", "mavlink", "execute"] {
        let args: &[&str] = if command.is_empty() {
            &["--help"]
        } else {
            &[command, "--help"]
        };
        let help = text(&gcs(args).stdout);
        for fcc in [
            "--prefix",
            "--time-scale",
            "--poll",
            "--summary-dir",
            "--heartbeat-ms",
        ] {
            assert!(!help.contains(fcc), "{command} {fcc}: {help}");
        }
    }
    let o = gcs(&["download", "--poll"]);
    assert_eq!(o.status.code(), Some(2), "refused, not ignored");
}
