//! Atomic, exclusive output files: the one owner of "a file appears under its final name only
//! when it is complete", for every file the tools write (recordings through
//! [`crate::RecordingWriter`], tables, figures, reports, scenes, man pages through
//! [`write_file`] and [`write_with`]).
//!
//! # The protocol, for a final path `DIR/NAME`
//! 1. **Lock.** Open (creating it if needed) the lock file `DIR/.NAME.lock` and take an advisory
//!    exclusive lock on it without waiting ([`File::try_lock`], `flock(2)` on Linux). If another
//!    writer holds it, fail at once with [`Error::Busy`], which names the path: two writers of
//!    one final name are refused up front instead of racing.
//! 2. **Verify.** A lock taken on a lock file that its previous holder has meanwhile unlinked
//!    (step 6) protects nothing: a third writer may already have created a new lock file under
//!    the same name and locked that. So after locking, compare the device and inode of the open
//!    lock file with those of the path (`fstat` against `stat`); if they differ or the path is
//!    gone, drop the lock and start again. Whoever holds a lock on the inode that the path names
//!    is therefore the only writer of `NAME`.
//! 3. **Clean.** Under the lock no other writer of `NAME` is alive, so every temporary file of
//!    `NAME` left in `DIR` by a killed writer (`.NAME.<pid>-<n>.partial`, and the older
//!    `.NAME.partial`) is stale: delete them.
//! 4. **Write** to a fresh temporary sibling `DIR/.NAME.<pid>-<n>.partial` (created with
//!    `O_EXCL`; `<n>` counts writers within the process), so no two writers ever share a
//!    temporary file even if the locks were ignored (e.g. a filesystem without `flock`).
//! 5. **Commit.** Flush, `fsync` the file, rename it to `NAME` (atomic within a filesystem) and
//!    `fsync` the directory so the rename itself survives a power cut (best effort: some
//!    filesystems refuse to `fsync` a directory, and the complete file is in place already).
//! 6. **Release.** Unlink the lock file while still holding the lock, then close it. Deleting it
//!    keeps the directory free of litter; step 2 is what makes the deletion safe. Dropping an
//!    uncommitted output (an error, a panic) deletes its temporary file and releases the lock;
//!    a kill leaves the hidden temporary file and the lock file, and the next writer of `NAME`
//!    removes the first (step 3) and reuses the second (the kernel releases a dead process's
//!    `flock`).
//!
//! The lock is advisory: it binds only writers that use this module (both our tools do). On a
//! filesystem that cannot lock at all (`flock` fails with `ENOLCK` or `EOPNOTSUPP`, or the
//! platform has no locks), the output is written without the lock and without step 3 (a
//! temporary file there might be a live writer's): files stay whole (step 4), but a second
//! writer is not refused. The bytes written never depend on the temporary name, so identical
//! writes still give identical files.
//!
//! # Errors
//! Every failure is an [`Error::Io`] naming the final path and the operation, with the
//! operating system's reason (`No space left on device (os error 28)`, …) as its source and in
//! its message, or [`Error::Busy`] (or [`Error::NotAFilePath`] for a path without a file name).
//!
//! # References
//! - `rename(2)`, `fsync(2)`, `flock(2)`, `open(2)` (`O_EXCL`): Linux man-pages. POSIX.1-2017
//!   `rename()`: a link named new "shall remain visible to other threads throughout the renaming
//!   operation and refer either to the file referred to by new or old before the operation
//!   began".
//! - [`File::try_lock`] (std, stable since Rust 1.89): `flock(fd, LOCK_EX | LOCK_NB)` on Unix. A
//!   `flock` lock belongs to an open file description of an inode, whatever name that inode has
//!   (or has lost) since: hence the inode check of step 2.
//! - Directory `fsync` after `rename`: "Files are hard", Dan Luu (2015),
//!   <https://danluu.com/file-consistency/>.

use std::ffi::{OsStr, OsString};
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::Error;

