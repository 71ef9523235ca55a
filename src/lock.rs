//! Advisory locks on directories: a run directory while a process writes it
//! ([`crate::output::RunTables`], a sweep's run), a sweep directory while its `sweep.json`
//! is checked or written.
//!
//! The lock is the operating system's (`File::try_lock`: `flock` on Unix, `LockFileEx` on
//! Windows) on the file [`LOCK_FILE`] in the directory, so it dies with its process, also
//! when the process is killed: a lock is never stale. The holder writes who it is into the
//! file (pid, host, start time, command) for the message of a refused process, and empties
//! it when it lets go. The file itself stays: removing it would let a process that opened
//! it just before lock a file no longer in the directory while a third one locks a new
//! file of the same name.
//!
//! Readers of a directory (`plot`, `movie`, `stats`) take the same lock shared
//! ([`ReadLock`]): no writer takes the directory while one reads it, and a reader neither
//! writes nor empties the file. The file is opened as every file of the crate
//! ([`crate::files::open`]): a symbolic link there is refused, never followed.

use crate::error::{Error, Result};
use crate::files;
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// The lock file of a run or sweep directory.
pub(crate) const LOCK_FILE: &str = ".precursors.lock";

/// An exclusive lock on a directory, released (and its file emptied) on drop.
#[derive(Debug)]
pub(crate) struct DirLock {
    file: File,
}

/// What [`DirLock::try_lock`] found.
#[derive(Debug)]
pub(crate) enum Attempt {
    /// This process holds the lock now.
    Locked(DirLock),
    /// Another process (or another open of the file in this one) holds it: who, as it
    /// wrote it.
    Held(String),
}

impl DirLock {
    /// Takes the lock of `dir` (which must exist) if no one holds it; never waits.
    ///
    /// # Errors
    /// [`Error::Io`] when the lock file cannot be opened, locked or written.
    pub(crate) fn try_lock(dir: &Path) -> Result<Attempt> {
        let path = dir.join(LOCK_FILE);
        // Not truncated on open: the holder's name is in it.
        let mut file = files::open(
            &path,
            OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false),
            "opening the lock file",
        )?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                // Readers only, if a shared lock is granted: their file holds no line (or
                // a killed writer's, which is not the holder).
                let who = match file.try_lock_shared() {
                    Ok(()) => "a reader of the directory (plot, movie or stats)".to_string(),
                    Err(_) => holder(&path),
                };
                return Ok(Attempt::Held(who));
            }
            Err(TryLockError::Error(e)) => return Err(Error::io("locking", &path, e)),
        }
        let me = identity();
        file.set_len(0)
            .and_then(|()| file.seek(SeekFrom::Start(0)))
            .and_then(|_| file.write_all(me.as_bytes()))
            .map_err(|e| Error::io("writing the lock file", &path, e))?;
        Ok(Attempt::Locked(DirLock { file }))
    }

    /// Takes the lock of `dir`, refusing at once when another process holds it.
    ///
    /// # Errors
    /// [`Error::DirectoryLocked`] naming the holder; [`Error::Io`] as
    /// [`DirLock::try_lock`].
    pub(crate) fn lock(dir: &Path) -> Result<DirLock> {
        match Self::try_lock(dir)? {
            Attempt::Locked(lock) => Ok(lock),
            Attempt::Held(holder) => Err(locked(dir, holder)),
        }
    }

    /// Takes the lock of `dir`, waiting up to `patience` for a holder that keeps it
    /// briefly (a sweep's `sweep.json` check).
    ///
    /// # Errors
    /// [`Error::DirectoryLocked`] naming the holder when it still holds the lock after
    /// `patience`; [`Error::Io`] as [`DirLock::try_lock`].
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub(crate) fn lock_waiting(dir: &Path, patience: Duration) -> Result<DirLock> {
        let start = Instant::now();
        loop {
            match Self::try_lock(dir)? {
                Attempt::Locked(lock) => return Ok(lock),
                Attempt::Held(holder) if start.elapsed() >= patience => {
                    return Err(locked(dir, holder))
                }
                Attempt::Held(_) => std::thread::sleep(Duration::from_millis(10)),
            }
        }
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // Emptied first, so a finished directory holds an empty lock file whoever wrote
        // it; closing the file would release the lock anyway.
        let _ = self.file.set_len(0);
        let _ = self.file.unlock();
    }
}

