//! What every section of the report shares: the run's configuration and
//! context, the Markdown writer and number formats, and the build, render
//! and walk helpers the sections time.

pub(crate) use std::error::Error;
pub(crate) use std::fmt::Write as _;
pub(crate) use std::path::{Path, PathBuf};
pub(crate) use std::process::Command;
pub(crate) use std::time::Instant;

pub(crate) use glam::DVec3;
pub(crate) use indicatif::ProgressBar;
pub(crate) use rrt_core::Connectivity;
pub(crate) use rrt_core::discrete_ray::{DiscreteRay, WalkEnd};
pub(crate) use rrt_core::raster::{Raster, cell};
pub(crate) use rrt_host::render::camera::Camera;
pub(crate) use rrt_host::render::{Image, RenderOptions, render};
pub(crate) use rrt_host::scene::{Scene, View};
pub(crate) use rrt_host::trace::{Mode, RayStats, TraceOptions, Tracer};
pub(crate) use rrt_host::voxelize::{BuildOptions, BuildReport, VoxelScene, build};
pub(crate) use rrt_host::world::Bounds;
pub(crate) use rrt_host::world::Ray;

pub(crate) use crate::plot::{self, Series};
pub(crate) use crate::{arts, head};

/// What a section or helper returns.
pub(crate) type Res<T> = Result<T, Box<dyn Error>>;

/// One section of the report.
pub(crate) type Section = fn(&mut Ctx) -> Res<()>;

/// Sizes of one run.
#[derive(Debug, Clone)]
pub(crate) struct Config {
    pub(crate) quick: bool,
    pub(crate) reps: usize,
    /// Image side of Table 1, the connectivity, verification and Embree
    /// sections (the peers' 512²).
    pub(crate) image: u32,
    /// Raster of Table 1 (the paper's 256³).
    pub(crate) t1_raster: u32,
    /// Rasters of the connectivity, verification and skipping sections.
    pub(crate) rasters: Vec<u32>,
    /// Sphere counts of Table 2.
    pub(crate) counts: Vec<usize>,
    /// Image side of Table 2.
    pub(crate) t2_image: u32,
    /// ARTS grid resolutions.
    pub(crate) grids: Vec<usize>,
    /// Rasters of the Embree comparison.
    pub(crate) embree_rasters: Vec<u32>,
}

impl Config {
    pub(crate) fn new(quick: bool, reps: Option<usize>) -> Self {
        if quick {
            Self {
                quick,
                reps: reps.unwrap_or(1),
                image: 32,
                t1_raster: 64,
                rasters: vec![64],
                counts: vec![10, 50],
                t2_image: 32,
                grids: vec![40, 120, 256],
                embree_rasters: vec![128],
            }
        } else {
            Self {
                quick,
                reps: reps.unwrap_or(5),
                image: 512,
                t1_raster: 256,
                rasters: vec![256, 1024],
                counts: vec![10, 50, 100, 200, 400, 500, 1000, 5000],
                t2_image: 512,
                grids: vec![40, 120, 256],
                embree_rasters: vec![1024, 2048],
            }
        }
    }
}

/// The median of `v` (mean of the two middle values for an even count).
pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// A Markdown document under construction.
#[derive(Default)]
pub(crate) struct Md(pub(crate) String);

impl Md {
    pub(crate) fn line(&mut self, s: &str) {
        self.0.push_str(s);
        self.0.push('\n');
    }
    pub(crate) fn para(&mut self, s: &str) {
        self.line(s);
        self.line("");
    }
    pub(crate) fn h2(&mut self, s: &str) {
        self.line(&format!("## {s}"));
        self.line("");
    }
    pub(crate) fn h3(&mut self, s: &str) {
        self.line(&format!("### {s}"));
        self.line("");
    }
    /// A table; the first column is left-aligned, the others right-aligned.
    pub(crate) fn table(&mut self, head: &[&str], rows: &[Vec<String>]) {
        self.line(&format!("| {} |", head.join(" | ")));
        let align: Vec<&str> = (0..head.len())
            .map(|i| if i == 0 { "---" } else { "---:" })
            .collect();
        self.line(&format!("| {} |", align.join(" | ")));
        for r in rows {
            self.line(&format!("| {} |", r.join(" | ")));
        }
        self.line("");
    }
}

