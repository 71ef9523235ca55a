//! The crate's file plumbing, one copy for every reader and writer: inputs are opened as
//! regular files without blocking and read within the memory available, counting the
//! bytes actually read; outputs are written atomically and replace only a regular file.
//!
//! Why: a FIFO named as an input blocked `open` forever, `/dev/zero` reported a length of
//! 0 and was read until memory ran out, and a rename over a character device named as an
//! output replaced the device (run as root: `/dev/null`) with a regular file.
//!
//! No symbolic link is followed: every file is opened by [`open`] (`O_NOFOLLOW` on Unix),
//! new files are created exclusively (`O_EXCL`), and a link where a file is read, written,
//! replaced or removed is refused ([`Error::NotARegularFile`], naming the link). Why: a
//! lock file `.precursors.lock` linked to a file outside its directory had the holder's
//! line written into that file, then the file emptied (run as root: any file of the
//! machine); a table linked elsewhere would have been truncated and written the same way.

use crate::error::{Error, Result};
use std::fs::{File, OpenOptions};
use std::io::Read;
use std::path::Path;

/// What a path names, as a message says it (`None`: a regular file).
fn special(file_type: std::fs::FileType) -> Option<&'static str> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if file_type.is_char_device() {
            return Some("a character device");
        }
        if file_type.is_block_device() {
            return Some("a block device");
        }
        if file_type.is_socket() {
            return Some("a socket");
        }
    }
    if file_type.is_dir() {
        Some("a directory")
    } else if file_type.is_symlink() {
        Some("a symbolic link")
    } else if file_type.is_file() {
        None
    } else {
        Some("not a regular file")
    }
}

/// Opens `path` as `options` say, the one open of every file the crate reads or writes:
/// a symbolic link at `path` is not followed (`O_NOFOLLOW` on Unix; elsewhere a link
/// found just before the open), the open never blocks (`O_NONBLOCK`: a FIFO), and
/// anything but a regular file is refused with [`Error::NotARegularFile`] naming it (a
/// link as `"a symbolic link"`). The directories above `path` are the caller's: only its
/// last component is checked.
///
/// # Errors
/// [`Error::NotARegularFile`]; [`Error::Io`] (with `operation`) when the open fails
/// otherwise (of kind [`std::io::ErrorKind::NotFound`] for a missing file,
/// [`std::io::ErrorKind::AlreadyExists`] for an existing one with `create_new`).
pub(crate) fn open(
    path: &Path,
    options: &mut OpenOptions,
    operation: &'static str,
) -> Result<File> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK);
    }
    #[cfg(not(unix))]
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
        return Err(Error::NotARegularFile {
            operation,
            path: path.to_path_buf(),
            kind: "a symbolic link",
        });
    }
    let file = match options.open(path) {
        Ok(file) => file,
        // `create_new` on an existing path (a link included: `O_EXCL` follows none):
        // the caller decides (another name for a temporary file).
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
            return Err(Error::io(operation, path, e))
        }
        Err(e) => {
            // `O_NOFOLLOW` on a link fails with `ELOOP`, a FIFO opened to write without
            // a reader with `ENXIO`: said as what the path is.
            check_replaceable(path, operation)?;
            return Err(Error::io(operation, path, e));
        }
    };
    let meta = file.metadata().map_err(|e| Error::io(operation, path, e))?;
    match special(meta.file_type()) {
        None => Ok(file),
        Some(kind) => Err(Error::NotARegularFile {
            operation,
            path: path.to_path_buf(),
            kind,
        }),
    }
}

/// A new, empty file at `path` opened to write, replacing a regular file there: the old
/// file is removed, then the new one created exclusively (`O_EXCL`), so that a link
/// placed at `path` meanwhile is refused, never written through.
///
/// # Errors
/// [`Error::NotARegularFile`] for anything but a regular file (or nothing) at `path`;
/// [`Error::Io`] when it cannot be removed or created.
pub(crate) fn create(path: &Path, operation: &'static str) -> Result<File> {
    remove_if_exists(path, operation)?;
    open(
        path,
        OpenOptions::new().write(true).create_new(true),
        operation,
    )
}

/// Removes the regular file `path` where it exists; anything else there (a link, a
/// FIFO, a directory) is refused and stays.
///
/// # Errors
/// [`Error::NotARegularFile`]; [`Error::Io`] when it cannot be removed.
pub(crate) fn remove_if_exists(path: &Path, operation: &'static str) -> Result<()> {
    check_replaceable(path, operation)?;
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io(operation, path, e)),
        _ => Ok(()),
    }
}

