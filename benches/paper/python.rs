//! The Python package against the command line: one render's call
//! overhead, an orbit's frames per second from a saved raster on one and
//! two threads, and the Ray example's frames against one process, as
//! `python/measure.py --json` measures them in the environment `tests/run`
//! makes (`target/python-venv` in the workspace, or `$RRT_VENV`), with the
//! package and the `rrt` binary built from this checkout as this bench is
//! built. Not measured in quick runs.

use serde_json::Value;

use crate::common::*;

/// Why the section has no figures: said in the report instead of them.
fn skipped(ctx: &mut Ctx, why: &str) -> Res<()> {
    ctx.log(&format!("Python: skipped: {why}"));
    ctx.md.para(&format!("Skipped: {why}"));
    Ok(())
}

/// The last line of `text` that is a JSON object.
fn last_json(text: &str) -> Res<Value> {
    let line = text
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with('{'))
        .ok_or("measure.py printed no JSON object")?;
    Ok(serde_json::from_str(line)?)
}

/// The number at `path` (keys) in `v`.
fn num(v: &Value, path: &[&str]) -> Res<f64> {
    let mut at = v;
    for key in path {
        at = at
            .get(key)
            .ok_or_else(|| format!("measure.py's JSON has no {}", path.join(".")))?;
    }
    at.as_f64()
        .ok_or_else(|| format!("measure.py's JSON: {} is not a number", path.join(".")).into())
}

/// The tail of a failed command's error output, for the report.
fn tail(stderr: &[u8]) -> String {
    let text = String::from_utf8_lossy(stderr);
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    lines[lines.len().saturating_sub(3)..].join(" / ")
}

