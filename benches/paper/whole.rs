//! The user's job against Embree, as whole processes: `rrt render
//! SCENE.nff` with the defaults (the exact mode, the default raster)
//! against `embree_nff` on the same scene, from the scene file and from a
//! saved raster, 1 and 2 threads; the image's PSNR against Embree's in
//! the exact and the paper's mode; the phases, the peak memory, and what
//! the exact mode's rays did.

use crate::common::*;
use crate::embree::find_embree;

/// The scenes of the comparison: the SPD scenes in `shared/data/spd` and
/// the one-sphere scene of the repository.
const SCENES: [&str; 7] = [
    "balls2",
    "balls3",
    "balls4",
    "teapot",
    "rings",
    "tetra",
    "one-sphere",
];

/// One process's figures.
#[derive(Clone, Debug, Default)]
pub(crate) struct Run {
    /// Wall time, s.
    pub(crate) wall: f64,
    /// Peak resident memory, MiB (NaN without `/usr/bin/time`).
    pub(crate) rss: f64,
    /// Standard output and error.
    pub(crate) out: String,
}

impl Run {
    /// A phase's seconds from rrt's summary line (`name 0.123 s`).
    pub(crate) fn phase(&self, name: &str) -> f64 {
        self.out
            .split(&format!("{name} "))
            .nth(1)
            .and_then(|t| t.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    }

    /// The raster's dimensions from rrt's summary line (`raster
    /// 485×485×31`), `?` without one.
    pub(crate) fn raster(&self) -> String {
        self.out
            .split("raster ")
            .nth(1)
            .and_then(|t| t.split([' ', ',']).next())
            .unwrap_or("?")
            .to_string()
    }

    /// A count from rrt's summary line (`123 name`).
    pub(crate) fn count(&self, name: &str) -> f64 {
        self.out
            .split(&format!(" {name}"))
            .next()
            .and_then(|t| t.split([' ', '(']).next_back())
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    }
}

/// Runs `cmd`, timed here (the wall time from spawning to exit, to the
/// clock's resolution), under `/usr/bin/time` for its peak memory when
/// that exists (its own wall time has only 10 ms steps, too coarse for
/// processes of a tenth of a second).
pub(crate) fn run(cmd: &Path, args: &[String]) -> Res<Run> {
    let time = Path::new("/usr/bin/time");
    let t = Instant::now();
    let o = if time.is_file() {
        Command::new(time)
            .args(["-f", "TIME %M"])
            .arg(cmd)
            .args(args)
            .output()?
    } else {
        Command::new(cmd).args(args).output()?
    };
    let wall = t.elapsed().as_secs_f64();
    let mut out = String::from_utf8_lossy(&o.stdout).into_owned();
    out.push_str(&String::from_utf8_lossy(&o.stderr));
    if !o.status.success() {
        return Err(format!("{} {}: {out}", cmd.display(), args.join(" ")).into());
    }
    let rss = out
        .lines()
        .find_map(|l| l.strip_prefix("TIME "))
        .and_then(|l| l.trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0);
    Ok(Run { wall, rss, out })
}

/// The scene file of `stem`.
pub(crate) fn scene_path(ctx: &Ctx, stem: &str) -> PathBuf {
    if stem == "one-sphere" {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes/one-sphere.toml")
    } else {
        ctx.spd(stem)
    }
}

/// `rrt render INPUT -o OUT --linear --width SIDE --height SIDE --threads
/// T`: an image of a scene or a saved raster, every other setting at its
/// default.
pub(crate) fn render_args(input: &str, out: &str, side: &str, threads: usize) -> Vec<String> {
    let t = threads.to_string();
    strings(&[
        "render",
        input,
        "-o",
        out,
        "--linear",
        "--width",
        side,
        "--height",
        side,
        "--threads",
        &t,
    ])
}

pub(crate) fn strings(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| (*s).to_string()).collect()
}

/// PSNR of two PNG files' pixels (NaN if one cannot be read).
fn png_psnr(a: &Path, b: &Path) -> f64 {
    match (image::open(a), image::open(b)) {
        (Ok(a), Ok(b)) => psnr(a.to_rgb8().as_raw(), b.to_rgb8().as_raw()),
        _ => f64::NAN,
    }
}

