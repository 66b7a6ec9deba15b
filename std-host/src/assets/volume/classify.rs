//! Classification: which samples are non-transparent, their colour, and
//! the gray-level gradient normal.
//!
//! ```
//! use rrt_host::assets::volume::{Classifier, ColorRamp, Ramp};
//! // Skin at 20 and above, bone (≥ 120) white, soft tissue skin-coloured;
//! // values 60..80 cut away by the opacity ramp.
//! let c = Classifier::iso(20.0)
//!     .with_opacity(Ramp::new(vec![(59.0, 1.0), (60.0, 0.0), (80.0, 0.0), (81.0, 1.0)]).unwrap())
//!     .with_color(ColorRamp::new(vec![(20.0, [200, 150, 120]), (120.0, [255, 255, 240])]).unwrap());
//! assert!(!c.is_opaque(10.0));
//! assert!(c.is_opaque(20.0));
//! assert!(!c.is_opaque(70.0));
//! assert_eq!(c.color(70.0, [0; 3]), [228, 203, 180]);
//! assert_eq!(c.color(500.0, [0; 3]), [255, 255, 240]);
//! ```
//!
//! # The rule
//! A sample of value `v` is **non-transparent** when `v ≥ iso` and, if an
//! opacity ramp is given, `opacity(v) ≥ ½`. The voxel record holds no
//! partial opacity (a discrete ray stops at the first non-transparent
//! voxel), so the ramp acts as a cut at one half: it removes value bands
//! (soft tissue between skin and bone, say) from the iso-surface. NaN is
//! transparent.
//!
//! Ramps are **piecewise linear** through their control points (values
//! strictly increasing), and constant beyond the first and last point.
//! Colour ramps interpolate each 8-bit channel linearly and round to
//! nearest; without one, a voxel gets the object's base colour.
//!
//! # Direct volume rendering
//! A classifier with [`Render::Direct`] is not cut at all: its opacity
//! ramp and colour ramp are the **transfer function** of direct volume
//! rendering ([`Classifier::direct`]). A sample of value `v` has opacity
//! [`Classifier::sample_opacity`]`(v)` (the ramp's, 0 below `iso`): the
//! opacity of a slab of the material **one data sample spacing thick**
//! (the placed volume's smallest sample spacing in the world). A ray that
//! crosses a length `ℓ` of it takes the opacity `1 − (1 − α)^(ℓ / spacing)`,
//! so the picture does not depend on the raster's resolution. Colours are
//! the colour ramp's (or the object's material colour). Every voxel of
//! opacity above 0 goes in the raster; the tracer composites the samples
//! of the voxels a ray visits ([`crate::trace`], *Direct volume
//! rendering*).
//!
//! ```
//! use rrt_host::assets::volume::{Classifier, ColorRamp, Ramp, Render};
//! // Air (below 40) clear, soft tissue faint, bone nearly opaque.
//! let tf = Classifier::direct(Ramp::new(vec![(40.0, 0.0), (60.0, 0.05), (150.0, 0.05), (200.0, 0.9)]).unwrap())
//!     .with_color(ColorRamp::new(vec![(40.0, [200, 90, 70]), (200.0, [255, 255, 240])]).unwrap());
//! assert_eq!(tf.render, Render::Direct);
//! assert_eq!(tf.sample_opacity(10.0), 0.0);
//! assert_eq!(tf.sample_opacity(100.0), 0.05);
//! assert_eq!(tf.color(200.0, [0; 3]), [255, 255, 240]);
//! ```
//!
//! # Normals
//! The core's volume voxelizer computes the normal of each boundary voxel
//! from the gray-level gradient of its integer grid with the
//! Zucker–Hummel 3×3×3 operator (face, edge and corner neighbours weighted
//! 1, 1/√2, 1/√3). [`gray_gradient`] is the same operator in `f64`, used
//! to check the core's normals and by tests.

use glam::DVec3;

use super::{Volume, VolumeError};

fn invalid(what: &str, msg: String) -> VolumeError {
    VolumeError::Invalid {
        what: what.into(),
        msg,
    }
}

