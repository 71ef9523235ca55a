//! The CUDA libraries the backend needs (`libcuda`, `libcufft`, `libnvrtc`): where they are
//! searched, opened by path so that the bindings, which open them by name, find them.
//!
//! The bindings (cudarc with `dynamic-loading`) `dlopen` each library by a list of names
//! (`libcufft.so`, `libcufft.so.13`, `libcufft.so.12`, ...), which finds only what the
//! loader's own search finds (`LD_LIBRARY_PATH`, `ld.so.cache`). A CUDA toolkit under
//! `/usr/local/cuda-13.0` or a Python environment's `nvidia/cu13/lib` is in neither. So the
//! libraries are looked for here, in the directories of [`search_dirs`], and opened by
//! path with `RTLD_NOW | RTLD_GLOBAL`; the handles are kept for the life of the process.
//! glibc matches a name without a slash against the sonames of the objects already loaded,
//! so the bindings' `dlopen("libcufft.so.12")` then gets the library opened here.
//!
//! Pure parts (the directories in order, the file names in a directory) are separate from
//! the opening, for the tests.

use crate::error::{Error, Result};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// What to do when a library is missing (every [`crate::Error::CudaUnavailable`] of the
/// libraries and the driver says it).
pub(crate) const HINT: &str = "install the NVIDIA driver and the CUDA 12 or 13 libraries \
    (cuFFT, NVRTC), or list their directory in LD_LIBRARY_PATH (docs/gpu.md)";

/// How many searched directories a message lists before "and N more".
const LISTED_DIRS: usize = 8;

/// A library the backend needs: the file names it may have, in order of preference.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wanted {
    /// The library's name in messages (`libcufft`).
    pub(crate) name: &'static str,
    /// What it is, for a person (`cuFFT`).
    pub(crate) what: &'static str,
    /// File names, preferred first. A name with a major version (`libcufft.so.12`) also
    /// matches the fully versioned files of that major (`libcufft.so.12.0.0.61`), which
    /// some installations have without the shorter link.
    pub(crate) files: &'static [&'static str],
    /// Names tried through the loader's own search after the directories (a name without
    /// a slash: `LD_LIBRARY_PATH`, `ld.so.cache`, the system's directories).
    pub(crate) by_name: &'static [&'static str],
}

/// The driver's library. Only `libcuda.so.1` by plain name: a toolkit's `stubs/libcuda.so`
/// (which makes the driver fail with `CUDA_ERROR_STUB_LIBRARY`) has no `.so.1`.
const LIBCUDA: Wanted = Wanted {
    name: "libcuda",
    what: "the NVIDIA driver's library",
    files: &["libcuda.so.1", "libcuda.so"],
    by_name: &["libcuda.so.1"],
};

/// cuFFT: CUDA 13 ships `libcufft.so.12`, CUDA 12 `libcufft.so.11`.
const LIBCUFFT: Wanted = Wanted {
    name: "libcufft",
    what: "cuFFT",
    files: &[
        "libcufft.so.12",
        "libcufft.so.11",
        "libcufft.so.13",
        "libcufft.so",
    ],
    by_name: &["libcufft.so.12", "libcufft.so.11", "libcufft.so.13"],
};

/// NVRTC: `libnvrtc.so.13` of CUDA 13, `libnvrtc.so.12` of CUDA 12.
const LIBNVRTC: Wanted = Wanted {
    name: "libnvrtc",
    what: "NVRTC, the CUDA runtime compiler",
    files: &["libnvrtc.so.13", "libnvrtc.so.12", "libnvrtc.so"],
    by_name: &["libnvrtc.so.13", "libnvrtc.so.12"],
};

/// cuFFT for a CUDA 12 driver: CUDA 12's `libcufft.so.11` first.
const LIBCUFFT_12: Wanted = Wanted {
    files: &[
        "libcufft.so.11",
        "libcufft.so.12",
        "libcufft.so.13",
        "libcufft.so",
    ],
    by_name: &["libcufft.so.11", "libcufft.so.12", "libcufft.so.13"],
    ..LIBCUFFT
};

/// NVRTC for a CUDA 12 driver: `libnvrtc.so.12` first.
const LIBNVRTC_12: Wanted = Wanted {
    files: &["libnvrtc.so.12", "libnvrtc.so.13", "libnvrtc.so"],
    by_name: &["libnvrtc.so.12", "libnvrtc.so.13"],
    ..LIBNVRTC
};