pub(crate) fn whole(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let (embree, how) = if ctx.no_embree {
        (None, "skipped (`--no-embree`)".to_string())
    } else {
        find_embree(ctx, ctx.embree_bin.as_deref())
    };
    let Some(rrt) = rrt_binary(ctx)? else {
        ctx.md.h2("The whole job against Embree");
        ctx.md
            .para("Not measured: no `rrt` binary beside the bench's (quick runs do not build it).");
        return Ok(());
    };
    let tmp = std::env::temp_dir().join(format!("rrt-whole-{}", std::process::id()));
    std::fs::create_dir_all(&tmp)?;
    let side = cfg.image.to_string();
    let mut rows = Vec::new();
    let mut saved_rows = Vec::new();
    let mut balls4 = None;
    let mut one_sphere = None;
    let mut one_sphere_saved = None;
    let mut slowest_load = (String::new(), f64::NAN);
    let mut worst = (f64::INFINITY, String::new());
    for stem in SCENES {
        let path = scene_path(ctx, stem);
        if !path.is_file() {
            ctx.log(&format!("whole job: {} missing, skipped", path.display()));
            continue;
        }
        ctx.log(&format!("whole job: {stem}"));
        let p = path.display().to_string();
        let ours_png = |t: usize| tmp.join(format!("{stem}-{t}.png"));
        let rrt_args = |t: usize, extra: &[&str]| -> Vec<String> {
            let out = ours_png(t).display().to_string();
            let mut a = render_args(&p, &out, &side, t);
            a.extend(strings(extra));
            a
        };
        let embree_png = tmp.join(format!("{stem}-embree.png"));
        let embree_args = |t: usize| {
            strings(&[
                "-w",
                &side,
                "-h",
                &side,
                "-d",
                "3",
                "-T",
                "-t",
                &t.to_string(),
                "-o",
                &embree_png.display().to_string(),
                &p,
            ])
        };
        // [threads][rrt, embree]
        let mut t = [[Vec::new(), Vec::new()], [Vec::new(), Vec::new()]];
        let mut last = [Run::default(), Run::default()];
        for _ in 0..cfg.reps {
            for (ti, th) in [1usize, 2].into_iter().enumerate() {
                let r = run(&rrt, &rrt_args(th, &[]))?;
                t[ti][0].push(r.wall);
                last[ti] = r;
                if let Some(e) = &embree
                    && stem != "one-sphere"
                {
                    t[ti][1].push(run(e, &embree_args(th))?.wall);
                }
            }
        }
        // The paper's mode, once, for its PSNR.
        let paper_png = tmp.join(format!("{stem}-paper.png"));
        let pp = paper_png.display().to_string();
        let paper_args = strings(&[
            "render", &p, "-o", &pp, "--linear", "--width", &side, "--height", &side, "--mode",
            "paper", "-q",
        ]);
        run(&rrt, &paper_args)?;
        let has_embree = embree_png.is_file();
        let exact_psnr = if has_embree {
            png_psnr(&ours_png(1), &embree_png)
        } else {
            f64::NAN
        };
        let paper_psnr = if has_embree {
            png_psnr(&paper_png, &embree_png)
        } else {
            f64::NAN
        };
        if exact_psnr < worst.0 {
            worst = (exact_psnr, stem.to_string());
        }
        let raster = last[0].raster();
        let [o1, e1, o2, e2] = [&t[0][0], &t[0][1], &t[1][0], &t[1][1]].map(|v| median(v));
        rows.push(vec![
            stem.to_string(),
            raster,
            secs(o1),
            secs(e1),
            f(o1 / e1, 1),
            secs(o2),
            secs(e2),
            f(o2 / e2, 1),
            secs(last[1].phase("voxelize")),
            secs(last[1].phase("light visibility")),
            secs(last[1].phase("render")),
            f(last[1].rss, 0),
            f(exact_psnr, 2),
            f(paper_psnr, 2),
        ]);
        if stem == "balls4" {
            balls4 = Some((o2, e2, o1, e1));
        }
        if stem == "one-sphere" {
            one_sphere = Some((o1, o2, last[1].rss));
        }

        // From a saved raster, one thread: `rrt voxelize` once, then the
        // renders interleaved with Embree's. One sphere instead: its raster
        // at 1024 saved, the file's size and its load time.
        if stem == "one-sphere" {
            let file = tmp.join("one-sphere-1024.rrt").display().to_string();
            let n = if cfg.quick { "128" } else { "1024" };
            run(
                &rrt,
                &strings(&["voxelize", &p, "-o", &file, "--raster", n, "-q"]),
            )?;
            let mib = std::fs::metadata(&file).map_or(f64::NAN, |m| m.len() as f64)
                / f64::from(1u32 << 20);
            let out = tmp.join("one-sphere-1024.png").display().to_string();
            let mut loads = Vec::new();
            let mut rss = Vec::new();
            for _ in 0..cfg.reps {
                let r = run(
                    &rrt,
                    &strings(&[
                        "render",
                        &file,
                        "-o",
                        &out,
                        "--width",
                        "64",
                        "--height",
                        "64",
                        "--threads",
                        "1",
                    ]),
                )?;
                loads.push(r.phase("load"));
                rss.push(r.rss);
            }
            one_sphere_saved = Some((mib, median(&loads), median(&rss)));
            let _ = std::fs::remove_file(&file);
            continue;
        }
        let rrt_file = tmp.join(format!("{stem}.rrt")).display().to_string();
        run(&rrt, &strings(&["voxelize", &p, "-o", &rrt_file, "-q"]))?;
        let saved_args = |th: usize| {
            let out = tmp.join(format!("{stem}-saved.png")).display().to_string();
            render_args(&rrt_file, &out, &side, th)
        };
        let mut ts = [
            [Vec::new(), Vec::new(), Vec::new()],
            [Vec::new(), Vec::new(), Vec::new()],
        ];
        let mut saved_last = Run::default();
        let file_mib = std::fs::metadata(&rrt_file).map_or(f64::NAN, |m| m.len() as f64)
            / f64::from(1u32 << 20);
        let mut loads = Vec::new();
        for _ in 0..cfg.reps {
            for (ti, th) in [1usize, 2].into_iter().enumerate() {
                let r = run(&rrt, &saved_args(th))?;
                ts[ti][0].push(r.wall);
                ts[ti][1].push(r.phase("render"));
                if th == 1 {
                    loads.push(r.phase("load"));
                    saved_last = r;
                }
                if let Some(e) = &embree {
                    ts[ti][2].push(run(e, &embree_args(th))?.wall);
                }
            }
        }
        let rays = saved_last.count("primary")
            + saved_last.count("reflected")
            + saved_last.count("refracted");
        let shadow = saved_last.count("shadow");
        let lit = saved_last.count("lights proven lit");
        let occluded = saved_last.count("proven occluded");
        let queries = (shadow + lit + occluded).max(1.0);
        if median(&loads) > slowest_load.1 || slowest_load.1.is_nan() {
            slowest_load = (stem.to_string(), median(&loads));
        }
        saved_rows.push(vec![
            stem.to_string(),
            f(file_mib, 1),
            secs(median(&loads)),
            secs(median(&ts[0][0])),
            secs(median(&ts[0][1])),
            secs(median(&ts[0][2])),
            f(median(&ts[0][0]) / median(&ts[0][2]), 2),
            secs(median(&ts[1][0])),
            secs(median(&ts[1][1])),
            secs(median(&ts[1][2])),
            f(median(&ts[1][0]) / median(&ts[1][2]), 2),
            f(100.0 * shadow / queries, 1),
            f(100.0 * occluded / queries, 1),
            f(
                100.0 * saved_last.count("blocked by the last blocker") / shadow.max(1.0),
                1,
            ),
            f(saved_last.count("steps/shadow ray"), 1),
            f(100.0 * saved_last.count("false hits") / rays.max(1.0), 0),
            f(
                100.0 * saved_last.count("in shared voxels") / saved_last.count("hits").max(1.0),
                1,
            ),
        ]);
        if stem == "balls4" {
            let (w, e) = (median(&ts[0][0]), median(&ts[0][2]));
            ctx.targets.push(vec![
                "balls4 from a saved raster, default mode, 1 thread: whole process ≤ Embree's"
                    .into(),
                format!("{} against {} s: {}×", secs(w), secs(e), f(w / e, 2)),
                yes(w <= e),
            ]);
        }
    }
    let _ = std::fs::remove_dir_all(&tmp);
    if let Some((o2, e2, o1, e1)) = balls4 {
        ctx.targets.push(vec![
            "`rrt render balls4.nff`, defaults, 2 threads: whole process ≤ 3× Embree's".into(),
            format!(
                "{} s against {} s: {}× (1 thread: {}×)",
                secs(o2),
                secs(e2),
                f(o2 / e2, 1),
                f(o1 / e1, 1)
            ),
            yes(o2 <= 3.0 * e2),
        ]);
    }
    if slowest_load.1.is_finite() {
        ctx.targets.push(vec![
            "loading a saved raster (the default raster of each scene) ≤ 50 ms".into(),
            format!("slowest {} s ({})", secs(slowest_load.1), slowest_load.0),
            yes(slowest_load.1 <= 0.05),
        ]);
    }
    if let Some((mib, load, rss)) = one_sphere_saved {
        ctx.targets.push(vec![
            format!(
                "saved one-sphere raster at {}: ≤ 20 MB, loaded in ≤ 50 ms",
                if cfg.quick { 128 } else { 1024 }
            ),
            format!(
                "{} MB, load {} s (1 thread; render of 64², peak {} MiB)",
                f(mib * f64::from(1u32 << 20) / 1e6, 1),
                secs(load),
                f(rss, 0)
            ),
            yes(mib * f64::from(1u32 << 20) <= 20e6 && load <= 0.05),
        ]);
    }
    if let Some((o1, o2, rss)) = one_sphere {
        ctx.targets.push(vec![
            "`rrt render scenes/one-sphere.toml`: ≤ 1 s and ≤ 200 MB".into(),
            format!(
                "{} s (1 thread), {} s (2 threads), {} MiB",
                secs(o1),
                secs(o2),
                f(rss, 0)
            ),
            yes(o2 <= 1.0 && rss <= 200.0),
        ]);
    }
    if worst.0.is_finite() {
        ctx.targets.push(vec![
            "Default (exact) mode ≥ 35 dB and ≥ 40 dB against Embree on the SPD scenes here".into(),
            format!("lowest {} dB ({})", f(worst.0, 2), worst.1),
            yes(worst.0 >= 40.0),
        ]);
    }
    let md = &mut ctx.md;
    md.h2("The whole job against Embree");
    md.para(&format!(
        "Whole processes, {0}×{0}, depth 3, each timed by the bench from its start to its exit, \
         every run of one configuration interleaved with the others round by round (medians of \
         {1}). **rrt**: `rrt render SCENE -o x.png --linear \
         --width {0} --height {0} --threads T` with every other setting at its default: the \
         exact mode and the raster fitted to the scene and the image. **Embree**: `embree_nff -w \
         {0} -h {0} -d 3 -T -t T` ({how}; `-T` traces refraction, which only scenes with T > 0 \
         use). Phases from rrt's summary line (2 threads). **PSNR**: the image against \
         Embree's, in the default (exact) mode and in the paper's (`--mode paper`, same default \
         raster rule). Peak memory from `/usr/bin/time` (2 threads).",
        cfg.image, cfg.reps
    ));
    md.table(
        &[
            "scene",
            "raster",
            "rrt s, 1 thread",
            "Embree s, 1 thread",
            "rrt / Embree",
            "rrt s, 2 threads",
            "Embree s, 2 threads",
            "rrt / Embree",
            "voxelize s",
            "light s",
            "render s",
            "rrt peak MiB",
            "exact PSNR dB",
            "paper PSNR dB",
        ],
        &rows,
    );
    md.h3("From a saved raster");
    md.para(
        "The same renders from the raster `rrt voxelize SCENE` saved (the default raster, with \
         the shadow classification), interleaved with Embree's whole process from the scene \
         file. **File**: the saved raster's size (format version 3: the plane made on load \
         from the records, the large sections LZ4-compressed); **load**: the load phase of \
         rrt's summary line (mapping, checksums, decoding, making the plane). **Uncertain**: \
         the share of the shadow queries of verified hits that the classification proved \
         neither lit nor occluded, which fired an exact shadow ray; **occluded**: the share it \
         proved occluded (an opaque sphere blocks every segment from the voxel to the light), \
         answered without a ray; **blocked by the last blocker**: the share of the uncertain \
         ones that the object that last blocked a shadow ray towards the same light in the \
         tile was found to block, without a walk; **steps per shadow ray**: the voxels each walked \
         one visited (an empty-space jump counts as one). \
         **False hits**: discrete hits verification rejected, per traced ray (eye, reflected, \
         refracted). **Shared-voxel hits**: the share of verified hits found in a voxel that \
         several objects share (through its object list).",
    );
    md.table(
        &[
            "scene",
            "file MiB",
            "load s, 1 thread",
            "rrt s, 1 thread",
            "of which render s",
            "Embree s, 1 thread",
            "rrt / Embree",
            "rrt s, 2 threads",
            "of which render s",
            "Embree s, 2 threads",
            "rrt / Embree",
            "uncertain %",
            "occluded %",
            "blocked by the last blocker %",
            "steps per shadow ray",
            "false hits per 100 rays",
            "shared-voxel hits %",
        ],
        &saved_rows,
    );
    Ok(())
}