fn check_points<T>(what: &str, points: &[(f64, T)]) -> Result<(), VolumeError> {
    if points.is_empty() {
        return Err(invalid(what, "needs at least one control point".into()));
    }
    for (n, w) in points.iter().enumerate() {
        if !w.0.is_finite() {
            return Err(invalid(
                what,
                format!("point {}: value {} is not finite", n + 1, w.0),
            ));
        }
    }
    for (n, w) in points.windows(2).enumerate() {
        if let [a, b] = w
            && a.0 >= b.0
        {
            return Err(invalid(
                what,
                format!(
                    "point {}: values must increase strictly ({} after {})",
                    n + 2,
                    b.0,
                    a.0
                ),
            ));
        }
    }
    Ok(())
}

/// Where `v` falls among `points`: the two neighbours and the weight of
/// the second (constant beyond the ends).
fn locate<T: Copy>(points: &[(f64, T)], v: f64) -> Option<(T, T, f64)> {
    let first = points.first()?;
    let last = points.last()?;
    if v <= first.0 {
        return Some((first.1, first.1, 0.0));
    }
    if v >= last.0 {
        return Some((last.1, last.1, 0.0));
    }
    let i = points.partition_point(|p| p.0 <= v);
    let (a, b) = (points.get(i.checked_sub(1)?)?, points.get(i)?);
    Some((a.1, b.1, (v - a.0) / (b.0 - a.0)))
}

/// A piecewise-linear opacity ramp: value → opacity in `[0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    points: Vec<(f64, f64)>,
}

impl Ramp {
    /// A ramp through `(value, opacity)` points.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] for no points, values that are not finite
    /// or do not increase strictly, or opacities outside `[0, 1]`.
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self, VolumeError> {
        check_points("opacity ramp", &points)?;
        if let Some((n, p)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| !(0.0..=1.0).contains(&p.1))
        {
            return Err(invalid(
                "opacity ramp",
                format!("point {}: opacity {} is outside 0..1", n + 1, p.1),
            ));
        }
        Ok(Self { points })
    }

    /// The opacity at `v` (NaN gives 0).
    #[must_use]
    pub fn at(&self, v: f64) -> f64 {
        if v.is_nan() {
            return 0.0;
        }
        locate(&self.points, v).map_or(0.0, |(a, b, t)| a + (b - a) * t)
    }

    /// The control points.
    #[must_use]
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }
}

/// A piecewise-linear colour ramp: value → 8-bit RGB.
#[derive(Clone, Debug, PartialEq)]
pub struct ColorRamp {
    points: Vec<(f64, [u8; 3])>,
}

impl ColorRamp {
    /// A ramp through `(value, colour)` points.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`] for no points or values that are not
    /// finite or do not increase strictly.
    pub fn new(points: Vec<(f64, [u8; 3])>) -> Result<Self, VolumeError> {
        check_points("colour ramp", &points)?;
        Ok(Self { points })
    }

    /// The colour at `v` (NaN gives the first point's colour).
    #[must_use]
    pub fn at(&self, v: f64) -> [u8; 3] {
        let v = if v.is_nan() { f64::NEG_INFINITY } else { v };
        locate(&self.points, v).map_or([0; 3], |(a, b, t)| {
            let mut out = [0u8; 3];
            for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
                let c = f64::from(x) + (f64::from(y) - f64::from(x)) * t;
                // Between two u8 values: in range.
                *o = c.round().clamp(0.0, 255.0) as u8;
            }
            out
        })
    }

    /// The control points.
    #[must_use]
    pub fn points(&self) -> &[(f64, [u8; 3])] {
        &self.points
    }
}

/// How a volume is rendered (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Render {
    /// The iso-surface: the boundary of the non-transparent voxels
    /// ([`Classifier::is_opaque`]), hit where a ray enters it.
    #[default]
    Iso,
    /// Direct volume rendering: the samples of every voxel a ray passes
    /// composited front to back through the transfer function (the
    /// opacity and colour ramps, with partial opacity).
    Direct,
}

impl Render {
    /// The name in a scene file (`render = "iso"` or `"direct"`).
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Iso => "iso",
            Self::Direct => "direct",
        }
    }
}

/// The classification of a volume (module docs): for an iso-surface the
/// iso-value and the ramps that cut it; for direct volume rendering the
/// transfer function (the opacity and colour ramps, points of
/// `(value, opacity)` and `(value, colour)`), with `iso` a floor below
/// which samples are clear.
#[derive(Clone, Debug, PartialEq)]
pub struct Classifier {
    /// Samples at or above this value may be non-transparent.
    pub iso: f64,
    /// Optional opacity ramp, cut at ½.
    pub opacity: Option<Ramp>,
    /// Optional colour ramp.
    pub color: Option<ColorRamp>,
    /// Iso-surface or direct volume rendering.
    pub render: Render,
}

