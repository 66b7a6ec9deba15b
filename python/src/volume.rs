//! numpy arrays as volumes: `rrt.volume` and `rrt.render_volume`.

use std::sync::Arc;

use glam::DVec3;
use indicatif::ProgressBar;
use numpy::{PyArray3, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyDictMethods};
use rrt_host::assets::volume::{
    Classifier, DEFAULT_MAX_BYTES, Grid, Placement, SampleType, Samples, Volume,
};
use rrt_host::cli::common::{ImageNeed, Purpose, ViewArgs, build_scene};
use rrt_host::scene::{
    Light, Material, Scene, SceneVolume, SourceLoc, View as HostView, VolumeObject,
};
use rrt_host::world::Bounds;

use crate::args::{RenderArgs, raster_args};
use crate::errors::Error;
use crate::image::{render_view, to_numpy};
use crate::raster::Raster;
use crate::view::View;

/// The name a volume from an array goes by in messages.
const NAME: &str = "array";
/// The default image side.
const DEFAULT_SIDE: u32 = 256;
/// The default camera's vertical field of view, degrees.
const DEFAULT_ANGLE: f64 = 30.0;
/// The default background.
const DEFAULT_BACKGROUND: [f64; 3] = [0.08, 0.08, 0.1];
/// The default transfer function's colours (a blue, white, red diverging
/// map, channels in `[0, 1]`) at 20%, 50% and 80% of the data's range:
/// across its opacity ramp.
const DEFAULT_COLOURS: [[f64; 3]; 3] = [[0.23, 0.30, 0.75], [0.87, 0.87, 0.87], [0.71, 0.02, 0.15]];

/// The samples of a C-contiguous 3D array, indexed `[z, y, x]` (x
/// fastest), and its dimensions `[nx, ny, nz]`. `float64` samples are
/// stored as `float32`.
fn samples(array: &Bound<'_, PyAny>) -> Result<([u32; 3], Samples), Error> {
    let bad = |m: String| Error::arg("array", m);
    let untyped = array.cast::<PyUntypedArray>().map_err(|_| {
        bad(format!(
            "expected a numpy array, found {}",
            type_name(array)
        ))
    })?;
    if untyped.ndim() != 3 {
        return Err(bad(format!(
            "expected 3 dimensions [z, y, x], found {} (shape {:?})",
            untyped.ndim(),
            untyped.shape()
        )));
    }
    let dtype = untyped.dtype();
    let py = array.py();
    let ty = [
        (numpy::dtype::<u8>(py), Some(SampleType::U8)),
        (numpy::dtype::<i16>(py), Some(SampleType::I16)),
        (numpy::dtype::<u16>(py), Some(SampleType::U16)),
        (numpy::dtype::<f32>(py), Some(SampleType::F32)),
        (numpy::dtype::<f64>(py), None),
    ]
    .into_iter()
    .find(|(d, _)| dtype.is_equiv_to(d))
    .map(|(_, t)| t)
    .ok_or_else(|| {
        bad(format!(
            "dtype {} is not a sample type; expected uint8, int16, uint16, float32 or float64 (cast with array.astype)",
            dtype
        ))
    })?;
    if !untyped.is_c_contiguous() {
        return Err(bad(
            "not C-contiguous (a view, a transpose or a slice with steps); pass numpy.ascontiguousarray(array)"
                .into(),
        ));
    }
    let shape = untyped.shape();
    let max = u64::from(rrt_host::assets::volume::MAX_AXIS);
    if shape.iter().any(|&n| n == 0 || n as u64 > max) {
        return Err(bad(format!(
            "shape {shape:?}: each dimension must be 1 to {max}"
        )));
    }
    let width = ty.map_or(4, SampleType::size);
    let bytes = shape
        .iter()
        .try_fold(width, |acc, &n| acc.checked_mul(n as u64))
        .unwrap_or(u64::MAX);
    if bytes > DEFAULT_MAX_BYTES {
        return Err(bad(format!(
            "shape {shape:?} takes {bytes} bytes as samples, more than the limit of {DEFAULT_MAX_BYTES} bytes"
        )));
    }
    // In 1..=MAX_AXIS after the check above.
    let dims = [shape[2] as u32, shape[1] as u32, shape[0] as u32];
    let copy = |e: numpy::AsSliceError| bad(e.to_string());
    let samples = match ty {
        Some(SampleType::U8) => Samples::U8(typed::<u8>(array)?.to_vec().map_err(copy)?),
        Some(SampleType::I16) => Samples::I16(typed::<i16>(array)?.to_vec().map_err(copy)?),
        Some(SampleType::U16) => Samples::U16(typed::<u16>(array)?.to_vec().map_err(copy)?),
        Some(SampleType::F32) => Samples::F32(typed::<f32>(array)?.to_vec().map_err(copy)?),
        None => Samples::F32(
            typed::<f64>(array)?
                .to_vec()
                .map_err(copy)?
                .into_iter()
                .map(|v| v as f32)
                .collect(),
        ),
    };
    Ok((dims, samples))
}

