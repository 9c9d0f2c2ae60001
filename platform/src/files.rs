//! Small state files that a reader, or the next start after a crash, must find whole: the old
//! contents or the new, never half of them. One owner for both sides:
//!
//! - the FCC's partitions keep their announcements with [`write_atomically`] and their lists,
//!   rewritten at every upload, with [`rewrite_durably`]; both durable (flushed to the disk
//!   before and after the rename or the exchange);
//! - the ground keeps what makes a restart smoother, whole but not flushed (after a power loss
//!   its clock is past what it reserved, and the rest it reads again from the FCC): the staged
//!   copies it must delete and the MAVLink memory with [`replace`], as [`rewrite_durably`] does
//!   without its flushes; what it rewrites every second or at every upload (its time-stamp and
//!   replay reservations, the lists it planned) as a [`LineFile`], one line overwritten in
//!   place.

use std::io;
use std::path::{Path, PathBuf};

/// A temporary name of this process's own beside `path`: two processes writing the same file
/// never share a half-written one.
fn temporary(path: &Path) -> PathBuf {
    path.with_extension(format!("tmp.{}", std::process::id()))
}

/// As [`rewrite_durably`] without the flushes: a crash of this process leaves the previous
/// contents or the new ones, whole; a power loss may leave either, or what the disk had before
/// them. For the ground's files, rewritten at every upload (the MAVLink memory), whose only
/// reader is the next start of their writer.
pub fn replace(path: &Path, bytes: &[u8]) -> io::Result<()> {
    exchange(path, bytes, false)
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

/// The file beside `path` that [`rewrite_durably`] writes the next contents into and then
/// exchanges with `path`: after the exchange it holds the previous contents. Its name keeps
/// none of `path`'s extension (`active-lists.frames` has `active-lists.spare`).
pub fn spare(path: &Path) -> PathBuf {
    path.with_extension("spare")
}

/// As [`write_atomically`] for a file rewritten again and again (the FCC's active lists, at
/// every upload) whose only reader is its writer's next start: the next start after a crash or
/// a power loss finds the previous contents or the new ones, whole, and no file is made or
/// deleted once both names exist. The contents are written into `path`'s [`spare`] and flushed,
/// the two names are exchanged in one step (`renameat2`'s `RENAME_EXCHANGE`) and the directory
/// is flushed. A new file at every write made ext4's allocator step over ever more recently
/// deleted inodes: at sixteen FCCs on one machine that cost an upload more than its flushes
/// (BENCHMARKS.md section 10).
///
/// Writers of the same directory take turns (an exclusive `flock` of the directory): an
/// instance on its way out after a `kill -9` of its launcher never writes the spare at the
/// same time as the one that replaced it. A reader other than the writer could see the
/// contents of the write after next if it were still reading then: none is. Where the file
/// system cannot exchange names, the spare is renamed over `path` (a plain atomic replacement).
pub fn rewrite_durably(path: &Path, bytes: &[u8]) -> io::Result<()> {
    exchange(path, bytes, true)
}

/// [`rewrite_durably`], flushed to the disk or not (`durable`).
fn exchange(path: &Path, bytes: &[u8], durable: bool) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir)?;
    let dir_file = std::fs::File::open(dir)?;
    rustix::fs::flock(&dir_file, rustix::fs::FlockOperation::LockExclusive)?;
    let spare = spare(path);
    let mut file = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(&spare)?;
    io::Write::write_all(&mut file, bytes)?;
    file.set_len(bytes.len() as u64)?;
    if durable {
        file.sync_all()?;
    }
    drop(file);
    match rustix::fs::renameat_with(
        rustix::fs::CWD,
        &spare,
        rustix::fs::CWD,
        path,
        rustix::fs::RenameFlags::EXCHANGE,
    ) {
        Ok(()) => {}
        // The first write (nothing to exchange with), or a file system that cannot exchange.
        Err(rustix::io::Errno::NOENT | rustix::io::Errno::INVAL | rustix::io::Errno::NOSYS) => {
            std::fs::rename(&spare, path)?;
        }
        Err(e) => return Err(e.into()),
    }
    // Flushes the exchange; the lock goes with the descriptor.
    if durable {
        dir_file.sync_all()?;
    }
    Ok(())
}