impl Classifier {
    /// Non-transparent at and above `iso`, base colour.
    #[must_use]
    pub const fn iso(iso: f64) -> Self {
        Self {
            iso,
            opacity: None,
            color: None,
            render: Render::Iso,
        }
    }

    /// Direct volume rendering with the opacity ramp `opacity` as the
    /// transfer function's opacity (no floor: `iso` is `f64::MIN`) and the
    /// base colour (add a colour ramp with [`Classifier::with_color`]).
    #[must_use]
    pub fn direct(opacity: Ramp) -> Self {
        Self {
            iso: f64::MIN,
            opacity: Some(opacity),
            color: None,
            render: Render::Direct,
        }
    }

    /// With the rendering `render`.
    #[must_use]
    pub const fn with_render(mut self, render: Render) -> Self {
        self.render = render;
        self
    }

    /// Whether the volume is rendered directly ([`Render::Direct`]).
    #[must_use]
    pub fn is_direct(&self) -> bool {
        self.render == Render::Direct
    }

    /// The transfer function's opacity of a sample of value `v` (direct
    /// volume rendering): 0 below `iso` or for NaN, else the opacity
    /// ramp's (1 without one). The opacity of a slab one data sample
    /// spacing thick.
    #[must_use]
    pub fn sample_opacity(&self, v: f64) -> f64 {
        if v >= self.iso {
            self.opacity_at(v)
        } else {
            0.0
        }
    }

    /// With an opacity ramp.
    #[must_use]
    pub fn with_opacity(mut self, ramp: Ramp) -> Self {
        self.opacity = Some(ramp);
        self
    }

    /// With a colour ramp.
    #[must_use]
    pub fn with_color(mut self, ramp: ColorRamp) -> Self {
        self.color = Some(ramp);
        self
    }

    /// Checks the iso-value is finite.
    ///
    /// # Errors
    /// [`VolumeError::Invalid`].
    pub fn validate(&self) -> Result<(), VolumeError> {
        if self.iso.is_finite() {
            Ok(())
        } else {
            Err(invalid(
                "classification",
                format!("iso-value {} is not finite", self.iso),
            ))
        }
    }

    /// Opacity at `v`: the ramp's, or 1 without one.
    #[must_use]
    pub fn opacity_at(&self, v: f64) -> f64 {
        self.opacity.as_ref().map_or(1.0, |r| r.at(v))
    }

    /// Whether a sample of value `v` is non-transparent.
    #[must_use]
    pub fn is_opaque(&self, v: f64) -> bool {
        v >= self.iso && self.opacity_at(v) >= 0.5
    }

    /// The colour of a voxel of value `v`: the ramp's, or `base`.
    #[must_use]
    pub fn color(&self, v: f64, base: [u8; 3]) -> [u8; 3] {
        self.color.as_ref().map_or(base, |r| r.at(v))
    }

    /// Number of the volume's samples that are non-transparent.
    #[must_use]
    pub fn count(&self, volume: &Volume) -> u64 {
        volume
            .samples()
            .iter()
            .filter(|&v| self.is_opaque(v))
            .count() as u64
    }
}