/// A shared lock on a directory, a reader's (`plot`, `movie`, `stats`): writers
/// ([`DirLock`]) are kept out while it is held, other readers are not. Released on drop;
/// the lock file is never written.
// Its readers (plot, sweep statistics) need feature `serde`.
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
#[derive(Debug)]
pub(crate) struct ReadLock {
    /// `None`: read without the lock ([`ReadLock::lock`]).
    _file: Option<File>,
}

impl ReadLock {
    /// Takes the shared lock of `dir`, refusing at once when a writer holds it. The lock
    /// file is created (empty) where it is missing; where it cannot be because the
    /// directory is not writable (a read-only file system, no permission to write) or
    /// does not exist, the directory is read without the lock: no writer has run there
    /// since the file would have been made, on a read-only file system none can start,
    /// and a missing directory is the reader's own error to report.
    ///
    /// # Errors
    /// [`Error::DirectoryLocked`] naming the writer; [`Error::NotARegularFile`] for a
    /// lock file that is a symbolic link or not a regular file; [`Error::Io`] when it
    /// cannot be opened or locked.
    #[cfg_attr(not(feature = "serde"), allow(dead_code))]
    pub(crate) fn lock(dir: &Path) -> Result<ReadLock> {
        use std::io::ErrorKind;
        const OPENING: &str = "opening the lock file";
        let path = dir.join(LOCK_FILE);
        let file = match files::open(&path, OpenOptions::new().read(true), OPENING) {
            Err(Error::Io { source, .. }) if source.kind() == ErrorKind::NotFound => {
                let mut create = OpenOptions::new();
                create.read(true).write(true).create_new(true);
                match files::open(&path, &mut create, OPENING) {
                    Err(Error::Io { source, .. }) => match source.kind() {
                        // Made by another process meanwhile.
                        ErrorKind::AlreadyExists => {
                            files::open(&path, OpenOptions::new().read(true), OPENING)
                        }
                        ErrorKind::NotFound
                        | ErrorKind::PermissionDenied
                        | ErrorKind::ReadOnlyFilesystem => return Ok(ReadLock { _file: None }),
                        _ => Err(Error::io(OPENING, &path, source)),
                    },
                    other => other,
                }
            }
            other => other,
        }?;
        match file.try_lock_shared() {
            Ok(()) => Ok(ReadLock { _file: Some(file) }),
            Err(TryLockError::WouldBlock) => Err(locked(dir, holder(&path))),
            Err(TryLockError::Error(e)) => Err(Error::io("locking", &path, e)),
        }
    }
}

fn locked(dir: &Path, holder: String) -> Error {
    Error::DirectoryLocked {
        path: PathBuf::from(dir),
        holder,
    }
}

/// The holder as it described itself in the lock file.
fn holder(path: &Path) -> String {
    // The first 4 kB: a holder writes one line; a file grown by something else is not read
    // whole.
    let mut text = String::new();
    if let Ok(file) = files::open(path, OpenOptions::new().read(true), "reading the lock file") {
        let _ = std::io::Read::read_to_string(&mut std::io::Read::take(file, 4096), &mut text);
    }
    let text = text.trim();
    if text.is_empty() {
        // It locked the file and has not written its name yet (microseconds).
        return "a process that has not written its name yet".into();
    }
    let mut who = shorten(text, 400);
    if let Some(pid) = dead_holder(text) {
        who.push_str(&format!(
            "; pid {pid} is no longer running on this host, yet the lock is held: by a \
             process it started, which inherited the lock (`fuser {}` names it), or, on a \
             network file system, by the server for a client that died (it lets go when the \
             client's lease ends)",
            path.display()
        ));
    }
    who
}

