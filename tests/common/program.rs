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
