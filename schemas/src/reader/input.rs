//! Opening a recording for reading: checked before anything is read.
//!
//! A path must name a regular file (a directory, a FIFO, a socket or a device such as
//! `/dev/zero` is refused before any byte is read, as those can block or never end) whose first
//! bytes are the MCAP magic (a 20 GB file of anything else is refused after 8 bytes). The file
//! is then read through a buffer of [`BUFFER_BYTES`].

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::Path;

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