/// Library `i` of [`WANTED`] in the order for a driver of CUDA `major`: cuFFT and NVRTC
/// of the driver's major version first (the driver is opened first), since a CUDA 13
/// library does not run on a CUDA 12 driver.
fn for_driver(i: usize, default: &'static Wanted, major: Option<u32>) -> &'static Wanted {
    match (i, major) {
        (1, Some(12)) => &LIBCUFFT_12,
        (2, Some(12)) => &LIBNVRTC_12,
        _ => default,
    }
}

/// The CUDA major version of the opened driver library (`cuDriverGetVersion`, which
/// needs no `cuInit`), if it answers.
#[cfg(unix)]
fn driver_major(driver: &Opened) -> Option<u32> {
    type Version = unsafe extern "C" fn(*mut std::ffi::c_int) -> std::ffi::c_int;
    let mut version: std::ffi::c_int = 0;
    // SAFETY: `cuDriverGetVersion(int*)` of the driver API, which writes one int and
    // returns 0 on success; the library stays loaded (`LOADED`).
    let status = unsafe {
        let symbol = driver.library.get::<Version>(b"cuDriverGetVersion").ok()?;
        symbol(&mut version)
    };
    (status == 0 && version > 0).then_some(version as u32 / 1000)
}

/// No driver library off Unix.
#[cfg(not(unix))]
fn driver_major(_: &Opened) -> Option<u32> {
    None
}

/// The libraries, in the order they are opened (the driver first: without it nothing
/// else matters).
const WANTED: [Wanted; 3] = [LIBCUDA, LIBCUFFT, LIBNVRTC];

/// The directories searched, in order, for an environment: `var` reads an environment
/// variable, `root` is where the system's directories are (`/`; a temporary directory in
/// the tests).
///
/// 1. `LD_LIBRARY_PATH`, in its order (what a user sets comes first);
/// 2. `CUDA_PATH`, then `CUDA_HOME`: each one's `lib64`, `lib`, `targets/x86_64-linux/lib`;
/// 3. `/usr/local/cuda` (the installed default), then `/usr/local/cuda-*`, newest version
///    first: `targets/x86_64-linux/lib`, `lib64`;
/// 4. `/usr/lib/x86_64-linux-gnu`, `/usr/lib64`, `/usr/lib/wsl/lib` (the driver's);
/// 5. Python environments' `site-packages/nvidia/*/lib` (pip's `nvidia-cufft-cu12`,
///    `nvidia-cuda-nvrtc`, CUDA 13's `nvidia/cu13/lib`): under `VIRTUAL_ENV`,
///    `CONDA_PREFIX`, `/usr/local/lib/python3*`, `/usr/lib/python3*` and
///    `~/.local/lib/python3*` (newest Python first).
///
/// Directories that do not exist are left out, each directory appears once (its first
/// place), and any directory with a component named `stubs` is skipped: a toolkit's stub
/// `libcuda.so` links but makes the driver fail with `CUDA_ERROR_STUB_LIBRARY`.
pub(crate) fn search_dirs(var: &dyn Fn(&str) -> Option<OsString>, root: &Path) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = Vec::new();
    if let Some(paths) = var("LD_LIBRARY_PATH") {
        // An empty entry means the working directory to the loader; not a place for CUDA.
        dirs.extend(std::env::split_paths(&paths).filter(|p| !p.as_os_str().is_empty()));
    }
    for name in ["CUDA_PATH", "CUDA_HOME"] {
        if let Some(home) = var(name).filter(|v| !v.is_empty()) {
            let home = PathBuf::from(home);
            dirs.push(home.join("lib64"));
            dirs.push(home.join("lib"));
            dirs.push(home.join("targets/x86_64-linux/lib"));
        }
    }
    let local = root.join("usr/local");
    let mut toolkits = vec![local.join("cuda")];
    toolkits.extend(newest_first(&local, "cuda-"));
    for toolkit in toolkits {
        dirs.push(toolkit.join("targets/x86_64-linux/lib"));
        dirs.push(toolkit.join("lib64"));
    }
    for system in ["usr/lib/x86_64-linux-gnu", "usr/lib64", "usr/lib/wsl/lib"] {
        dirs.push(root.join(system));
    }
    for site in python_sites(var, root) {
        dirs.extend(subdirs(&site.join("nvidia")).map(|d| d.join("lib")));
    }
    let mut seen = std::collections::HashSet::new();
    dirs.retain(|d| !is_stubs(d) && d.is_dir() && seen.insert(d.clone()));
    dirs
}

