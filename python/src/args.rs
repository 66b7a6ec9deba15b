//! The keyword arguments the render calls share, checked as the command
//! line checks its options.

use clap::ValueEnum;
use rrt_host::cli::common::{MAX_RASTER, MAX_THREADS, MIN_RASTER, ModeArg, RasterArgs};
use rrt_host::cli::ray::ConnectivityArg;

use crate::errors::Error;

/// A whole number in `lo..=hi` for argument `arg`.
pub fn whole(arg: &str, v: i64, lo: i64, hi: i64) -> Result<u32, Error> {
    if (lo..=hi).contains(&v) {
        u32::try_from(v).map_err(|_| Error::arg(arg, format!("{v} is too large")))
    } else {
        Err(Error::arg(arg, format!("expected {lo} to {hi}, found {v}")))
    }
}

/// A value of a `clap` enum by its command-line name (`"exact"`,
/// `"twenty-six"`).
fn named<T: ValueEnum>(arg: &str, s: &str) -> Result<T, Error> {
    T::from_str(s, false).map_err(|_| {
        let names: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        Error::arg(
            arg,
            format!("expected one of {}, found {s:?}", names.join(", ")),
        )
    })
}

/// How to voxelize: `raster=`, `mode=`, `connectivity=`.
pub fn raster_args(
    raster: Option<i64>,
    mode: &str,
    connectivity: &str,
) -> Result<RasterArgs, Error> {
    Ok(RasterArgs {
        raster: raster
            .map(|r| whole("raster", r, MIN_RASTER, MAX_RASTER))
            .transpose()?,
        connectivity: named::<ConnectivityArg>("connectivity", connectivity)?,
        mode: named::<ModeArg>("mode", mode)?,
        bounds: None,
        max_memory: None,
    })
}

/// How to render: the image size, rays, threads and the values returned.
#[derive(Debug, Clone, Copy)]
pub struct RenderArgs {
    /// Width, or the view's.
    pub width: Option<u32>,
    /// Height, or the view's.
    pub height: Option<u32>,
    /// K×K rays per pixel.
    pub supersample: u32,
    /// Depth of the ray tree.
    pub depth: u32,
    /// The least weight of a traced reflected or refracted ray
    /// (`--min-weight`).
    pub min_weight: f64,
    /// Threads, 0 for one per core.
    pub threads: usize,
    /// Frame `k` of an `n`-frame orbit of the view (`k` taken modulo `n`).
    pub frame: Option<(u64, u64)>,
    /// Linear `float32` values instead of 8-bit sRGB codes.
    pub float: bool,
    /// A fourth channel, the coverage, with the colour in straight alpha.
    pub alpha: bool,
}

impl RenderArgs {
    /// Checks the arguments.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        width: Option<i64>,
        height: Option<i64>,
        supersample: i64,
        depth: i64,
        threads: i64,
        frame: Option<(i64, i64)>,
        float: bool,
        alpha: bool,
    ) -> Result<Self, Error> {
        let side = i64::from(rrt_host::render::MAX_SIDE);
        let max_threads = i64::try_from(MAX_THREADS).unwrap_or(i64::MAX);
        let frame = match frame {
            None => None,
            Some((k, n)) if n >= 1 && k >= 0 => Some((k.unsigned_abs(), n.unsigned_abs())),
            Some((k, n)) => {
                return Err(Error::arg(
                    "frame",
                    format!("expected (k, n) with k ≥ 0 and n ≥ 1, found ({k}, {n})"),
                ));
            }
        };
        Ok(Self {
            width: width.map(|w| whole("width", w, 1, side)).transpose()?,
            height: height.map(|h| whole("height", h, 1, side)).transpose()?,
            supersample: whole(
                "supersample",
                supersample,
                1,
                i64::from(rrt_host::render::MAX_SUPERSAMPLE),
            )?,
            depth: whole("depth", depth, 1, 64)?,
            min_weight: rrt_host::trace::DEFAULT_MIN_WEIGHT,
            threads: whole("threads", threads, 0, max_threads)? as usize,
            frame,
            float,
            alpha,
        })
    }

    /// With `min_weight`, checked as `--min-weight` is: 0 to 1.
    pub fn with_min_weight(self, min_weight: f64) -> Result<Self, Error> {
        let min_weight = rrt_host::cli::common::parse_min_weight(&min_weight.to_string())
            .map_err(|m| Error::arg("min_weight", m))?;
        Ok(Self { min_weight, ..self })
    }
}
