//! A voxelized scene rendered from a view to a numpy array.

use indicatif::ProgressBar;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use rrt_host::cli::common::RasterArgs;
use rrt_host::output::encoding::{Codes, Encoding, codes};
use rrt_host::render::camera::Camera;
use rrt_host::render::{Image, RenderOptions, check_sizes, render};
use rrt_host::scene::View;
use rrt_host::trace::{TraceOptions, Tracer};
use rrt_host::voxelize::VoxelScene;

use crate::args::RenderArgs;
use crate::errors::Error;

/// Renders `scene` from `view` (frame `a.frame` of its orbit, at
/// `a.width × a.height` or the view's resolution) in the mode and with the
/// connectivity of `raster`, as `rrt render` does.
pub fn render_view(
    scene: &VoxelScene,
    view: &View,
    raster: &RasterArgs,
    a: &RenderArgs,
) -> Result<Image, Error> {
    let view = crate::view::View::framed(view, a.frame);
    let [rw, rh] = view.resolution;
    let (w, h) = (a.width.unwrap_or(rw), a.height.unwrap_or(rh));
    check_sizes(w, h, a.supersample)?;
    let camera = Camera::new(&view, w, h)?;
    let tracer = Tracer::new(
        scene,
        TraceOptions {
            mode: raster.mode.into(),
            connectivity: raster.connectivity.into(),
            depth: a.depth,
            ..TraceOptions::default()
        },
    )?;
    let opts = RenderOptions {
        supersample: a.supersample,
        threads: a.threads,
    };
    let (image, _, _) = render(&tracer, &camera, &opts, &ProgressBar::hidden())?;
    Ok(image)
}

/// The image as an `(H, W, 3)` array: the 8-bit sRGB codes of the PNG
/// `rrt render` writes, or with `float` the linear `float32` values of
/// its OpenEXR output.
pub fn to_numpy<'py>(py: Python<'py>, image: Image, float: bool) -> PyResult<Bound<'py, PyAny>> {
    let shape = [image.height as usize, image.width as usize, 3];
    if float {
        return Ok(PyArray1::from_vec(py, image.linear)
            .reshape(shape)?
            .into_any());
    }
    let Codes::Eight(bytes) = codes(&image, Encoding::default()) else {
        return Err(pyo3::exceptions::PyRuntimeError::new_err(
            "8-bit encoding gave 16-bit codes",
        ));
    };
    Ok(PyArray1::from_vec(py, bytes).reshape(shape)?.into_any())
}