/// Whether a path lies in a `stubs` directory.
fn is_stubs(dir: &Path) -> bool {
    dir.components().any(|c| c.as_os_str() == "stubs")
}

/// The `site-packages`/`dist-packages` directories of the Python environments found
/// cheaply (no Python run), in the order of [`search_dirs`].
fn python_sites(var: &dyn Fn(&str) -> Option<OsString>, root: &Path) -> Vec<PathBuf> {
    let mut prefixes: Vec<PathBuf> = ["VIRTUAL_ENV", "CONDA_PREFIX"]
        .into_iter()
        .filter_map(|name| var(name).filter(|v| !v.is_empty()).map(PathBuf::from))
        .collect();
    prefixes.push(root.join("usr/local"));
    prefixes.push(root.join("usr"));
    if let Some(home) = var("HOME").filter(|v| !v.is_empty()) {
        prefixes.push(PathBuf::from(home).join(".local"));
    }
    let mut sites = Vec::new();
    for prefix in prefixes {
        for python in newest_first(&prefix.join("lib"), "python3") {
            sites.push(python.join("site-packages"));
            sites.push(python.join("dist-packages"));
        }
    }
    sites
}

/// The entries of `dir` named `prefix` followed by a version (`cuda-13.0`, `python3.12`;
/// also `python3`), newest version first, then those whose rest is not a version, by name.
fn newest_first(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut found: Vec<(Option<Vec<u64>>, String, PathBuf)> = entries(dir)
        .filter_map(|(name, path)| {
            let rest = name.strip_prefix(prefix)?.trim_start_matches('.');
            Some((version(rest), name.clone(), path))
        })
        .collect();
    // Versions descending (`None`, not a version, after every version); then names.
    found.sort_by(|a, b| match (&a.0, &b.0) {
        (Some(x), Some(y)) => y.cmp(x).then_with(|| a.1.cmp(&b.1)),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.1.cmp(&b.1),
    });
    found.into_iter().map(|(_, _, path)| path).collect()
}

/// `13.0.48` as `[13, 0, 48]`; the empty string as `[]` (`python3` itself); anything else
/// (`13.0-rc`) as no version.
fn version(text: &str) -> Option<Vec<u64>> {
    if text.is_empty() {
        return Some(Vec::new());
    }
    text.split('.').map(|part| part.parse().ok()).collect()
}

/// The subdirectories of `dir`, by name.
fn subdirs(dir: &Path) -> impl Iterator<Item = PathBuf> {
    let mut found: Vec<(String, PathBuf)> = entries(dir).filter(|(_, p)| p.is_dir()).collect();
    found.sort();
    found.into_iter().map(|(_, path)| path)
}

/// The entries of `dir` whose names are UTF-8 (none when it cannot be read).
fn entries(dir: &Path) -> impl Iterator<Item = (String, PathBuf)> {
    std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(|entry| {
            let entry = entry.ok()?;
            Some((entry.file_name().into_string().ok()?, entry.path()))
        })
}

/// The files of `dir` that may be `wanted`, in order of preference: each of its names
/// present (a file or a link to one), then the fully versioned files of that name
/// (`libnvrtc.so.13.0.48` for `libnvrtc.so.13`), newest first.
pub(crate) fn candidates(dir: &Path, wanted: &Wanted) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for file in wanted.files {
        let exact = dir.join(file);
        if exact.is_file() {
            found.push(exact);
        }
        // Only names with a major version: `libcufft.so.*` would take any version.
        let has_major = file.rsplit_once(".so.").is_some();
        if has_major {
            found.extend(
                newest_first(dir, &format!("{file}."))
                    .into_iter()
                    .filter(|p| p.is_file()),
            );
        }
    }
    let mut seen = std::collections::HashSet::new();
    found.retain(|p| seen.insert(p.clone()));
    found
}