/// How often [`Output::create`] retries when the lock file it locked was unlinked under it
/// (each retry means another writer finished in between, so a few suffice in practice).
const LOCK_ATTEMPTS: usize = 64;

/// Counts the temporary files made by this process, so that two writers in one process (two
/// threads) never share a temporary name either.
static NEXT_TEMP: AtomicU64 = AtomicU64::new(0);

#[cfg(test)]
thread_local! {
    /// Tests only: a pause between opening the lock file and locking it, to widen the window
    /// in which its holder can release (and unlink) it (the race of step 2).
    static PAUSE_BEFORE_LOCK: std::cell::Cell<std::time::Duration> =
        const { std::cell::Cell::new(std::time::Duration::ZERO) };
}

/// The file name `.NAME.lock` of the lock file of `name`.
fn lock_name(name: &OsStr) -> OsString {
    let mut s = OsString::from(".");
    s.push(name);
    s.push(".lock");
    s
}

/// Whether `entry` is a temporary file of the final name `name`: `.NAME.<pid>-<n>.partial`, or
/// the older fixed `.NAME.partial`.
fn is_temp_of(entry: &OsStr, name: &OsStr) -> bool {
    let (Some(entry), Some(name)) = (entry.to_str(), name.to_str()) else {
        return false;
    };
    let Some(rest) = entry.strip_prefix('.').and_then(|r| r.strip_prefix(name)) else {
        return false;
    };
    let Some(middle) = rest.strip_suffix(".partial") else {
        return false;
    };
    if middle.is_empty() {
        return true; // `.NAME.partial`
    }
    let Some(middle) = middle.strip_prefix('.') else {
        return false;
    };
    match middle.split_once('-') {
        Some((pid, n)) => {
            let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
            digits(pid) && digits(n)
        }
        None => false,
    }
}

/// An output being written: the lock on its final name and its temporary file. Create it,
/// write the [`File`] it hands out, then [`commit`](Self::commit); dropping it uncommitted
/// deletes the temporary file. See the module docs for the protocol.
#[derive(Debug)]
pub struct Output {
    path: PathBuf,
    tmp: PathBuf,
    lock_path: PathBuf,
    /// The open, locked lock file; `None` once released.
    lock: Option<File>,
    committed: bool,
}

impl Output {
    /// Locks `path`'s name, removes stale temporary files of it, and creates a fresh temporary
    /// file, returned open for writing. [`Error::Busy`] if another writer holds the lock.
    pub fn create(path: &Path) -> Result<(Self, File), Error> {
        let file = path.display().to_string();
        let name = path
            .file_name()
            .ok_or_else(|| Error::NotAFilePath { file: file.clone() })?;
        let io = |op, source| Error::Io { file: file.clone(), op, source };
        let lock_path = path.with_file_name(lock_name(name));
        let (lock, locked) = lock(&lock_path, path)?;
        let mut out = Self {
            path: path.to_path_buf(),
            tmp: PathBuf::new(),
            lock_path,
            lock: Some(lock),
            committed: false,
        };
        if locked {
            out.remove_stale_temps(name);
        }
        let mut tmp_name = OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(
            ".{}-{}.partial",
            std::process::id(),
            NEXT_TEMP.fetch_add(1, Ordering::Relaxed)
        ));
        let tmp = path.with_file_name(tmp_name);
        let f = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(|e| io("creating its temporary file", e))?;
        out.tmp = tmp;
        Ok((out, f))
    }

    /// The final path (holds the new file only after [`commit`](Self::commit)).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file being written.
    pub fn temp_path(&self) -> &Path {
        &self.tmp
    }

    /// Makes the written `file` (the one [`create`](Self::create) returned, flushed by the
    /// caller) appear under the final path: `fsync`, rename, `fsync` of the directory, release
    /// of the lock. Returns the final path. On error the temporary file is deleted and the
    /// final path is untouched.
    pub fn commit(mut self, file: File) -> Result<PathBuf, Error> {
        let io = |op, source| Error::Io { file: self.path.display().to_string(), op, source };
        file.sync_all().map_err(|e| io("fsync of its temporary file", e))?;
        drop(file);
        std::fs::rename(&self.tmp, &self.path)
            .map_err(|e| io("renaming its temporary file to it", e))?;
        self.committed = true;
        let dir = match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        // best effort (see the module docs, step 5)
        let _ = File::open(dir).and_then(|d| d.sync_all());
        Ok(self.path.clone())
    }

    /// Deletes every temporary file of `name` in the directory (module docs, step 3). Best
    /// effort: a file that cannot be listed or deleted is left, and never blocks the write.
    fn remove_stale_temps(&self, name: &OsStr) {
        let dir = match self.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            if is_temp_of(&e.file_name(), name) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if !self.committed && !self.tmp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        if let Some(lock) = self.lock.take() {
            // unlink while holding the lock (module docs, step 6), then unlock by closing
            let _ = std::fs::remove_file(&self.lock_path);
            drop(lock);
        }
    }
}

