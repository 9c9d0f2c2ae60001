//! JSON with paths: a value and its path from the top (`mission.items[3].params[4]`), so that
//! every error of the `.plan` and GeoJSON importers names the element it is about.
//!
//! # Why not `serde_path_to_error`
//!
//! Evaluated against this walker, and not taken. `serde_path_to_error` records the path of the
//! first error serde meets while deserializing into typed structs; on a `.plan` whose fourth
//! item has a string for param 5 it says `mission.items[3].params[4]: invalid type: string "x",
//! expected f64 at line 4 column 54`, the same path as ours. But most errors and every
//! *not supported* element of the importers are found after the types are read: a latitude of
//! 123 is a valid `f64` (the crate passes it), the meaning and range of `params[i]` depend on
//! the item's `command` and `frame`, a second fly-zone or an eleventh no-fly-zone is a rule of
//! the FCC, and [`crate::import`] lists every such element with its path instead of stopping at
//! the first. Those need the path of a value the program is looking at, which is what [`At`]
//! carries; with the crate the importers would keep this walker and add typed mirrors of the
//! `.plan` and GeoJSON formats on top.

use serde_json::{Map, Value};

use crate::import::MissionFileError;
use crate::values::field_error;

/// Parses JSON text; a syntax error carries the parser's line and column.
pub(crate) fn parse_json(text: &str) -> Result<Value, MissionFileError> {
    serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let message = match message.rfind(" at line ") {
            Some(k) => message.get(..k).unwrap_or(&message).to_owned(),
            None => message,
        };
        MissionFileError::Syntax {
            line: e.line(),
            // serde_json says column 0 for an error before a line's first character (an empty
            // file, a file that ends right after a newline); our columns count from 1.
            column: e.column().max(1),
            message,
        }
    })
}

/// A JSON value and its path from the top, e.g. `mission.items[3].params[4]`.
#[derive(Debug, Clone)]
pub(crate) struct At<'a> {
    pub(crate) value: &'a Value,
    pub(crate) path: String,
}

impl<'a> At<'a> {
    pub(crate) fn root(value: &'a Value) -> Self {
        Self {
            value,
            path: String::new(),
        }
    }

    fn child(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_owned()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The error `reason` at this value.
    pub(crate) fn error(&self, reason: impl Into<String>) -> MissionFileError {
        let path = if self.path.is_empty() {
            "(top level)".to_owned()
        } else {
            self.path.clone()
        };
        field_error(path, reason)
    }

    pub(crate) fn object(&self) -> Result<&'a Map<String, Value>, MissionFileError> {
        self.value
            .as_object()
            .ok_or_else(|| self.error(format!("expected an object, found {}", kind(self.value))))
    }

    /// The member `key`, which must be there.
    pub(crate) fn field(&self, key: &str) -> Result<At<'a>, MissionFileError> {
        match self.object()?.get(key) {
            Some(value) => Ok(At {
                value,
                path: self.child(key),
            }),
            None => Err(field_error(self.child(key), "missing")),
        }
    }

    /// The member `key`, if this is an object that has it.
    pub(crate) fn opt(&self, key: &str) -> Option<At<'a>> {
        self.value.as_object()?.get(key).map(|value| At {
            value,
            path: self.child(key),
        })
    }

    /// The elements of an array.
    pub(crate) fn items(&self) -> Result<Vec<At<'a>>, MissionFileError> {
        let array = self
            .value
            .as_array()
            .ok_or_else(|| self.error(format!("expected an array, found {}", kind(self.value))))?;
        Ok(array
            .iter()
            .enumerate()
            .map(|(i, value)| At {
                value,
                path: format!("{}[{i}]", self.path),
            })
            .collect())
    }

    pub(crate) fn number(&self) -> Result<f64, MissionFileError> {
        self.value
            .as_f64()
            .ok_or_else(|| self.error(format!("expected a number, found {}", kind(self.value))))
    }

    /// A number, or `None` for null (QGC writes NaN as null).
    pub(crate) fn opt_number(&self) -> Result<Option<f64>, MissionFileError> {
        if self.value.is_null() {
            Ok(None)
        } else {
            self.number().map(Some)
        }
    }

    pub(crate) fn integer(&self) -> Result<u64, MissionFileError> {
        self.value.as_u64().ok_or_else(|| {
            self.error(format!(
                "expected an integer of at least 0, found {}",
                kind(self.value)
            ))
        })
    }

    pub(crate) fn boolean(&self) -> Result<bool, MissionFileError> {
        self.value.as_bool().ok_or_else(|| {
            self.error(format!(
                "expected true or false, found {}",
                kind(self.value)
            ))
        })
    }

    /// The string field `key`, which must be `expected`.
    pub(crate) fn expect_string(&self, key: &str, expected: &str) -> Result<(), MissionFileError> {
        let at = self.field(key)?;
        match at.string()? {
            s if s == expected => Ok(()),
            other => Err(at.error(format!("{other:?}: expected {expected:?}"))),
        }
    }

    pub(crate) fn string(&self) -> Result<&'a str, MissionFileError> {
        self.value
            .as_str()
            .ok_or_else(|| self.error(format!("expected a string, found {}", kind(self.value))))
    }
}

fn kind(value: &Value) -> String {
    match value {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => format!("the number {n}"),
        Value::String(s) => format!("the string {s:?}"),
        Value::Array(_) => "an array".to_owned(),
        Value::Object(_) => "an object".to_owned(),
    }
}