/// `array` as a typed 3D array (its dtype checked before).
fn typed<'a, 'py, T: numpy::Element>(
    array: &'a Bound<'py, PyAny>,
) -> Result<&'a Bound<'py, PyArray3<T>>, Error> {
    array
        .cast::<PyArray3<T>>()
        .map_err(|e| Error::arg("array", e.to_string()))
}

/// The Python type name of `v`, for messages.
fn type_name(v: &Bound<'_, PyAny>) -> String {
    v.get_type()
        .name()
        .map_or_else(|_| "?".into(), |n| n.to_string())
}

/// The transfer function: a dict with `iso`, `opacity` (`[value, alpha]`
/// points) and `colours` (`[value, r, g, b]` points), the TOML volume
/// keys, checked by the host's own validation; `None`: the default over
/// the data's range `(lo, hi)`.
fn classifier(
    transfer: Option<&Bound<'_, PyDict>>,
    range: (f64, f64),
) -> Result<Classifier, Error> {
    let bad = |m: String| Error::arg("transfer", m);
    let Some(t) = transfer else {
        let (lo, hi) = range;
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::arg(
                "array",
                format!(
                    "samples from {lo} to {hi}: the default transfer function spreads over the data's range; give transfer="
                ),
            ));
        }
        let at = |f: f64| lo + f * (hi - lo);
        // Opaque from the middle of the range up (the cut at ½ of a ramp
        // from 0 at 20% to 1 at 80%); a partial-opacity renderer reads the
        // same ramp as a soft edge around it.
        let opacity = [[at(0.2), 0.0], [at(0.8), 1.0]];
        let colours: Vec<[f64; 4]> = DEFAULT_COLOURS
            .iter()
            .enumerate()
            .map(|(i, c)| [at(0.2 + 0.3 * i as f64), c[0], c[1], c[2]])
            .collect();
        return Classifier::from_points(None, Some(&opacity), Some(&colours), None)
            .map_err(|e| bad(e.to_string()));
    };
    let mut iso = None;
    let mut opacity: Option<Vec<[f64; 2]>> = None;
    let mut colours: Option<Vec<[f64; 4]>> = None;
    let mut render: Option<String> = None;
    for (k, v) in t.iter() {
        let key: String = k
            .extract()
            .map_err(|_| bad(format!("keys are strings, found {}", type_name(&k))))?;
        match key.as_str() {
            "iso" => {
                iso = Some(v.extract::<f64>().map_err(|_| {
                    bad(format!("iso: expected a number, found {}", type_name(&v)))
                })?);
            }
            "opacity" => {
                opacity = Some(v.extract().map_err(|_| {
                    bad("opacity: expected a list of [value, alpha] points".into())
                })?);
            }
            "colours" => {
                colours = Some(v.extract().map_err(|_| {
                    bad("colours: expected a list of [value, r, g, b] points".into())
                })?);
            }
            "render" => {
                render = Some(v.extract().map_err(|_| {
                    bad(format!(
                        "render: expected \"iso\" or \"direct\", found {}",
                        type_name(&v)
                    ))
                })?);
            }
            other => {
                return Err(bad(format!(
                    "unknown key {other:?}; expected iso, opacity, colours, render"
                )));
            }
        }
    }
    Classifier::from_points(
        iso,
        opacity.as_deref(),
        colours.as_deref(),
        render.as_deref(),
    )
    .map_err(|e| bad(e.to_string()))
}

