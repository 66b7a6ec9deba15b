//! Arguments and helpers shared by `rrt render`, `rrt voxelize` and
//! `rrt info`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use glam::DVec3;
use indicatif::ProgressBar;
use rrt_core::light::ExactRecords;

use super::CliError;
use super::ray::ConnectivityArg;
use crate::fit::{Bytes, FitOptions, RasterNeed, default_max_memory, default_raster};
use crate::output::rasterfile;
use crate::scene::{Scene, View};
use crate::trace::Mode;
use crate::voxelize::{BuildOptions, BuildReport, VoxelScene, build};
use crate::world::{Bounds, WORLD_LIMIT};

/// The built-in scene: SPD `balls2.nff`, the paper's 91-sphereflake.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/balls2.nff");
/// The name the built-in scene goes by in messages.
pub const DEFAULT_SCENE_NAME: &str = "balls2.nff (built-in)";
/// The smallest `--raster`: one voxel inside the margins.
pub const MIN_RASTER: i64 = 2 * crate::fit::size::DEFAULT_MARGIN as i64 + 1;
/// The largest `--raster`: the core's longest raster axis.
pub const MAX_RASTER: i64 = rrt_core::raster::MAX_AXIS as i64;

/// How to voxelize a scene.
#[derive(Debug, Clone, clap::Args)]
pub struct RasterArgs {
    /// Voxels along the scene's longest axis, 5 to 65536 (two voxels of
    /// margin on each side) [default: fitted to the scene and the image,
    /// 64 to 1024: one surface voxel per 16 rays of the image, more where
    /// voxels would crowd with objects (adding at most two per ray) or
    /// small objects cluster; at least
    /// a pixel's footprint where voxels are
    /// the picture (the paper's mode, volumes, .vox models, CSG)].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(MIN_RASTER..=MAX_RASTER))]
    pub raster: Option<u32>,
    /// Connectivity of the discrete rays (the surfaces are voxelized thick
    /// enough for it).
    #[arg(long, value_enum, default_value_t = ConnectivityArg::Adaptive)]
    pub connectivity: ConnectivityArg,
    /// What a hit is and how it is lit. `exact` and `verified` voxelize
    /// every object conservatively (every voxel its surface passes
    /// through, with the list of all objects of a voxel several share); a
    /// raster saved that way renders in every mode. `paper` voxelizes the
    /// paper's raster (one object per voxel), which renders only in the
    /// paper's mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Exact)]
    pub mode: ModeArg,
    /// World box to voxelize, `X0,Y0,Z0,X1,Y1,Z1` (default: all geometry).
    #[arg(long, value_name = "X0,Y0,Z0,X1,Y1,Z1", value_parser = parse_bounds, allow_hyphen_values = true)]
    pub bounds: Option<Bounds>,
    /// Refuse scenes, rasters and images needing more memory than this
    /// (bytes, or with K, M, G, T suffixes; binary units) [default: half
    /// of the machine's RAM].
    #[arg(long, value_name = "SIZE", value_parser = parse_memory)]
    pub max_memory: Option<u64>,
}

/// The `--mode` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModeArg {
    /// The exact ray tracer's image: every object of a voxel intersected
    /// exactly, the true point and normal, exact shadows.
    Exact,
    /// The paper's intersection verification: exact hit point and normal,
    /// the precomputed light visibility.
    Verified,
    /// The paper's raw discrete mode: the first surface voxel is the hit,
    /// its stored normal, precomputed illumination and light visibility
    /// (fastest).
    Paper,
}

impl From<ModeArg> for Mode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Exact => Self::Exact,
            ModeArg::Verified => Self::Verified,
            ModeArg::Paper => Self::Paper,
        }
    }
}

/// What a build is for: its light pass computes what that needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Purpose {
    /// A raster to save: complete light visibility, for every mode (the
    /// shadow classification for records of exact objects; the paper's
    /// bits for the verified mode, which reads them).
    Save,
    /// A render now, in the mode asked for: the exact mode reads no light
    /// bits of exact objects, the verified mode the paper's.
    Render,
}

impl RasterArgs {
    /// Whether hits are the voxels themselves.
    #[must_use]
    pub fn discrete(&self) -> bool {
        self.mode == ModeArg::Paper
    }

