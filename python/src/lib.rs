//! `rrt` for Python: scenes, saved rasters and numpy volumes rendered to
//! numpy images through `rrt-host`, with the GIL released while rrt works.
//!
//! * `rrt.render(scene, ...)`: an NFF or TOML scene or a saved raster, as
//!   `rrt render` renders it (the same pixels as its PNG, or the linear
//!   values of its OpenEXR output with `float=True`; with `alpha=True` a
//!   fourth channel, each pixel's coverage, and the colour in straight
//!   alpha).
//! * `rrt.render_volume(array, ...)`: a 3D numpy array as a volume,
//!   classified by a transfer function (the TOML `iso`, `opacity` and
//!   `colours` keys), framed by a default camera.
//! * `rrt.voxelize(scene, output)` saves a raster as `rrt voxelize` does;
//!   `rrt.load(path)` reads one; `Raster.render(view=..., frame=(k, n))`
//!   renders it from any view, or frame `k` of an `n`-frame orbit.
//! * `rrt.View`: a camera (`from_`, `at`, `up`, `angle`, `resolution`);
//!   `View.orbit(k, n)` is the host's orbit.
//!
//! Bad arguments raise `ValueError` naming the argument; errors of scenes,
//! rasters and files raise `rrt.RrtError`, with the messages of the `rrt`
//! command line.

mod args;
mod errors;
mod image;
mod raster;
mod view;
mod volume;

use pyo3::prelude::*;

/// The Python module `rrt`.
#[pymodule]
fn rrt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("RrtError", m.py().get_type::<errors::RrtError>())?;
    m.add_class::<view::View>()?;
    m.add_class::<raster::Raster>()?;
    m.add_function(wrap_pyfunction!(raster::render, m)?)?;
    m.add_function(wrap_pyfunction!(raster::voxelize, m)?)?;
    m.add_function(wrap_pyfunction!(raster::load, m)?)?;
    m.add_function(wrap_pyfunction!(volume::render_volume, m)?)?;
    m.add_function(wrap_pyfunction!(volume::volume, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
