//! What the importers of mission files share (the TOML file, QGroundControl `.plan`, GeoJSON):
//! the one error type, with the line and column or the field path of what is wrong, and the
//! rule that an import is exact or refused unless the operator asked to drop what the ICD
//! cannot carry (docs/mission-files.md).

use core::fmt;
use std::path::PathBuf;

/// Why a mission file cannot be read or turned into a plan.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MissionFileError {
    /// The file cannot be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        message: String,
    },
    /// TOML syntax or type error (also a missing or unknown key), with line and column
    /// (1-based) and the message.
    #[error("line {line}, column {column}: {message}")]
    Syntax {
        /// Line, from 1.
        line: usize,
        /// Column in characters, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value that the wire types refuse, with the field path (e.g.
    /// `waypoints[2].latitude_deg`) and the reason.
    #[error("{path}: {reason}")]
    Field {
        /// Where, e.g. `areas[1].circle.radius_m`.
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// An imported file (QGroundControl `.plan`, GeoJSON) holds elements that the ICD cannot
    /// carry or the FCC cannot hold, and the import was not told to drop them: the plan would
    /// not be the one planned. Every such element, in file order (at least one).
    #[error(
        "not imported: {} element{} the ICD cannot carry or the FCC cannot hold{}",
        .elements.len(),
        if .elements.len() == 1 { "" } else { "s" },
        each(.elements)
    )]
    Unsupported {
        /// The elements, each with its JSON path and the reason.
        elements: Vec<Dropped>,
    },
}

/// An element of an imported file that the ICD cannot carry or the FCC cannot hold: where (the
/// JSON path, e.g. `mission.items[4]`, `geoFence.polygons[1]`, `features[2]`) and why. An import
/// refuses the file for it ([`MissionFileError::Unsupported`]) unless told to drop such
/// elements; then it lists every one it left out. An export uses it too, for what the target
/// format cannot hold.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dropped {
    /// The JSON path of the element, e.g. `geoFence.circles[0]`.
    pub path: String,
    /// What is not carried (and, where something is kept instead, what).
    pub reason: String,
}

impl fmt::Display for Dropped {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.reason)
    }
}

/// `; <path>: <reason>` for every element, as [`MissionFileError::Unsupported`] lists them.
fn each(elements: &[Dropped]) -> String {
    elements.iter().map(|e| format!("; {e}")).collect()
}

/// What an import does with an element that the ICD cannot carry or the FCC cannot hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unsupported {
    /// Refuse the file with every such element named ([`MissionFileError::Unsupported`]): the
    /// operator is never told about a plan that is not the one they made.
    #[default]
    Refuse,
    /// Leave every such element out and list it
    /// ([`QgcImport::dropped`](crate::qgc::QgcImport::dropped)): the operator chose to validate
    /// and upload what remains.
    Drop,
}

/// The import's result as `unsupported` wants it: the dropped elements, or the refusal when
/// there are any and they may not be dropped.
pub(crate) fn exact_or_dropped(
    dropped: Vec<Dropped>,
    unsupported: Unsupported,
) -> Result<Vec<Dropped>, MissionFileError> {
    match unsupported {
        Unsupported::Refuse if !dropped.is_empty() => {
            Err(MissionFileError::Unsupported { elements: dropped })
        }
        _ => Ok(dropped),
    }
}

pub(crate) fn note(path: impl Into<String>, reason: impl Into<String>) -> Dropped {
    Dropped {
        path: path.into(),
        reason: reason.into(),
    }
}