pub(crate) fn python(ctx: &mut Ctx) -> Res<()> {
    ctx.md.h2("Python");
    if ctx.cfg.quick {
        return skipped(
            ctx,
            "not measured in quick runs (the package's release build alone takes minutes); `--section python` measures it.",
        );
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let venv =
        std::env::var_os("RRT_VENV").map_or_else(|| root.join("target/python-venv"), PathBuf::from);
    let py = venv.join("bin/python");
    if !py.is_file() {
        return skipped(
            ctx,
            &format!(
                "no Python environment at `{}` (`bash tests/run` makes it, with numpy, pytest, maturin and ray).",
                venv.display()
            ),
        );
    }
    // The command line the figures compare with, built as this bench is
    // (the same profile and flags).
    let Some(rrt) = rrt_binary(ctx)? else {
        return Err("no rrt binary beside the bench's".into());
    };
    // The package from this checkout (maturin from the environment; cargo
    // reuses python/target).
    ctx.log(&format!(
        "Python: installing ./python into {}",
        venv.display()
    ));
    let path = std::env::var_os("PATH").unwrap_or_default();
    let mut paths = vec![venv.join("bin")];
    paths.extend(std::env::split_paths(&path));
    let installed = Command::new(&py)
        .current_dir(&root)
        .args([
            "-m",
            "pip",
            "install",
            "-q",
            "--disable-pip-version-check",
            "--no-build-isolation",
            "--force-reinstall",
            "--no-deps",
            "./python",
        ])
        .env("PATH", std::env::join_paths(paths)?)
        .output()?;
    if !installed.status.success() {
        return skipped(
            ctx,
            &format!(
                "`pip install ./python` failed in `{}`: {}",
                venv.display(),
                tail(&installed.stderr)
            ),
        );
    }
    let rounds = if ctx.cfg.quick {
        2
    } else {
        ctx.cfg.reps.max(4)
    };
    ctx.log(&format!(
        "Python: python/measure.py --json --rounds {rounds}"
    ));
    let measured = Command::new(&py)
        .current_dir(&root)
        .arg("python/measure.py")
        .args(["--json", "--rounds", &rounds.to_string()])
        .env("RRT_CLI", &rrt)
        .output()?;
    if !measured.status.success() {
        return Err(format!("python/measure.py failed: {}", tail(&measured.stderr)).into());
    }
    let m = last_json(&String::from_utf8_lossy(&measured.stdout))?;
    let frames = num(&m, &["frames"])?;
    let (cli, call, process) = (
        num(&m, &["render", "cli"])?,
        num(&m, &["render", "call"])?,
        num(&m, &["render", "process"])?,
    );
    let (fps1, fps2) = (
        num(&m, &["orbit", "fps", "1"])?,
        num(&m, &["orbit", "fps", "2"])?,
    );
    let raster = m["orbit"]["raster"]
        .as_array()
        .map(|d| {
            d.iter()
                .map(|v| v.as_u64().map_or_else(|| "?".into(), |v| v.to_string()))
                .collect::<Vec<_>>()
                .join("×")
        })
        .unwrap_or_default();
    let ms = |s: f64| f(s * 1000.0, 1);
    let ratio = |a: f64, b: f64| format!("{}×", f(a / b, 2));
    let mut rows = vec![
        vec![
            "one render, `rrt render` process (parse, voxelize, render, PNG)".into(),
            format!("{} ms", ms(cli)),
            "1×".into(),
        ],
        vec![
            "the same render, `rrt.render` called in a running interpreter".into(),
            format!("{} ms", ms(call)),
            ratio(call, cli),
        ],
        vec![
            "the same render, a `python -c \"import rrt; rrt.render(...)\"` process".into(),
            format!("{} ms", ms(process)),
            ratio(process, cli),
        ],
        vec![
            format!("orbit of {frames:.0} frames from a saved raster, 1 thread"),
            format!("{} fps", f(fps1, 2)),
            "1×".into(),
        ],
        vec![
            format!("orbit of {frames:.0} frames from a saved raster, 2 threads"),
            format!("{} fps", f(fps2, 2)),
            ratio(fps2, fps1),
        ],
    ];
    let ray = if m["ray"].is_null() {
        None
    } else {
        Some((
            num(&m, &["ray", "ray"])?,
            num(&m, &["ray", "process"])?,
            num(&m, &["ray", "startup"])?,
            num(&m, &["ray", "workers"])?,
        ))
    };
    if let Some((r, s, startup, workers)) = ray {
        rows.push(vec![
            format!("{frames:.0} frames in one process (2 threads)"),
            format!("{} s", secs(s)),
            "1×".into(),
        ]);
        rows.push(vec![
            format!("{frames:.0} frames as Ray tasks ({workers:.0} workers, 1 thread each; start-up {} s not counted)", secs(startup)),
            format!("{} s", secs(r)),
            ratio(r, s),
        ]);
    }
    ctx.md.para(&format!(
        "`python/measure.py --json --rounds {rounds}` in `{}` (the package installed from this checkout \
         with `pip install ./python`, the `rrt` binary it compares with built as this bench is): \
         one render of `scenes/one-sphere.toml` at 256² three ways, interleaved, medians of {rounds}; \
         an orbit of {frames:.0} frames at 256² from a saved raster of the built-in 91-sphereflake \
         (raster {raster}), `Raster.render(frame=(k, {frames:.0}))`, medians of {} rounds on 1 and 2 \
         threads; the same frames as tasks of `python/examples/ray_orbit.py` on a local Ray cluster, \
         each task loading the saved raster, against one process, medians of {} rounds.",
        venv.strip_prefix(&root).unwrap_or(&venv).display(),
        (rounds / 2).max(1),
        (rounds / 2).max(1),
    ));
    ctx.md.table(&["measurement", "time", "ratio"], &rows);
    let mut reading = String::new();
    let overhead = call - cli;
    if overhead <= 0.0 {
        let _ = write!(
            reading,
            "`rrt.render` called in a running interpreter returned its array {} ms sooner than the \
             `rrt` process wrote its PNG: the call starts no process and encodes no file (the parse, \
             voxelization and render are the same code), so its own overhead is below what this run \
             resolves. ",
            ms(-overhead)
        );
    } else {
        let _ = write!(
            reading,
            "`rrt.render` takes {} ms more than the command line's whole process ({}× its time): the \
             overhead of the call and of the numpy array, against the process start and PNG encoding \
             the call does not pay. ",
            ms(overhead),
            f(call / cli, 2)
        );
    }
    let _ = write!(
        reading,
        "A fresh Python process that imports rrt and renders takes {} ms, {} ms more than the `rrt` \
         process: the interpreter's start-up and the imports. The orbit renders {} frames per second on \
         one thread and {} on two ({}×{}). ",
        ms(process),
        ms(process - cli),
        f(fps1, 1),
        f(fps2, 1),
        f(fps2 / fps1, 2),
        if fps2 / fps1 < 1.3 {
            "; the second thread gained little or nothing in this run: the machine's two cores are \
             shared with other jobs (the load averages at the top of this file), and two threads can \
             only help while a core is idle"
        } else {
            "; the machine's two cores bound it at 2×"
        }
    );
    match ray {
        Some((r, s, _, workers)) if r > s => {
            let _ = write!(
                reading,
                "On Ray the {frames:.0} frames take {}× the single process's time: the {workers:.0} \
                 workers share the same two cores the process's two threads use, and each task also \
                 loads the raster and ships its frame back, so Ray adds scheduling and transfer and \
                 no cores here; it pays where the workers are other machines. The frames are \
                 byte-identical to the single process's.",
                f(r / s, 2)
            );
        }
        Some((r, s, _, _)) => {
            let _ = write!(
                reading,
                "On Ray the {frames:.0} frames take {}× the single process's time (byte-identical \
                 frames): one thread per task scales better than two threads in one render on this \
                 machine, despite each task loading the raster.",
                f(r / s, 2)
            );
        }
        None => reading.push_str(
            "Ray is not installed in the environment: no Ray figures (`pip install ray` there).",
        ),
    }
    ctx.md.para(&reading);
    Ok(())
}
