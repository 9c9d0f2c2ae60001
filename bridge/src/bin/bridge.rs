//! `bridge`: forwards chosen iceoryx2 services of this host to Zenoh and back (`[bridge]` of the
//! configuration, docs/two-hosts.md). The launcher starts it when `[bridge] enabled`; it runs
//! on its own too (`bridge --config fcc.toml`). The process is `missionlink_bridge::main`.
//!
//! `bridge credentials --out DIR --host NAME=ADDRESS --host NAME` makes the credentials the
//! bridges authenticate each other with (`missionlink_bridge::credentials`): a directory per
//! host under DIR, to be copied to that host.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use missionlink_bridge::credentials::{self, Host};
use missionlink_partitions::config::FccArgs;

/// Bridge between the FCC's iceoryx2 services and Zenoh.
#[derive(Debug, Parser)]
#[command(name = "bridge", version)]
struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    config: FccArgs,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Makes the credentials for the bridges' mutual TLS: a certificate authority of this
    /// deployment's own (its private key is never written) and, for each --host, a directory
    /// OUT/NAME with ca.pem, certificate.pem and private-key.pem (mode 0600, directory 0700).
    /// Copy each directory to its host and name it in [bridge] credentials. Nothing existing is
    /// overwritten.
    Credentials {
        /// Where the hosts' directories are written.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A host: NAME, or NAME=ADDRESS[,ADDRESS...] with the addresses (or DNS names) of its
        /// `listen` endpoints, which the connecting bridge checks; repeat for every host.
        #[arg(long = "host", value_name = "NAME[=ADDRESS,...]", required = true)]
        hosts: Vec<Host>,
    },
}

fn main() -> ExitCode {
    let args = Args::parse();
    match args.command {
        None => missionlink_bridge::main(&args.config),
        Some(Command::Credentials { out, hosts }) => match credentials::generate(&out, &hosts) {
            Ok(dirs) => {
                for (host, dir) in hosts.iter().zip(&dirs) {
                    let names = if host.addresses.is_empty() {
                        "no address: it connects only".to_owned()
                    } else {
                        format!("listens as {}", host.addresses.join(", "))
                    };
                    println!("{}: {} ({names})", host.name, dir.display());
                }
                println!(
                    "copy each directory to its host (keep the modes), and set [bridge] credentials to it there"
                );
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("bridge credentials: {e}");
                ExitCode::from(missionlink_partitions::runtime::CONFIG_EXIT_CODE)
            }
        },
    }
}
