//! World space: the `f64` coordinates scenes are written in.
//!
//! [`Bounds`] (a world box), [`Ray`] (a continuous ray) and [`Hit`] (an
//! exact ray–surface intersection) are what every phase that works in the
//! world shares: the scene readers and asset loaders, the shape model,
//! the camera, intersection verification and shading. Nothing here knows
//! the raster; [`crate::frame`] maps world space into it.

use glam::DVec3;

/// The largest magnitude of a world coordinate a scene may use: every
/// point of every object, every light and the eye lie within `±1e60` on
/// every axis. Beyond it the squares and products of the exact
/// intersections, of shading and of the camera (a torus's quartic reaches
/// the fourth power of its coordinates) could overflow `f64`, and an image
/// would lose objects or light without a word; so the scene readers,
/// fitting a raster ([`crate::fit`]), the camera and the saved-raster
/// loader refuse such scenes instead. Far beyond any physical scene (the
/// observable universe is about `1e27` metres across) and beyond the
/// `f32` range of tracers such as Embree. Messages spell it `±1e60`:
///
/// ```
/// assert_eq!(format!("±{:e}", rrt_host::world::WORLD_LIMIT), "±1e60");
/// ```
pub const WORLD_LIMIT: f64 = 1e60;

/// A world number as messages and reports print it: Rust's shortest
/// decimal form in the usual range, the exponent form where that would
/// spell out dozens of digits.
///
/// ```
/// use rrt_host::world::Coord;
/// assert_eq!(Coord(2.5).to_string(), "2.5");
/// assert_eq!(Coord(-1e60).to_string(), "-1e60");
/// assert_eq!(Coord(1.25e-9).to_string(), "1.25e-9");
/// assert_eq!(Coord(0.0).to_string(), "0");
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Coord(pub f64);

impl std::fmt::Display for Coord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || !a.is_finite() || (1e-6..1e16).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// Whether every coordinate of `v` lies within [`WORLD_LIMIT`] (so is
/// finite).
///
/// ```
/// use glam::DVec3;
/// use rrt_host::world::within_world;
/// assert!(within_world(DVec3::new(1e60, -1e60, 0.0)));
/// assert!(!within_world(DVec3::new(0.0, 2e60, 0.0)));
/// assert!(!within_world(DVec3::new(f64::NAN, 0.0, 0.0)));
/// ```
#[must_use]
pub fn within_world(v: DVec3) -> bool {
    v.abs().cmple(DVec3::splat(WORLD_LIMIT)).all()
}

/// The unit vector along `v`, for every finite non-zero `v`, however
/// short or long: `v.try_normalize()` where that succeeds (the same bits),
/// else `v` scaled by its largest coordinate first, so that its squared
/// length neither underflows nor overflows. `None` for zero or
/// non-finite vectors.
///
/// ```
/// use glam::DVec3;
/// use rrt_host::world::unit;
/// assert_eq!(unit(DVec3::new(0.0, 0.0, 1e-300)), Some(DVec3::Z));
/// let v = DVec3::new(3.0, 4.0, 0.0);
/// assert_eq!(unit(v), Some(v.normalize()));
/// assert!((unit(v * 1e-300).unwrap() - v.normalize()).length() < 1e-15);
/// assert_eq!(unit(DVec3::ZERO), None);
/// assert_eq!(unit(DVec3::new(f64::NAN, 1.0, 0.0)), None);
/// ```
#[must_use]
pub fn unit(v: DVec3) -> Option<DVec3> {
    v.try_normalize().or_else(|| {
        let m = v.abs().max_element();
        if m > 0.0 && m.is_finite() {
            (v / m).try_normalize()
        } else {
            None
        }
    })
}

/// An axis-aligned box in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Lowest corner.
    pub min: DVec3,
    /// Highest corner.
    pub max: DVec3,
}

impl Bounds {
    /// Whether both corners lie within [`WORLD_LIMIT`] ([`within_world`]).
    #[must_use]
    pub fn within_world(&self) -> bool {
        within_world(self.min) && within_world(self.max)
    }

    /// The empty box (`min = +∞`, `max = −∞`): [`Bounds::include`] grows it.
    pub const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    /// Grows the box to hold `lo..hi`.
    pub fn include(&mut self, lo: DVec3, hi: DVec3) {
        self.min = self.min.min(lo);
        self.max = self.max.max(hi);
    }

    /// Grows the box to hold `other`.
    pub fn include_bounds(&mut self, other: Self) {
        self.include(other.min, other.max);
    }

    /// The box around `points` ([`Bounds::EMPTY`] for none).
    #[must_use]
    pub fn around(points: impl IntoIterator<Item = DVec3>) -> Self {
        let mut b = Self::EMPTY;
        for p in points {
            b.include(p, p);
        }
        b
    }

    /// Whether the box holds at least one point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        !(self.min.cmple(self.max).all())
    }

    /// `max − min`.
    #[must_use]
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }
}

/// A ray `origin + t·dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: DVec3,
    /// Direction (any non-zero length).
    pub dir: DVec3,
}

impl Ray {
    /// The ray from `origin` along `dir`.
    #[must_use]
    pub const fn new(origin: DVec3, dir: DVec3) -> Self {
        Self { origin, dir }
    }

    /// The point at parameter `t`.
    #[must_use]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + self.dir * t
    }
}

/// A ray–surface intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f64,
    /// Unit surface normal (see the module docs for its orientation).
    pub normal: DVec3,
    /// Surface parameters: barycentric `(u, v)` of vertices 1 and 2 for a
    /// triangle, 0 otherwise.
    pub u: f64,
    /// See [`Hit::u`].
    pub v: f64,
}

impl Hit {
    /// A hit at `t` with unit normal `normal` and no surface parameters.
    #[must_use]
    pub const fn new(t: f64, normal: DVec3) -> Self {
        Self {
            t,
            normal,
            u: 0.0,
            v: 0.0,
        }
    }
}