/// A library opened and kept open.
#[derive(Debug)]
pub(crate) struct Opened {
    /// Where it was found (a path, or the plain name the loader resolved).
    pub(crate) path: PathBuf,
    /// The handle: dropping it would let the library go.
    #[cfg(unix)]
    library: libloading::os::unix::Library,
}

/// Opens `path` (a path, or a plain name for the loader's own search) with
/// `RTLD_NOW | RTLD_GLOBAL`: every symbol resolved now (a too-old or broken library fails
/// here, with the loader's message, not in a solve), and visible to the libraries loaded
/// later (libcufft and libnvrtc of one toolkit may depend on each other).
#[cfg(unix)]
fn open(path: &Path) -> std::result::Result<Opened, String> {
    use libloading::os::unix::{Library, RTLD_GLOBAL, RTLD_NOW};
    // SAFETY: loading a shared object runs its initialisers. The objects opened here are
    // the NVIDIA driver's and the CUDA toolkit's libraries, found by their file names in
    // the directories of `search_dirs` (stub libraries skipped); their initialisers are
    // meant to run in any process that links them. The handle is kept for the life of the
    // process (`LOADED`), so no symbol the bindings take from it outlives it.
    let library = unsafe { Library::open(Some(path), RTLD_NOW | RTLD_GLOBAL) };
    library
        .map(|library| Opened {
            path: path.to_path_buf(),
            library,
        })
        // libloading's `dlopen failed`, then the loader's own message (its source).
        .map_err(|e| match std::error::Error::source(&e) {
            Some(cause) => format!("{e}: {cause}"),
            None => e.to_string(),
        })
}

/// Shared objects are loaded by `dlopen` on Unix only.
#[cfg(not(unix))]
fn open(_: &Path) -> std::result::Result<Opened, String> {
    Err("the CUDA backend loads its libraries on Linux only".into())
}

/// Opens the first of `wanted`'s candidates in `dirs` that opens, else (`by_name`) the
/// first of its plain names the loader finds. The error is the reason of a
/// [`Error::CudaUnavailable`]: the library, the directories searched (the first
/// [`LISTED_DIRS`], then how many more) and why the last file found did not open.
pub(crate) fn open_first(
    wanted: &Wanted,
    dirs: &[PathBuf],
    by_name: bool,
) -> std::result::Result<Opened, String> {
    let mut last_failure: Option<(PathBuf, String)> = None;
    for dir in dirs {
        for path in candidates(dir, wanted) {
            match open(&path) {
                Ok(opened) => return Ok(opened),
                Err(e) => last_failure = Some((path, e)),
            }
        }
    }
    let mut by_name_failure = None;
    if by_name {
        for name in wanted.by_name {
            match open(Path::new(name)) {
                Ok(mut opened) => {
                    opened.path = loaded_path(name).unwrap_or(opened.path);
                    return Ok(opened);
                }
                Err(e) => by_name_failure = Some(e),
            }
        }
    }
    let names = wanted.files.join(", ");
    let mut reason = format!(
        "{} ({}) not found: none of {names} opened in {}",
        wanted.name,
        wanted.what,
        listed(dirs)
    );
    if by_name {
        reason.push_str(&format!(
            ", nor by the loader's search of {}",
            wanted.by_name.join(", ")
        ));
    }
    match (last_failure, by_name_failure) {
        (Some((path, e)), _) => reason.push_str(&format!("; {} did not open: {e}", path.display())),
        (None, Some(e)) => reason.push_str(&format!("; {e}")),
        (None, None) => {}
    }
    Err(reason)
}

/// The directories of a message: the first [`LISTED_DIRS`], then how many more.
fn listed(dirs: &[PathBuf]) -> String {
    if dirs.is_empty() {
        return "no directory (none of the searched ones exists)".into();
    }
    let shown: Vec<String> = dirs
        .iter()
        .take(LISTED_DIRS)
        .map(|d| d.display().to_string())
        .collect();
    let mut text = shown.join(", ");
    if dirs.len() > LISTED_DIRS {
        text.push_str(&format!(" and {} more", dirs.len() - LISTED_DIRS));
    }
    text
}