/// Whether `e` says that the filesystem (or platform) cannot lock files at all.
fn locks_unsupported(e: &std::io::Error) -> bool {
    const ENOLCK: i32 = 37; // Linux
    const EOPNOTSUPP: i32 = 95; // Linux
    e.kind() == std::io::ErrorKind::Unsupported || matches!(e.raw_os_error(), Some(ENOLCK | EOPNOTSUPP))
}

/// Takes the exclusive lock of `lock_path` (steps 1 and 2 of the module docs); `path` is the
/// final path, for the messages. Returns the open lock file and whether it is locked (`false`
/// only where the filesystem cannot lock, see the module docs).
fn lock(lock_path: &Path, path: &Path) -> Result<(File, bool), Error> {
    let file = path.display().to_string();
    let io = |op, source| Error::Io { file: file.clone(), op, source };
    for _ in 0..LOCK_ATTEMPTS {
        let f = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(lock_path)
            .map_err(|e| io("creating its lock file", e))?;
        #[cfg(test)]
        std::thread::sleep(PAUSE_BEFORE_LOCK.with(|p| p.get()));
        match f.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(Error::Busy {
                    file: file.clone(),
                    lock: lock_path.display().to_string(),
                })
            }
            Err(std::fs::TryLockError::Error(e)) if locks_unsupported(&e) => return Ok((f, false)),
            Err(std::fs::TryLockError::Error(e)) => return Err(io("locking its lock file", e)),
        }
        let held = f.metadata().map_err(|e| io("reading its lock file", e))?;
        match std::fs::metadata(lock_path) {
            Ok(now) if now.dev() == held.dev() && now.ino() == held.ino() => return Ok((f, true)),
            // unlinked (or replaced) by a writer that finished meanwhile: try again
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io("reading its lock file", e)),
        }
    }
    Err(Error::Busy { file, lock: lock_path.display().to_string() })
}

/// Writes `bytes` to `path` atomically and exclusively (module docs).
pub fn write_file(path: &Path, bytes: impl AsRef<[u8]>) -> Result<PathBuf, Error> {
    write_with(path, |f| {
        f.write_all(bytes.as_ref()).map_err(|e| Error::Io {
            file: path.display().to_string(),
            op: "writing",
            source: e,
        })
    })
}