/// A transfer function's control point or key that is refused by
/// [`Classifier::from_points`]: the key it is at (`iso`, `opacity[2]`,
/// `colours[1][0]`, arrays counting from 0) and what is wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {message}")]
pub struct TransferError {
    /// Where: `iso`, `opacity`, `colours`, or one point (`opacity[i]`)
    /// or its value (`opacity[i][0]`).
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl Classifier {
    /// The classification a transfer function's points describe, as a
    /// volume's `iso`, `opacity` and `colours` keys in a TOML scene give
    /// them: `opacity` points `[value, alpha]` with alpha in `[0, 1]`,
    /// `colours` points `[value, r, g, b]` with channels in `[0, 1]`
    /// (rounded to 8 bits), values finite and strictly increasing along
    /// each ramp. Without `iso` the opacity ramp alone decides; one of the
    /// two is required. `render` (the `render` key) is `"iso"` or
    /// `"direct"` ([`Render`]); without it, a volume whose opacity ramp has
    /// a point strictly between 0 and 1 is rendered directly and any other
    /// as its iso-surface. Direct rendering needs an opacity ramp.
    ///
    /// ```
    /// use rrt_host::assets::volume::Classifier;
    /// let c = Classifier::from_points(None, Some(&[[0.2, 0.0], [0.8, 1.0]]), Some(&[[0.0, 1.0, 0.0, 0.0]]), None)?;
    /// assert!(c.is_opaque(0.6) && !c.is_opaque(0.4) && !c.is_direct());
    /// assert_eq!(c.color(0.5, [0; 3]), [255, 0, 0]);
    /// let soft = Classifier::from_points(None, Some(&[[0.2, 0.0], [0.8, 0.3]]), None, None)?;
    /// assert!(soft.is_direct());
    /// let e = Classifier::from_points(Some(1.0), Some(&[[0.5, 0.0], [0.5, 1.0]]), None, None).unwrap_err();
    /// assert_eq!(e.to_string(), "opacity[1][0]: expected values that increase along the ramp");
    /// # Ok::<(), rrt_host::assets::volume::classify::TransferError>(())
    /// ```
    ///
    /// # Errors
    /// [`TransferError`] naming the first bad key or point.
    pub fn from_points(
        iso: Option<f64>,
        opacity: Option<&[[f64; 2]]>,
        colours: Option<&[[f64; 4]]>,
        render: Option<&str>,
    ) -> Result<Self, TransferError> {
        let err = |key: String, message: &str| TransferError {
            key,
            message: message.into(),
        };
        // Point by point: each point's form, then its value against the
        // previous point's.
        let check = |ramp: &str, values: &[f64], ok: &dyn Fn(usize) -> bool, form: &str| {
            for (i, v) in values.iter().enumerate() {
                if !ok(i) {
                    return Err(err(format!("{ramp}[{i}]"), form));
                }
                if i > 0 && !(*v > values[i - 1]) {
                    return Err(err(
                        format!("{ramp}[{i}][0]"),
                        "expected values that increase along the ramp",
                    ));
                }
            }
            Ok(())
        };
        // With an opacity ramp and no iso-value, the ramp alone decides.
        let mut classifier = match (iso, opacity) {
            (Some(iso), _) => Self::iso(iso),
            (None, Some(_)) => Self::iso(f64::MIN),
            (None, None) => {
                return Err(err(
                    "iso".into(),
                    "missing: give an iso-value, an opacity ramp, or both",
                ));
            }
        };
        if let Some(o) = opacity {
            let values: Vec<f64> = o.iter().map(|p| p[0]).collect();
            check(
                "opacity",
                &values,
                &|i| o[i][0].is_finite() && (0.0..=1.0).contains(&o[i][1]),
                "expected [value, alpha] with alpha in [0, 1]",
            )?;
            let ramp = Ramp::new(o.iter().map(|p| (p[0], p[1])).collect())
                .map_err(|e| err("opacity".into(), &e.to_string()))?;
            classifier = classifier.with_opacity(ramp);
        }
        if let Some(c) = colours {
            let values: Vec<f64> = c.iter().map(|p| p[0]).collect();
            check(
                "colours",
                &values,
                &|i| {
                    c[i].iter().all(|x| x.is_finite())
                        && c[i][1..].iter().all(|x| (0.0..=1.0).contains(x))
                },
                "expected [value, r, g, b] with channels in [0, 1]",
            )?;
            // In [0, 255] after the check above.
            let ch = |x: f64| (x * 255.0).round() as u8;
            let ramp = ColorRamp::new(
                c.iter()
                    .map(|p| (p[0], [ch(p[1]), ch(p[2]), ch(p[3])]))
                    .collect(),
            )
            .map_err(|e| err("colours".into(), &e.to_string()))?;
            classifier = classifier.with_color(ramp);
        }
        classifier
            .validate()
            .map_err(|e| err("iso".into(), &e.to_string()))?;
        // A ramp of only 0 and 1 is a cut of the iso-surface.
        let partial = opacity.is_some_and(|o| o.iter().any(|p| p[1] > 0.0 && p[1] < 1.0));
        let render = match render {
            None if partial => Render::Direct,
            None | Some("iso") => Render::Iso,
            Some("direct") => Render::Direct,
            Some(other) => {
                return Err(err(
                    "render".into(),
                    &format!("expected \"iso\" or \"direct\", found \"{other}\""),
                ));
            }
        };
        if render == Render::Direct && opacity.is_none() {
            return Err(err(
                "render".into(),
                "direct volume rendering needs a transfer function: give opacity = [[value, alpha], …]",
            ));
        }
        Ok(classifier.with_render(render))
    }
}

/// Sum of the Zucker–Hummel weights on one face of the 3×3×3 cube
/// (`1 + 4/√2 + 4/√3`): a linear field of slope `g` gives a face
/// difference of `2·g·ZH_FACE`.
pub const ZH_FACE: f64 =
    1.0 + 4.0 * std::f64::consts::FRAC_1_SQRT_2 + 4.0 / 1.732_050_807_568_877_2;

/// The gray-level gradient at grid point `(i, j, k)` of the scalar field
/// `f` (values per grid step), by the Zucker–Hummel 3×3×3 operator,
/// normalised so that a linear field gives its exact gradient.
pub fn gray_gradient(f: impl Fn(i64, i64, i64) -> f64, i: i64, j: i64, k: i64) -> DVec3 {
    let w = [1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0 / 3f64.sqrt()];
    let mut g = DVec3::ZERO;
    for axis in 0..3 {
        // The two opposite faces are summed in the same order, so a
        // constant field gives exactly 0.
        let mut face = [0.0f64; 2];
        for (side, sign) in [-1i64, 1].into_iter().enumerate() {
            for a in -1..=1i64 {
                for b in -1..=1i64 {
                    let mut d = [a, b, 0];
                    d.rotate_right((axis + 1) % 3);
                    d[axis] = sign;
                    let others = usize::from(a != 0) + usize::from(b != 0);
                    face[side] += w[others] * f(i + d[0], j + d[1], k + d[2]);
                }
            }
        }
        g[axis] = face[1] - face[0];
    }
    g / (2.0 * ZH_FACE)
}

/// The gray-level normal: the negated, normalised [`gray_gradient`]
/// (pointing from high to low values, out of the object); `None` where
/// the gradient vanishes.
pub fn gray_normal(f: impl Fn(i64, i64, i64) -> f64, i: i64, j: i64, k: i64) -> Option<DVec3> {
    (-gray_gradient(f, i, j, k)).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramps_interpolate_and_clamp() {
        let r = Ramp::new(vec![(0.0, 0.0), (10.0, 1.0)]).unwrap();
        assert_eq!(r.at(-5.0), 0.0);
        assert_eq!(r.at(2.5), 0.25);
        assert_eq!(r.at(99.0), 1.0);
        assert_eq!(r.at(f64::NAN), 0.0);
        assert!(Ramp::new(vec![(1.0, 0.0), (1.0, 1.0)]).is_err());
        assert!(Ramp::new(vec![(1.0, 1.5)]).is_err());
        assert!(Ramp::new(vec![]).is_err());
        let c = ColorRamp::new(vec![(0.0, [0, 0, 0]), (4.0, [255, 100, 1])]).unwrap();
        assert_eq!(c.at(1.0), [64, 25, 0]);
    }

    #[test]
    fn gradient_of_linear_field_is_exact() {
        let f = |i: i64, j: i64, k: i64| 3.0 * i as f64 - 2.0 * j as f64 + 0.5 * k as f64;
        let g = gray_gradient(f, 4, 5, 6);
        assert!((g - DVec3::new(3.0, -2.0, 0.5)).length() < 1e-12, "{g}");
        let n = gray_normal(f, 0, 0, 0).unwrap();
        assert!((n - DVec3::new(-3.0, 2.0, -0.5).normalize()).length() < 1e-12);
        assert!(gray_normal(|_, _, _| 1.0, 0, 0, 0).is_none());
        // A non-linear field against the operator written out over all 26
        // neighbours.
        let f = |i: i64, j: i64, k: i64| ((i * i * 7 + j * 3 - k * k * k + i * j * k) % 11) as f64;
        let mut want = DVec3::ZERO;
        for dz in -1..=1i64 {
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let d = [dx, dy, dz];
                    let nz = d.iter().filter(|c| **c != 0).count();
                    if nz == 0 {
                        continue;
                    }
                    let w = 1.0 / (nz as f64).sqrt();
                    for a in 0..3 {
                        if d[a] != 0 {
                            // The weight counts the offsets across axis a.
                            let across = nz - 1;
                            let wa = 1.0 / ((across + 1) as f64).sqrt();
                            assert_eq!(w, wa);
                            want[a] += wa * d[a] as f64 * f(2 + dx, 3 + dy, 4 + dz);
                        }
                    }
                }
            }
        }
        let got = gray_gradient(f, 2, 3, 4);
        assert!(
            (got - want / (2.0 * ZH_FACE)).length() < 1e-12,
            "{got} {want}"
        );
    }
}