    /// The build options these arguments ask for, for `purpose`, with
    /// `default_raster` voxels along the longest axis unless `--raster`
    /// says otherwise.
    #[must_use]
    pub fn build_options(&self, purpose: Purpose, default_raster: u32) -> BuildOptions {
        let raster = self.raster.unwrap_or(default_raster);
        let mut o = match self.mode {
            ModeArg::Paper => BuildOptions::paper(raster),
            _ => BuildOptions::new(raster),
        };
        o.light.exact_records = match (purpose, self.mode) {
            // The verified mode reads the paper's bits: saved so, the
            // raster renders the scene's verified image.
            (Purpose::Save, ModeArg::Verified) => ExactRecords::Paper,
            (Purpose::Save, _) => ExactRecords::Classify,
            (Purpose::Render, ModeArg::Exact) => ExactRecords::Skip,
            (Purpose::Render, _) => ExactRecords::Paper,
        };
        o.connectivity = self.connectivity.into();
        o.fit = FitOptions {
            bounds: self.bounds,
            max_memory: self.max_memory.unwrap_or_else(default_max_memory),
            ..o.fit
        };
        o
    }
}

/// Parses `X0,Y0,Z0,X1,Y1,Z1`.
///
/// # Errors
/// A message naming the bad part.
pub fn parse_bounds(s: &str) -> Result<Bounds, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 6 {
        return Err(format!(
            "expected six comma-separated numbers X0,Y0,Z0,X1,Y1,Z1, found {s:?}"
        ));
    }
    let mut v = [0f64; 6];
    for (slot, p) in v.iter_mut().zip(&parts) {
        *slot = p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.abs() <= WORLD_LIMIT)
            .ok_or_else(|| format!("expected a finite number within ±1e60, found {p:?}"))?;
    }
    let b = Bounds {
        min: DVec3::new(v[0], v[1], v[2]),
        max: DVec3::new(v[3], v[4], v[5]),
    };
    if !b.min.cmplt(b.max).all() {
        return Err(format!(
            "expected X0 < X1, Y0 < Y1 and Z0 < Z1, found {s:?}"
        ));
    }
    Ok(b)
}

/// Parses a byte count: digits with an optional K, M, G or T suffix
/// (binary units, an optional trailing `B` or `iB`).
///
/// # Errors
/// A message for a malformed or overflowing size.
pub fn parse_memory(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (digits, shift) = match t.chars().last() {
        Some('K' | 'k') => (&t[..t.len() - 1], 10),
        Some('M' | 'm') => (&t[..t.len() - 1], 20),
        Some('G' | 'g') => (&t[..t.len() - 1], 30),
        Some('T' | 't') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let n: u64 = digits
        .parse()
        .map_err(|_| format!("expected a size like 512M or 8G, found {s:?}"))?;
    n.checked_mul(1u64 << shift)
        .filter(|&v| v > 0)
        .ok_or_else(|| format!("{s:?} is not a usable size"))
}

/// The most `--threads`.
pub const MAX_THREADS: usize = 1024;

/// Parses a whole number from `lo` to `hi`; `what` names the range in
/// the message ("expected 1 to 64, found 0").
fn whole_in(s: &str, lo: i64, hi: i64, what: &str) -> Result<i64, String> {
    match s.trim().parse::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        Ok(v) => Err(format!("expected {what}, found {v}")),
        Err(_) => Err(format!("expected a whole number, found {s:?}")),
    }
}

/// Parses `--threads`: 0 (one per core) to [`MAX_THREADS`].
///
/// # Errors
/// A message for anything else.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    let hi = i64::try_from(MAX_THREADS).unwrap_or(i64::MAX);
    let v = whole_in(s, 0, hi, &format!("0 (one per core) to {MAX_THREADS}"))?;
    usize::try_from(v).map_err(|e| e.to_string())
}

/// Parses `--depth`: 1 to 64.
///
/// # Errors
/// A message for anything else.
pub fn parse_depth(s: &str) -> Result<u32, String> {
    let v = whole_in(s, 1, 64, "1 to 64")?;
    u32::try_from(v).map_err(|e| e.to_string())
}

/// Parses `--min-weight`: a number from 0 to 1.
///
/// # Errors
/// A message for anything else.
pub fn parse_min_weight(s: &str) -> Result<f64, String> {
    let w = s
        .trim()
        .parse::<f64>()
        .map_err(|_| format!("expected a number from 0 to 1, found {s:?}"))?;
    if (0.0..=1.0).contains(&w) {
        Ok(w)
    } else {
        Err(format!("expected a number from 0 to 1, found {w}"))
    }
}