/// Writes `path` atomically and exclusively with `write`, which gets the open temporary file;
/// its error is returned as is (it should name `path`). Returns the final path.
pub fn write_with<E: From<Error>>(
    path: &Path,
    write: impl FnOnce(&mut File) -> Result<(), E>,
) -> Result<PathBuf, E> {
    let (out, mut f) = Output::create(path)?;
    write(&mut f)?;
    Ok(out.commit(f)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn temp_names_are_recognised_exactly() {
        let n = OsStr::new("a.mcap");
        for yes in [".a.mcap.partial", ".a.mcap.12-0.partial", ".a.mcap.4194304-17.partial"] {
            assert!(is_temp_of(OsStr::new(yes), n), "{yes}");
        }
        for no in [
            "a.mcap",
            ".a.mcap.lock",
            ".a.mcap.1-2.partial.x",
            ".a.mcap.x-2.partial",
            ".a.mcap.12.partial",
            ".a.mcap.1-.partial",
            ".a.mcap.1-2-3.partial",
            // the temporary file of another final name that starts with this one
            ".a.mcap.1-2.3-4.partial",
            ".a.mcapx.1-2.partial",
            ".b.mcap.1-2.partial",
        ] {
            assert!(!is_temp_of(OsStr::new(no), n), "{no}");
        }
    }

    /// Only "cannot lock here" lets a write go on unlocked; any other locking error stops it.
    #[test]
    fn filesystems_without_locks_are_recognised() {
        assert!(locks_unsupported(&std::io::Error::from_raw_os_error(37))); // ENOLCK
        assert!(locks_unsupported(&std::io::Error::from_raw_os_error(95))); // EOPNOTSUPP
        assert!(locks_unsupported(&std::io::ErrorKind::Unsupported.into()));
        assert!(!locks_unsupported(&std::io::Error::from_raw_os_error(13))); // EACCES
        assert!(!locks_unsupported(&std::io::Error::from_raw_os_error(5))); // EIO
    }

    #[test]
    fn a_second_writer_is_refused_while_the_first_holds_the_name() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.csv");
        let (first, mut f) = Output::create(&path).unwrap();
        let e = Output::create(&path).unwrap_err();
        assert!(matches!(e, Error::Busy { .. }), "{e}");
        let msg = e.to_string();
        assert!(msg.contains(&*path.to_string_lossy()) && msg.contains("another process is writing"), "{msg}");
        // another name in the same directory is independent
        write_file(&dir.path().join("y.csv"), "y").unwrap();
        f.write_all(b"first").unwrap();
        first.commit(f).unwrap();
        // released: the next writer gets it
        write_file(&path, "second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        assert_eq!(listing(dir.path()), ["x.csv", "y.csv"]);
    }

    #[test]
    fn stale_temps_of_the_name_are_removed_and_others_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r.mcap");
        for stale in [".r.mcap.partial", ".r.mcap.99999999-3.partial", ".r.mcap.lock"] {
            std::fs::write(dir.path().join(stale), "from a killed writer").unwrap();
        }
        std::fs::write(dir.path().join(".other.mcap.1-1.partial"), "another name's").unwrap();
        write_file(&path, "new").unwrap();
        assert_eq!(listing(dir.path()), [".other.mcap.1-1.partial", "r.mcap"]);
    }

    /// A lock file unlinked under a waiting writer (the previous holder finished between the
    /// waiter's open and its lock) is detected, and the waiter locks the new one.
    #[test]
    fn a_lock_on_an_unlinked_lock_file_is_not_trusted() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("z.bin");
        let lock_path = dir.path().join(".z.bin.lock");
        // the waiter's view: it opened the old lock file, which is then unlinked
        let old = File::create(&lock_path).unwrap();
        std::fs::remove_file(&lock_path).unwrap();
        // a third writer has created and locked a new lock file under the name
        let new = File::create(&lock_path).unwrap();
        new.try_lock().unwrap();
        // locking the old inode succeeds, but the name now refers to another inode
        old.try_lock().unwrap();
        let held = old.metadata().unwrap();
        let now = std::fs::metadata(&lock_path).unwrap();
        assert_ne!((held.dev(), held.ino()), (now.dev(), now.ino()));
        // and `lock` (which opens by name) sees the new one as busy
        assert!(matches!(lock(&lock_path, &path), Err(Error::Busy { .. })));
        drop(new);
        let (f, locked) = lock(&lock_path, &path).unwrap();
        assert!(locked);
        let (a, b) = (f.metadata().unwrap(), std::fs::metadata(&lock_path).unwrap());
        assert_eq!((a.dev(), a.ino()), (b.dev(), b.ino()));
    }

    #[test]
    fn a_failed_write_leaves_nothing_and_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.json");
        let r: Result<PathBuf, Error> = write_with(&path, |_| {
            Err(Error::Io {
                file: "t.json".into(),
                op: "writing",
                source: std::io::Error::from_raw_os_error(28),
            })
        });
        assert!(r.unwrap_err().to_string().contains("No space left on device"));
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
        // the final name is a directory: the rename fails, naming the path and the reason
        std::fs::create_dir(&path).unwrap();
        let e = write_file(&path, "x").unwrap_err().to_string();
        assert!(e.contains(&*path.to_string_lossy()) && e.contains("Is a directory"), "{e}");
        assert_eq!(listing(dir.path()), ["t.json"]);
        // a directory that does not exist: named, with the reason
        let e = write_file(&dir.path().join("nope/t.json"), "x").unwrap_err().to_string();
        assert!(e.contains("nope/t.json") && e.contains("No such file or directory"), "{e}");
    }

    /// Writers in many threads of one process: never two at once, and the file is always one
    /// writer's whole content.
    #[test]
    fn concurrent_writers_in_one_process_never_mix() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.txt");
        let results: Vec<Result<PathBuf, Error>> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..8)
                .map(|k| {
                    let path = &path;
                    s.spawn(move || write_file(path, vec![b'a' + k as u8; 1 << 20]))
                })
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(results.iter().any(|r| r.is_ok()));
        for r in &results {
            if let Err(e) = r {
                assert!(matches!(e, Error::Busy { .. }), "{e}");
            }
        }
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), 1 << 20);
        assert!(bytes.iter().all(|&b| b == bytes[0]));
        assert_eq!(listing(dir.path()), ["c.txt"]);
    }

    /// Exclusivity under churn: threads that write the same name over and over (each lock is
    /// released, its file unlinked and a new one created many times) never hold it together.
    /// This is the race of the module docs' step 2: without the inode check, a writer that
    /// locked an unlinked lock file would write alongside the holder of the new one.
    #[test]
    fn writers_of_one_name_never_overlap_under_churn() {
        use std::sync::atomic::AtomicUsize;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("churn.txt");
        let active = AtomicUsize::new(0);
        let (wrote, refused) = (AtomicUsize::new(0), AtomicUsize::new(0));
        std::thread::scope(|s| {
            for k in 0..4u8 {
                let (path, active, wrote, refused) = (&path, &active, &wrote, &refused);
                s.spawn(move || {
                    for i in 0..300u64 {
                        // open the lock file, then lock it up to 2 ms later
                        PAUSE_BEFORE_LOCK.with(|p| p.set(std::time::Duration::from_micros(i % 5 * 500)));
                        let r = write_with(path, |f| {
                            let before = active.fetch_add(1, Ordering::SeqCst);
                            let bytes = [b'0' + k; 4096];
                            let r = f.write_all(&bytes);
                            std::thread::yield_now();
                            let after = active.fetch_sub(1, Ordering::SeqCst);
                            assert_eq!((before, after), (0, 1), "two writers of one name at once");
                            r.map_err(|e| Error::Io { file: "churn.txt".into(), op: "writing", source: e })
                        });
                        match r {
                            Ok(_) => wrote.fetch_add(1, Ordering::Relaxed),
                            Err(Error::Busy { .. }) => refused.fetch_add(1, Ordering::Relaxed),
                            Err(e) => panic!("{e}"),
                        };
                    }
                });
            }
        });
        let (wrote, refused) = (wrote.into_inner(), refused.into_inner());
        assert_eq!(wrote + refused, 1200);
        assert!(wrote > 0);
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.len() == 4096 && bytes.iter().all(|&b| b == bytes[0]));
        assert_eq!(listing(dir.path()), ["churn.txt"]);
    }
}