/// The pid of a holder line (`pid P on host H, ...`) written on this host by a process
/// that is no longer running (Linux: no `/proc/P`); `None` when it runs, when another
/// host wrote it, or when this cannot be told.
fn dead_holder(line: &str) -> Option<u32> {
    let rest = line.strip_prefix("pid ")?;
    let digits = rest
        .find(|c: char| !c.is_ascii_digit())
        .unwrap_or(rest.len());
    let pid: u32 = rest[..digits].parse().ok()?;
    let written_on = rest[digits..]
        .strip_prefix(" on host ")
        .map(|h| h.split(',').next().unwrap_or(""));
    if written_on.is_some() && written_on != host().as_deref() {
        return None;
    }
    let proc = Path::new("/proc");
    (proc.join("self").exists() && !proc.join(pid.to_string()).exists()).then_some(pid)
}

/// This machine's host name, as the holder line gives it.
fn host() -> Option<String> {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
}

/// Who this process is: `pid P on host H, since T: COMMAND`.
fn identity() -> String {
    let host = host();
    let command: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    format!(
        "pid {}{}, since {}: {}",
        std::process::id(),
        host.map(|h| format!(" on host {h}")).unwrap_or_default(),
        started(),
        shorten(&command.join(" "), 300)
    )
}

/// The process's start as UTC `YYYY-MM-DDTHH:MM:SSZ` (the time of the first call:
/// close enough, the lock is taken early).
fn started() -> String {
    static START: std::sync::OnceLock<SystemTime> = std::sync::OnceLock::new();
    let since = START
        .get_or_init(SystemTime::now)
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc(since)
}

/// Seconds since 1970-01-01T00:00:00Z as UTC `YYYY-MM-DDTHH:MM:SSZ`.
fn utc(since: u64) -> String {
    let (days, secs) = ((since / 86_400) as i64, since % 86_400);
    // Days to a civil date (H. Hinnant's algorithm, proleptic Gregorian calendar).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        secs / 3600,
        (secs % 3600) / 60,
        secs % 60
    )
}

/// `text` cut to `max` characters (with `...`).
fn shorten(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        text.to_string()
    } else {
        format!("{}...", text.chars().take(max - 3).collect::<String>())
    }
}

/// The guard of a mutex, also when a thread panicked while holding it: the crate's
/// shared buffers and pools stay usable after a panic (a panicking part poisons no
/// result: the solve or run panics as a whole), so a poisoned lock is taken as it is.
/// The one copy of the poison-tolerant guards (`read`, `write`, `into_inner` beside it).
pub(crate) fn lock<T>(mutex: &std::sync::Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The read guard of an `RwLock`, poisoned or not ([`lock`]).
pub(crate) fn read<T>(lock: &std::sync::RwLock<T>) -> std::sync::RwLockReadGuard<'_, T> {
    lock.read()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The write guard of an `RwLock`, poisoned or not ([`lock`]).
pub(crate) fn write<T>(lock: &std::sync::RwLock<T>) -> std::sync::RwLockWriteGuard<'_, T> {
    lock.write()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The value of a mutex through `&mut`, poisoned or not ([`lock`]).
pub(crate) fn get_mut<T>(mutex: &mut std::sync::Mutex<T>) -> &mut T {
    mutex
        .get_mut()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// [`std::sync::Condvar::wait_timeout`] on `guard`, poisoned or not ([`lock`]); whether
/// it timed out is not needed by its callers.
pub(crate) fn wait_timeout<'a, T>(
    condvar: &std::sync::Condvar,
    guard: std::sync::MutexGuard<'a, T>,
    timeout: std::time::Duration,
) -> std::sync::MutexGuard<'a, T> {
    match condvar.wait_timeout(guard, timeout) {
        Ok((guard, _)) => guard,
        Err(poisoned) => poisoned.into_inner().0,
    }
}

