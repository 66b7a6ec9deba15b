//! Scenes and saved rasters: `rrt.render`, `rrt.voxelize`, `rrt.load` and
//! `rrt.Raster`.

use std::path::PathBuf;
use std::sync::Arc;

use pyo3::prelude::*;
use rrt_host::cli::common::{ImageNeed, Loaded, Purpose, ViewArgs, load_or_build};
use rrt_host::cli::voxelize::VoxelizeArgs;
use rrt_host::output::rasterfile;
use rrt_host::render::camera::Camera;
use rrt_host::voxelize::VoxelScene;

use crate::args::{RenderArgs, raster_args};
use crate::errors::Error;
use crate::image::{render_view, to_numpy};
use crate::view::View;

/// A voxelized scene, everything but the view: read from a saved raster
/// (`rrt.load`), saved by `rrt.voxelize`, or built from an array
/// (`rrt.volume`). Render it from any view with `Raster.render`; the
/// image does not depend on the thread count.
#[pyclass(frozen, module = "rrt")]
pub struct Raster {
    pub scene: Arc<VoxelScene>,
}

#[pymethods]
impl Raster {
    /// The view the scene was voxelized with.
    #[getter]
    fn view(&self) -> View {
        View {
            inner: self.scene.view.clone(),
        }
    }

    /// Voxels along x, y and z.
    #[getter]
    fn dims(&self) -> (u32, u32, u32) {
        let d = self.scene.extent().dims();
        (d[0], d[1], d[2])
    }

    /// Whether the raster is exact (it renders in every mode) rather than
    /// the paper's (it renders in `mode="paper"` only).
    #[getter]
    fn exact(&self) -> bool {
        self.scene.exact
    }

    /// Renders the raster from `view` (default: its own), or from frame
    /// `k` of the `n`-frame orbit of that view with `frame=(k, n)`, as
    /// `rrt render FILE.rrt` does: an `(H, W, 3)` array of the PNG's 8-bit
    /// sRGB codes, or with `float=True` the linear `float32` values; with
    /// `alpha=True` an `(H, W, 4)` array, the coverage in the fourth
    /// channel and the colour in straight alpha (as `rrt.render`).
    #[pyo3(signature = (view = None, *, frame = None, width = None, height = None, supersample = 1, depth = 3, min_weight = rrt_host::trace::DEFAULT_MIN_WEIGHT, threads = 0, mode = "exact", connectivity = "adaptive", float = false, alpha = false))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        view: Option<PyRef<'py, View>>,
        frame: Option<(i64, i64)>,
        width: Option<i64>,
        height: Option<i64>,
        supersample: i64,
        depth: i64,
        min_weight: f64,
        threads: i64,
        mode: &str,
        connectivity: &str,
        float: bool,
        alpha: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let a = RenderArgs::new(
            width,
            height,
            supersample,
            depth,
            threads,
            frame,
            float,
            alpha,
        )?
        .with_min_weight(min_weight)?;
        let raster = raster_args(None, mode, connectivity)?;
        let view = view.map_or_else(|| self.scene.view.clone(), |v| v.inner.clone());
        let scene = Arc::clone(&self.scene);
        let image = py.detach(move || render_view(&scene, &view, &raster, &a))?;
        to_numpy(py, image, &a)
    }

    /// Saves the raster to `path` (a name ending in `.rrt`), as `rrt
    /// voxelize` writes it: through a temporary file renamed over `path`.
    /// Returns the file's length in bytes.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<u64> {
        if !path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("rrt"))
        {
            return Err(Error::arg(
                "path",
                format!(
                    "{}: a saved raster is written to a file whose name ends in .rrt",
                    path.display()
                ),
            )
            .into());
        }
        let scene = Arc::clone(&self.scene);
        Ok(py.detach(move || rasterfile::save(&scene, &path).map_err(Error::from))?)
    }

    fn __repr__(&self) -> String {
        let (x, y, z) = self.dims();
        format!(
            "<rrt.Raster {x}×{y}×{z}, {}>",
            if self.scene.exact { "exact" } else { "paper" }
        )
    }
}

/// The view overrides of a `View` given for a scene.
fn view_args(view: Option<&View>) -> ViewArgs {
    let v = view.map(|v| &v.inner);
    ViewArgs {
        from: v.map(|v| v.from),
        at: v.map(|v| v.at),
        up: v.map(|v| v.up),
        angle: v.map(|v| v.angle),
    }
}

