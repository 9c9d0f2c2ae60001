//! `gcs`: the ground control station tool. For now the frame inspector (`inspect`, `encode`);
//! the mission commands follow with the partitions.

use std::io::{self, BufRead, Write};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use missionlink_partitions::inspect::{
    MessageJson, encode_json, inspect_datagram, parse_hex, render_text,
};

/// Ground control station of missionlink: STANAG 4586 mission and area transfer.
#[derive(Debug, Parser)]
#[command(name = "gcs", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
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
        /// Datagrams in hex.
        hex: Vec<String>,
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

fn parse_id(s: &str) -> Result<u32, String> {
    let t = s.trim();
    match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(h) => u32::from_str_radix(h, 16),
        None => t.parse(),
    }
    .map_err(|e| format!("{s:?} is not a 32-bit ID: {e}"))
}

/// The inputs: the arguments, or the non-blank, non-comment lines of stdin.
fn inputs(args: Vec<String>) -> io::Result<Vec<String>> {
    if !args.is_empty() {
        return Ok(args);
    }
    let mut lines = Vec::new();
    for line in io::stdin().lock().lines() {
        let line = line?;
        let t = line.trim();
        if !t.is_empty() && !t.starts_with('#') {
            lines.push(t.to_owned());
        }
    }
    Ok(lines)
}

fn inspect(
    json: bool,
    addressing: Option<(u32, u32)>,
    hex: Vec<String>,
    out: &mut impl Write,
) -> io::Result<bool> {
    let mut all_ok = true;
    for (n, text) in inputs(hex)?.iter().enumerate() {
        let datagram = n + 1;
        let results = match parse_hex(text) {
            Ok(bytes) => inspect_datagram(&bytes, addressing),
            Err(e) => vec![Err(e)],
        };
        for (i, result) in results.into_iter().enumerate() {
            let message = i + 1;
            match result.and_then(|m| MessageJson::new(&m.envelope, &m.message, m.length)) {
                Ok(m) if json => {
                    let line = serde_json::to_string(&m).map_err(io::Error::other)?;
                    writeln!(out, "{line}")?;
                }
                Ok(m) => write!(out, "{}", render_text(&m))?,
                Err(e) => {
                    all_ok = false;
                    eprintln!("datagram {datagram}, message {message}: {e}");
                }
            }
        }
    }
    Ok(all_ok)
}

fn encode(json: Vec<String>, out: &mut impl Write) -> io::Result<bool> {
    let mut all_ok = true;
    for (n, text) in inputs(json)?.iter().enumerate() {
        match encode_json(text) {
            Ok(frame) => writeln!(out, "{}", hex::encode(frame))?,
            Err(e) => {
                all_ok = false;
                eprintln!("message {}: {e}", n + 1);
            }
        }
    }
    Ok(all_ok)
}

fn main() -> ExitCode {
    missionlink_partitions::init_logging();
    let cli = Cli::parse();
    let mut out = io::stdout().lock();
    let result = match cli.command {
        Command::Inspect {
            json,
            local_id,
            peer_id,
            hex,
        } => inspect(json, local_id.zip(peer_id), hex, &mut out),
        Command::Encode { json } => encode(json, &mut out),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("gcs: {e}");
            ExitCode::FAILURE
        }
    }
}
