//! A voxelized scene rendered from a view to a numpy array.

use indicatif::ProgressBar;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use rrt_host::cli::common::RasterArgs;
use rrt_host::output::encoding::{Codes, Encoding, SampleKind, Samples, rgba};
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
            min_weight: a.min_weight,
            ..TraceOptions::default()
        },
    )?;
    let opts = RenderOptions {
        supersample: a.supersample,
        threads: a.threads,
        alpha: a.alpha,
    };
    let (image, _, _) = render(&tracer, &camera, &opts, &ProgressBar::hidden())?;
    Ok(image)
}

/// The image as an `(H, W, 3)` array: the 8-bit sRGB codes of the PNG
/// `rrt render` writes, or with `a.float` the linear `float32` values of
/// its OpenEXR output; with `a.alpha` an `(H, W, 4)` array of the straight
/// colour and the coverage ([`rgba`]).
pub fn to_numpy<'py>(py: Python<'py>, image: Image, a: &RenderArgs) -> PyResult<Bound<'py, PyAny>> {
    let kind = if a.float {
        SampleKind::Float
    } else {
        SampleKind::Codes(Encoding::default())
    };
    let (channels, samples) = if a.alpha {
        let samples = rgba(&image, kind).ok_or_else(|| {
            pyo3::exceptions::PyRuntimeError::new_err("the image was rendered without alpha")
        })?;
        (4, samples)
    } else if a.float {
        (3, Samples::Float(image.linear.into()))
    } else {
        (3, Samples::of(&image, kind))
    };
    let shape = [image.height as usize, image.width as usize, channels];
    match samples {
        Samples::Float(v) => Ok(PyArray1::from_vec(py, v.into_owned())
            .reshape(shape)?
            .into_any()),
        Samples::Codes(Codes::Eight(bytes)) => {
            Ok(PyArray1::from_vec(py, bytes).reshape(shape)?.into_any())
        }
        Samples::Codes(Codes::Sixteen(_)) => Err(pyo3::exceptions::PyRuntimeError::new_err(
            "8-bit encoding gave 16-bit codes",
        )),
    }
}