/// Whether the regular file `path` exists (a marker such as a sweep run's `done`),
/// without following a link: `false` where nothing is there.
///
/// # Errors
/// [`Error::NotARegularFile`] for a link or anything but a regular file there;
/// [`Error::Io`] when `path` cannot be examined.
#[cfg_attr(not(feature = "serde"), allow(dead_code))]
pub(crate) fn is_file(path: &Path, operation: &'static str) -> Result<bool> {
    check_replaceable(path, operation)?;
    Ok(std::fs::symlink_metadata(path).is_ok())
}

/// Opens `path` for reading as a regular file ([`open`]).
fn open_regular(path: &Path, operation: &'static str) -> Result<File> {
    open(path, OpenOptions::new().read(true), operation)
}

/// The bytes of the regular file `path`, read up to the memory the machine can give its
/// text once parsed (a few times its size): a longer file (or one that grows while it is
/// read) is refused with [`Error::OutOfMemory`] after reading that much, whatever length
/// the file system reports.
///
/// # Errors
/// [`Error::Io`] (with `operation`) when the file cannot be opened or read;
/// [`Error::NotARegularFile`]; [`Error::OutOfMemory`].
pub(crate) fn read_bytes(path: &Path, operation: &'static str) -> Result<Vec<u8>> {
    let file = open_regular(path, operation)?;
    // A parsed text takes about five times its bytes: a file that reports its length is
    // refused unread when that is too much; the bytes read are bounded too (a device or
    // a file of `/proc` reports 0).
    let size = file
        .metadata()
        .map_err(|e| Error::io(operation, path, e))?
        .len();
    crate::cost::check_memory(
        || format!("reading {} ({size} bytes)", path.display()),
        5.0 * size as f64,
        "the file is too large for this machine",
    )?;
    let limit = crate::cost::available_memory().map_or(u64::MAX, |m| (m / 5.0) as u64);
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(operation, path, e))?;
    if bytes.len() as u64 > limit {
        return Err(Error::OutOfMemory {
            what: format!("reading {} (more than {limit} bytes)", path.display()),
            needed_bytes: 5.0 * bytes.len() as f64,
            available_bytes: 5.0 * limit as f64,
            hint: "the file is too large for this machine",
        });
    }
    Ok(bytes)
}

/// The text of the regular file `path` ([`read_bytes`]); bytes that are not UTF-8 are
/// [`Error::Io`] of kind [`std::io::ErrorKind::InvalidData`], as
/// [`std::fs::read_to_string`] reports them.
///
/// # Errors
/// As [`read_bytes`].
pub(crate) fn read_text(path: &Path, operation: &'static str) -> Result<String> {
    String::from_utf8(read_bytes(path, operation)?).map_err(|e| {
        Error::io(
            operation,
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()),
        )
    })
}

/// [`read_text`], or `None` when `path` does not exist.
///
/// # Errors
/// As [`read_bytes`], but for a missing file.
pub(crate) fn read_text_if_exists(path: &Path, operation: &'static str) -> Result<Option<String>> {
    match read_text(path, operation) {
        Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => Ok(None),
        other => other.map(Some),
    }
}

/// Refuses a `path` that exists and is not a regular file (a directory, a FIFO, a device,
/// a socket, a symbolic link: [`Error::NotARegularFile`]); nothing there, or a regular
/// file, may be replaced. Called before a rename over `path`, which would replace a link
/// rather than follow it, and so silently.
///
/// # Errors
/// [`Error::NotARegularFile`]; [`Error::Io`] when `path` cannot be examined.
pub(crate) fn check_replaceable(path: &Path, operation: &'static str) -> Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(meta) => match special(meta.file_type()) {
            None => Ok(()),
            Some(kind) => Err(Error::NotARegularFile {
                operation,
                path: path.to_path_buf(),
                kind,
            }),
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(Error::io(operation, path, e)),
    }
}