/// Where the loader found a library opened by its plain `name`: the mapped file of this
/// process whose name starts with it (Linux's `/proc/self/maps`).
fn loaded_path(name: &str) -> Option<PathBuf> {
    let maps = std::fs::read_to_string("/proc/self/maps").ok()?;
    maps.lines()
        .filter_map(|line| line.split_whitespace().nth(5))
        .map(PathBuf::from)
        .find(|path| {
            path.file_name()
                .and_then(|f| f.to_str())
                .is_some_and(|f| f.starts_with(name))
        })
}

/// A `stubs` directory of `LD_LIBRARY_PATH` holding a `libcuda.so`: the bindings open
/// `libcuda.so` by name before `libcuda.so.1`, so the loader would give them the stub even
/// with the driver's library opened here.
pub(crate) fn stub_in_library_path(var: &dyn Fn(&str) -> Option<OsString>) -> Option<PathBuf> {
    let paths = var("LD_LIBRARY_PATH")?;
    std::env::split_paths(&paths).find(|d| is_stubs(d) && d.join("libcuda.so").is_file())
}

/// The libraries opened so far, kept for the life of the process.
static LOADED: Mutex<Vec<Opened>> = Mutex::new(Vec::new());

/// Finds and opens the libraries; returns their paths (`libcuda`, `libcufft`,
/// `libnvrtc`). A library opened by an earlier call is not searched again; one that was
/// missing is searched again (an installation or `LD_LIBRARY_PATH` may have changed).
pub(crate) fn load() -> Result<Vec<PathBuf>> {
    let unavailable = |reason: String| Error::CudaUnavailable {
        reason,
        hint: HINT.to_string(),
    };
    let var = |name: &str| std::env::var_os(name);
    if let Some(stubs) = stub_in_library_path(&var) {
        return Err(unavailable(format!(
            "LD_LIBRARY_PATH lists {}, a CUDA toolkit's stub libcuda.so, which the bindings \
             would open instead of the driver's (CUDA_ERROR_STUB_LIBRARY): remove it from \
             LD_LIBRARY_PATH",
            stubs.display()
        )));
    }
    // A poisoned lock means a panic while opening; the handles it holds are still valid.
    let mut loaded = crate::lock::lock(&LOADED);
    let mut dirs: Option<Vec<PathBuf>> = None;
    let mut paths = Vec::with_capacity(WANTED.len());
    for (i, default) in WANTED.iter().enumerate() {
        if let Some(opened) = loaded.get(i) {
            paths.push(opened.path.clone());
            continue;
        }
        let wanted = for_driver(i, default, loaded.first().and_then(driver_major));
        let dirs = dirs.get_or_insert_with(|| search_dirs(&var, Path::new("/")));
        let opened = open_first(wanted, dirs, true).map_err(unavailable)?;
        paths.push(opened.path.clone());
        loaded.push(opened);
    }
    Ok(paths)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A fresh directory under the system's temporary directory, removed when dropped.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str) -> Scratch {
            let dir = std::env::temp_dir().join(format!(
                "precursors-libraries-{}-{name}",
                std::process::id()
            ));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Scratch(dir)
        }

        /// Creates `dir` under the scratch directory, returns its path.
        fn dir(&self, dir: &str) -> PathBuf {
            let path = self.0.join(dir);
            std::fs::create_dir_all(&path).unwrap();
            path
        }

        /// Writes `bytes` as the file `path` (its directory created).
        fn file(&self, path: &str, bytes: &[u8]) -> PathBuf {
            let path = self.0.join(path);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, bytes).unwrap();
            path
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn env(vars: &[(&str, &Path)]) -> HashMap<String, OsString> {
        vars.iter()
            .map(|(k, v)| (k.to_string(), v.as_os_str().to_owned()))
            .collect()
    }

    #[test]
    fn the_search_keeps_its_order_and_skips_stubs() {
        let s = Scratch::new("order");
        let root = s.dir("root");
        let user_a = s.dir("user/a");
        let user_b = s.dir("user/b");
        let stubs = s.dir("toolkit/lib64/stubs");
        let cuda_path = s.dir("toolkit");
        let cuda_lib64 = s.dir("toolkit/lib64");
        let cuda_targets = s.dir("toolkit/targets/x86_64-linux/lib");
        let cuda_12 = s.dir("root/usr/local/cuda-12.4/targets/x86_64-linux/lib");
        let cuda_12_64 = s.dir("root/usr/local/cuda-12.4/lib64");
        let cuda_13 = s.dir("root/usr/local/cuda-13.0/targets/x86_64-linux/lib");
        let cuda_9 = s.dir("root/usr/local/cuda-9.2/lib64");
        let default = s.dir("root/usr/local/cuda/targets/x86_64-linux/lib");
        s.dir("root/usr/local/cuda-13.0/targets/x86_64-linux/lib/stubs");
        let gnu = s.dir("root/usr/lib/x86_64-linux-gnu");
        let wsl = s.dir("root/usr/lib/wsl/lib");
        let venv = s.dir("venv");
        let cu13 = s.dir("venv/lib/python3.12/site-packages/nvidia/cu13/lib");
        let cufft = s.dir("venv/lib/python3.12/site-packages/nvidia/cufft/lib");
        let old = s.dir("venv/lib/python3.9/site-packages/nvidia/cuda_nvrtc/lib");
        let system = s.dir("root/usr/local/lib/python3.11/dist-packages/nvidia/cu12/lib");
        let home = s.dir("home");
        let local = s.dir("home/.local/lib/python3.10/site-packages/nvidia/cufft/lib");
        let mut ld = std::env::join_paths([&user_b, &stubs, &user_a, &user_b]).unwrap();
        ld.push(":"); // an empty entry: skipped
        let mut vars = env(&[
            ("CUDA_PATH", &cuda_path),
            ("VIRTUAL_ENV", &venv),
            ("HOME", &home),
        ]);
        vars.insert("LD_LIBRARY_PATH".into(), ld);
        let dirs = search_dirs(&|k| vars.get(k).cloned(), &root);
        let expected = vec![
            user_b,
            user_a,
            cuda_lib64,
            cuda_targets,
            default,
            cuda_13,
            cuda_12,
            cuda_12_64,
            cuda_9,
            gnu,
            wsl,
            cu13,
            cufft,
            old,
            system,
            local,
        ];
        assert_eq!(dirs, expected);
        assert!(dirs.iter().all(|d| !is_stubs(d)));
    }

    #[test]
    fn an_empty_environment_searches_only_the_system() {
        let s = Scratch::new("empty");
        let root = s.dir("root");
        assert!(search_dirs(&|_| None, &root).is_empty());
        let lib64 = s.dir("root/usr/lib64");
        assert_eq!(search_dirs(&|_| None, &root), vec![lib64]);
    }

    #[test]
    fn candidates_take_the_preferred_names_then_the_versioned_files() {
        let s = Scratch::new("candidates");
        let dir = s.dir("lib");
        for name in [
            "libnvrtc.so",
            "libnvrtc.so.12",
            "libnvrtc.so.13.0.48",
            "libnvrtc.so.13.1.2",
            "libnvrtc.so.13.x", // not a version: after the versions
            "libnvrtc-builtins.so.13",
            "libcufft.so.11",
        ] {
            s.file(&format!("lib/{name}"), b"");
        }
        let names: Vec<String> = candidates(&dir, &LIBNVRTC)
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            names,
            [
                "libnvrtc.so.13.1.2",
                "libnvrtc.so.13.0.48",
                "libnvrtc.so.13.x",
                "libnvrtc.so.12",
                "libnvrtc.so"
            ]
        );
        let cufft = candidates(&dir, &LIBCUFFT);
        assert_eq!(cufft, vec![dir.join("libcufft.so.11")]);
        assert!(candidates(&dir, &LIBCUDA).is_empty());
        assert!(candidates(&s.0.join("missing"), &LIBCUDA).is_empty());
    }

    #[test]
    fn a_file_that_is_not_a_library_is_named_with_the_directories_searched() {
        let s = Scratch::new("garbage");
        let empty = s.dir("empty");
        let garbage = s.file("broken/libcufft.so.12", b"not an ELF object, just bytes");
        let mut dirs = vec![empty.clone(), s.dir("broken")];
        let reason = open_first(&LIBCUFFT, &dirs, false).unwrap_err();
        assert!(reason.starts_with("libcufft (cuFFT) not found"), "{reason}");
        assert!(reason.contains(&empty.display().to_string()), "{reason}");
        assert!(
            reason.contains(&format!("{} did not open", garbage.display())),
            "{reason}"
        );
        // The loader's own words (glibc: "file too short" or "invalid ELF header").
        assert!(
            reason.contains("too short") || reason.contains("ELF"),
            "{reason}"
        );
        assert!(!reason.contains("loader's search"), "{reason}");
        // Many directories: the first eight, then how many more.
        dirs.extend((0..10).map(|i| s.dir(&format!("more/{i}"))));
        let reason = open_first(&LIBCUFFT, &dirs, false).unwrap_err();
        assert!(reason.contains(" and 4 more"), "{reason}");
        assert!(reason.contains(&s.0.join("more/5").display().to_string()));
        assert!(!reason.contains(&s.0.join("more/6").display().to_string()));
        // And the error the user sees says what to do.
        let error = Error::CudaUnavailable {
            reason,
            hint: HINT.into(),
        };
        assert!(error.to_string().contains("LD_LIBRARY_PATH"), "{error}");
    }

    #[test]
    fn nothing_found_says_so() {
        let reason = open_first(&LIBNVRTC, &[], false).unwrap_err();
        assert_eq!(
            reason,
            "libnvrtc (NVRTC, the CUDA runtime compiler) not found: none of libnvrtc.so.13, \
             libnvrtc.so.12, libnvrtc.so opened in no directory (none of the searched ones \
             exists)"
        );
    }

    /// A real shared object opens from its directory, by the name given (the C library of
    /// this process, linked as `libcufft.so.12`), and the path found is returned.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_shared_object_opens_by_path() {
        // `libc.so.6`, or `libc-2.31.so` of older glibc.
        let Some(libc) = loaded_path("libc.so.6").or_else(|| loaded_path("libc-")) else {
            panic!("this test process maps no C library (/proc/self/maps)");
        };
        let s = Scratch::new("real");
        let dir = s.dir("lib");
        s.file("lib/libcufft.so.13", b"garbage, tried after .so.12");
        std::os::unix::fs::symlink(&libc, dir.join("libcufft.so.12")).unwrap();
        let opened = open_first(&LIBCUFFT, std::slice::from_ref(&dir), false).unwrap();
        assert_eq!(opened.path, dir.join("libcufft.so.12"));
    }

    #[test]
    fn a_stubs_directory_in_the_library_path_is_refused() {
        let s = Scratch::new("stubs");
        let stubs = s.dir("cuda/lib64/stubs");
        let ld = std::env::join_paths([s.dir("other"), stubs.clone()]).unwrap();
        let var = |k: &str| (k == "LD_LIBRARY_PATH").then(|| ld.clone());
        assert_eq!(stub_in_library_path(&var), None);
        s.file("cuda/lib64/stubs/libcuda.so", b"");
        assert_eq!(stub_in_library_path(&var), Some(stubs));
    }

    /// A CUDA 12 driver takes CUDA 12's cuFFT (`.so.11`) and NVRTC (`.so.12`) first, a
    /// CUDA 13 driver (or one that does not say) CUDA 13's (`.so.12`, `.so.13`).
    #[test]
    fn the_libraries_of_the_drivers_version_come_first() {
        let first = |i: usize, major| for_driver(i, &WANTED[i], major).files[0];
        assert_eq!(first(1, Some(12)), "libcufft.so.11");
        assert_eq!(first(2, Some(12)), "libnvrtc.so.12");
        for major in [Some(13), None] {
            assert_eq!(first(1, major), "libcufft.so.12");
            assert_eq!(first(2, major), "libnvrtc.so.13");
        }
        assert_eq!(first(0, Some(12)), "libcuda.so.1");
    }

    #[test]
    fn versions_order_numerically() {
        assert_eq!(version("13.0.48"), Some(vec![13, 0, 48]));
        assert_eq!(version(""), Some(vec![]));
        assert_eq!(version("13.0-rc"), None);
        let s = Scratch::new("versions");
        for name in ["cuda-9.2", "cuda-12.10", "cuda-12.4", "cuda-x", "cudnn"] {
            s.dir(name);
        }
        let order: Vec<String> = newest_first(&s.0, "cuda-")
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(order, ["cuda-12.10", "cuda-12.4", "cuda-9.2", "cuda-x"]);
    }
}
