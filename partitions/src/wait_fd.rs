//! The UDP link pair's sockets as iceoryx2 WaitSet attachments, so voting-monitoring sleeps on
//! its sockets and its listeners in one WaitSet. The pair itself
//! ([`missionlink_platform::udp::LinkPair`]) is shared with the ground and knows nothing of
//! iceoryx2; the attachment is the FCC's business and lives here.

use std::fmt;
use std::os::fd::AsRawFd;

use iceoryx2::prelude::{FileDescriptor, FileDescriptorBased, SynchronousMultiplexing};
use missionlink_platform::udp::{LinkError, LinkPair};

/// A socket's descriptor as a WaitSet attachment (not owning: the socket closes it, so the
/// pair must outlive the attachment).
pub struct SocketFd(FileDescriptor);

impl fmt::Debug for SocketFd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SocketFd")
    }
}

impl FileDescriptorBased for SocketFd {
    fn file_descriptor(&self) -> &FileDescriptor {
        &self.0
    }
}

impl SynchronousMultiplexing for SocketFd {}

impl SocketFd {
    /// The attachment of `socket`'s descriptor (`None` when it has none).
    pub fn of(socket: &impl AsRawFd) -> Option<Self> {
        FileDescriptor::non_owning_new(socket.as_raw_fd()).map(Self)
    }
}

/// The WaitSet attachments of the direct and the LTE socket of `links`.
pub fn attachments(links: &LinkPair) -> Result<[SocketFd; 2], LinkError> {
    let [direct, lte] = links.sockets();
    let fd = |socket: &std::net::UdpSocket, link: &str| {
        FileDescriptor::non_owning_new(socket.as_raw_fd())
            .map(SocketFd)
            .ok_or_else(|| LinkError(format!("{link} link: no file descriptor")))
    };
    Ok([fd(direct, "direct")?, fd(lte, "LTE")?])
}
