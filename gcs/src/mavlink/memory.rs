//! What `gcs mavlink` remembers across its restarts, in a small text file of its state
//! directory: the items of the lists it committed, under the ICD §11 checksums the FCC confirmed
//! for them, and the vehicle's home. The FCC holds the lists, not the client's items: read back
//! from the FCC after a restart, a take-off becomes the FCC's first waypoint and a land is added
//! (the `.plan` export's items). With the memory, a download returns the items the client
//! uploaded, as long as the FCC still holds those lists (the same checksums); lists another
//! ground station uploaded since are read back from the FCC.
//!
//! The format, line by line (`#` starts a comment): `missionlink-mavlink 1`; `ids MISSION
//! FENCE` (the checksums, hexadecimal); `home LAT LON ALT TYPE` (optional; TYPE the ICD's
//! altitude type number, or `-`); `mission N` and `fence N`, each followed by N lines `item
//! COMMAND FRAME P1 P2 P3 P4 X Y Z`. Floats are written as Rust writes them, the shortest text
//! that reads back to the same value, NaN included (MAVLink's "unset" parameter).

use core::fmt::Write as _;
use core::str::FromStr;

use missionlink_interfaces::wire::AltitudeType;

use super::home::Home;
use super::plan::Item;

/// The first line of a memory file.
const HEADER: &str = "missionlink-mavlink 1";

/// What the vehicle remembers.
#[derive(Debug, Clone, PartialEq)]
pub struct Memory {
    /// The ICD §11 checksums of the lists the FCC confirmed: mission, areas.
    pub ids: (u32, u32),
    /// The mission items as the client uploaded them.
    pub mission: Vec<Item>,
    /// The fence items as the client uploaded them.
    pub fence: Vec<Item>,
    /// The vehicle's home.
    pub home: Option<Home>,
}

/// Why a memory file is not read: the line and what is wrong with it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {reason}")]
pub struct MemoryError {
    /// The line, from 1.
    pub line: usize,
    /// What is wrong.
    pub reason: String,
}

impl Memory {
    /// The memory as the text of its file.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "{HEADER}");
        let _ = writeln!(out, "ids {:08x} {:08x}", self.ids.0, self.ids.1);
        if let Some(h) = self.home {
            let kind = h
                .altitude_type
                .map_or_else(|| "-".to_owned(), |t| (t as u8).to_string());
            let _ = writeln!(
                out,
                "home {} {} {} {kind}",
                h.latitude_deg, h.longitude_deg, h.altitude_m
            );
        }
        for (name, items) in [("mission", &self.mission), ("fence", &self.fence)] {
            let _ = writeln!(out, "{name} {}", items.len());
            for i in items {
                let [p1, p2, p3, p4] = i.params;
                let _ = writeln!(
                    out,
                    "item {} {} {p1} {p2} {p3} {p4} {} {} {}",
                    i.command, i.frame, i.x, i.y, i.z
                );
            }
        }
        out
    }

    /// Reads the text of a memory file.
    pub fn from_text(text: &str) -> Result<Self, MemoryError> {
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(n, l)| (n + 1, l.split('#').next().unwrap_or_default().trim()))
            .filter(|(_, l)| !l.is_empty());
        let error = |line: usize, reason: &str| MemoryError {
            line,
            reason: reason.to_owned(),
        };
        match lines.next() {
            Some((_, HEADER)) => {}
            Some((n, _)) => return Err(error(n, &format!("expected `{HEADER}`"))),
            None => return Err(error(1, "empty")),
        }
        let mut memory = Memory {
            ids: (0, 0),
            mission: Vec::new(),
            fence: Vec::new(),
            home: None,
        };
        let mut list: Option<(bool, usize)> = None;
        for (n, line) in lines {
            let words: Vec<&str> = line.split_whitespace().collect();
            match words.as_slice() {
                ["ids", mission, fence] => {
                    let id = |w: &str| {
                        u32::from_str_radix(w, 16)
                            .map_err(|_| error(n, "a checksum is 8 hex digits"))
                    };
                    memory.ids = (id(mission)?, id(fence)?);
                }
                ["home", lat, lon, alt, kind] => {
                    let altitude_type = match *kind {
                        "-" => None,
                        k => Some(
                            k.parse::<u8>()
                                .ok()
                                .and_then(|k| AltitudeType::try_from(k).ok())
                                .ok_or_else(|| error(n, "an altitude type is 0 to 3, or -"))?,
                        ),
                    };
                    memory.home = Some(Home {
                        latitude_deg: number(n, lat)?,
                        longitude_deg: number(n, lon)?,
                        altitude_m: number(n, alt)?,
                        altitude_type,
                    });
                }
                [name @ ("mission" | "fence"), count] => {
                    let count = count
                        .parse::<usize>()
                        .map_err(|_| error(n, "the count of items is a number"))?;
                    list = Some((*name == "mission", count));
                }
                ["item", command, frame, p1, p2, p3, p4, x, y, z] => {
                    let Some((mission, count)) = list else {
                        return Err(error(n, "an item before `mission N` or `fence N`"));
                    };
                    let items = if mission {
                        &mut memory.mission
                    } else {
                        &mut memory.fence
                    };
                    if items.len() == count {
                        return Err(error(n, "more items than the list's count"));
                    }
                    items.push(Item {
                        command: number(n, command)?,
                        frame: number(n, frame)?,
                        params: [
                            number(n, p1)?,
                            number(n, p2)?,
                            number(n, p3)?,
                            number(n, p4)?,
                        ],
                        x: number(n, x)?,
                        y: number(n, y)?,
                        z: number(n, z)?,
                    });
                }
                _ => return Err(error(n, "not a line of a memory file")),
            }
        }
        Ok(memory)
    }
}