pub(crate) fn f(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "–".into()
    }
}

pub(crate) fn secs(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else if v >= 0.1 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    }
}

pub(crate) fn dims(scene: &VoxelScene) -> String {
    let d = scene.extent().dims();
    format!("{}×{}×{}", d[0], d[1], d[2])
}

/// A scene built from an NFF scene.
pub(crate) struct Built {
    pub(crate) scene: VoxelScene,
    pub(crate) report: BuildReport,
}

/// The paper's raster (one object per voxel, the paper's light bits).
pub(crate) fn build_nff(
    scene: &Scene,
    raster: u32,
    conn: Connectivity,
    threads: usize,
    bounds: Option<Bounds>,
) -> Res<Built> {
    build_with(scene, BuildOptions::paper(raster), conn, threads, bounds)
}

/// The exact raster `rrt voxelize` saves (object lists, the shadow
/// classification): every mode renders from it.
pub(crate) fn build_exact(scene: &Scene, raster: u32, threads: usize) -> Res<Built> {
    build_with(
        scene,
        BuildOptions::new(raster),
        Connectivity::Adaptive,
        threads,
        None,
    )
}

fn build_with(
    scene: &Scene,
    mut opts: BuildOptions,
    conn: Connectivity,
    threads: usize,
    bounds: Option<Bounds>,
) -> Res<Built> {
    opts.connectivity = conn;
    opts.threads = threads;
    opts.fit.bounds = bounds;
    let (scene, report) = build(scene, &opts, &ProgressBar::hidden())?;
    Ok(Built { scene, report })
}

/// One render.
pub(crate) struct Rendered {
    pub(crate) secs: f64,
    pub(crate) stats: RayStats,
    pub(crate) image: Image,
}

pub(crate) fn render_scene(
    scene: &VoxelScene,
    view: &View,
    side: u32,
    opts: TraceOptions,
    supersample: u32,
    threads: usize,
) -> Res<Rendered> {
    let camera = Camera::new(view, side, side)?;
    let tracer = Tracer::new(scene, opts)?;
    let (image, stats, time) = render(
        &tracer,
        &camera,
        &RenderOptions {
            supersample,
            threads,
            alpha: false,
        },
        &ProgressBar::hidden(),
    )?;
    Ok(Rendered {
        secs: time.as_secs_f64(),
        stats,
        image,
    })
}

pub(crate) fn depth3(conn: Connectivity, mode: Mode) -> TraceOptions {
    TraceOptions {
        mode,
        connectivity: conn,
        depth: 3,
        ..TraceOptions::default()
    }
}

/// Camera rays through the pixel centres, row by row.
pub(crate) fn camera_rays(view: &View, side: u32) -> Res<Vec<Ray>> {
    let camera = Camera::new(view, side, side)?;
    let mut rays = Vec::with_capacity((side * side) as usize);
    for y in 0..side {
        for x in 0..side {
            rays.push(camera.primary(x, y));
        }
    }
    Ok(rays)
}

/// Rays per second of steps: all rays but shadow rays of the light pass.
pub(crate) fn steps_per_ray(s: &RayStats) -> f64 {
    s.steps as f64 / s.rays().max(1) as f64
}

/// What one walk of a set of discrete rays gave.
pub(crate) struct Walked {
    pub(crate) secs: f64,
    pub(crate) steps: u64,
    /// Per ray: the hit voxel's index, if any.
    pub(crate) hits: Vec<Option<usize>>,
}

