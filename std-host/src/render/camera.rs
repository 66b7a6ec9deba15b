//! The pinhole camera, exactly as `embree_nff` (`peers/embree_nff`) sets it
//! up, so that images compare pixel for pixel.
//!
//! One ray through each pixel centre. NFF's `angle` spans the centres of
//! the first and the last pixel rows, so the distance between neighbouring
//! pixel centres on an image plane at distance 1 is
//! `pitch = 2·tan(angle/2) / (H − 1)` (with `H − 1` taken as 1 for a
//! one-row image, as `embree_nff` does); pixels are square, so columns use
//! the same pitch. With `fwd = normalize(at − from)`,
//! `right = normalize(fwd × up)` and `up' = right × fwd`, pixel `(x, y)`
//! (`y = 0` at the top) looks along
//!
//! ```text
//! dir = normalize(fwd + right·(x − (W−1)/2)·pitch + up'·((H−1)/2 − y)·pitch)
//! ```
//!
//! `embree_nff` computes in `f32`; this camera computes the same formula in
//! `f64`. Like `embree_nff`, it ignores `hither`.
//!
//! Supersampling with `K × K` samples per pixel uses a box filter: the
//! samples sit at offsets `(i + 0.5)/K − 0.5` pixels from the centre on
//! each axis ([`sample_offset`]); `K = 1` is the centre ray.

use glam::DVec3;

use crate::scene::View;
use crate::world::{Ray, WORLD_LIMIT, within_world};

/// Why a camera cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CameraError {
    /// `from` and `at` coincide (or are not finite).
    #[error("camera: `from` and `at` must be distinct finite points")]
    NoDirection,
    /// `from` or `at` lies beyond [`WORLD_LIMIT`].
    #[error("camera: `from` and `at` must lie within ±{WORLD_LIMIT:e} world units")]
    BeyondWorld,
    /// `up` is zero or parallel to the view direction.
    #[error("camera: `up` must not be zero or parallel to the view direction (at − from)")]
    NoUp,
    /// The angle is not strictly between 0 and 180 degrees.
    #[error("camera: angle must be between 0 and 180 degrees (exclusive), not {0}")]
    Angle(f64),
    /// A zero image size.
    #[error("camera: image size must be at least 1×1, not {0}×{1}")]
    Size(u32, u32),
}

/// A pinhole camera for a `width × height` image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (every primary ray's origin).
    pub origin: DVec3,
    /// Unit view direction, `normalize(at − from)`.
    pub forward: DVec3,
    /// Unit right vector, `normalize(forward × up)`.
    pub right: DVec3,
    /// Unit up vector of the image, `right × forward`.
    pub up: DVec3,
    /// Distance between neighbouring pixel centres on the plane at
    /// distance 1 from the eye.
    pub pitch: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// The camera of an NFF view for a `width × height` image (the CLI may
    /// override the file's resolution).
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate view or a zero size.
    pub fn new(view: &View, width: u32, height: u32) -> Result<Self, CameraError> {
        Self::look_at(view.from, view.at, view.up, view.angle, width, height)
    }

    /// A camera at `from` looking at `at`.
    ///
    /// # Errors
    /// [`CameraError`] for a degenerate view or a zero size.
    pub fn look_at(
        from: DVec3,
        at: DVec3,
        up: DVec3,
        angle_degrees: f64,
        width: u32,
        height: u32,
    ) -> Result<Self, CameraError> {
        if width == 0 || height == 0 {
            return Err(CameraError::Size(width, height));
        }
        if !(angle_degrees > 0.0 && angle_degrees < 180.0) {
            return Err(CameraError::Angle(angle_degrees));
        }
        if !from.is_finite() {
            return Err(CameraError::NoDirection);
        }
        if !(within_world(from) && (within_world(at) || !at.is_finite())) {
            return Err(CameraError::BeyondWorld);
        }
        let forward = crate::world::unit(at - from).ok_or(CameraError::NoDirection)?;
        // Normalise `up` first, as the parser's check does, so that every
        // view the parser accepts makes a camera.
        let up_dir = crate::world::unit(up).ok_or(CameraError::NoUp)?;
        let right = forward
            .cross(up_dir)
            .try_normalize()
            .ok_or(CameraError::NoUp)?;
        let up = right.cross(forward);
        let span = f64::from(height.max(2) - 1);
        let pitch = 2.0 * (angle_degrees.to_radians() / 2.0).tan() / span;
        Ok(Self {
            origin: from,
            forward,
            right,
            up,
            pitch,
            width,
            height,
        })
    }

    /// The unit direction through image position `(x, y)` in pixels,
    /// continuous: `(0, 0)` is the centre of the top-left pixel, `x` grows
    /// to the right and `y` downwards.
    #[must_use]
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let sx = (x - f64::from(self.width - 1) * 0.5) * self.pitch;
        let sy = (f64::from(self.height - 1) * 0.5 - y) * self.pitch;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// The primary ray through the centre of pixel `(x, y)`.
    #[must_use]
    pub fn primary(&self, x: u32, y: u32) -> Ray {
        self.ray(f64::from(x), f64::from(y))
    }

    /// The ray through image position `(x, y)` (see [`Camera::direction`]).
    #[must_use]
    pub fn ray(&self, x: f64, y: f64) -> Ray {
        Ray::new(self.origin, self.direction(x, y))
    }

    /// The `k × k` supersampling rays of pixel `(x, y)`, row by row, for a
    /// box filter (average their colours). `k = 0` is taken as 1.
    pub fn samples(&self, x: u32, y: u32, k: u32) -> impl Iterator<Item = Ray> + '_ {
        let k = k.max(1);
        (0..k).flat_map(move |j| {
            (0..k).map(move |i| {
                self.ray(
                    f64::from(x) + sample_offset(i, k),
                    f64::from(y) + sample_offset(j, k),
                )
            })
        })
    }
}

