//! Opening a recording for reading: checked before anything is read.
//!
//! A path must name a regular file (a directory, a FIFO, a socket or a device such as
//! `/dev/zero` is refused before any byte is read, as those can block or never end) whose first
//! bytes are the MCAP magic (a 20 GB file of anything else is refused after 8 bytes). The file
//! is then read through a buffer of [`BUFFER_BYTES`], or, by [`crate::stream_recording`],
//! through read-only memory maps of [`WINDOW_BYTES`] at a time ([`Windows`]).
//!
//! Why maps, and why windows (issue 24 item 5): `read` copies every byte from the page cache
//! into the process (the kernel's copy was 7–8 % of `analyze summary`'s CPU time on the 120-s
//! two-elbow recording); a map lets the MCAP reader copy straight from the page cache. A map of
//! the whole file would make the process's resident memory grow with the file (its pages count
//! as resident once touched), against the rule that memory is bounded by the work, not the
//! input: one window of [`WINDOW_BYTES`] is mapped at a time and unmapped when read.
//!
//! The risk (memmap2's `Mmap` docs: a file modified while mapped is undefined behaviour; on
//! Linux a page past a file's new end after a truncation raises SIGBUS, which kills the
//! process): `sim` never writes a recording in place (it writes a hidden `.partial` and
//! renames it), so a recording read here changes only if something else rewrites it. What is
//! done about that: the file's length is checked against the length it was opened with before
//! each window is mapped and after the last one (a file that changed size is an error naming
//! it, as with `read`), which leaves only a truncation within the time one window takes (about
//! 15 ms at 500 MB/s); bytes changed in place are read as they are and fail the CRCs. A file
//! that cannot be mapped (a file system without mmap) is read with `read`.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

use memmap2::{Advice, Mmap, MmapOptions};

use crate::Error;

/// Read buffer between the file and the MCAP reader.
pub(crate) const BUFFER_BYTES: usize = 256 << 10;

/// Opens `path`, checks it is a regular file that starts with the MCAP magic, and returns it
/// positioned at its start, with its length and the label errors use.
pub(crate) fn open(path: &Path) -> Result<(BufReader<File>, u64, String), Error> {
    let label = path.display().to_string();
    let io = |op, source| Error::Io { file: label.clone(), op, source };
    let (file, len) = open_regular(path)?;
    let mut magic = [0u8; 8];
    let mut reader = BufReader::with_capacity(BUFFER_BYTES, file);
    let head = read_up_to(&mut reader, &mut magic).map_err(|e| io("reading", e))?;
    if magic[..head] != mcap::MAGIC[..] {
        return Err(Error::NotMcap { file: label, len });
    }
    let mut file = reader.into_inner();
    std::io::Seek::rewind(&mut file).map_err(|e| io("reading", e))?;
    Ok((BufReader::with_capacity(BUFFER_BYTES, file), len, label))
}

/// Bytes of the file mapped at a time by [`Windows`] (a multiple of every page size).
pub(crate) const WINDOW_BYTES: u64 = 8 << 20;

/// A file of known length read through read-only maps of [`WINDOW_BYTES`], one at a time, from
/// its start (module doc); [`Windows::new`] falls back to `read` when the file cannot be mapped.
pub(crate) struct Windows {
    file: File,
    /// The length the file was opened with.
    len: u64,
    /// Where the mapped window starts in the file.
    at: u64,
    /// The window (`None` before the first and when mapping is not possible).
    map: Option<Mmap>,
    /// Bytes of the window already read.
    pos: usize,
    /// `read` instead, after a failed first map.
    fallback: Option<BufReader<File>>,
}

impl Windows {
    /// The file `file` of length `len` (as opened and checked by [`open`]), read from its start.
    pub(crate) fn new(file: File, len: u64) -> std::io::Result<Self> {
        let mut w = Windows { file, len, at: 0, map: None, pos: 0, fallback: None };
        if len > 0 && w.map_window().is_err() {
            let mut file = w.file.try_clone()?;
            std::io::Seek::rewind(&mut file)?;
            w.fallback = Some(BufReader::with_capacity(BUFFER_BYTES, file));
        }
        Ok(w)
    }

    /// The file must still have the length it was opened with.
    fn check_len(&self) -> std::io::Result<()> {
        let now = self.file.metadata()?.len();
        if now != self.len {
            return Err(std::io::Error::other(format!("the file changed size while being read: {} bytes when opened, {now} now", self.len)));
        }
        Ok(())
    }