/// Writes `bytes` to `path` atomically: into a new temporary file of the same directory
/// (`.NAME.tmp<pid>-<n>-<ns>`), synced, then renamed over `path` and the directory
/// synced, so that `path` holds either its old content or the new one, whole, after a
/// crash or a full disk. Only a regular file (or nothing) is replaced
/// ([`check_replaceable`]).
///
/// # Errors
/// [`Error::NotARegularFile`]; [`Error::Io`] (with `operation`) when the file cannot be
/// written, synced or renamed (the temporary file is removed).
pub(crate) fn write_atomically(path: &Path, bytes: &[u8], operation: &'static str) -> Result<()> {
    use std::io::Write;
    use std::sync::atomic::{AtomicU64, Ordering};
    let io = |p: &Path, e: std::io::Error| Error::io(operation, p, e);
    let name = path.file_name().ok_or_else(|| {
        io(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
        )
    })?;
    check_replaceable(path, operation)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    static CALLS: AtomicU64 = AtomicU64::new(0);
    let (tmp, mut file) = loop {
        let call = CALLS.fetch_add(1, Ordering::Relaxed);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".tmp{}-{call}-{nanos}", std::process::id()));
        let tmp = dir.join(tmp_name);
        match open(
            &tmp,
            OpenOptions::new().write(true).create_new(true),
            operation,
        ) {
            Ok(file) => break (tmp, file),
            Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::AlreadyExists => {
                continue
            }
            // Named by the file written, as every other failure of the write.
            Err(Error::Io { source, .. }) => return Err(io(path, source)),
            Err(e) => return Err(e),
        }
    };
    if let Err(e) = file.write_all(bytes).and_then(|()| file.sync_all()) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(path, e));
    }
    drop(file);
    // Checked again just before the rename: the check above may be long past for a
    // large file.
    if let Err(e) = check_replaceable(path, operation) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    if let Err(e) = std::fs::rename(&tmp, path) {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(path, e));
    }
    sync_dir(dir).map_err(|e| io(dir, e))
}

/// Removes from `dir` the temporary files [`write_atomically`] names for `names`
/// (`.NAME.tmp...`), left by a writer killed while writing one: call it only while
/// holding the directory (its lock), so that no live writer's file is removed.
///
/// # Errors
/// [`Error::Io`] when `dir` cannot be read or a temporary file removed.
pub(crate) fn remove_temporaries(dir: &Path, names: &[String]) -> Result<()> {
    let prefixes: Vec<String> = names.iter().map(|n| format!(".{n}.tmp")).collect();
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io("reading directory", dir, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| Error::io("reading directory", dir, e))?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if prefixes.iter().any(|p| name.starts_with(p.as_str())) {
            match std::fs::remove_file(entry.path()) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                    return Err(Error::io("removing a temporary file", entry.path(), e))
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// Syncs a directory's entries (a rename into it) to disk; a no-op where directories
/// cannot be opened (Windows).
pub(crate) fn sync_dir(dir: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    std::fs::File::open(dir)?.sync_all()?;
    #[cfg(not(unix))]
    let _ = dir;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("precursors-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_directory_is_neither_read_nor_replaced() {
        let dir = scratch("dir");
        let e = read_text(&dir, "reading").unwrap_err();
        assert!(
            matches!(
                e,
                Error::NotARegularFile {
                    kind: "a directory",
                    ..
                }
            ),
            "{e}"
        );
        let e = write_atomically(&dir, b"x", "writing").unwrap_err();
        assert!(
            matches!(
                e,
                Error::NotARegularFile {
                    kind: "a directory",
                    ..
                }
            ),
            "{e}"
        );
        assert!(dir.is_dir());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_neither_followed_nor_replaced_and_a_missing_file_is_none() {
        let dir = scratch("link");
        let target = dir.join("target");
        std::fs::write(&target, "kept").unwrap();
        let link = dir.join("link");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let e = write_atomically(&link, b"new", "writing").unwrap_err();
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
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "kept");
        // Nor read through, nor created through, nor removed.
        for e in [
            read_text(&link, "reading").unwrap_err(),
            create(&link, "creating").unwrap_err(),
            open(&link, OpenOptions::new().append(true), "opening").unwrap_err(),
            remove_if_exists(&link, "removing").unwrap_err(),
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
        }
        // A dangling link: nothing is created at its target.
        let dangling = dir.join("dangling");
        std::os::unix::fs::symlink(dir.join("nowhere"), &dangling).unwrap();
        let e = open(
            &dangling,
            OpenOptions::new().read(true).write(true).create(true),
            "opening",
        )
        .unwrap_err();
        assert!(matches!(e, Error::NotARegularFile { .. }), "{e}");
        assert!(!dir.join("nowhere").exists());
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert!(read_text_if_exists(&dir.join("none"), "reading")
            .unwrap()
            .is_none());
        write_atomically(&target, b"new", "writing").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn dev_zero_is_refused_without_reading_it() {
        let e = read_bytes(Path::new("/dev/zero"), "reading").unwrap_err();
        assert!(
            matches!(
                e,
                Error::NotARegularFile {
                    kind: "a character device",
                    ..
                }
            ),
            "{e}"
        );
    }
}
