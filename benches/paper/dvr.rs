//! Direct volume rendering against Tachyon: the CT engine block
//! (`scenes/dvr-engine-tachyon.toml`, the volume of Tachyon's `engine.dat`
//! example with a comparable transfer function) rendered by rrt and by
//! Tachyon at the same resolution, interleaved, on one and two threads;
//! the two images side by side.

use rrt_host::fit::{RasterNeed, default_raster};

use crate::common::*;

/// Tachyon's figures of one run (seconds).
struct TachyonRun {
    parse: f64,
    render: f64,
    wall: f64,
}

/// Runs `tachyon` on `dat` (in its folder, which its volume path is
/// relative to) at `side`², `threads` threads, no antialiasing, writing
/// `out` (PNG).
fn run_tachyon(bin: &Path, dat: &Path, side: u32, threads: usize, out: &Path) -> Res<TachyonRun> {
    let dir = dat.parent().ok_or("engine.dat has no folder")?;
    let t0 = Instant::now();
    let o = Command::new(bin)
        .current_dir(dir)
        .arg(dat.file_name().ok_or("engine.dat has no name")?)
        .args(["-res", &side.to_string(), &side.to_string()])
        .args(["-numthreads", &threads.to_string(), "-aasamples", "0"])
        .args(["-format", "PNG", "-o"])
        .arg(out)
        .output()?;
    let wall = t0.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&o.stdout).replace('\r', "\n");
    let time = |label: &str| -> Res<f64> {
        let line = text
            .lines()
            .find(|l| l.contains(label))
            .ok_or_else(|| format!("tachyon printed no {label:?}"))?;
        let words: Vec<&str> = line.split_whitespace().collect();
        let v = words
            .len()
            .checked_sub(2)
            .and_then(|i| words.get(i))
            .ok_or("tachyon time without a value")?;
        Ok(v.parse::<f64>()?)
    };
    if !o.status.success() {
        return Err(format!("{} failed: {}", bin.display(), text.trim()).into());
    }
    Ok(TachyonRun {
        parse: time("Scene Parsing Time")?,
        render: time("Ray Tracing Time")?,
        wall,
    })
}

/// `tachyon-nox` (or `tachyon`) on the PATH and the `engine.dat` example
/// of `tachyon-doc`; installed by `run_peers.sh tachyon` when missing
/// (full runs only).
fn find_tachyon(ctx: &Ctx) -> Option<(PathBuf, PathBuf)> {
    let which = |name: &str| {
        Command::new("sh")
            .args(["-c", &format!("command -v {name}")])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()))
    };
    let dat = PathBuf::from("/usr/share/doc/tachyon/examples/scenes/engine.dat");
    let found = || {
        Some((
            which("tachyon-nox").or_else(|| which("tachyon"))?,
            dat.clone(),
        ))
        .filter(|(_, d)| d.is_file())
    };
    if let Some(f) = found() {
        return Some(f);
    }
    if ctx.cfg.quick {
        return None;
    }
    let script = ctx.data.join("../peers/run_peers.sh");
    ctx.log(&format!(
        "installing Tachyon: bash {} tachyon",
        script.display()
    ));
    let _ = Command::new("bash")
        .arg(&script)
        .arg("tachyon")
        .env("SCENES", "balls1")
        .env("THREADS", "1")
        .env("RUNS", "1")
        .stdout(std::process::Stdio::null())
        .status();
    found()
}

/// The engine scene for rrt, reading the volume from the run's data
/// folder.
fn engine_scene(ctx: &Ctx) -> Res<Scene> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let file = root.join("dvr-engine-tachyon.toml");
    let text = std::fs::read_to_string(&file)?;
    let volume = ctx.data.join("volumes/ct_engine.nrrd");
    let text = text.replace(
        "../../shared/data/volumes/ct_engine.nrrd",
        &volume.display().to_string(),
    );
    Ok(rrt_host::scene::toml::parse(
        &file.display().to_string(),
        &text,
        &root,
        &rrt_host::scene::toml::Options::default(),
    )?)
}

/// Writes linear 8-bit RGB `rgb` (`side`²) as a PNG.
fn save_png(path: &Path, rgb: &[u8], side: u32) -> Res<()> {
    image::save_buffer(path, rgb, side, side, image::ExtendedColorType::Rgb8)?;
    Ok(())
}

