//! The two UDP links of ICD §1 as one pair of sockets: each node receives on its direct and its
//! LTE port and sends every frame on both links (the FCC's downlink, the GCS's uplink), each
//! copy signed for its link when the node has a sending key (ICD §9). The sockets are
//! non-blocking, so a driver can sleep on them next to its other inputs (the FCC's partitions
//! attach them to an iceoryx2 WaitSet: `missionlink_partitions::wait_fd`). A [`DatagramTap`]
//! may watch every datagram the pair sends and receives (the GCS's `--pcap` capture).

use std::fmt;
use std::io::ErrorKind;
use std::net::{SocketAddr, UdpSocket};
use std::sync::Arc;

use missionlink_interfaces::contracts::Link;
use missionlink_interfaces::wire::MAX_SIGNED_FRAME_LEN;
use missionlink_protocol::link::signing::Signer;

use crate::clock::monotonic_ns;

/// Sees every datagram a [`LinkPair`] sends or receives, as it went on the wire (signed copies
/// included): a capture of the links for Wireshark. It lives here, in the link driver, so the
/// sans-IO services never know of it; what it does with the bytes is the tap's business (the
/// GCS writes pcap, `missionlink_gcs::pcap`).
pub trait DatagramTap: fmt::Debug + Send + Sync {
    /// A datagram of `link` from `from` to `to`.
    fn datagram(&self, link: Link, from: SocketAddr, to: SocketAddr, bytes: &[u8]);
}

/// Datagrams read per socket per wake-up at most, so one flooded link cannot starve the other.
pub const MAX_READS_PER_WAKE: usize = 32;

/// Datagrams one [`LinkPair::receive`] hands over at most: [`MAX_READS_PER_WAKE`] per socket.
pub const MAX_READS_PER_RECEIVE: usize = 2 * MAX_READS_PER_WAKE;

/// Largest datagram read: a few 548-byte frames back to back.
pub const MAX_DATAGRAM: usize = 2048;

/// A node's two ends bound on loopback to ports the system chose, before the peer's ends are
/// known: the GCS of the demo and of the tests binds these, hands their addresses to the FCC it
/// starts, then [`LocalEnds::connect`]s them to the ports the FCC announces. No port is freed
/// and bound again, so nothing else on the machine can take it in between.
#[derive(Debug)]
pub struct LocalEnds {
    direct: UdpSocket,
    lte: UdpSocket,
}

impl LocalEnds {
    /// Binds both ends on 127.0.0.1, port 0.
    pub fn bind_loopback() -> Result<Self, LinkError> {
        let any = SocketAddr::from(([127, 0, 0, 1], 0));
        Ok(Self {
            direct: bind(any, "direct")?,
            lte: bind(any, "LTE")?,
        })
    }

    /// Where the direct and the LTE end are bound.
    pub fn addrs(&self) -> Result<[SocketAddr; 2], LinkError> {
        addrs(&self.direct, &self.lte)
    }

    /// The link pair to the peer's ends.
    pub fn connect(
        self,
        peer_direct: SocketAddr,
        peer_lte: SocketAddr,
    ) -> Result<LinkPair, LinkError> {
        LinkPair::from_sockets(self.direct, self.lte, peer_direct, peer_lte)
    }
}

/// The direct and the LTE socket of one node, and where the peer receives.
#[derive(Debug)]
pub struct LinkPair {
    direct: UdpSocket,
    lte: UdpSocket,
    peer_direct: SocketAddr,
    peer_lte: SocketAddr,
    signer: Option<Signer>,
    /// The capture, with the local addresses of the direct and the LTE socket (read once).
    tap: Option<(Arc<dyn DatagramTap>, [SocketAddr; 2])>,
}

/// A socket that could not be set up.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct LinkError(pub String);

fn bind(addr: SocketAddr, link: &str) -> Result<UdpSocket, LinkError> {
    UdpSocket::bind(addr)
        .map_err(|e| LinkError(format!("cannot bind the {link} link to {addr}: {e}")))
}

fn addrs(direct: &UdpSocket, lte: &UdpSocket) -> Result<[SocketAddr; 2], LinkError> {
    let addr = |s: &UdpSocket, link: &str| {
        s.local_addr()
            .map_err(|e| LinkError(format!("{link} link: {e}")))
    };
    Ok([addr(direct, "direct")?, addr(lte, "LTE")?])
}

fn non_blocking(socket: &UdpSocket, link: &str) -> Result<(), LinkError> {
    socket
        .set_nonblocking(true)
        .map_err(|e| LinkError(format!("{link} link: {e}")))
}

