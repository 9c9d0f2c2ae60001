//! A capture of both links as a pcap file, for Wireshark and tshark with the STANAG 4586
//! dissector of `tools/wireshark/missionlink.lua`: every datagram the GCS sends and receives on
//! the direct and the LTE link (ICD §1), as the UDP/IPv4 packet it was, with its real addresses
//! and ports.
//!
//! The classic pcap format (not pcapng) with link type RAW (101: each packet starts with its IPv4
//! header) is all a UDP capture needs and every tool reads it; it is small enough to write here
//! rather than take a crate for it. Headers are written in this machine's byte order, which the
//! magic number tells the reader; the packets themselves are big-endian as on the wire.

use std::fs::File;
use std::io::{self, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::Path;
use std::sync::Mutex;
use std::time::{SystemTime, UNIX_EPOCH};

use missionlink_interfaces::contracts::Link;
use missionlink_platform::udp::DatagramTap;

/// pcap's magic number (microsecond time stamps).
const MAGIC: u32 = 0xa1b2_c3d4;
/// LINKTYPE_RAW: the packet starts with its IP header.
const LINKTYPE_RAW: u32 = 101;
/// Longest packet kept: more than any datagram of the links (IP and UDP headers included).
const SNAPLEN: u32 = 65_535;
/// IPv4 header without options, and the UDP header.
const IPV4_HEADER: usize = 20;
const UDP_HEADER: usize = 8;

/// Writes a pcap file, one record per datagram; shared by both links (a mutex: each record is
/// written whole, in the order the datagrams passed).
#[derive(Debug)]
pub struct PcapWriter {
    file: Mutex<File>,
}

impl PcapWriter {
    /// Creates (or truncates) `path` and writes the file header.
    pub fn create(path: &Path) -> io::Result<Self> {
        let mut file = File::create(path)?;
        file.write_all(&file_header())?;
        Ok(Self {
            file: Mutex::new(file),
        })
    }

    /// Appends one UDP datagram from `from` to `to` at `at`.
    pub fn write(
        &self,
        at: SystemTime,
        from: SocketAddr,
        to: SocketAddr,
        payload: &[u8],
    ) -> io::Result<()> {
        let record = record(at, from, to, payload)?;
        let mut file = self
            .file
            .lock()
            .map_err(|_| io::Error::other("the capture file's lock is poisoned"))?;
        // One write per record, unbuffered: a GCS that ends at any moment leaves a whole file.
        file.write_all(&record)
    }
}

impl DatagramTap for PcapWriter {
    fn datagram(&self, link: Link, from: SocketAddr, to: SocketAddr, bytes: &[u8]) {
        if let Err(e) = self.write(SystemTime::now(), from, to, bytes) {
            // The capture is for debugging: losing it must not stop the link.
            tracing::warn!(?link, %e, "cannot write the datagram to the pcap capture");
        }
    }
}

/// The 24-byte file header.
fn file_header() -> Vec<u8> {
    let mut h = Vec::with_capacity(24);
    h.extend_from_slice(&MAGIC.to_ne_bytes());
    h.extend_from_slice(&2u16.to_ne_bytes()); // version 2.4
    h.extend_from_slice(&4u16.to_ne_bytes());
    h.extend_from_slice(&0i32.to_ne_bytes()); // time zone: UTC
    h.extend_from_slice(&0u32.to_ne_bytes()); // accuracy of time stamps
    h.extend_from_slice(&SNAPLEN.to_ne_bytes());
    h.extend_from_slice(&LINKTYPE_RAW.to_ne_bytes());
    h
}

fn ipv4(addr: SocketAddr) -> io::Result<Ipv4Addr> {
    match addr.ip() {
        IpAddr::V4(ip) => Ok(ip),
        // The links are IPv4 (ICD §1).
        IpAddr::V6(ip) => ip.to_ipv4_mapped().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, format!("{ip} is not IPv4"))
        }),
    }
}

