//! Two hosts on one machine for tests/system/two_hosts.rs and benches/bridge.rs: two network
//! namespaces joined by a veth pair, with the link-local pair 169.254.77.1 (host A) and
//! 169.254.77.2 (host B) on it and nothing else, made with iproute2's `ip` and removed when the
//! guard is dropped (also when the test fails). Needs root.

use std::os::fd::AsFd;
use std::process::Command;

/// `ip`, from the path or where Debian puts it (root's path has /usr/sbin, another user's may
/// not).
fn ip_command() -> &'static str {
    ["/usr/sbin/ip", "/sbin/ip", "/usr/bin/ip"]
        .into_iter()
        .find(|p| std::path::Path::new(p).is_file())
        .unwrap_or("ip")
}

/// Host A's and host B's addresses on the veth.
pub const ADDR_A: &str = "169.254.77.1";
pub const ADDR_B: &str = "169.254.77.2";
fn ip(args: &[&str]) {
    let out = Command::new(ip_command())
        .args(args)
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run `ip` (iproute2; .ci/run and tools/test install it): {e}")
        });
    assert!(
        out.status.success(),
        "ip {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The two namespaces and the veth pair of one test; removed when dropped.
pub struct Hosts {
    /// Host A's namespace.
    pub a: String,
    /// Host B's namespace.
    pub b: String,
    veth_a: String,
}

impl Hosts {
    /// Makes namespaces and a veth pair named after `tag` and this process (unique to the run).
    pub fn new(tag: &str) -> Self {
        assert!(
            rustix::process::geteuid().is_root(),
            "tests/system/two_hosts.rs needs root (network namespaces and a veth pair): run it as root, as CI's .ci/run does"
        );
        let id = std::process::id();
        let hosts = Self {
            a: format!("ml-{tag}-{id}-a"),
            b: format!("ml-{tag}-{id}-b"),
            // Interface names are at most 15 bytes.
            veth_a: format!("ml{tag}{}a", id % 100_000),
        };
        let veth_b = format!("ml{tag}{}b", id % 100_000);
        ip(&["netns", "add", &hosts.a]);
        ip(&["netns", "add", &hosts.b]);
        ip(&[
            "link",
            "add",
            &hosts.veth_a,
            "type",
            "veth",
            "peer",
            "name",
            &veth_b,
        ]);
        ip(&["link", "set", &hosts.veth_a, "netns", &hosts.a]);
        ip(&["link", "set", &veth_b, "netns", &hosts.b]);
        for (ns, dev, addr) in [
            (&hosts.a, &hosts.veth_a, ADDR_A),
            (&hosts.b, &veth_b, ADDR_B),
        ] {
            ip(&["-n", ns, "addr", "add", &format!("{addr}/30"), "dev", dev]);
            ip(&["-n", ns, "link", "set", dev, "up"]);
            ip(&["-n", ns, "link", "set", "lo", "up"]);
        }
        hosts
    }

    /// Moves the calling thread into namespace `ns`; processes it starts afterwards run there.
    pub fn enter(ns: &str) {
        let file = std::fs::File::open(format!("/run/netns/{ns}")).unwrap();
        rustix::thread::move_into_link_name_space(
            file.as_fd(),
            Some(rustix::thread::LinkNameSpaceType::Network),
        )
        .unwrap();
    }

    /// Sets the veth down (`false`) or up.
    pub fn link(&self, up: bool) {
        ip(&[
            "-n",
            &self.a,
            "link",
            "set",
            &self.veth_a,
            if up { "up" } else { "down" },
        ]);
    }
}

impl Drop for Hosts {
    fn drop(&mut self) {
        // Deleting a namespace deletes the veth end in it, and with it the pair.
        for ns in [&self.a, &self.b] {
            let _ = Command::new(ip_command())
                .args(["netns", "del", ns])
                .status();
        }
    }
}