/// A view of the whole of `b` from the front, right and above (z up), at
/// `w × h` pixels: its bounding sphere fits the narrower field of view.
fn framing(b: Bounds, w: u32, h: u32) -> HostView {
    let centre = (b.min + b.max) / 2.0;
    let radius = (b.max - b.min).length() / 2.0;
    let half = (DEFAULT_ANGLE / 2.0).to_radians();
    let aspect = f64::from(w.max(2) - 1) / f64::from(h.max(2) - 1);
    let half_wide = (half.tan() * aspect).atan();
    let distance = radius / half.min(half_wide).sin() * 1.02;
    HostView {
        from: centre + DVec3::new(0.55, -1.0, 0.45).normalize() * distance,
        at: centre,
        up: DVec3::Z,
        angle: DEFAULT_ANGLE,
        hither: 0.0,
        resolution: [w, h],
        loc: SourceLoc::new(NAME, 0, 0),
    }
}

/// Three finite numbers `> 0` for `spacing`.
fn spacing(s: [f64; 3]) -> Result<[f64; 3], Error> {
    if s.iter().all(|v| v.is_finite() && *v > 0.0) {
        Ok(s)
    } else {
        Err(Error::arg(
            "spacing",
            format!("expected three finite numbers > 0 (x, y, z), found {s:?}"),
        ))
    }
}

/// Builds the raster of a volume scene: the array at the origin with its
/// spacing, classified, under one light near the eye.
#[allow(clippy::too_many_arguments)]
fn build(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    spacing_xyz: [f64; 3],
    transfer: Option<&Bound<'_, PyDict>>,
    camera: Option<&View>,
    background: [f64; 3],
    a: &RenderArgs,
    raster: Option<i64>,
) -> Result<Raster, Error> {
    let spacing_xyz = spacing(spacing_xyz)?;
    if !background.iter().all(|c| (0.0..=1.0).contains(c)) {
        return Err(Error::arg(
            "background",
            format!("expected channels in [0, 1], found {background:?}"),
        ));
    }
    let raster = raster_args(raster, "exact", "adaptive")?;
    let (dims, samples) = samples(array)?;
    let volume = Volume::new(dims, Grid::axis_aligned(spacing_xyz, DVec3::ZERO), samples)
        .map_err(|e| Error::arg("array", e.to_string()))?;
    let classifier = classifier(transfer, volume.range())?;
    // A raster that can be saved, unless the volume is rendered directly
    // (which no raster file holds: `Raster.save` then says so).
    let purpose = if classifier.is_direct() {
        Purpose::Render
    } else {
        Purpose::Save
    };
    let view = match camera {
        Some(v) => v.inner.clone(),
        None => framing(
            volume.physical_bounds(),
            a.width.unwrap_or(DEFAULT_SIDE),
            a.height.unwrap_or(DEFAULT_SIDE),
        ),
    };
    let placement =
        Placement::new(DVec3::ZERO, 1.0).map_err(|e| Error::arg("array", e.to_string()))?;
    let loc = SourceLoc::new(NAME, 0, 0);
    let mut scene = Scene::empty(Arc::from(NAME), view.clone());
    scene.background = DVec3::from(background);
    // Above and beside the eye: shading shows the shape.
    let eye = view.from - view.at;
    scene.lights.push(Light {
        position: view.at + eye + DVec3::Z * eye.length() * 0.6 + eye.cross(DVec3::Z) * 0.3,
        colour: None,
        loc: loc.clone(),
    });
    scene.materials.push(Material {
        ks: 0.25,
        shine: 20.0,
        kd: 0.9,
        ..Material::DEFAULT
    });
    scene.volumes.push(VolumeObject {
        data: SceneVolume {
            volume: Arc::new(volume),
            placement,
            classifier,
        },
        material: 0,
        loc,
    });
    let (w, h, k, threads) = (a.width, a.height, a.supersample, a.threads);
    let (voxels, _) = py.detach(move || {
        let no_overrides = ViewArgs {
            from: None,
            at: None,
            up: None,
            angle: None,
        };
        build_scene(
            &scene,
            &raster,
            purpose,
            &ImageNeed {
                view: &no_overrides,
                width: w,
                height: h,
                samples: k,
                memory: 0,
            },
            threads,
            &ProgressBar::hidden(),
        )
    })?;
    Ok(Raster {
        scene: Arc::new(voxels),
    })
}

