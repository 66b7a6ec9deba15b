//! `rrt.View`: a camera, and the host's orbit.

use glam::DVec3;
use pyo3::prelude::*;
use rrt_host::render::camera::Camera;
use rrt_host::scene::{SourceLoc, View as HostView};

use crate::errors::Error;

/// A camera: the eye `from_`, the point `at` it looks at (the image
/// centre), the `up` direction, the vertical field of view `angle` in
/// degrees (between the centres of the top and bottom pixel rows) and the
/// `resolution` `(width, height)`.
///
/// `View(from_, at, up=(0, 0, 1), angle=40.0, resolution=(256, 256))`
#[pyclass(frozen, module = "rrt")]
#[derive(Clone, Debug)]
pub struct View {
    pub inner: HostView,
}

/// Three finite numbers for argument `arg`.
fn vec3(arg: &str, v: [f64; 3]) -> Result<DVec3, Error> {
    let d = DVec3::from(v);
    if d.is_finite() {
        Ok(d)
    } else {
        Err(Error::arg(
            arg,
            format!("expected finite numbers, found {v:?}"),
        ))
    }
}

impl View {
    /// A view checked as the renderer's camera checks it.
    pub fn checked(inner: HostView) -> Result<Self, Error> {
        let [w, h] = inner.resolution;
        Camera::new(&inner, w, h)?;
        Ok(Self { inner })
    }

    /// `view`, or frame `k` of its `n`-frame orbit.
    pub fn framed(view: &HostView, frame: Option<(u64, u64)>) -> HostView {
        match frame {
            Some((k, n)) => view.orbit(k, n),
            None => view.clone(),
        }
    }
}

#[pymethods]
impl View {
    #[new]
    #[pyo3(signature = (from_, at, up = [0.0, 0.0, 1.0], angle = 40.0, resolution = (256, 256)))]
    fn new(
        from_: [f64; 3],
        at: [f64; 3],
        up: [f64; 3],
        angle: f64,
        resolution: (i64, i64),
    ) -> PyResult<Self> {
        let side = i64::from(rrt_host::render::MAX_SIDE);
        let w = crate::args::whole("resolution", resolution.0, 1, side)?;
        let h = crate::args::whole("resolution", resolution.1, 1, side)?;
        Ok(Self::checked(HostView {
            from: vec3("from_", from_)?,
            at: vec3("at", at)?,
            up: vec3("up", up)?,
            angle,
            hither: 0.0,
            resolution: [w, h],
            loc: SourceLoc::new("python", 0, 0),
        })?)
    }

    /// The eye position.
    #[getter]
    fn from_(&self) -> [f64; 3] {
        self.inner.from.to_array()
    }

    /// The point looked at.
    #[getter]
    fn at(&self) -> [f64; 3] {
        self.inner.at.to_array()
    }

    /// The up direction.
    #[getter]
    fn up(&self) -> [f64; 3] {
        self.inner.up.to_array()
    }

    /// The vertical field of view in degrees.
    #[getter]
    fn angle(&self) -> f64 {
        self.inner.angle
    }

    /// `(width, height)` in pixels.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        (self.inner.resolution[0], self.inner.resolution[1])
    }

    /// Frame `k` of an orbit of `n` frames: the eye rotated by 360°·k/n
    /// about the axis through `at` along `up` (frame 0 is this view).
    fn orbit(&self, k: i64, n: i64) -> PyResult<Self> {
        let a = crate::args::RenderArgs::new(None, None, 1, 1, 0, Some((k, n)), false, false)?;
        Ok(Self {
            inner: Self::framed(&self.inner, a.frame),
        })
    }

    fn __repr__(&self) -> String {
        let v = &self.inner;
        format!(
            "View(from_={:?}, at={:?}, up={:?}, angle={:?}, resolution={:?})",
            v.from.to_array(),
            v.at.to_array(),
            v.up.to_array(),
            v.angle,
            (v.resolution[0], v.resolution[1])
        )
    }

    fn __eq__(&self, other: &Self) -> bool {
        let (a, b) = (&self.inner, &other.inner);
        (a.from, a.at, a.up, a.angle, a.resolution) == (b.from, b.at, b.up, b.angle, b.resolution)
    }
}