/// Parses `--angle`: degrees strictly between 0 and 180.
///
/// # Errors
/// A message for anything else.
pub fn parse_angle(s: &str) -> Result<f64, String> {
    let a = s
        .trim()
        .parse::<f64>()
        .map_err(|_| format!("expected a number of degrees, found {s:?}"))?;
    if a > 0.0 && a < 180.0 {
        Ok(a)
    } else {
        Err(format!(
            "expected degrees between 0 and 180 (both excluded), found {a}"
        ))
    }
}

/// Parses `X,Y,Z` as a world vector within [`WORLD_LIMIT`].
///
/// # Errors
/// A message naming the bad part.
pub fn parse_vec3(s: &str) -> Result<DVec3, String> {
    let v = super::num::triple(s, |p| {
        p.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.abs() <= WORLD_LIMIT)
            .ok_or_else(|| format!("expected a finite number within ±1e60, found {p:?}"))
    })?;
    Ok(DVec3::from(v))
}

/// View overrides.
#[derive(Debug, Clone, clap::Args)]
pub struct ViewArgs {
    /// Eye position, `X,Y,Z` (overrides the scene's `from`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub from: Option<DVec3>,
    /// Point looked at, `X,Y,Z` (overrides the scene's `at`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub at: Option<DVec3>,
    /// Up direction, `X,Y,Z` (overrides the scene's `up`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<DVec3>,
    /// Vertical field of view in degrees, between 0 and 180 (both
    /// excluded): the angle between the centres of the top and bottom
    /// pixel rows (overrides the scene's `angle`).
    #[arg(long, value_name = "DEGREES", value_parser = parse_angle, allow_hyphen_values = true)]
    pub angle: Option<f64>,
}

impl ViewArgs {
    /// `view` with the overrides applied.
    #[must_use]
    pub fn apply(&self, view: &View) -> View {
        View {
            from: self.from.unwrap_or(view.from),
            at: self.at.unwrap_or(view.at),
            up: self.up.unwrap_or(view.up),
            angle: self.angle.unwrap_or(view.angle),
            ..view.clone()
        }
    }
}

/// A progress bar on stderr when `show` and stderr is a terminal; hidden
/// otherwise. Each phase names itself and its unit ([`crate::progress`]).
#[must_use]
pub fn progress(show: bool) -> ProgressBar {
    if !show || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    ProgressBar::new(0)
}

/// Reads an NFF or TOML scene (the built-in one for `None`): the bytes
/// of an NFF file parsed on `bar`, a spinner while a TOML scene and the
/// files it names are read; a TOML scene whose volumes and vertices
/// would take more than `max_memory` bytes is refused before they are
/// read.
///
/// # Errors
/// The parser's located error.
pub fn read_scene(
    path: Option<&Path>,
    bar: &ProgressBar,
    max_memory: u64,
) -> Result<(Scene, Duration), CliError> {
    let t = Instant::now();
    let scene = match path {
        Some(p)
            if p.extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml")) =>
        {
            crate::progress::spinner(bar, format!("reading {}", p.display()));
            Scene::load_within(p, &ProgressBar::hidden(), max_memory)
        }
        Some(p) => {
            crate::progress::phase(bar, "reading", crate::progress::Unit::Bytes, 0);
            Scene::load_within(p, bar, max_memory)
        }
        None => Scene::parse(DEFAULT_SCENE_NAME, DEFAULT_SCENE.as_bytes()),
    };
    bar.disable_steady_tick();
    Ok((scene?, t.elapsed()))
}

/// The image a build is for, which the default raster is fitted to:
/// the view with its overrides, and the size (the scene's resolution
/// where `None`).
#[derive(Debug, Clone, Copy)]
pub struct ImageNeed<'a> {
    /// View overrides.
    pub view: &'a ViewArgs,
    /// Width in pixels.
    pub width: Option<u32>,
    /// Height in pixels.
    pub height: Option<u32>,
    /// Rays per pixel.
    pub samples: u32,
    /// Bytes of the image the raster is rendered into, counted with the
    /// raster against the memory limit (0: none, or not yet known).
    pub memory: u64,
}

/// Where a render's scene comes from.
#[derive(Debug)]
pub enum Loaded {
    /// Voxelized now from a scene file.
    Built {
        /// The voxelized scene.
        scene: VoxelScene,
        /// What the build did.
        report: BuildReport,
        /// Parse time.
        parse: Duration,
    },
    /// Read from a saved raster.
    Saved {
        /// The voxelized scene.
        scene: VoxelScene,
        /// Load time.
        load: Duration,
    },
}

