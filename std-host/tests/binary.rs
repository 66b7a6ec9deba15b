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
        (&["render", "--width", "0"][..], "must be positive"),
        (&["render", "--width", "-5"][..], "must be positive"),
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

#[test]
fn help_says_what_is_accepted() {
    let text = |args: &[&str]| String::from_utf8(rrt(args).stdout).unwrap();
    let render = text(&["render", "--help"]);
    // Help text is wrapped to the terminal: compare words.
    let words = render.split_whitespace().collect::<Vec<_>>().join(" ");
    for want in [
        "An NFF or TOML scene",
        ".png",
        ".ppm",
        ".exr",
        ".pfm",
        "--linear",
        "--bits",
        "5 to 65536",
        "Vertical field of view",
        "top and bottom pixel rows",
        // Each range as the parser accepts it.
        "Image width in pixels, 1 to 32768",
        "Image height in pixels, 1 to 32768",
        "K from 1 to 16",
        "Depth of the ray tree, 1 to 64",
        "0 (one per core) to 1024",
        "between 0 and 180 (both excluded)",
    ] {
        assert!(words.contains(want), "render --help lacks {want:?}");
    }
    // The top-level help describes the tool, not the crate.
    let top = text(&["--help"]);
    assert!(
        top.starts_with("rrt: 3D raster (discrete) ray tracing"),
        "{top}"
    );
    // One default per option.
    let threads = render
        .split("--threads")
        .nth(1)
        .unwrap()
        .split("\n  -")
        .next()
        .unwrap();
    assert_eq!(threads.matches("default").count(), 1, "{threads}");
    let voxelize = text(&["voxelize", "--help"]);
    assert!(voxelize.contains("An NFF or TOML scene"));
    let words = voxelize.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(words.contains("its name ends in .rrt"), "{voxelize}");
    assert!(words.contains("0 (one per core) to 1024"), "{voxelize}");
    let ray = text(&["ray", "--help"]);
    assert!(ray.contains("--dims") && ray.contains("--raster"));
}

#[test]
fn arguments_out_of_range_are_refused_as_the_help_says() {
    for (args, expect) in [
        (&["render", "--raster", "4"][..], "5..=65536"),
        (&["render", "--supersample", "0"][..], "must be positive"),
        // Negative numbers get the range, not clap's "use -- -1" tip.
        (
            &["render", "--supersample", "-2"][..],
            "must be positive, found -2",
        ),
        (
            &["render", "--height", "-5"][..],
            "must be positive, found -5",
        ),
        (
            &["render", "--depth", "-1"][..],
            "expected 1 to 64, found -1",
        ),
        (
            &["render", "--depth", "65"][..],
            "expected 1 to 64, found 65",
        ),
        (
            &["render", "--threads", "-1"][..],
            "expected 0 (one per core) to 1024, found -1",
        ),
        // 100000 threads used to be accepted (and took minutes to start).
        (
            &["voxelize", "-o", "x.rrt", "--threads", "100000"][..],
            "expected 0 (one per core) to 1024, found 100000",
        ),
        (&["render", "--angle", "0"][..], "between 0 and 180"),
        (&["render", "--angle", "-30"][..], "between 0 and 180"),
        (&["render", "--angle", "180"][..], "between 0 and 180"),
        // A view that makes no camera is refused before voxelizing.
        (
            &[
                "render",
                "-o",
                "/tmp/rrt-never-written.png",
                "--from",
                "0,0,0",
                "--at",
                "0,0,0",
            ][..],
            "`from` and `at` must be distinct",
        ),
        // Bounds away from all geometry, at the default raster: the
        // bounds are named (not the memory a raster of them would need).
        (
            &[
                "render",
                "-o",
                "/tmp/rrt-never-written.png",
                "--bounds",
                "100,100,100,101,101,101",
            ][..],
            "contain no geometry",
        ),
        // A raster goes to a .rrt file, never to standard output or over
        // an image or a scene.
        (&["voxelize", "-o", "-"][..], "not to standard output"),
        (
            &["voxelize", "-o", "/tmp/rrt-never-written.png"][..],
            "whose name ends in .rrt",
        ),
        (
            &["ray", "--origin", "0,0,0", "--dir", "1,0,0"][..],
            "give --dims NX,NY,NZ for a ray through an empty raster, or --raster",
        ),
        (
            &[
                "ray", "--dims", "4,4,4", "--origin", "0,0,0", "--dir", "0,0,0",
            ][..],
            "a ray needs a direction",
        ),
        (
            &[
                "ray",
                "--dims",
                "4,4,4",
                "--origin",
                "0,0,0",
                "--dir",
                "0.000001,0,0",
            ][..],
            "rounds to zero",
        ),
        (
            &[
                "render",
                "-o",
                "/tmp/rrt-never-written.png",
                "--raster",
                "32",
                "--bounds",
                "100,100,100,101,101,101",
            ][..],
            "contain no geometry",
        ),
        // Bounds at the world's limit are spelt with exponents.
        (
            &[
                "render",
                "-o",
                "/tmp/rrt-never-written.png",
                "--raster",
                "32",
                "--bounds=-1e60,-1e60,-1e60,-0.9e60,-0.9e60,-0.9e60",
            ][..],
            "the bounds [-1e60, -1e60, -1e60] to [-9e59, -9e59, -9e59] contain no geometry",
        ),
    ] {
        let out = rrt(args);
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expect), "{args:?}: {err}");
    }
    assert!(!std::path::Path::new("/tmp/rrt-never-written.png").exists());
}

