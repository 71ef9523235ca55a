//! The program `precursors` (feature `cli`) as the tests run it: one way to start it.

use std::path::Path;
use std::process::{Command, Output};

/// SLURM's job-array variables: the program must not take a shard from the test's
/// environment (the tests may run inside an array task).
pub const SLURM_VARS: [&str; 5] = [
    "SLURM_ARRAY_TASK_ID",
    "SLURM_ARRAY_TASK_COUNT",
    "SLURM_ARRAY_TASK_MIN",
    "SLURM_ARRAY_TASK_MAX",
    "SLURM_ARRAY_TASK_STEP",
];

/// The program with `args`, without SLURM's array variables.
pub fn command(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_precursors"));
    for name in SLURM_VARS {
        command.env_remove(name);
    }
    command.args(args);
    command
}

/// Runs the program with `args` to its end.
pub fn precursors(args: &[&str]) -> Output {
    command(args).output().unwrap()
}

/// A path as an argument.
pub fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// What the program wrote to stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Every file under `dir` (relative path, bytes; a special file by its kind), sorted.
pub fn contents(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let entry = entry.unwrap();
            let p = entry.path();
            let name = p.strip_prefix(dir).unwrap().display().to_string();
            let kind = entry.file_type().unwrap();
            if kind.is_dir() {
                stack.push(p);
            } else if kind.is_file() {
                out.push((name, std::fs::read(&p).unwrap()));
            } else {
                out.push((name, format!("{kind:?}").into_bytes()));
            }
        }
    }
    out.sort();
    out
}