/// A 3D numpy array as a volume, voxelized into a `Raster` to render from
/// any view (or save). See `render_volume` for the arguments.
#[pyfunction]
#[pyo3(signature = (array, *, spacing = [1.0, 1.0, 1.0], transfer = None, camera = None, background = DEFAULT_BACKGROUND, width = None, height = None, raster = None, threads = 0))]
#[allow(clippy::too_many_arguments)]
pub fn volume(
    py: Python<'_>,
    array: &Bound<'_, PyAny>,
    spacing: [f64; 3],
    transfer: Option<&Bound<'_, PyDict>>,
    camera: Option<PyRef<'_, View>>,
    background: [f64; 3],
    width: Option<i64>,
    height: Option<i64>,
    raster: Option<i64>,
    threads: i64,
) -> PyResult<Raster> {
    let a = RenderArgs::new(width, height, 1, 1, threads, None, false, false)?;
    Ok(build(
        py,
        array,
        spacing,
        transfer,
        camera.as_deref(),
        background,
        &a,
        raster,
    )?)
}

/// Renders a 3D numpy array as a volume: an `(H, W, 3)` array of 8-bit
/// sRGB codes (`float=True`: linear `float32`; `alpha=True`: `(H, W, 4)`,
/// the coverage in the fourth channel and the colour in straight alpha, as
/// `rrt.render`: where nothing but the background is seen it is 0, through
/// the volume the opacity composited).
///
/// * `array`: indexed `[z, y, x]`, C-contiguous, dtype `uint8`, `int16`,
///   `uint16`, `float32` or `float64` (stored as `float32`).
/// * `spacing`: the sample spacing along x, y and z (world units).
/// * `transfer`: a dict with the TOML volume keys: `iso` (a value),
///   `opacity` (`[[value, alpha], ...]`) and `colours` (`[[value, r, g,
///   b], ...]`, channels in [0, 1]); values increase along each ramp.
///   Default: an opacity ramp from 0 at 20% to 1 at 80% of the data's
///   range (opaque from the middle up while opacity is a cut at ½),
///   coloured blue, white, red across it.
/// * `camera`: an `rrt.View`; default: the whole volume from the front,
///   right and above, z up. `frame=(k, n)`: frame `k` of its orbit.
#[pyfunction]
#[pyo3(signature = (array, *, width = None, height = None, spacing = [1.0, 1.0, 1.0], transfer = None, camera = None, frame = None, background = DEFAULT_BACKGROUND, supersample = 1, depth = 3, min_weight = rrt_host::trace::DEFAULT_MIN_WEIGHT, threads = 0, raster = None, float = false, alpha = false))]
#[allow(clippy::too_many_arguments)]
pub fn render_volume<'py>(
    py: Python<'py>,
    array: &Bound<'py, PyAny>,
    width: Option<i64>,
    height: Option<i64>,
    spacing: [f64; 3],
    transfer: Option<&Bound<'py, PyDict>>,
    camera: Option<PyRef<'py, View>>,
    frame: Option<(i64, i64)>,
    background: [f64; 3],
    supersample: i64,
    depth: i64,
    min_weight: f64,
    threads: i64,
    raster: Option<i64>,
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
    let r = build(
        py,
        array,
        spacing,
        transfer,
        camera.as_deref(),
        background,
        &a,
        raster,
    )?;
    let modes = raster_args(None, "exact", "adaptive")?;
    let scene = Arc::clone(&r.scene);
    let image = py.detach(move || render_view(&scene, &scene.view, &modes, &a))?;
    to_numpy(py, image, &a)
}