#[test]
fn info_checks_every_checksum() {
    let dir = std::env::temp_dir().join(format!("rrt-bin-{}-info", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("x.rrt");
    let made = rrt(&[
        "voxelize",
        "-q",
        "--raster",
        "40",
        "-o",
        f.to_str().unwrap(),
    ]);
    assert!(made.status.success());
    let quick = rrt(&["info", f.to_str().unwrap()]);
    assert!(quick.status.success());
    let text = String::from_utf8_lossy(&quick.stdout);
    assert!(
        text.contains("format version 3, sparse, compressed"),
        "{text}"
    );
    assert!(
        text.contains("checksums: not checked (rrt info --check)"),
        "{text}"
    );
    let good = rrt(&["info", "--check", f.to_str().unwrap()]);
    assert!(good.status.success());
    assert!(
        String::from_utf8_lossy(&good.stdout)
            .contains("checksums: header and all sections match; the raster loads")
    );
    // One flipped bit in the records (the middle of the file) or the plane.
    let bytes = std::fs::read(&f).unwrap();
    for at in [bytes.len() / 2, 300, bytes.len() - 10] {
        let mut bad = bytes.clone();
        bad[at] ^= 0x10;
        std::fs::write(&f, &bad).unwrap();
        let out = rrt(&["info", "--check", f.to_str().unwrap()]);
        assert!(!out.status.success(), "flipped byte {at} not found");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("corrupt"), "{err}");
        assert!(out.stdout.is_empty());
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scene read from a pipe (`/dev/stdin`) is read whole: the check for a
/// saved raster's magic does not take its first bytes (here a light,
/// eight bytes) from the parser.
#[cfg(target_os = "linux")]
#[test]
fn a_scene_from_a_pipe_is_read_whole() {
    use std::io::Write;
    use std::process::Stdio;
    let dir = std::env::temp_dir().join(format!("rrt-bin-{}-pipe", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let scene = "l 4 4 4\nv\nfrom 0 -5 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 16 16\n\
        f 0.9 0.4 0.2 0.8 0.2 20 0 1\ns 0 0 0.7 0.7\np 3\n-2 -2 0\n2 -2 0\n2 2 0\n";
    std::fs::write(dir.join("s.nff"), scene).unwrap();
    let render = |input: &str, out: &str, stdin: Stdio| {
        Command::new(env!("CARGO_BIN_EXE_rrt"))
            .args(["render", "-q", input, "--raster", "32", "-o", out])
            .current_dir(&dir)
            .stdin(stdin)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run rrt")
    };
    let file = render("s.nff", "file.png", Stdio::null())
        .wait_with_output()
        .unwrap();
    assert!(
        file.status.success(),
        "{}",
        String::from_utf8_lossy(&file.stderr)
    );
    let mut child = render("/dev/stdin", "pipe.png", Stdio::piped());
    child
        .stdin
        .take()
        .unwrap()
        .write_all(scene.as_bytes())
        .unwrap();
    let pipe = child.wait_with_output().unwrap();
    assert!(
        pipe.status.success(),
        "{}",
        String::from_utf8_lossy(&pipe.stderr)
    );
    assert!(
        std::fs::read(dir.join("file.png")).unwrap()
            == std::fs::read(dir.join("pipe.png")).unwrap(),
        "the piped scene renders another image"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