fn number<T: FromStr>(line: usize, word: &str) -> Result<T, MemoryError> {
    word.parse().map_err(|_| MemoryError {
        line,
        reason: format!("`{word}` is not a number of its field"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn memory() -> Memory {
        let item = |command, z| Item {
            command,
            frame: 3,
            params: [0.5, 0.0, f32::NAN, 0.1],
            x: 482_600_000,
            y: 116_600_000,
            z,
        };
        Memory {
            ids: (0xdead_beef, 7),
            mission: vec![item(22, 30.0), item(16, 120.25)],
            fence: vec![item(5001, 0.0)],
            home: Some(Home {
                latitude_deg: 48.26,
                longitude_deg: 11.660_000_1,
                altitude_m: 0.1,
                altitude_type: Some(AltitudeType::Wgs84),
            }),
        }
    }

    /// NaN is not equal to itself: items are compared by their bits.
    fn bits(m: &Memory) -> Vec<[u32; 4]> {
        m.mission
            .iter()
            .chain(&m.fence)
            .map(|i| i.params.map(f32::to_bits))
            .collect()
    }

    #[test]
    fn reads_back_what_it_wrote() {
        let m = memory();
        let back = Memory::from_text(&m.to_text()).unwrap();
        assert_eq!(bits(&back), bits(&m));
        assert_eq!(back.ids, m.ids);
        assert_eq!(back.home, m.home);
        assert_eq!(back.mission.len(), 2);
        assert_eq!(back.mission[1].z, 120.25);
    }

    #[test]
    fn a_bad_line_is_named() {
        let text = memory().to_text().replace("item 16 3", "item 16 x");
        let e = Memory::from_text(&text).unwrap_err();
        assert_eq!(e.line, 6, "{e}");
        assert!(e.reason.contains("`x`"), "{e}");
        let e = Memory::from_text("missionlink-mavlink 1\nmission 0\nitem 1 2 3").unwrap_err();
        assert_eq!(e.line, 3, "{e}");
        assert!(Memory::from_text("something else").is_err());
    }
}
