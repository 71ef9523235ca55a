//! CSV tables continued after a crash (used by `run_scene`; tested in
//! `tests/checkpoint.rs`): on resume a table keeps its complete rows up to the
//! checkpoint's event and drops the rest, including a last row cut by the crash.
#![allow(dead_code)] // each user takes its own part

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter};
use std::path::Path;

/// The text a resumed table starts from: `header`, then the rows of `old` whose first
/// column (an event index) is at most `keep`. A last row cut by a crash (no trailing
/// newline, or not as many fields as the header) is dropped; the same damage on an
/// earlier row, an index that is not a whole number, or another header is refused with
/// its line number (the table was not written by this run).
pub fn rows_to_keep(old: &str, header: &str, keep: usize) -> Result<String, String> {
    let fields = header.split(',').count();
    let mut text = format!("{header}\n");
    let mut lines: Vec<&str> = old.split_inclusive('\n').collect();
    if lines.is_empty() {
        return Ok(text);
    }
    let first = lines.remove(0);
    if first.trim_end_matches(['\n', '\r']) != header {
        return Err(format!(
            "line 1 is not the header {header:?}: the table was written by another program"
        ));
    }
    let count = lines.len();
    for (k, line) in lines.into_iter().enumerate() {
        let last = k + 1 == count;
        let complete = line.ends_with('\n');
        let row = line.trim_end_matches(['\n', '\r']);
        if !complete || row.split(',').count() != fields {
            if last {
                break; // cut by a crash
            }
            return Err(format!(
                "line {} has {} fields, the header {fields}",
                k + 2,
                row.split(',').count()
            ));
        }
        let index: usize = row.split(',').next().unwrap_or("").parse().map_err(|e| {
            format!(
                "line {}: the event index is not a whole number ({e})",
                k + 2
            )
        })?;
        if index <= keep {
            text.push_str(row);
            text.push('\n');
        }
    }
    Ok(text)
}

/// A table ready for appending rows: new (the header only) with `keep = None`, or the
/// existing `path` cut back by [`rows_to_keep`] (a missing file starts empty).
pub fn open(path: &Path, header: &str, keep: Option<usize>) -> io::Result<BufWriter<File>> {
    let text = match keep {
        None => format!("{header}\n"),
        Some(k) => match fs::read_to_string(path) {
            Ok(old) => rows_to_keep(&old, header, k)
                .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?,
            Err(e) if e.kind() == io::ErrorKind::NotFound => format!("{header}\n"),
            Err(e) => return Err(e),
        },
    };
    fs::write(path, text)?;
    let file = OpenOptions::new().append(true).open(path)?;
    Ok(BufWriter::new(file))
}
