//! Rasters at scale: balls4 voxelized and saved at rasters from 512 to
//! 4096 voxels along its longest axis, then rendered from each saved file
//! as whole processes (file size, load, render, peak memory), and a
//! 4096³ raster's memory estimate.

use crate::common::*;
use crate::whole::{Run, render_args, run, scene_path, strings};

/// Rasters of a full run, and the one the others are compared to.
const RASTERS: [u32; 4] = [512, 1024, 2048, 4096];
const REFERENCE: u32 = 1024;
/// The same for a quick run.
const QUICK_RASTERS: [u32; 3] = [64, 128, 256];
const QUICK_REFERENCE: u32 = 128;
/// Peak memory the largest raster must stay within (MiB).
const MEMORY_TARGET_MIB: f64 = 2048.0;

/// One raster's figures.
struct Row {
    raster: u32,
    dims: String,
    voxelize: Run,
    file_mib: f64,
    renders: Vec<Run>,
}

impl Row {
    fn median_of(&self, f: impl Fn(&Run) -> f64) -> f64 {
        median(&self.renders.iter().map(f).collect::<Vec<_>>())
    }
    fn render(&self) -> f64 {
        self.median_of(|r| r.phase("render"))
    }
    fn load(&self) -> f64 {
        self.median_of(|r| r.phase("load"))
    }
    /// The larger of the voxelization's and the renders' peak memory.
    fn peak(&self) -> f64 {
        self.renders
            .iter()
            .map(|r| r.rss)
            .fold(self.voxelize.rss, f64::max)
    }
}

