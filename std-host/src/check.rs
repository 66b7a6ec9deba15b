//! Invariant checkers shared by the tests and the fuzz targets (feature
//! `check`): each returns `Err` with a description of the first broken
//! invariant, so that callers can panic with it or collect it.

#![deny(missing_docs)]

use crate::camera::Camera;
use crate::fit::{FitOptions, fit};
use crate::scene::{ParseOptions, nff};

pub use crate::scene::check_scene;

/// Feeds arbitrary bytes (as the file `fuzz.nff`) to the NFF parser, then
/// to the camera and a 32-voxel raster fit, and checks: an error names the
/// file; a parsed scene keeps the guarantees of
/// [`Scene`](crate::scene::Scene) ([`check_scene`]) and makes a camera;
/// a fit either fails with an error or gives at most 32 voxels per axis,
/// objects with existing materials and every light. A panic or a hang
/// inside is a bug the caller sees as such.
///
/// # Errors
/// The first broken invariant.
pub fn nff_input(data: &[u8]) -> Result<(), String> {
    let opts = ParseOptions {
        max_vertices: 1 << 16,
        max_file_bytes: 1 << 20,
    };
    let scene = match nff::parse_bytes("fuzz.nff", data, &opts) {
        Ok(scene) => scene,
        Err(e) => {
            let msg = e.to_string();
            return if msg.starts_with("fuzz.nff") {
                Ok(())
            } else {
                Err(format!("error without its file: {msg}"))
            };
        }
    };
    check_scene(&scene).map_err(|e| format!("parsed scene breaks a guarantee: {e}"))?;
    let [w, h] = scene.view.resolution;
    Camera::new(&scene.view, w, h)
        .map_err(|e| format!("the parser accepted a view the camera refuses: {e}"))?;
    let fit_opts = FitOptions {
        max_memory: 64 << 20,
        ..FitOptions::new(32)
    };
    if let Ok(fitted) = fit(&scene, &fit_opts) {
        let dims = fitted.frame.dims();
        if !dims.iter().all(|&n| (1..=32).contains(&n)) {
            return Err(format!("fit made a {dims:?} raster for raster 32"));
        }
        if let Some(o) = fitted
            .objects
            .iter()
            .find(|o| o.material >= scene.materials.len())
        {
            return Err(format!("fitted object with a missing material: {o:?}"));
        }
        if fitted.lights.len() != scene.lights.len() {
            return Err("fit lost lights".into());
        }
    }
    Ok(())
}

/// The checks of the `scene_toml` fuzz target (shared with
/// `tests/fuzz_regressions.rs`) on arbitrary bytes: the TOML scene parser
/// (with no file reads) must not panic; an error must name the input file
/// (`fuzz.toml`); a scene that parses must keep every guarantee of
/// [`crate::scene::Scene`] and fit a small raster or return a `FitError`.
///
/// # Errors
/// A description of the first broken guarantee.
pub fn toml_input(data: &[u8]) -> Result<(), String> {
    let Ok(text) = std::str::from_utf8(data) else {
        return Ok(());
    };
    let opts = crate::scene::toml::Options {
        read_files: false,
        ..crate::scene::toml::Options::default()
    };
    match crate::scene::toml::parse("fuzz.toml", text, std::path::Path::new("."), &opts) {
        Err(e) => {
            let msg = e.to_string();
            if msg.starts_with("fuzz.toml") {
                Ok(())
            } else {
                Err(format!("error does not name the file: {msg}"))
            }
        }
        Ok(scene) => {
            check_scene(&scene)?;
            let _ = fit(&scene, &FitOptions::new(16));
            Ok(())
        }
    }
}
