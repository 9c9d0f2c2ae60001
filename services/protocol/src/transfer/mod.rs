//! Transfers of mission and area data (paper §3.1.5-§3.1.9; ICD §5): the one [`sender`] and the
//! mission and area [`receiver`]s, used in both directions (inverted use, paper §3.2), the
//! waypoint buffer and list ([`mission`]) and the area buffer and list ([`areas`]) with their
//! assembly and the checks of ICD §7, the checksums of both lists ([`integrity`], ICD §11) and
//! the memory that makes closers idempotent ([`closer`], ICD §11), the staged missions
//! ([`staged`], ICD §8), and the sender's window sized to the link ([`window`], ICD §10.4).

pub mod areas;
pub mod closer;
pub mod integrity;
pub mod mission;
pub mod plan;
pub mod receiver;
pub mod sender;
pub mod staged;
pub mod window;
