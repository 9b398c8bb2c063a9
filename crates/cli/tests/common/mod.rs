//! Helpers shared by the command line's tests.

/// Runs the `fourfold` binary with `args`: its exit code, stdout and stderr.
pub fn fourfold(args: &[&str]) -> (Option<i32>, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_fourfold"))
        .args(args)
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.code(), text(&out.stdout), text(&out.stderr))
}