/// The value of a mutex, poisoned or not ([`lock`]).
pub(crate) fn into_inner<T>(mutex: std::sync::Mutex<T>) -> T {
    mutex
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lock_is_refused_naming_its_holder_and_released_on_drop() {
        let dir = std::env::temp_dir().join(format!("precursors-lock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let first = DirLock::lock(&dir).unwrap();
        // Another open of the file, even in this process, is another holder.
        match DirLock::lock(&dir) {
            Err(Error::DirectoryLocked { holder, .. }) => {
                assert!(
                    holder.starts_with(&format!("pid {}", std::process::id())),
                    "{holder}"
                );
            }
            other => panic!("{other:?}"),
        }
        let e = DirLock::lock_waiting(&dir, Duration::from_millis(30)).unwrap_err();
        assert!(matches!(e, Error::DirectoryLocked { .. }), "{e:?}");
        drop(first);
        assert_eq!(std::fs::read(dir.join(LOCK_FILE)).unwrap(), b"");
        drop(DirLock::lock(&dir).unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_holder_that_no_longer_runs_is_named_so_with_what_to_do() {
        let dir = std::env::temp_dir().join(format!("precursors-dead-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(LOCK_FILE);
        // A lock held by a handle whose line names a pid above Linux's largest (2^22).
        let mut held = std::fs::File::create(&path).unwrap();
        held.lock().unwrap();
        let host = host().map(|h| format!(" on host {h}")).unwrap_or_default();
        write!(
            held,
            "pid 4999999{host}, since 2026-11-29T00:00:00Z: precursors run"
        )
        .unwrap();
        match DirLock::lock(&dir) {
            Err(Error::DirectoryLocked { holder, .. }) => {
                assert!(holder.starts_with("pid 4999999"), "{holder}");
                if Path::new("/proc/self").exists() {
                    assert!(holder.contains("no longer running") && holder.contains("fuser"));
                }
            }
            other => panic!("{other:?}"),
        }
        // A running holder (this process), and one on another host, are not called dead.
        assert_eq!(
            dead_holder(&format!("pid {}{host}, since", std::process::id())),
            None
        );
        assert_eq!(
            dead_holder("pid 4999999 on host elsewhere.invalid, since"),
            None
        );
        drop(held);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn readers_share_the_lock_keep_writers_out_and_write_nothing() {
        let dir = std::env::temp_dir().join(format!("precursors-lock-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join(LOCK_FILE);
        let first = ReadLock::lock(&dir).unwrap();
        let second = ReadLock::lock(&dir).unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"");
        match DirLock::lock(&dir) {
            Err(Error::DirectoryLocked { holder, .. }) => {
                assert!(holder.starts_with("a reader"), "{holder}")
            }
            other => panic!("{other:?}"),
        }
        drop((first, second));
        let writer = DirLock::lock(&dir).unwrap();
        let line = std::fs::read(&file).unwrap();
        match ReadLock::lock(&dir) {
            Err(Error::DirectoryLocked { holder, .. }) => {
                assert!(
                    holder.starts_with(&format!("pid {}", std::process::id())),
                    "{holder}"
                );
            }
            other => panic!("{other:?}"),
        }
        // The refused reader neither wrote nor emptied the holder's line.
        assert_eq!(std::fs::read(&file).unwrap(), line);
        drop(writer);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_lock_file_that_is_a_link_is_refused_and_its_target_kept() {
        let dir = std::env::temp_dir().join(format!("precursors-lock-link-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("target");
        std::fs::write(&target, "kept").unwrap();
        std::os::unix::fs::symlink(&target, dir.join(LOCK_FILE)).unwrap();
        for e in [
            DirLock::lock(&dir).unwrap_err(),
            ReadLock::lock(&dir).unwrap_err(),
        ] {
            assert!(
                matches!(
                    e,
                    Error::NotARegularFile {
                        kind: "a symbolic link",
                        ..
                    }
                ),
                "{e}"
            );
            assert!(e.to_string().contains(LOCK_FILE), "{e}");
        }
        assert_eq!(std::fs::read(&target).unwrap(), b"kept");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn times_are_utc_dates() {
        // References: Python's datetime.fromtimestamp(s, timezone.utc).
        for (s, t) in [
            (0, "1970-01-01T00:00:00Z"),
            (951_825_600, "2000-02-29T12:00:00Z"),
            (1_709_251_199, "2024-02-29T23:59:59Z"),
            (4_102_444_800, "2100-01-01T00:00:00Z"),
        ] {
            assert_eq!(utc(s), t);
        }
        assert_eq!(started().len(), 20);
    }
}