pub(crate) fn dvr(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let side = cfg.image;
    ctx.md.h2("Direct volume rendering against Tachyon");
    if !ctx.data.join("volumes/ct_engine.nrrd").is_file() {
        ctx.md
            .para("Skipped: no `volumes/ct_engine.nrrd` in the data folder.");
        return Ok(());
    }
    let scene = engine_scene(ctx)?;
    let need = RasterNeed {
        view: &scene.view,
        image: [side, side],
        samples: 1,
        discrete: false,
    };
    let raster = default_raster(&scene, &need);
    ctx.log(&format!("DVR: building the engine at raster {raster}"));
    let t = Instant::now();
    let built = build_exact(&scene, raster, 2)?;
    let build_s = t.elapsed().as_secs_f64();
    let vs = &built.scene;
    let opts = TraceOptions::default();
    let tachyon = find_tachyon(ctx);
    let tmp = std::env::temp_dir().join(format!("rrt-paper-dvr-{}", std::process::id()));
    std::fs::create_dir_all(&tmp)?;
    let threads = [1usize, 2];
    let mut ours = [Vec::new(), Vec::new()];
    let mut theirs: [Vec<TachyonRun>; 2] = [Vec::new(), Vec::new()];
    let mut image = None;
    let mut stats = RayStats::default();
    for rep in 0..cfg.reps {
        ctx.log(&format!("DVR: round {}", rep + 1));
        for (ti, &th) in threads.iter().enumerate() {
            if let Some((bin, dat)) = &tachyon {
                let png = tmp.join(format!("tachyon_engine_{th}.png"));
                theirs[ti].push(run_tachyon(bin, dat, side, th, &png)?);
            }
            let out = render_scene(vs, &scene.view, side, opts, 1, th)?;
            ours[ti].push(out.secs);
            if image.is_none() {
                stats = out.stats;
                image = Some(out.image);
            }
        }
    }
    let image = image.ok_or("no render")?;
    save_png(&ctx.plots.join("dvr-engine-rrt.png"), &image.rgb, side)?;
    let tachyon_png = tmp.join("tachyon_engine_1.png");
    let (psnr_db, tachyon_shown) = match image::open(&tachyon_png) {
        Ok(t) => {
            // Tachyon's camera is left-handed: its image is rrt's
            // mirrored left to right. Saved as Tachyon made it; compared
            // mirrored back.
            let t = t.to_rgb8();
            save_png(&ctx.plots.join("dvr-engine-tachyon.png"), t.as_raw(), side)?;
            let flipped = image::imageops::flip_horizontal(&t);
            (psnr(&image.rgb, flipped.as_raw()), true)
        }
        Err(_) => (f64::NAN, false),
    };
    let _ = std::fs::remove_dir_all(&tmp);
    let med = |v: &[f64]| median(v);
    let mut rows = Vec::new();
    for (ti, &th) in threads.iter().enumerate() {
        let t = &theirs[ti];
        let tr = med(&t.iter().map(|r| r.render).collect::<Vec<_>>());
        let tp = med(&t.iter().map(|r| r.parse).collect::<Vec<_>>());
        let tw = med(&t.iter().map(|r| r.wall).collect::<Vec<_>>());
        let or = med(&ours[ti]);
        rows.push(vec![
            th.to_string(),
            secs(or),
            if t.is_empty() { "–".into() } else { secs(tr) },
            if t.is_empty() {
                "–".into()
            } else {
                format!("{}×", f(or / tr, 1))
            },
            if t.is_empty() { "–".into() } else { secs(tp) },
            if t.is_empty() { "–".into() } else { secs(tw) },
        ]);
    }
    let rays = stats.primary.max(1) as f64;
    ctx.md.para(&format!(
        "The CT engine block (256 × 256 × 110 samples, 8-bit; `../shared/data/volumes/ct_engine.nrrd`, \
         the volume of Tachyon's `engine.dat` example) rendered directly at {side}², one ray per pixel: \
         rrt from `scenes/dvr-engine-tachyon.toml` (the default exact mode and adaptive rays, raster \
         {} fitted to the samples; building it took {} s on 2 threads: the samples at the voxel centres, \
         the raster of the {} voxels of opacity above 0, the distance field), Tachyon 0.99 \
         (`tachyon-nox engine.dat -res {side} {side} -numthreads T -aasamples 0`). \
         {} runs of each, interleaved; medians, in seconds. rrt's time is its render (as Tachyon's \
         *Ray Tracing Time*); Tachyon's scene parsing (reading the volume) and whole process are shown \
         beside it. The transfer function is Tachyon's: every value above 0 has some opacity, the \
         air's noise (values 1–15) too, so the volume's whole box is in rrt's raster and there is no \
         empty space to skip inside it.",
        dims(vs),
        secs(build_s),
        built.report.records,
        cfg.reps,
    ));
    ctx.md.table(
        &[
            "threads",
            "rrt render",
            "Tachyon render",
            "rrt / Tachyon",
            "Tachyon parse",
            "Tachyon process",
        ],
        &rows,
    );
    if tachyon.is_none() {
        ctx.md.para(
            "Tachyon was not found (`tachyon-nox` and `/usr/share/doc/tachyon/examples/scenes/engine.dat`, \
             installed by `../shared/peers/run_peers.sh tachyon`): rrt's times alone.",
        );
    }
    ctx.md.para(&format!(
        "rrt composited {} volume samples per ray ({} voxel steps per ray) on the {side}² image. \
         Images (linear, no gamma, as both write them): rrt | Tachyon (as Tachyon renders it, mirrored).",
        f(stats.samples as f64 / rays, 1),
        f(steps_per_ray(&stats), 1),
    ));
    let link = &ctx.plots_link;
    ctx.md.line(&format!(
        "![rrt, direct volume rendering]({link}/dvr-engine-rrt.png){}",
        if tachyon_shown {
            format!(" ![Tachyon, engine.dat]({link}/dvr-engine-tachyon.png)")
        } else {
            String::new()
        }
    ));
    ctx.md.line("");
    ctx.md.para(&format!(
        "PSNR of rrt's image against Tachyon's mirrored back: {} dB. Where they differ: \
         Tachyon's camera is left-handed (its image is mirrored) and its zoom fixed (rrt's 53.13° \
         field of view matches it; Tachyon samples pixel corners, rrt pixel centres); Tachyon \
         stretches the 110 slices over the box's 0.8 units of depth, rrt keeps the samples cubic \
         (0.86 units); Tachyon marches fixed steps of about one voxel with nearest-voxel samples and \
         *adds* opacities until they reach 1, rrt visits each voxel the ray passes (adaptive \
         discrete ray), takes the trilinear value at its centre and composites \
         `1 − (1 − α)^(ℓ/spacing)` over the ray's chord ℓ through the voxel, stopping at 0.99; \
         Tachyon's colour map is its own black–red–yellow–white, rrt's the piecewise linear ramp \
         of the scene. Neither lights the samples here (rrt: a material of kd 2 and no lights). \
         Tachyon runs no early termination and has no shading or gradient work to do; rrt \
         computes the gray-level gradient and looks up each voxel's record (object list) on the way.",
        f(psnr_db, 1)
    ));
    Ok(())
}
