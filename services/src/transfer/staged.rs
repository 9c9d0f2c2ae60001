//! Staged missions (ICD §8): the Mission ID that names one.
//!
//! The FCC holds up to [`MAX_STAGED_MISSIONS`](missionlink_interfaces::capacity::MAX_STAGED_MISSIONS)
//! staged missions beside the active lists, each named by a Mission ID: non-empty printable
//! ASCII of at most 19 characters (#13000 field 1, #2011 field 6, #50000 field 2, #50001 field 3,
//! all Char20). The GCS and the FCC check an ID with the one rule here.

use core::fmt;

use missionlink_interfaces::wire::Text;

/// Characters of a Mission ID at most (Char20 holds 19 and its terminator).
pub const MAX_MISSION_ID_LEN: usize = 19;

/// The name of a staged mission (ICD §8). Ordered by its bytes, the order of the report.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MissionId(Text<20>);

/// Why a text is not a Mission ID.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MissionIdError {
    /// The ID is empty: an empty Mission ID names the active lists, never a staged mission.
    Empty,
    /// Longer than [`MAX_MISSION_ID_LEN`] characters.
    TooLong {
        /// Bytes given.
        len: usize,
    },
    /// Holds a byte that is not printable ASCII (0x20..=0x7e).
    NotPrintable {
        /// Byte offset of the first such byte.
        at: usize,
    },
}

impl fmt::Display for MissionIdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => write!(f, "the Mission ID is empty"),
            Self::TooLong { len } => write!(
                f,
                "the Mission ID has {len} characters, at most {MAX_MISSION_ID_LEN} fit"
            ),
            Self::NotPrintable { at } => write!(
                f,
                "the Mission ID holds a character that is not printable ASCII at byte {at}"
            ),
        }
    }
}

impl core::error::Error for MissionIdError {}

impl MissionId {
    /// The Mission ID `s`, if it is non-empty printable ASCII of at most 19 characters.
    pub fn new(s: &str) -> Result<Self, MissionIdError> {
        if s.is_empty() {
            return Err(MissionIdError::Empty);
        }
        if let Some(at) = s.bytes().position(|b| !(0x20..=0x7e).contains(&b)) {
            return Err(MissionIdError::NotPrintable { at });
        }
        Text::new(s)
            .map(Self)
            .map_err(|_| MissionIdError::TooLong { len: s.len() })
    }

    /// The Mission ID a received field holds, by the same rule.
    pub fn of_text(text: &Text<20>) -> Result<Self, MissionIdError> {
        Self::new(text.as_str())
    }

    /// The ID as the Char20 field carries it.
    pub fn text(&self) -> Text<20> {
        self.0
    }

    /// The ID.
    pub fn as_str(&self) -> &str {
        self.0.as_str()
    }
}

impl fmt::Display for MissionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl fmt::Debug for MissionId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_of_icd_8() {
        assert_eq!(
            MissionId::new("survey-north").map(|i| i.to_string()),
            Ok("survey-north".into())
        );
        assert_eq!(MissionId::new(""), Err(MissionIdError::Empty));
        assert_eq!(
            MissionId::new(&"a".repeat(19)).map(|i| i.as_str().len()),
            Ok(19)
        );
        assert_eq!(
            MissionId::new(&"a".repeat(20)),
            Err(MissionIdError::TooLong { len: 20 })
        );
        assert_eq!(
            MissionId::new("ab\tc"),
            Err(MissionIdError::NotPrintable { at: 2 })
        );
        assert_eq!(
            MissionId::new("né"),
            Err(MissionIdError::NotPrintable { at: 1 })
        );
        assert_eq!(
            MissionId::of_text(&Text::default()),
            Err(MissionIdError::Empty)
        );
    }

    #[test]
    fn ordered_by_bytes_as_the_report_is() {
        let mut ids =
            ["b", "B", "a1", "a"].map(|s| MissionId::new(s).unwrap_or_else(|e| panic!("{e}")));
        ids.sort();
        assert_eq!(
            ids.map(|i| i.to_string()),
            ["B", "a", "a1", "b"].map(String::from)
        );
    }
}