/// A file of one line that its one writer overwrites in place, kept open: no file is made or
/// deleted per write, which at one rewrite a second per vehicle (the ground service's time-stamp
/// and replay reservations, ICD §9) cost more CPU in the file system than all the rest of its
/// work at 250 vehicles. Lines of one width (numbers written with a fixed number of digits)
/// make every write one `pwrite` that a reader sees whole; a shorter line than the last also
/// truncates the file. Not flushed, as [`replace`]: the next start reads it, and a line that
/// does not read counts as none.
#[derive(Debug)]
pub struct LineFile {
    path: PathBuf,
    file: std::fs::File,
    /// The file's length as this writer left it.
    len: u64,
}

impl LineFile {
    /// Opens `path` for writing, made if it is not there, its contents left as they are.
    pub fn open(path: &Path) -> io::Result<Self> {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)?;
        let len = file.metadata()?.len();
        Ok(Self {
            path: path.to_owned(),
            file,
            len,
        })
    }

    /// The line in `path`, without its newline; `None` when there is no file or it cannot be
    /// read.
    pub fn read(path: &Path) -> Option<String> {
        let text = std::fs::read_to_string(path).ok()?;
        Some(text.trim_end_matches('\n').to_owned())
    }

    /// Writes `line` and a newline over what the file holds.
    pub fn write(&mut self, line: &str) -> io::Result<()> {
        let bytes = format!("{line}\n");
        std::os::unix::fs::FileExt::write_all_at(&self.file, bytes.as_bytes(), 0)?;
        let len = bytes.len() as u64;
        if len < self.len {
            self.file.set_len(len)?;
        }
        self.len = len;
        Ok(())
    }

    /// Where the file is.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Flushes a directory's entries (a rename or a removal in it) to the disk.
pub fn sync_dir(dir: &Path) -> io::Result<()> {
    std::fs::File::open(dir)?.sync_all()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::MetadataExt;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn an_atomic_write_leaves_the_new_contents_whole_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("state");
        write_atomically(&path, b"old\n").unwrap();
        write_atomically(&path, b"new contents\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new contents\n");
        assert_eq!(names(dir.path()), ["state"]);
    }

    #[test]
    fn a_line_file_is_overwritten_in_place() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lease");
        assert_eq!(LineFile::read(&path), None);
        let mut file = LineFile::open(&path).unwrap();
        let inode = std::fs::metadata(&path).unwrap().ino();
        file.write("00000000000000001234").unwrap();
        file.write("00000000000000005678").unwrap();
        assert_eq!(
            LineFile::read(&path).as_deref(),
            Some("00000000000000005678")
        );
        // A shorter line leaves nothing of the longer one; the same file throughout.
        file.write("7").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"7\n");
        assert_eq!(std::fs::metadata(&path).unwrap().ino(), inode);
        // Opened again, it keeps what it held until written.
        drop(file);
        let mut again = LineFile::open(&path).unwrap();
        assert_eq!(LineFile::read(&path).as_deref(), Some("7"));
        again.write("8").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"8\n");
    }

    #[test]
    fn a_rewrite_exchanges_two_files_and_makes_none_after_the_second() {
        for rewrite in [
            rewrite_durably as fn(&Path, &[u8]) -> io::Result<()>,
            replace,
        ] {
            rewrites_by_exchange(rewrite);
        }
    }

    fn rewrites_by_exchange(rewrite_durably: fn(&Path, &[u8]) -> io::Result<()>) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lists.frames");
        rewrite_durably(&path, b"first, the longest of the contents\n").unwrap();
        assert_eq!(names(dir.path()), ["lists.frames"]);
        rewrite_durably(&path, b"second\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second\n");
        // The spare holds the previous contents, whole.
        assert_eq!(
            std::fs::read(spare(&path)).unwrap(),
            b"first, the longest of the contents\n"
        );
        let inodes = |p: &Path| std::fs::metadata(p).unwrap().ino();
        let (a, b) = (inodes(&path), inodes(&spare(&path)));
        // A shorter write after a longer one leaves nothing of the longer one.
        rewrite_durably(&path, b"third\n").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"third\n");
        assert_eq!(std::fs::read(spare(&path)).unwrap(), b"second\n");
        // The same two files, their names exchanged: no file made, none deleted.
        assert_eq!((inodes(&path), inodes(&spare(&path))), (b, a));
        assert_eq!(names(dir.path()), ["lists.frames", "lists.spare"]);
    }
}