pub(crate) fn scale(ctx: &mut Ctx) -> Res<()> {
    let cfg = ctx.cfg.clone();
    let title = "Rasters at scale";
    let Some(rrt) = rrt_binary(ctx)? else {
        ctx.md.h2(title);
        ctx.md
            .para("Not measured: no `rrt` binary beside the bench's (quick runs do not build it).");
        return Ok(());
    };
    let scene = ctx.spd("balls4");
    if !scene.is_file() {
        ctx.md.h2(title);
        ctx.md
            .para(&format!("Not measured: {} is missing.", scene.display()));
        return Ok(());
    }
    let (rasters, reference): (&[u32], u32) = if cfg.quick {
        (&QUICK_RASTERS, QUICK_REFERENCE)
    } else {
        (&RASTERS, REFERENCE)
    };
    let tmp = std::env::temp_dir().join(format!("rrt-scale-{}", std::process::id()));
    std::fs::create_dir_all(&tmp)?;
    let p = scene.display().to_string();
    let side = cfg.image.to_string();
    let file_of = |n: u32| tmp.join(format!("balls4-{n}.rrt")).display().to_string();

    let mut rows = Vec::new();
    for &n in rasters {
        ctx.log(&format!("scale: balls4 at raster {n}"));
        let file = file_of(n);
        let voxelize = run(
            &rrt,
            &strings(&["voxelize", &p, "-o", &file, "--raster", &n.to_string()]),
        )?;
        let file_mib =
            std::fs::metadata(&file).map_or(f64::NAN, |m| m.len() as f64) / f64::from(1u32 << 20);
        rows.push(Row {
            raster: n,
            dims: voxelize.raster(),
            voxelize,
            file_mib,
            renders: Vec::new(),
        });
    }
    let out = tmp.join("balls4.png").display().to_string();
    for _ in 0..cfg.reps {
        for row in &mut rows {
            let file = file_of(row.raster);
            row.renders
                .push(run(&rrt, &render_args(&file, &out, &side, 1))?);
        }
    }

    // A 4096³ raster (one sphere, the raster a cube): its memory estimate,
    // against a stated limit so that the answer does not depend on the
    // machine's memory.
    let one_sphere = scene_path(ctx, "one-sphere");
    let cube = 4096;
    let refused = Command::new(&rrt)
        .args(["voxelize", &one_sphere.display().to_string(), "-o"])
        .arg(tmp.join("cube.rrt"))
        .args(["--raster", &cube.to_string(), "--max-memory", "16G", "-q"])
        .output()?;
    let refusal = if refused.status.success() {
        None
    } else {
        Some(
            String::from_utf8_lossy(&refused.stderr)
                .lines()
                .next()
                .unwrap_or("")
                .replace(&one_sphere.display().to_string(), "scenes/one-sphere.toml")
                .replace(&tmp.join("cube.rrt").display().to_string(), "cube.rrt"),
        )
    };
    let _ = std::fs::remove_dir_all(&tmp);

    let base = rows
        .iter()
        .find(|r| r.raster == reference)
        .map_or(f64::NAN, Row::render);
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.raster.to_string(),
                r.dims.clone(),
                secs(r.voxelize.wall),
                secs(r.voxelize.phase("voxelize")),
                secs(r.voxelize.phase("light visibility")),
                secs(r.voxelize.phase("save")),
                f(r.voxelize.rss, 0),
                f(r.file_mib, 1),
                secs(r.load()),
                secs(r.render()),
                f(r.render() / base, 2),
                f(r.median_of(|x| x.count("steps/ray")), 1),
                f(r.median_of(|x| x.count("steps/shadow ray walked")), 1),
                secs(r.median_of(|x| x.wall)),
                f(r.median_of(|x| x.rss), 0),
            ]
        })
        .collect();

    if let Some(largest) = rows.last() {
        let peak = largest.peak();
        ctx.targets.push(vec![
            format!(
                "balls4 voxelizes and renders at raster {} within 2 GiB peak RSS",
                largest.raster
            ),
            format!(
                "{} MiB (voxelize {} MiB, render {} MiB)",
                f(peak, 0),
                f(largest.voxelize.rss, 0),
                f(largest.median_of(|x| x.rss), 0)
            ),
            yes(peak <= MEMORY_TARGET_MIB),
        ]);
    }
    let above: Vec<&Row> = rows.iter().filter(|r| r.raster > reference).collect();
    if !above.is_empty() && base.is_finite() {
        let worst = above
            .iter()
            .map(|r| r.render() / base)
            .fold(f64::NAN, f64::max);
        ctx.targets.push(vec![
            format!(
                "balls4 render from saved rasters (1 thread): at {} ≤ 1.25× the time at {reference}",
                above
                    .iter()
                    .map(|r| r.raster.to_string())
                    .collect::<Vec<_>>()
                    .join(" and ")
            ),
            above
                .iter()
                .map(|r| format!("{}: {}×", r.raster, f(r.render() / base, 2)))
                .collect::<Vec<_>>()
                .join(", "),
            yes(worst <= 1.25),
        ]);
    }
    if let Some(slowest) = rows.iter().max_by(|a, b| a.load().total_cmp(&b.load())) {
        ctx.targets.push(vec![
            "loading a saved balls4 raster ≤ 50 ms, every raster measured".into(),
            format!(
                "slowest {} s (raster {})",
                secs(slowest.load()),
                slowest.raster
            ),
            yes(slowest.load() <= 0.05),
        ]);
    }

    let md = &mut ctx.md;
    md.h2(&format!(
        "{title}: balls4 from {} to {}",
        rasters.first().copied().unwrap_or(0),
        rasters.last().copied().unwrap_or(0)
    ));
    md.para(&format!(
        "SPD `balls4.nff` voxelized by `rrt voxelize balls4.nff -o F.rrt --raster N` (defaults \
         otherwise: the exact mode, 2 threads) once per raster, then rendered from the saved file \
         by `rrt render F.rrt -o x.png --linear --width {side} --height {side} --threads 1`, the \
         rasters interleaved round by round (medians of {reps}). **Voxelize s** is that whole \
         process, with its phases from its summary line (light visibility: the shadow \
         classification of every surface voxel for every light, which a saved raster keeps \
         for renders from any view; save: the file written, after checking that the plane's \
         opaque cells are the records' voxels); **file**, the saved raster (format version 3: the records, the plane made \
         again on load); **load** and **render**, the phases of rrt's summary line (load: \
         mapping, checksums, decoding, making the plane); **render / {reference}**, the render \
         phase against the one at raster {reference}; **steps per ray** over all rays traced and \
         **per shadow ray** walked (an empty-space jump counts as one); **process s** and **peak MiB**, the whole \
         render process and its peak resident memory (`/usr/bin/time`).",
        reps = cfg.reps,
    ));
    md.table(
        &[
            "raster N",
            "raster",
            "voxelize s",
            "of which voxelize",
            "light visibility",
            "save",
            "voxelize peak MiB",
            "file MiB",
            "load s",
            "render s",
            &format!("render / {reference}"),
            "steps per ray",
            "steps per shadow ray",
            "process s",
            "peak MiB",
        ],
        &table,
    );
    md.para(&match refusal {
        Some(msg) => format!(
            "A {cube}³ raster (`rrt voxelize scenes/one-sphere.toml --raster {cube} \
             --max-memory 16G`) is refused before anything is allocated: `{}`",
            msg.trim()
        ),
        None => format!("A {cube}³ raster of one sphere was voxelized within 16 GiB."),
    });
    if let Some(largest) = rows.last() {
        let cells: f64 = largest
            .dims
            .split('×')
            .map(|d| d.parse::<f64>().unwrap_or(f64::NAN))
            .product();
        md.para(&format!(
            "What bounds these figures: the plane is one byte per voxel of the raster's box \
             in address space ({} GiB at raster {}), but only its pages within 16 voxels of a \
             surface are ever written (the distance field leaves farther cells empty; skipping \
             there reads the line level and the coarse level over 8³ bricks). A plane of up to \
             256 MiB asks the kernel for 2 MiB pages, a larger one for 4 KiB pages (a row or \
             two of the raster each), so that a written cell brings in only its own rows: that \
             resident part of the plane is still most of the peak memory, and the kernel's \
             zeroing of those pages the largest part of the load time, before the line level \
             (profiled at 4096; it varies between runs with the kernel's state). The light visibility phase walks the tube of every surface \
             voxel towards every light: the surface voxels grow with the square of the raster's \
             side and the walks with the side. The render takes more steps per ray as the \
             voxels shrink (jumps through empty space are bounded by the line level's bound of 120 \
             voxels) and its plane reads miss the caches more often.",
            f(cells / f64::from(1u32 << 30), 1),
            largest.raster
        ));
    }
    Ok(())
}