/// Loads `path` as a saved raster when it starts with the raster magic,
/// else parses and voxelizes it as an NFF or TOML scene (the built-in
/// scene for `None`); the loading or the voxelizing runs on `threads`
/// threads (0: one per core). `check_view` sees the scene's view before
/// any voxelizing (a bad view is refused before the long work) and
/// returns the bytes of the image to be rendered, which count with the
/// raster against `--max-memory`.
///
/// # Errors
/// The parser's, builder's or raster file's error; `--raster` or
/// `--bounds` given for a saved raster; `--bounds` that hold none of the
/// scene's geometry; `check_view`'s error; a raster and image that
/// together need more than the memory limit.
pub fn load_or_build(
    path: Option<&PathBuf>,
    raster: &RasterArgs,
    purpose: Purpose,
    image: &ImageNeed<'_>,
    threads: usize,
    show_progress: bool,
    check_view: &dyn Fn(&View) -> Result<u64, CliError>,
) -> Result<Loaded, CliError> {
    if let Some(p) = path
        && rasterfile::names_raster(p)
    {
        for (given, arg) in [
            (raster.raster.is_some(), "--raster"),
            (raster.bounds.is_some(), "--bounds"),
        ] {
            if given {
                return Err(CliError::Arg {
                    arg,
                    message: format!(
                        "{} is a saved raster; its resolution and bounds were fixed by `rrt voxelize`",
                        p.display()
                    ),
                });
            }
        }
        let t = Instant::now();
        let bar = progress(show_progress);
        crate::progress::phase(&bar, "loading", crate::progress::Unit::Bytes, 0);
        let limit = raster.max_memory.unwrap_or_else(default_max_memory);
        // On `threads` threads, as a build would be.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|source| CliError::Threads { threads, source })?;
        let scene = pool.install(|| rasterfile::load_within(p, &bar, limit));
        bar.finish_and_clear();
        let scene = scene?;
        let image = check_view(&scene.view)?;
        if scene.memory().saturating_add(image) > limit {
            return Err(CliError::Arg {
                arg: "--max-memory",
                message: format!(
                    "{}: the raster takes {} once loaded and the image {}, together more than the limit of {}",
                    p.display(),
                    Bytes(scene.memory()),
                    Bytes(image),
                    Bytes(limit)
                ),
            });
        }
        return Ok(Loaded::Saved {
            scene,
            load: t.elapsed(),
        });
    }
    let bar = progress(show_progress);
    let limit = raster.max_memory.unwrap_or_else(default_max_memory);
    let (scene, parse) = match read_scene(path.map(PathBuf::as_path), &bar, limit) {
        Ok(r) => r,
        Err(e) => {
            bar.finish_and_clear();
            return Err(e);
        }
    };
    let built = check_view(&scene.view).and_then(|memory| {
        let image = ImageNeed { memory, ..*image };
        build_scene(&scene, raster, purpose, &image, threads, &bar)
    });
    bar.finish_and_clear();
    let (vs, report) = built?;
    Ok(Loaded::Built {
        scene: vs,
        report,
        parse,
    })
}

