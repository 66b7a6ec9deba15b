//! `rrt ray`: trace one discrete ray and list its voxels.

use std::io::Write;

use rrt_core::discrete_ray::{Connectivity, DiscreteRay};
use rrt_core::fixed::FRAC_BITS;
use rrt_core::raster::Extent;

use super::CliError;
use super::num::{decimal_to_fixed, triple};

/// Arguments of `rrt ray`.
#[derive(Debug, Clone, clap::Args)]
pub struct RayArgs {
    /// Raster dimensions in voxels, `NX,NY,NZ` (each 1..=65536), for a ray
    /// through an empty raster; one of --dims and --raster is needed.
    #[arg(long, value_name = "NX,NY,NZ", value_parser = parse_dims, conflicts_with = "raster")]
    pub dims: Option<[u32; 3]>,
    /// A raster saved by `rrt voxelize` (instead of --dims): walk the ray
    /// through its scene
    /// (origin and direction in its voxel units), report each hit voxel,
    /// its object id and whether intersection verification accepts it.
    #[arg(long, value_name = "FILE.rrt")]
    pub raster: Option<std::path::PathBuf>,
    /// Ray origin in voxel units (voxel i spans [i, i+1)); decimals allowed.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_origin, allow_hyphen_values = true)]
    pub origin: [i64; 3],
    /// Ray direction in voxel units per unit of the ray parameter, not
    /// zero; decimals allowed.
    #[arg(long, value_name = "DX,DY,DZ", value_parser = parse_dir, allow_hyphen_values = true)]
    pub dir: [i32; 3],
    /// Connectivity of the discrete ray.
    #[arg(long, value_enum, default_value_t = ConnectivityArg::Adaptive)]
    pub connectivity: ConnectivityArg,
}

/// The `--connectivity` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ConnectivityArg {
    /// 6-connected: every voxel the ray passes through.
    Six,
    /// 26-connected: one voxel per slice across the driving axis (renders
    /// in the paper's mode only: it steps diagonally past voxels the ray
    /// passes through).
    TwentySix,
    /// 26-steps in empty space, 6-steps near surfaces.
    Adaptive,
}

impl From<ConnectivityArg> for Connectivity {
    fn from(c: ConnectivityArg) -> Self {
        match c {
            ConnectivityArg::Six => Self::Six,
            ConnectivityArg::TwentySix => Self::TwentySix,
            ConnectivityArg::Adaptive => Self::Adaptive,
        }
    }
}

fn parse_dims(s: &str) -> Result<[u32; 3], String> {
    let d = triple(s, |p| {
        p.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected a whole number of voxels, found {p:?}"))
    })?;
    Extent::new(d[0], d[1], d[2]).map_err(|e| e.to_string())?;
    Ok(d)
}

fn parse_origin(s: &str) -> Result<[i64; 3], String> {
    let limit = i128::from(rrt_core::discrete_ray::ORIGIN_LIMIT);
    triple(s, |p| {
        let v = decimal_to_fixed(p)?;
        if v.abs() > limit {
            return Err(format!(
                "{p} is outside the accepted range of ±{} voxels",
                limit >> FRAC_BITS
            ));
        }
        i64::try_from(v).map_err(|_| format!("{p} out of range"))
    })
}

fn parse_dir(s: &str) -> Result<[i32; 3], String> {
    let d = triple(s, |p| {
        let v = decimal_to_fixed(p)?;
        i32::try_from(v).map_err(|_| {
            format!(
                "{p} does not fit the fixed-point direction (|d| < {} voxels)",
                1i64 << (31 - FRAC_BITS)
            )
        })
    })?;
    if d == [0; 3] {
        return Err(format!(
            "{s:?} is zero (or rounds to zero in fixed point, 1/{} voxel): a ray needs a direction",
            1u32 << FRAC_BITS
        ));
    }
    Ok(d)
}