/// Offset in pixels of sub-sample `i` of `k` from the pixel centre:
/// `(i + 0.5)/k − 0.5`, so the `k` samples split the pixel evenly.
///
/// ```
/// use rrt_host::render::camera::sample_offset;
/// assert_eq!(sample_offset(0, 1), 0.0);
/// assert_eq!([0, 1].map(|i| sample_offset(i, 2)), [-0.25, 0.25]);
/// ```
#[must_use]
pub fn sample_offset(i: u32, k: u32) -> f64 {
    let k = f64::from(k.max(1));
    (f64::from(i) + 0.5) / k - 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[track_caller]
    fn close(a: DVec3, b: DVec3) {
        assert!((a - b).length() < 1e-12, "{a} vs {b}");
    }

    /// Looking down −z from (0,0,5) with y up and a 90° angle on a 3×3
    /// image: pitch = 2·tan(45°)/2 = 1, so the corner pixels look along
    /// (±1, ±1, −1)/√3 and the edge centres along (±1, 0, −1)/√2.
    #[test]
    fn hand_computed_rays() {
        let cam =
            Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 90.0, 3, 3).unwrap();
        assert!((cam.pitch - 1.0).abs() < 1e-15);
        close(cam.forward, -DVec3::Z);
        close(cam.right, DVec3::X);
        close(cam.up, DVec3::Y);
        let s3 = 3f64.sqrt();
        let s2 = 2f64.sqrt();
        close(cam.primary(0, 0).dir, DVec3::new(-1.0, 1.0, -1.0) / s3);
        close(cam.primary(2, 0).dir, DVec3::new(1.0, 1.0, -1.0) / s3);
        close(cam.primary(2, 2).dir, DVec3::new(1.0, -1.0, -1.0) / s3);
        close(cam.primary(0, 1).dir, DVec3::new(-1.0, 0.0, -1.0) / s2);
        close(cam.primary(1, 2).dir, DVec3::new(0.0, -1.0, -1.0) / s2);
        close(cam.primary(1, 1).dir, -DVec3::Z);
        assert_eq!(cam.primary(0, 0).origin, DVec3::new(0.0, 0.0, 5.0));
    }

    /// A wide image keeps square pixels: a 5×3 image at 90° has pitch 1
    /// (from the 3 rows), so the leftmost column is 2 pitches off axis.
    #[test]
    fn square_pixels_on_a_wide_image() {
        let cam = Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Z, 90.0, 5, 3).unwrap();
        // forward +x, up +z: right = x × z = −y.
        close(cam.right, -DVec3::Y);
        close(cam.primary(0, 1).dir, DVec3::new(1.0, 2.0, 0.0).normalize());
        close(
            cam.primary(4, 0).dir,
            DVec3::new(1.0, -2.0, 1.0).normalize(),
        );
    }

    /// The angle spans the centres of the first and last rows.
    #[test]
    fn angle_spans_outer_row_centres() {
        let cam = Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Z, 45.0, 512, 512).unwrap();
        let top = cam.direction(255.5, 0.0);
        let bottom = cam.direction(255.5, 511.0);
        let angle = top.angle_between(bottom).to_degrees();
        assert!((angle - 45.0).abs() < 1e-9, "{angle}");
    }

    /// On an odd image the centre pixel looks exactly at `at`, from the
    /// SPD balls view (whose `up` is not perpendicular to the view).
    #[test]
    fn centre_pixel_of_odd_image_points_at_at() {
        let from = DVec3::new(2.1, 1.3, 1.7);
        let at = DVec3::new(0.3, -0.2, 0.1);
        let cam = Camera::look_at(from, at, DVec3::Z, 45.0, 513, 301).unwrap();
        let ray = cam.primary(256, 150);
        close(ray.dir, (at - from).normalize());
        let t = (at - from).length();
        close(ray.at(t), at);
        // The frame is orthonormal.
        assert!(cam.right.dot(cam.up).abs() < 1e-15 && cam.forward.dot(cam.up).abs() < 1e-15);
        assert!((cam.up.length() - 1.0).abs() < 1e-15);
        // Image up agrees with the scene's up.
        assert!(cam.up.z > 0.0);
    }

    #[test]
    fn one_row_image_as_embree_nff() {
        // embree_nff: span = (H > 1 ? H : 2) − 1.
        let cam = Camera::look_at(DVec3::ZERO, DVec3::X, DVec3::Z, 90.0, 3, 1).unwrap();
        assert!((cam.pitch - 2.0).abs() < 1e-15);
        close(cam.primary(1, 0).dir, DVec3::X);
    }

    #[test]
    fn supersampling_positions() {
        let cam =
            Camera::look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y, 90.0, 3, 3).unwrap();
        let third = [0, 1, 2].map(|i| sample_offset(i, 3));
        for (got, want) in third.into_iter().zip([-1.0 / 3.0, 0.0, 1.0 / 3.0]) {
            assert!((got - want).abs() < 1e-15, "{third:?}");
        }
        let one: Vec<Ray> = cam.samples(1, 2, 1).collect();
        assert_eq!(one, vec![cam.primary(1, 2)]);
        let four: Vec<Ray> = cam.samples(1, 1, 2).collect();
        assert_eq!(four.len(), 4);
        // Row by row: top-left sample first, at (0.75, 0.75).
        close(four[0].dir, cam.direction(0.75, 0.75));
        close(four[1].dir, cam.direction(1.25, 0.75));
        close(four[3].dir, cam.direction(1.25, 1.25));
        // The samples' mean direction is the centre ray's (symmetry).
        let mean = four.iter().map(|r| r.dir).sum::<DVec3>().normalize();
        close(mean, cam.primary(1, 1).dir);
    }

    #[test]
    fn degenerate_views_are_refused() {
        let p = DVec3::ONE;
        assert_eq!(
            Camera::look_at(p, p, DVec3::Z, 45.0, 8, 8),
            Err(CameraError::NoDirection)
        );
        assert_eq!(
            Camera::look_at(p, DVec3::ZERO, p, 45.0, 8, 8),
            Err(CameraError::NoUp)
        );
        assert_eq!(
            Camera::look_at(p, DVec3::ZERO, DVec3::Z, 180.0, 8, 8),
            Err(CameraError::Angle(180.0))
        );
        assert_eq!(
            Camera::look_at(p, DVec3::ZERO, DVec3::Z, 45.0, 0, 8),
            Err(CameraError::Size(0, 8))
        );
        assert_eq!(
            Camera::look_at(DVec3::NAN, DVec3::ZERO, DVec3::Z, 45.0, 8, 8),
            Err(CameraError::NoDirection)
        );
        assert_eq!(
            Camera::look_at(DVec3::ZERO, DVec3::X * 1e61, DVec3::Z, 45.0, 8, 8),
            Err(CameraError::BeyondWorld)
        );
        assert_eq!(
            Camera::look_at(DVec3::Y * -2e60, DVec3::ZERO, DVec3::Z, 45.0, 8, 8),
            Err(CameraError::BeyondWorld)
        );
    }
}
