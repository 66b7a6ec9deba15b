//! The `rrt` binary itself: exit codes and where its output goes. The
//! behaviour of each subcommand is tested through the library in `tests/`.

use std::process::Command;

fn rrt(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rrt"))
        .args(args)
        .output()
        .expect("run rrt")
}

#[test]
fn ray_succeeds_with_the_report_on_stdout() {
    let out = rrt(&[
        "ray",
        "--dims",
        "2,2,2",
        "--origin",
        "0.5,0.5,0.5",
        "--dir",
        "1,0,0",
    ]);
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        s.lines().collect::<Vec<_>>()[1..],
        ["0 0 0", "1 0 0", "miss"]
    );
    assert!(out.stderr.is_empty());
}

#[test]
fn bad_arguments_exit_non_zero_with_a_message() {
    let out = rrt(&[
        "ray", "--dims", "0,2,2", "--origin", "0,0,0", "--dir", "1,0,0",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("dimension x is zero"));
    assert!(out.stdout.is_empty());
}
