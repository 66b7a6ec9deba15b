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
    /// Raster dimensions in voxels, `NX,NY,NZ` (each 1..=65536).
    #[arg(long, value_name = "NX,NY,NZ", value_parser = parse_dims)]
    pub dims: [u32; 3],
    /// Ray origin in voxel units (voxel i spans [i, i+1)); decimals allowed.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_origin, allow_hyphen_values = true)]
    pub origin: [i64; 3],
    /// Ray direction in voxel units per unit of the ray parameter; decimals allowed.
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
    /// 26-connected: one voxel per slice across the driving axis.
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
    triple(s, |p| {
        let v = decimal_to_fixed(p)?;
        i32::try_from(v).map_err(|_| {
            format!(
                "{p} does not fit the fixed-point direction (|d| < {} voxels)",
                1i64 << (31 - FRAC_BITS)
            )
        })
    })
}

/// Runs `rrt ray`, writing its report to `out`.
///
/// # Errors
/// [`CliError`] for a bad raster or an output error.
pub fn run(args: &RayArgs, out: &mut impl Write) -> Result<(), CliError> {
    let [nx, ny, nz] = args.dims;
    let extent = Extent::new(nx, ny, nz).map_err(|e| CliError::Arg {
        arg: "--dims",
        message: e.to_string(),
    })?;
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
    let Some(ray) = ray else {
        writeln!(out, "miss")?;
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
