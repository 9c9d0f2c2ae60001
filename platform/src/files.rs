//! Small state files that a reader, or the next start after a crash, must find whole: the old
//! contents or the new, never half of them. One owner for both sides: the FCC's partitions keep
//! their lists with [`write_atomically`] (durable: flushed to the disk before and after the
//! rename), the ground keeps what makes a restart smoother (its time-stamp reservation, the
//! lists it planned, the staged copies it must delete, the MAVLink memory) with [`replace`],
//! whole but not flushed: after a power loss the ground's clock is past what it reserved, and
//! the rest it reads again from the FCC.

use std::io;
use std::path::{Path, PathBuf};

/// A temporary name of this process's own beside `path`: two processes writing the same file
/// never share a half-written one.
fn temporary(path: &Path) -> PathBuf {
    path.with_extension(format!("tmp.{}", std::process::id()))
}

/// Writes `bytes` to `path` whole: a temporary file beside it, renamed over it. A reader sees
/// the previous contents or the new ones; a crash of this process leaves one of them.
pub fn replace(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let tmp = temporary(path);
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

/// Writes `bytes` to `path` so that a reader, or the next start after a crash or a power loss,
/// finds either the previous file or the new one, whole: a temporary file of this process's own
/// is written and flushed to the disk, renamed over `path`, and the directory is flushed so that
/// the rename itself survives. Makes the directory if it is not there.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let dir = path.parent();
    if let Some(dir) = dir {
        std::fs::create_dir_all(dir)?;
    }
    let tmp = temporary(path);
    let mut file = std::fs::File::create(&tmp)?;
    io::Write::write_all(&mut file, bytes)?;
    file.sync_all()?;
    drop(file);
    std::fs::rename(&tmp, path)?;
    if let Some(dir) = dir {
        sync_dir(dir)?;
    }
    Ok(())
}

/// Flushes a directory's entries (a rename or a removal in it) to the disk.
pub fn sync_dir(dir: &Path) -> io::Result<()> {
    std::fs::File::open(dir)?.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_leave_the_new_contents_whole_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        for (i, write) in [
            replace as fn(&Path, &[u8]) -> io::Result<()>,
            write_atomically,
        ]
        .into_iter()
        .enumerate()
        {
            let path = dir.path().join(format!("state-{i}"));
            write(&path, b"old\n").unwrap();
            write(&path, b"new contents\n").unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), b"new contents\n");
        }
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }
}