/// Voxelizes a scene already in memory as `rrt render` and `rrt
/// voxelize` voxelize a scene file: `raster`'s options for `purpose`,
/// the raster fitted to `image` unless `--raster` is given, on `threads`
/// threads (0: one per core), with `bar` for the phases.
///
/// # Errors
/// `--bounds` that hold none of the scene's geometry; a volume rendered
/// directly in a raster to be saved; the builder's error.
pub fn build_scene(
    scene: &Scene,
    raster: &RasterArgs,
    purpose: Purpose,
    image: &ImageNeed<'_>,
    threads: usize,
    bar: &ProgressBar,
) -> Result<(VoxelScene, BuildReport), CliError> {
    check_bounds(scene, raster)?;
    // A saved raster cannot hold a volume rendered directly: said before
    // voxelizing.
    if purpose == Purpose::Save
        && let Some(v) = scene.volumes.iter().find(|v| v.data.classifier.is_direct())
    {
        return Err(CliError::Arg {
            arg: "SCENE",
            message: format!(
                "{}: a volume rendered directly (render = \"direct\") cannot be saved in a raster file; render the scene itself, or give the volume render = \"iso\"",
                v.loc
            ),
        });
    }
    let view = image.view.apply(&scene.view);
    let need = RasterNeed {
        view: &view,
        image: [
            image.width.unwrap_or(view.resolution[0]),
            image.height.unwrap_or(view.resolution[1]),
        ],
        samples: image.samples,
        discrete: raster.discrete(),
    };
    let mut opts = raster.build_options(purpose, default_raster(scene, &need));
    opts.threads = threads;
    opts.fit.image = image.memory;
    build(scene, &opts, bar).map_err(|e| {
        use crate::voxelize::BuildError;
        let beyond_fixed_point = matches!(
            e,
            BuildError::Fit(crate::fit::FitError::OutOfRange { .. }) | BuildError::Voxelize { .. }
        );
        match raster.bounds {
            // Objects that reach far outside a small box are out of its
            // raster's reach: the box is the cause.
            Some(b) if beyond_fixed_point => CliError::Arg {
                arg: "--bounds",
                message: format!(
                    "{e}: the box [{:?}, {:?}, {:?}] to [{:?}, {:?}, {:?}] is too small for the objects that reach outside it; give a larger box or a smaller --raster",
                    b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
                ),
            },
            _ => e.into(),
        }
    })
}

/// Refuses `--bounds` that do not meet the box around the scene's
/// geometry, before the raster is sized (the builder refuses bounds that
/// meet the box but hold no surface voxel).
fn check_bounds(scene: &Scene, raster: &RasterArgs) -> Result<(), CliError> {
    let Some(bounds) = raster.bounds else {
        return Ok(());
    };
    let all = scene.bounds();
    let meets = all.min.cmple(bounds.max).all() && bounds.min.cmple(all.max).all();
    if meets {
        return Ok(());
    }
    Err(crate::voxelize::BuildError::EmptyBounds {
        file: scene.file.to_string(),
        bounds,
    }
    .into())
}

/// Seconds with three decimals.
#[must_use]
pub fn secs(d: Duration) -> String {
    format!("{:.3} s", d.as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_sizes() {
        assert_eq!(parse_memory("1024"), Ok(1024));
        assert_eq!(parse_memory("8G"), Ok(8 << 30));
        assert_eq!(parse_memory("512MiB"), Ok(512 << 20));
        assert_eq!(parse_memory("3kB"), Ok(3 << 10));
        assert!(parse_memory("0").is_err());
        assert!(parse_memory("lots").is_err());
        assert!(parse_memory("99999999999T").is_err());
    }

    #[test]
    fn bounds_need_six_ordered_numbers() {
        let b = parse_bounds("-1,-2,-3,1,2,3").unwrap();
        assert_eq!(b.min, DVec3::new(-1.0, -2.0, -3.0));
        assert!(parse_bounds("1,2,3").is_err());
        assert!(parse_bounds("0,0,0,1,1,0").is_err());
        assert!(parse_bounds("0,0,0,1,1,nan").is_err());
    }

    #[test]
    fn counts_and_angles_in_range() {
        assert_eq!(parse_threads("0"), Ok(0));
        assert_eq!(parse_threads(" 8 "), Ok(8));
        assert!(
            parse_threads("-1")
                .unwrap_err()
                .contains("0 (one per core) to 1024")
        );
        assert!(parse_threads("100000").is_err());
        assert!(parse_threads("two").unwrap_err().contains("whole number"));
        assert_eq!(parse_depth("64"), Ok(64));
        assert_eq!(parse_min_weight("0"), Ok(0.0));
        assert_eq!(parse_min_weight(" 1e-3"), Ok(1e-3));
        assert_eq!(parse_min_weight("1"), Ok(1.0));
        for bad in ["-0.5", "1.5", "nan", "inf", "", "x"] {
            assert!(
                parse_min_weight(bad).unwrap_err().contains("from 0 to 1"),
                "{bad}"
            );
        }
        assert!(parse_depth("0").unwrap_err().contains("1 to 64, found 0"));
        assert!(parse_depth("-3").is_err());
        assert_eq!(parse_angle("40"), Ok(40.0));
        for bad in ["0", "180", "-5", "nan", "inf", "wide"] {
            assert!(parse_angle(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn builtin_scene_parses() {
        let (s, _) = read_scene(None, &ProgressBar::hidden(), u64::MAX).unwrap();
        assert_eq!(s.spheres.len(), 91);
        assert_eq!(&*s.file, DEFAULT_SCENE_NAME);
    }
}
