//! What the end-to-end tests of the binary share: running it, the example scenes, scratch
//! files and reading its CSV.

// Each test crate uses a part of these.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// The path of an example scene (`examples/scenes/NAME`).
pub fn scene(name: &str) -> String {
    format!("{}/../examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// Runs the `mechgen` binary with `args`.
pub fn mechgen(args: &[&str]) -> Output {
    match Command::new(env!("CARGO_BIN_EXE_mechgen"))
        .args(args)
        .output()
    {
        Ok(output) => output,
        Err(e) => panic!("cannot run mechgen: {e}"),
    }
}

/// Bytes the binary wrote, as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh path under Cargo's per-test scratch directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("mechgen-cli-tests");
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir.join(name)
}

/// The header and the rows of the CSV a run wrote to stdout, as text.
pub fn csv_rows(out: &Output) -> (Vec<String>, Vec<Vec<String>>) {
    let csv = text(&out.stdout);
    let mut lines = csv.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or_default()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_owned).collect())
        .collect();
    (header, rows)
}