/// One record: its 16-byte header, then the IPv4 packet holding the UDP datagram.
fn record(at: SystemTime, from: SocketAddr, to: SocketAddr, payload: &[u8]) -> io::Result<Vec<u8>> {
    let too_long = || io::Error::new(io::ErrorKind::InvalidInput, "datagram too long for IPv4");
    let udp_len = u16::try_from(UDP_HEADER + payload.len()).map_err(|_| too_long())?;
    let ip_len = u16::try_from(IPV4_HEADER + usize::from(udp_len)).map_err(|_| too_long())?;
    let since = at.duration_since(UNIX_EPOCH).unwrap_or_default();
    // pcap's seconds are 32 bits: good until 2106.
    let seconds = u32::try_from(since.as_secs()).unwrap_or(u32::MAX);

    let [l0, l1] = ip_len.to_be_bytes();
    let [s0, s1, s2, s3] = ipv4(from)?.octets();
    let [d0, d1, d2, d3] = ipv4(to)?.octets();
    // Version 4 with 5 words of header, length, don't fragment, time to live 64, UDP (17), the
    // header checksum (0 while it is computed), source, destination.
    let header = |c0, c1| -> [u8; IPV4_HEADER] {
        [
            0x45, 0, l0, l1, 0, 0, 0x40, 0, 64, 17, c0, c1, s0, s1, s2, s3, d0, d1, d2, d3,
        ]
    };
    let [c0, c1] = internet_checksum(&header(0, 0)).to_be_bytes();
    let ip = header(c0, c1);

    let mut out = Vec::with_capacity(16 + usize::from(ip_len));
    out.extend_from_slice(&seconds.to_ne_bytes());
    out.extend_from_slice(&since.subsec_micros().to_ne_bytes());
    out.extend_from_slice(&u32::from(ip_len).to_ne_bytes()); // bytes kept
    out.extend_from_slice(&u32::from(ip_len).to_ne_bytes()); // bytes on the wire
    out.extend_from_slice(&ip);
    out.extend_from_slice(&from.port().to_be_bytes());
    out.extend_from_slice(&to.port().to_be_bytes());
    out.extend_from_slice(&udp_len.to_be_bytes());
    // UDP checksum 0: "not computed", allowed over IPv4 (RFC 768); loopback sockets leave it
    // to the kernel too.
    out.extend_from_slice(&0u16.to_be_bytes());
    out.extend_from_slice(payload);
    Ok(out)
}

/// The IPv4 header checksum (RFC 1071): the ones' complement of the ones' complement sum of the
/// 16-bit words.
fn internet_checksum(header: &[u8]) -> u16 {
    let mut sum: u32 = header
        .chunks(2)
        .map(|w| match w {
            [hi, lo] => u32::from(u16::from_be_bytes([*hi, *lo])),
            [hi] => u32::from(*hi) << 8,
            _ => 0,
        })
        .sum();
    while sum > 0xffff {
        sum = (sum & 0xffff) + (sum >> 16);
    }
    // The loop leaves at most 16 bits.
    !(sum as u16)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]

    use super::*;
    use std::time::Duration;

    #[test]
    fn a_record_is_an_ipv4_udp_packet_with_a_valid_header_checksum() {
        let from: SocketAddr = "127.0.0.1:4587".parse().unwrap();
        let to: SocketAddr = "127.0.0.1:4586".parse().unwrap();
        let at = UNIX_EPOCH + Duration::from_micros(1_700_000_000_123_456);
        let r = record(at, from, to, &[1, 2, 3]).unwrap();
        assert_eq!(r.len(), 16 + 20 + 8 + 3);
        assert_eq!(
            u32::from_ne_bytes(r[0..4].try_into().unwrap()),
            1_700_000_000
        );
        assert_eq!(u32::from_ne_bytes(r[4..8].try_into().unwrap()), 123_456);
        assert_eq!(u32::from_ne_bytes(r[8..12].try_into().unwrap()), 31);
        let ip = &r[16..36];
        // A header with its checksum sums to 0xffff: its checksum is 0.
        assert_eq!(internet_checksum(ip), 0);
        assert_eq!(&ip[12..20], &[127, 0, 0, 1, 127, 0, 0, 1]);
        assert_eq!(&r[36..44], &[0x11, 0xeb, 0x11, 0xea, 0, 11, 0, 0]);
        assert_eq!(&r[44..], &[1, 2, 3]);
    }

    #[test]
    fn the_file_starts_with_the_pcap_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("links.pcap");
        let w = PcapWriter::create(&path).unwrap();
        let from: SocketAddr = "127.0.0.1:1".parse().unwrap();
        w.write(SystemTime::now(), from, from, b"x").unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 24 + 16 + 29);
        assert_eq!(u32::from_ne_bytes(bytes[0..4].try_into().unwrap()), MAGIC);
        assert_eq!(u32::from_ne_bytes(bytes[20..24].try_into().unwrap()), 101);
    }
}