/// Runs `rrt ray`, writing its report to `out`.
///
/// # Errors
/// [`CliError`] for a bad raster or an output error.
pub fn run(args: &RayArgs, out: &mut impl Write) -> Result<(), CliError> {
    if let Some(path) = &args.raster {
        return run_saved(args, path, out);
    }
    let Some([nx, ny, nz]) = args.dims else {
        return Err(CliError::Arg {
            arg: "--dims",
            message: "give --dims NX,NY,NZ for a ray through an empty raster, or --raster FILE.rrt for one through a saved raster".into(),
        });
    };
    let extent = Extent::new(nx, ny, nz).map_err(|e| CliError::Arg {
        arg: "--dims",
        message: e.to_string(),
    })?;
    let Some(ray) = start(args, extent, out)? else {
        return Ok(());
    };
    // Without a saved raster the voxels are empty: list the path.
    for v in ray.path(args.connectivity.into()) {
        let [x, y, z] = extent.coord(v.index).unwrap_or_default();
        writeln!(out, "{x} {y} {z}")?;
    }
    writeln!(out, "miss")?;
    Ok(())
}

/// The report's first line (the ray in fixed point) and the ray through
/// `extent`; `None`, reported as `miss`, when it misses the raster.
fn start(
    args: &RayArgs,
    extent: Extent,
    out: &mut impl Write,
) -> Result<Option<DiscreteRay>, CliError> {
    let [ox, oy, oz] = args.origin;
    let [dx, dy, dz] = args.dir;
    writeln!(
        out,
        "origin_fx={ox},{oy},{oz} dir_fx={dx},{dy},{dz} frac_bits={FRAC_BITS} voxel=corner"
    )?;
    let ray = DiscreteRay::new(extent, args.origin, args.dir).map_err(|e| CliError::Arg {
        arg: "--origin",
        message: e.to_string(),
    })?;
    if ray.is_none() {
        writeln!(out, "miss")?;
    }
    Ok(ray)
}

/// `rrt ray --raster FILE.rrt`: the voxels up to each hit, then
/// `hit X Y Z object ID verify accepted`, or `verify rejected: false hit`
/// (the continuous ray misses the object), or `verify rejected:
/// intersection farther on`; after a rejection the walk resumes, as the
/// renderer's does; `miss` if the ray leaves the raster without an
/// accepted hit. Only the voxel's owner is verified here, in the voxel's
/// neighbourhood (the renderer tests every object of the voxel's list and
/// accepts the nearest intersection the walk has reached).
fn run_saved(args: &RayArgs, path: &std::path::Path, out: &mut impl Write) -> Result<(), CliError> {
    use rrt_core::raster::cell;
    let scene = crate::output::rasterfile::load(path)?;
    let mode: Connectivity = args.connectivity.into();
    if mode == Connectivity::TwentySix
        && scene.separation != rrt_core::voxelize::Separation::TwentySix
    {
        return Err(crate::trace::TraceError::Separation.into());
    }
    let extent = scene.extent();
    let Some(ray) = start(args, extent, out)? else {
        return Ok(());
    };
    let raster = scene
        .raster()
        .map_err(|e| crate::trace::TraceError::Raster(e.to_string()))?;
    let store = scene
        .store()
        .map_err(|e| crate::trace::TraceError::Raster(e.to_string()))?;
    // The continuous ray in the world, for verification.
    let one = f64::from(1u32 << FRAC_BITS);
    let o = glam::DVec3::from(args.origin.map(|v| v as f64 / one));
    let d = glam::DVec3::from(args.dir.map(|v| f64::from(v) / one));
    let world = crate::world::Ray::new(
        scene.frame.raster_to_world(o),
        d.normalize_or(glam::DVec3::X),
    );
    for v in ray.voxels(&raster, mode).map_err(|e| CliError::Arg {
        arg: "--raster",
        message: e.to_string(),
    })? {
        let [x, y, z] = extent.coord(v.index).unwrap_or_default();
        writeln!(out, "{x} {y} {z}")?;
        if v.cell & cell::OPAQUE == 0 {
            continue;
        }
        let Some(rec) = store.get(v.index) else {
            continue;
        };
        let owner = store.owner(rec);
        let verdict = scene
            .objects
            .get(owner as usize)
            .map_or(crate::trace::Verdict::False, |obj| {
                crate::trace::verify(&scene.frame, obj, &world, [x, y, z], 0.0)
            });
        let what = match verdict {
            crate::trace::Verdict::Hit(_) => "accepted",
            crate::trace::Verdict::Ahead => "rejected: intersection farther on",
            crate::trace::Verdict::False => "rejected: false hit",
        };
        writeln!(out, "hit {x} {y} {z} object {owner} verify {what}")?;
        if matches!(verdict, crate::trace::Verdict::Hit(_)) {
            return Ok(());
        }
    }
    writeln!(out, "miss")?;
    Ok(())
}
