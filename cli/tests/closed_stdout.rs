//! `mechgen` with standard output closed (`>&-`) fails as it does on a full device, instead of
//! reporting rows it never wrote; a redirection to `/dev/null` still succeeds.

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

        let null = mechgen_with_stdout("> /dev/null", command);
        let stderr = String::from_utf8_lossy(&null.stderr);
        assert!(null.status.success(), "{command}: {stderr}");
    }
}
