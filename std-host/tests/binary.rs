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

#[test]
fn render_without_a_scene_writes_rrt_png() {
    let dir = std::env::temp_dir().join(format!("rrt-bin-{}-default", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_rrt"))
        .args([
            "render", "--width", "24", "--height", "24", "--raster", "64",
        ])
        .current_dir(&dir)
        .output()
        .expect("run rrt");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = std::fs::read(dir.join("rrt.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"));
    let summary = String::from_utf8(out.stdout).unwrap();
    assert!(
        summary.starts_with("rrt.png: 24×24, raster 64×"),
        "{summary}"
    );
    assert_eq!(summary.lines().count(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn render_errors_exit_non_zero_with_one_message() {
    for (args, expect) in [
        (
            &["render", "/no/such/scene.nff"][..],
            "cannot read /no/such/scene.nff",
        ),
        (
            &["render", "-o", "/no/such/dir/out.png"][..],
            "cannot write /no/such/dir/out.png",
        ),
        (&["render", "--width", "0"][..], "width: expected 1 to"),
        (&["render", "--raster", "0"][..], "--raster"),
        (
            &["info", "/no/such/file.rrt"][..],
            "/no/such/file.rrt: cannot open",
        ),
    ] {
        let out = rrt(args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
}