impl LinkPair {
    /// Binds the local ends (port 0: the system chooses, see [`LinkPair::local_addrs`]); frames
    /// go to the peer's ends.
    pub fn bind(
        local_direct: SocketAddr,
        local_lte: SocketAddr,
        peer_direct: SocketAddr,
        peer_lte: SocketAddr,
    ) -> Result<Self, LinkError> {
        Self::from_sockets(
            bind(local_direct, "direct")?,
            bind(local_lte, "LTE")?,
            peer_direct,
            peer_lte,
        )
    }

    /// Over sockets the caller bound already (so that the process that binds a port is the one
    /// that chose it: no port is freed and bound again by someone else).
    pub fn from_sockets(
        direct: UdpSocket,
        lte: UdpSocket,
        peer_direct: SocketAddr,
        peer_lte: SocketAddr,
    ) -> Result<Self, LinkError> {
        non_blocking(&direct, "direct")?;
        non_blocking(&lte, "LTE")?;
        Ok(Self {
            direct,
            lte,
            peer_direct,
            peer_lte,
            signer: None,
            tap: None,
        })
    }

    /// The same pair showing every datagram it sends and receives to `tap`.
    pub fn with_tap(mut self, tap: Arc<dyn DatagramTap>) -> Result<Self, LinkError> {
        self.tap = Some((tap, self.local_addrs()?));
        Ok(self)
    }

    /// The same pair signing every frame it sends with `signer` (ICD §9); `None`: unsigned.
    pub fn with_signer(mut self, signer: Option<Signer>) -> Self {
        self.signer = signer;
        self
    }

    /// Whether a datagram waits on either socket, without reading it (a `MSG_PEEK` of one
    /// byte on each: what a spinning FCC partition loop looks at,
    /// `missionlink_partitions::runtime::Pending`).
    pub fn has_datagrams(&self) -> bool {
        let mut byte = [0u8; 1];
        [&self.direct, &self.lte]
            .iter()
            .any(|socket| socket.peek_from(&mut byte).is_ok())
    }

    /// Where the direct and the LTE socket are bound.
    pub fn local_addrs(&self) -> Result<[SocketAddr; 2], LinkError> {
        addrs(&self.direct, &self.lte)
    }

    /// The direct and the LTE socket (to wait on them: a WaitSet's attachments, a poll).
    pub fn sockets(&self) -> [&UdpSocket; 2] {
        [&self.direct, &self.lte]
    }

    /// Reads what both sockets hold (up to [`MAX_READS_PER_WAKE`] each) and hands each datagram
    /// to `f` with its link and CLOCK_MONOTONIC receive time.
    pub fn receive(&self, buf: &mut [u8], mut f: impl FnMut(Link, &[u8], u64)) {
        for (link, socket) in [(Link::Direct, &self.direct), (Link::Lte, &self.lte)] {
            for _ in 0..MAX_READS_PER_WAKE {
                match socket.recv_from(buf) {
                    Ok((len, from)) => {
                        let at = monotonic_ns();
                        let datagram = buf.get(..len).unwrap_or_default();
                        if let Some((tap, [direct, lte])) = &self.tap {
                            let to = if link == Link::Direct { *direct } else { *lte };
                            tap.datagram(link, from, to, datagram);
                        }
                        f(link, datagram, at);
                    }
                    Err(e) if e.kind() == ErrorKind::WouldBlock => break,
                    Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                    Err(e) => {
                        // ICMP port unreachable from a peer not yet started, and the like.
                        tracing::debug!(?link, %e, "receive error");
                        break;
                    }
                }
            }
        }
    }

    /// Sends `frame` on both links, each copy signed for its link when the pair has a signer.
    /// A link that fails is logged; the other still carries it.
    pub fn send_both(&self, frame: &[u8]) -> usize {
        let mut sent = 0;
        let mut signed = [0u8; MAX_SIGNED_FRAME_LEN];
        for (link, socket, peer) in [
            (Link::Direct, &self.direct, self.peer_direct),
            (Link::Lte, &self.lte, self.peer_lte),
        ] {
            let datagram = match &self.signer {
                None => frame,
                Some(signer) => match signer.sign(link, frame, &mut signed) {
                    Ok(len) => signed.get(..len).unwrap_or_default(),
                    Err(e) => {
                        // Our own frame: a defect, never an input; nothing unsigned goes out.
                        tracing::error!(?link, %e, "cannot sign a frame: not sent");
                        continue;
                    }
                },
            };
            match socket.send_to(datagram, peer) {
                Ok(_) => {
                    sent += 1;
                    if let Some((tap, [direct, lte])) = &self.tap {
                        let from = if link == Link::Direct { *direct } else { *lte };
                        tap.datagram(link, from, peer, datagram);
                    }
                }
                Err(e) => tracing::debug!(?link, %peer, %e, "send failed"),
            }
        }
        sent
    }
}