/// Renders an NFF or TOML scene or a saved raster (`None`: the built-in
/// 91-sphereflake) as `rrt render` does, with the same defaults: an
/// `(H, W, 3)` array of the PNG's 8-bit sRGB codes, or with `float=True`
/// the linear `float32` values of its OpenEXR output.
///
/// `alpha=True` adds a fourth channel, `(H, W, 4)`: each pixel's coverage,
/// 1 − the transmittance of its rays to the background (0 where they all
/// see the background, 1 where they all end on a surface or in a volume
/// opaque enough to end them, the opacity composited through volumes
/// rendered directly in between, averaged over the supersamples), as a
/// linear code 0–255 (or a float in [0, 1]). The colour is then straight
/// (not premultiplied), as PNG's RGBA keeps it: the pixel's colour without
/// the background divided by the coverage, the background's colour where
/// the coverage is 0. Over the scene's background,
/// `rgb · a + background · (1 − a)` (in linear values) is the 3-channel
/// image; where the coverage is 0 or 1 the colour channels equal it.
///
/// `view` replaces the scene's camera (its resolution is the default
/// size), `frame=(k, n)` renders frame `k` of the `n`-frame orbit of the
/// view, `raster` is `--raster`, `min_weight` `--min-weight`, `mode` is
/// `"exact"`, `"verified"` or `"paper"`, `connectivity` `"adaptive"`,
/// `"six"` or `"twenty-six"` (with `mode="paper"` only).
#[pyfunction]
#[pyo3(signature = (scene = None, *, view = None, frame = None, width = None, height = None, supersample = 1, depth = 3, min_weight = rrt_host::trace::DEFAULT_MIN_WEIGHT, threads = 0, mode = "exact", connectivity = "adaptive", raster = None, float = false, alpha = false))]
#[allow(clippy::too_many_arguments)]
pub fn render<'py>(
    py: Python<'py>,
    scene: Option<PathBuf>,
    view: Option<PyRef<'py, View>>,
    frame: Option<(i64, i64)>,
    width: Option<i64>,
    height: Option<i64>,
    supersample: i64,
    depth: i64,
    min_weight: f64,
    threads: i64,
    mode: &str,
    connectivity: &str,
    raster: Option<i64>,
    float: bool,
    alpha: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let mut a = RenderArgs::new(
        width,
        height,
        supersample,
        depth,
        threads,
        frame,
        float,
        alpha,
    )?
    .with_min_weight(min_weight)?;
    let raster = raster_args(raster, mode, connectivity)?;
    let given = view.as_deref().map(|v| v.inner.clone());
    if let Some(v) = &given {
        a.width = a.width.or(Some(v.resolution[0]));
        a.height = a.height.or(Some(v.resolution[1]));
    }
    let overrides = view_args(view.as_deref());
    let image = py.detach(move || {
        let size = |v: &rrt_host::scene::View| {
            (
                a.width.unwrap_or(v.resolution[0]),
                a.height.unwrap_or(v.resolution[1]),
            )
        };
        let check_view = |v: &rrt_host::scene::View| {
            let v = overrides.apply(v);
            let (w, h) = size(&v);
            // The Python caller holds the image; it is not counted here.
            Camera::new(&v, w, h).map(|_| 0).map_err(Into::into)
        };
        let loaded = load_or_build(
            scene.as_ref(),
            &raster,
            Purpose::Render,
            &ImageNeed {
                view: &overrides,
                width: a.width,
                height: a.height,
                samples: a.supersample,
                memory: 0,
            },
            a.threads,
            false,
            &check_view,
        )?;
        let (Loaded::Built { scene, .. } | Loaded::Saved { scene, .. }) = &loaded;
        render_view(scene, &overrides.apply(&scene.view), &raster, &a)
    })?;
    to_numpy(py, image, &a)
}

/// Voxelizes an NFF or TOML scene (`None`: the built-in one) and saves
/// the raster to `output` (a name ending in `.rrt`), as `rrt voxelize`
/// does; returns it as a `Raster`. `raster`, `mode` and `connectivity` as
/// for `render`; the file does not depend on `threads`.
#[pyfunction]
#[pyo3(signature = (scene, output, *, raster = None, mode = "exact", connectivity = "adaptive", threads = 0))]
pub fn voxelize(
    py: Python<'_>,
    scene: Option<PathBuf>,
    output: PathBuf,
    raster: Option<i64>,
    mode: &str,
    connectivity: &str,
    threads: i64,
) -> PyResult<Raster> {
    let args = VoxelizeArgs {
        scene,
        output,
        raster: raster_args(raster, mode, connectivity)?,
        threads: crate::args::whole(
            "threads",
            threads,
            0,
            i64::try_from(rrt_host::cli::common::MAX_THREADS).unwrap_or(i64::MAX),
        )? as usize,
        quiet: true,
        uncompressed: false,
        dense: false,
    };
    let scene = py.detach(move || -> Result<VoxelScene, Error> {
        rrt_host::cli::voxelize::run(&args, &mut std::io::sink())?;
        Ok(rasterfile::load(&args.output)?)
    })?;
    Ok(Raster {
        scene: Arc::new(scene),
    })
}

/// Reads a raster saved by `rrt voxelize`, `rrt.voxelize` or
/// `Raster.save`, after checking its sections' checksums.
#[pyfunction]
pub fn load(py: Python<'_>, path: PathBuf) -> PyResult<Raster> {
    let scene = py.detach(move || rasterfile::load(&path).map_err(Error::from))?;
    Ok(Raster {
        scene: Arc::new(scene),
    })
}