    /// Maps the window at `at` (after checking the file's length).
    fn map_window(&mut self) -> std::io::Result<()> {
        self.map = None;
        self.check_len()?;
        let n = (self.len - self.at).min(WINDOW_BYTES) as usize;
        // SAFETY: read-only, private to this reader, and the file's length was just checked; a
        // file rewritten by another process while mapped is the risk the module doc describes
        let map = unsafe { MmapOptions::new().offset(self.at).len(n).populate().map(&self.file)? };
        let _ = map.advise(Advice::Sequential);
        self.map = Some(map);
        self.pos = 0;
        Ok(())
    }
}

impl Read for Windows {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if let Some(f) = self.fallback.as_mut() {
            return f.read(buf);
        }
        loop {
            if let Some(map) = &self.map {
                let rest = &map[self.pos..];
                if !rest.is_empty() {
                    let n = rest.len().min(buf.len());
                    buf[..n].copy_from_slice(&rest[..n]);
                    self.pos += n;
                    return Ok(n);
                }
                self.at += map.len() as u64;
                self.map = None;
            }
            if self.at >= self.len {
                // the end: the file must not have grown either
                self.check_len()?;
                return Ok(0);
            }
            self.map_window()?;
        }
    }
}

/// Opens `path` for reading if it names a regular file (links followed), with its length; a
/// directory, FIFO, socket or device (a link to `/dev/zero` included) is refused with
/// [`Error::NotAFile`] before it is opened, so a FIFO without a writer cannot block. The guard
/// every reader of a user's file goes through, recordings and tables alike (`analyze diff`
/// reads JSON and CSV tables through it).
pub fn open_regular(path: &Path) -> Result<(File, u64), Error> {
    let label = || path.display().to_string();
    let io = |op, source| Error::Io { file: label(), op, source };
    let meta = std::fs::metadata(path).map_err(|e| io("opening", e))?;
    if !meta.is_file() {
        return Err(Error::NotAFile { file: label(), kind: file_kind(&meta) });
    }
    let file = File::open(path).map_err(|e| io("opening", e))?;
    // what was opened is what was checked (the path may have been replaced in between)
    let meta = file.metadata().map_err(|e| io("opening", e))?;
    if !meta.is_file() {
        return Err(Error::NotAFile { file: label(), kind: file_kind(&meta) });
    }
    Ok((file, meta.len()))
}

/// Whether the file at `path` starts with the MCAP magic: reads at most its first 8 bytes
/// after the checks of [`open_regular`].
pub fn starts_with_mcap_magic(path: &Path) -> Result<bool, Error> {
    let (mut file, _) = open_regular(path)?;
    let mut magic = [0u8; 8];
    let head = read_up_to(&mut file, &mut magic).map_err(|source| Error::Io { file: path.display().to_string(), op: "reading", source })?;
    Ok(head == magic.len() && magic[..] == mcap::MAGIC[..])
}

/// Reads until `buf` is full or the input ends; the number of bytes read.
pub(crate) fn read_up_to(input: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match input.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

/// What a path that is not a regular file is, for the error.
#[cfg(unix)]
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_dir() {
        "a directory"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

#[cfg(not(unix))]
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() { "a directory" } else { "not a regular file" }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// Read through the windows, a file gives its bytes exactly (three windows, the last one
    /// partial, with reads of odd sizes across their ends); a file that grows or shrinks while
    /// read is an error saying so, never a crash or a short read.
    #[test]
    fn windows_read_the_file_and_refuse_one_that_changes_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        let len = 2 * WINDOW_BYTES as usize + 12_345;
        let bytes: Vec<u8> = (0..len).map(|k| (k * 7919 % 251) as u8).collect();
        std::fs::write(&path, &bytes).unwrap();
        let mut w = Windows::new(File::open(&path).unwrap(), len as u64).unwrap();
        assert!(w.fallback.is_none(), "the file is mapped");
        let (mut got, mut buf) = (Vec::new(), vec![0u8; 1_000_003]);
        loop {
            let n = w.read(&mut buf).unwrap();
            if n == 0 {
                break;
            }
            got.extend_from_slice(&buf[..n]);
        }
        assert!(got == bytes, "{} bytes read of {len}", got.len());
        for change in ["grows", "shrinks"] {
            let mut w = Windows::new(File::open(&path).unwrap(), len as u64).unwrap();
            assert_eq!(w.read(&mut buf).unwrap(), buf.len());
            if change == "grows" {
                std::fs::OpenOptions::new().append(true).open(&path).unwrap().write_all(b"more").unwrap();
            } else {
                std::fs::OpenOptions::new().write(true).open(&path).unwrap().set_len(WINDOW_BYTES + 10).unwrap();
            }
            let err = std::iter::repeat_with(|| w.read(&mut buf)).find(|r| !matches!(r, Ok(n) if *n > 0)).unwrap().unwrap_err();
            assert!(err.to_string().contains("changed size while being read"), "{change}: {err}");
            std::fs::write(&path, &bytes).unwrap();
        }
    }
}