/// Walks every ray to its first opaque voxel (with or without skipping).
pub(crate) fn walk_all(
    raster: &Raster<'_>,
    rays: &[Option<DiscreteRay>],
    mode: Connectivity,
    skip: bool,
) -> Res<Walked> {
    let raster = *raster;
    let mut hits = Vec::with_capacity(rays.len());
    let mut steps = 0u64;
    let t0 = Instant::now();
    for r in rays {
        let Some(mut r) = *r else {
            hits.push(None);
            continue;
        };
        let test = |_: usize, c: u8| c & cell::OPAQUE != 0;
        let end = if skip {
            r.walk_skipping(&raster, mode, u32::MAX, test)?
        } else {
            r.walk(&raster, mode, u32::MAX, test)?
        };
        steps += u64::from(r.steps());
        hits.push((end == WalkEnd::Hit).then(|| r.hit().index));
    }
    let secs = t0.elapsed().as_secs_f64();
    Ok(Walked { secs, steps, hits })
}

pub(crate) fn discrete_rays(scene: &VoxelScene, rays: &[Ray]) -> Res<Vec<Option<DiscreteRay>>> {
    let tracer = Tracer::new(scene, depth3(Connectivity::Adaptive, Mode::Paper))?;
    Ok(rays.iter().map(|r| tracer.discrete_ray(r)).collect())
}

/// PSNR in dB of two RGB8 images of the same size.
pub(crate) fn psnr(a: &[u8], b: &[u8]) -> f64 {
    if a.len() != b.len() || a.is_empty() {
        return f64::NAN;
    }
    let se: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).powi(2))
        .sum();
    let mse = se / a.len() as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

/// The three sphereflakes: name, file stem, sphere count, paper's Table 1
/// seconds, paper's false-hit share (%).
pub(crate) const FLAKES: [(&str, &str, u32, f64, f64); 3] = [
    ("91-sphereflake", "balls2", 91, 26.5, 1.72),
    ("820-sphereflake", "balls3", 820, 29.3, 5.06),
    ("7381-sphereflake", "balls4", 7381, 38.4, 7.94),
];

pub(crate) struct Ctx {
    pub(crate) cfg: Config,
    pub(crate) data: PathBuf,
    pub(crate) plots: PathBuf,
    /// The plots folder as the report links it.
    pub(crate) plots_link: String,
    pub(crate) md: Md,
    /// Lines for the targets section.
    pub(crate) targets: Vec<Vec<String>>,
    /// Paragraphs after the targets table: how much a missed target
    /// misses by and what bounds it.
    pub(crate) notes: Vec<String>,
    pub(crate) seed: u64,
    pub(crate) embree_bin: Option<PathBuf>,
    pub(crate) no_embree: bool,
}

impl Ctx {
    pub(crate) fn spd(&self, stem: &str) -> PathBuf {
        self.data.join("spd").join(format!("{stem}.nff"))
    }
    pub(crate) fn log(&self, s: &str) {
        eprintln!("[paper] {s}");
    }
}

pub(crate) fn yes(b: bool) -> String {
    if b { "yes".into() } else { "no".into() }
}

/// The `rrt` binary beside the bench's: for a full run built now (`cargo
/// build -p rrt-host` with the bench's profile and flags, so both have the
/// same instruction set); a quick run takes it as it is, `None` if absent.
pub(crate) fn rrt_binary(ctx: &Ctx) -> Res<Option<PathBuf>> {
    let exe = std::env::current_exe()?;
    let dir = exe.parent().ok_or("no folder for the bench binary")?;
    if ctx.cfg.quick {
        let rrt = dir.join("rrt");
        return Ok(rrt.is_file().then_some(rrt));
    }
    let profile = if dir.ends_with("release") {
        "release"
    } else {
        "dev"
    };
    ctx.log(&format!("building rrt ({profile})"));
    let status = Command::new(env!("CARGO"))
        .args([
            "build",
            "-q",
            "-p",
            "rrt-host",
            "--bin",
            "rrt",
            "--profile",
            profile,
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()?;
    if !status.success() {
        return Err("cargo build -p rrt-host failed".into());
    }
    Ok(Some(dir.join("rrt")))
}
