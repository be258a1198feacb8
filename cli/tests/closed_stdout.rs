//! `mechgen` with standard output closed (`>&-`) fails as it does on a full device, instead of
//! reporting rows it never wrote; `/dev/null`, write-only or read-write, still succeeds.

use std::process::{Command, Output};

/// Runs `mechgen ARGS` through the shell with standard output redirected by `redirect`.
fn mechgen_with_stdout(redirect: &str, args: &str) -> Output {
    let binary = env!("CARGO_BIN_EXE_mechgen");
    let scene = format!(
        "{}/../examples/scenes/four_bar.mech",
        env!("CARGO_MANIFEST_DIR")
    );
    Command::new("sh")
        .arg("-c")
        .arg(format!("exec '{binary}' {args} '{scene}' {redirect}"))
        .output()
        .expect("sh runs")
}

#[test]
#[cfg(target_os = "linux")]
fn a_closed_stdout_fails_like_a_full_one() {
    for command in ["solve --at 0,1", "check"] {
        let closed = mechgen_with_stdout(">&-", command);
        let stderr = String::from_utf8_lossy(&closed.stderr);
        assert_eq!(closed.status.code(), Some(1), "{command}: {stderr}");
        assert!(stderr.contains("cannot write to stdout"), "{stderr}");
        assert!(!stderr.contains("wrote"), "{stderr}");

        let full = mechgen_with_stdout("> /dev/full", command);
        assert_eq!(full.status.code(), Some(1), "{command}");

        // Write-only (`>`) and read-write (`<>`, as Python's `subprocess.DEVNULL` opens it,
        // and as Rust's runtime reopens a closed descriptor): both are a caller's choice.
        for null in ["> /dev/null", "1<> /dev/null"] {
            let out = mechgen_with_stdout(null, command);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "{command} {null}: {stderr}");
        }
    }
}
