//! Shading maths: pure functions, no raster, matching `embree_nff`.
//!
//! The SPD readme leaves intensities open and suggests, for `nl` lights,
//! `I = sqrt(nl) / (2·nl)` per light, with the same `I` for the ambient
//! term ([`crate::scene::light_intensity`]). A hit on a surface of colour `C` is shaded
//! (Phong highlights, Whitted secondary rays) as
//!
//! ```text
//! I·Kd·C  +  Σ visible lights  I·Lrgb·( Kd·C·max(N·L, 0) + Ks·max(R·V, 0)^Shine )
//!         +  Ks·reflected  +  T·refracted
//! ```
//!
//! with `N` the normal turned to face the incoming ray (two-sided
//! shading, [`face_forward`]), `L` the unit direction to the light, `R` the
//! reflection of `L` about `N`, and `V = −ray direction`. A light the
//! surface faces away from (`N·L ≤ 0`) adds nothing and needs no shadow
//! ray ([`faces_light`]). As in `embree_nff`, the highlight is added only
//! when `Ks > 0` and `R·V > 0`, and a reflected ray is spawned only when
//! `Ks > 0`.
//!
//! Unlike `embree_nff`, which shades `T > 0` materials as opaque, rrt
//! refracts: [`refract`] bends the ray by Snell's law, entering or leaving
//! the object according to the side of the surface's own normal it comes
//! from, and falls back to the mirror direction under total internal
//! reflection.
//!
//! The final colour is linear, clamped to `[0, 1]` and stored in 8 bits
//! with round-to-nearest, as `embree_nff`'s `(uint8_t)(v*255 + 0.5)`; no
//! gamma ([`to_rgb8`]).

use glam::DVec3;

use crate::scene::Material;

/// `normal`, negated if it points along `dir` (the incoming ray's
/// direction), so that it faces the viewer: two-sided shading.
#[must_use]
pub fn face_forward(normal: DVec3, dir: DVec3) -> DVec3 {
    if normal.dot(dir) > 0.0 {
        -normal
    } else {
        normal
    }
}

/// Whether a light in unit direction `to_light` lights the side `normal`
/// faces: only then is a shadow ray fired.
#[must_use]
pub fn faces_light(normal: DVec3, to_light: DVec3) -> bool {
    normal.dot(to_light) > 0.0
}

/// The mirror direction of `dir` about the unit `normal`:
/// `dir − 2·(dir·n)·n` (either side of the normal).
#[must_use]
pub fn reflect(dir: DVec3, normal: DVec3) -> DVec3 {
    dir - normal * (2.0 * dir.dot(normal))
}

/// The ambient term `I·Kd·C`.
#[must_use]
pub fn ambient(material: &Material, intensity: f64) -> DVec3 {
    material.colour * (intensity * material.kd)
}

/// One light's contribution `I·Lrgb·(Kd·C·(N·L) + Ks·(R·V)^Shine)`, for a
/// light that is visible (its shadow ray reached it).
///
/// `normal` must face the viewer ([`face_forward`]); `dir` is the unit
/// direction of the incoming ray, `to_light` the unit direction from the
/// hit to the light and `light_rgb` its colour. Zero when the surface
/// faces away from the light.
#[must_use]
pub fn direct(
    material: &Material,
    normal: DVec3,
    dir: DVec3,
    to_light: DVec3,
    light_rgb: DVec3,
    intensity: f64,
) -> DVec3 {
    let ndl = normal.dot(to_light);
    if ndl <= 0.0 {
        return DVec3::ZERO;
    }
    let lc = light_rgb * intensity;
    let mut c = lc * material.colour * (material.kd * ndl);
    if material.ks > 0.0 {
        // Phong: R = L reflected about N, compared with V = −dir.
        let r = normal * (2.0 * ndl) - to_light;
        let rv = -r.dot(dir);
        if rv > 0.0 {
            c += lc * (material.ks * rv.powf(material.shine));
        }
    }
    c
}

/// The whole local colour: ambient plus each visible light, given as
/// `(unit direction to the light, its colour)`.
#[must_use]
pub fn local(
    material: &Material,
    normal: DVec3,
    dir: DVec3,
    visible_lights: impl IntoIterator<Item = (DVec3, DVec3)>,
    intensity: f64,
) -> DVec3 {
    visible_lights
        .into_iter()
        .fold(ambient(material, intensity), |c, (l, rgb)| {
            c + direct(material, normal, dir, l, rgb, intensity)
        })
}

/// Adds the secondary rays' colours: `local + Ks·reflected + T·refracted`.
#[must_use]
pub fn combine(material: &Material, local: DVec3, reflected: DVec3, refracted: DVec3) -> DVec3 {
    local + reflected * material.ks + refracted * material.transmittance
}

/// The direction a transmitted ray takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refraction {
    /// Bent by Snell's law (unit vector).
    Transmitted(DVec3),
    /// Total internal reflection: the mirror direction instead (unit
    /// vector); the renderer traces it with the transmitted weight `T`.
    TotalInternalReflection(DVec3),
}

impl Refraction {
    /// The direction, whichever it is.
    #[must_use]
    pub fn dir(self) -> DVec3 {
        match self {
            Self::Transmitted(d) | Self::TotalInternalReflection(d) => d,
        }
    }
}

/// Refraction of the unit direction `dir` at a surface with unit normal
/// `normal` (the surface's own, outward normal, *not* turned towards the
/// ray) between outside (index 1) and the object (index `ior`).
///
/// The ray enters when it comes from the side `normal` points to
/// (`dir·normal < 0`: from index 1 into `ior`), and leaves otherwise. With
/// `η` the ratio of the indices and `cos i` taken against the normal on the
/// incoming side, the transmitted direction is
/// `η·dir + (η·cos i − cos t)·n`, `cos t = sqrt(1 − η²(1 − cos² i))`;
/// when the root's argument is negative the light is totally reflected.
/// A non-positive or non-finite `ior` leaves the direction unchanged.
#[must_use]
pub fn refract(dir: DVec3, normal: DVec3, ior: f64) -> Refraction {
    if !(ior > 0.0 && ior.is_finite()) {
        return Refraction::Transmitted(dir);
    }
    let entering = dir.dot(normal) < 0.0;
    let (n, eta) = if entering {
        (normal, 1.0 / ior)
    } else {
        (-normal, ior)
    };
    let cos_i = -dir.dot(n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return Refraction::TotalInternalReflection(reflect(dir, n).normalize_or(dir));
    }
    let t = dir * eta + n * (eta * cos_i - k.sqrt());
    Refraction::Transmitted(t.normalize_or(dir))
}

/// One channel to 8 bits: clamped to `[0, 1]`, then `v·255 + 0.5`
/// truncated (round to nearest); NaN gives 0.
///
/// ```
/// use rrt_host::trace::shading::channel_to_u8;
/// assert_eq!([0.0, 0.5, 1.0, 7.0, -1.0, f64::NAN].map(channel_to_u8), [0, 128, 255, 255, 0, 0]);
/// ```
#[must_use]
pub fn channel_to_u8(v: f64) -> u8 {
    if v.is_nan() {
        return 0;
    }
    let scaled = v.clamp(0.0, 1.0) * 255.0 + 0.5;
    // In [0.5, 255.5]: truncation to u8 cannot overflow.
    scaled as u8
}

/// A linear colour to 8-bit RGB ([`channel_to_u8`] per channel).
#[must_use]
pub fn to_rgb8(c: DVec3) -> [u8; 3] {
    [c.x, c.y, c.z].map(channel_to_u8)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light_intensity;

    #[track_caller]
    fn close3(a: DVec3, b: DVec3) {
        assert!((a - b).length() < 1e-12, "{a} vs {b}");
    }

    fn material(kd: f64, ks: f64, shine: f64) -> Material {
        Material {
            colour: DVec3::new(1.0, 0.5, 0.25),
            kd,
            ks,
            shine,
            transmittance: 0.0,
            ior: 1.0,
            loc: None,
        }
    }

    #[test]
    fn spd_intensities() {
        assert_eq!(light_intensity(0), 0.5);
        assert_eq!(light_intensity(1), 0.5);
        assert!((light_intensity(3) - 3f64.sqrt() / 6.0).abs() < 1e-15);
        assert_eq!(light_intensity(4), 0.25);
        // nl lights of intensity I at normal incidence on a white Kd = 1
        // surface sum to sqrt(nl)/2.
        assert!((light_intensity(9) * 9.0 - 1.5).abs() < 1e-15);
    }

    #[test]
    fn two_sided_normals() {
        let n = DVec3::Z;
        assert_eq!(face_forward(n, DVec3::new(0.3, 0.0, -1.0)), n);
        assert_eq!(face_forward(n, DVec3::new(0.3, 0.0, 1.0)), -n);
        assert!(faces_light(n, DVec3::Z));
        assert!(!faces_light(n, -DVec3::Z));
        assert!(!faces_light(n, DVec3::X), "grazing light: no shadow ray");
    }

    #[test]
    fn reflection_direction() {
        let d = DVec3::new(1.0, -1.0, 0.0).normalize();
        close3(reflect(d, DVec3::Y), DVec3::new(1.0, 1.0, 0.0).normalize());
        // The side of the normal does not matter.
        close3(reflect(d, -DVec3::Y), DVec3::new(1.0, 1.0, 0.0).normalize());
        close3(reflect(-DVec3::Z, DVec3::Z), DVec3::Z);
    }

    /// Hand-computed Phong terms.
    #[test]
    fn phong_by_hand() {
        let m = material(0.8, 0.5, 3.0);
        let i = light_intensity(2);
        let down = -DVec3::Z;
        // Light straight above a surface seen straight from above:
        // N·L = 1, R = N, R·V = 1.
        let c = direct(&m, DVec3::Z, down, DVec3::Z, DVec3::ONE, i);
        close3(c, (m.colour * 0.8 + DVec3::splat(0.5)) * i);
        // Light at 45°: N·L = R·V = 1/√2.
        let l = DVec3::new(1.0, 0.0, 1.0).normalize();
        let s = 0.5f64.sqrt();
        let rgb = DVec3::new(1.0, 0.5, 0.0);
        let c = direct(&m, DVec3::Z, down, l, rgb, i);
        close3(
            c,
            rgb * i * (m.colour * (0.8 * s) + DVec3::splat(0.5 * s.powi(3))),
        );
        // The viewer on the mirror side of the light: highlight at full.
        let v = DVec3::new(1.0, 0.0, -1.0).normalize(); // ray direction
        let l = DVec3::new(1.0, 0.0, 1.0).normalize();
        let c = direct(&m, DVec3::Z, v, l, DVec3::ONE, i);
        close3(c, (m.colour * (0.8 * s) + DVec3::splat(0.5)) * i);
        // Behind the surface: nothing.
        assert_eq!(direct(&m, DVec3::Z, down, -l, DVec3::ONE, i), DVec3::ZERO);
        // Ks = 0: no highlight even with Shine 0 (0^0 avoided, as embree_nff).
        let matte = material(1.0, 0.0, 0.0);
        let c = direct(&matte, DVec3::Z, down, DVec3::Z, DVec3::ONE, i);
        close3(c, matte.colour * i);
        // Viewer beside the light, far from the mirror direction: R·V < 0,
        // no highlight (and Kd = 0: nothing at all).
        let l = DVec3::new(1.0, 0.0, 0.01).normalize();
        let d = DVec3::new(-1.0, 0.0, -0.01).normalize();
        let c = direct(&material(0.0, 1.0, 0.0), DVec3::Z, d, l, DVec3::ONE, i);
        assert_eq!(c, DVec3::ZERO);
    }

    /// The whole formula against the SPD balls floor under 3 lights.
    #[test]
    fn local_and_combined_colour() {
        // f 1 0.75 0.33 0.8 0 100000 0 1 (balls floor).
        let floor = Material {
            colour: DVec3::new(1.0, 0.75, 0.33),
            kd: 0.8,
            ks: 0.0,
            shine: 100_000.0,
            transmittance: 0.0,
            ior: 1.0,
            loc: None,
        };
        let i = light_intensity(3);
        let n = DVec3::Z;
        let d = DVec3::new(0.0, 0.6, -0.8);
        let lights = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.6, 0.0, 0.8)];
        let c = local(&floor, n, d, lights.iter().map(|&l| (l, DVec3::ONE)), i);
        let expect = floor.colour * (i * 0.8) * (1.0 + 1.0 + 0.8);
        close3(c, expect);
        let glass = Material {
            ks: 0.25,
            transmittance: 0.5,
            ior: 1.5,
            ..floor.clone()
        };
        let total = combine(&glass, c, DVec3::ONE, DVec3::new(0.2, 0.4, 0.0));
        close3(total, c + DVec3::splat(0.25) + DVec3::new(0.1, 0.2, 0.0));
    }

    #[test]
    fn refraction_by_snell() {
        let n = DVec3::Z;
        // Normal incidence: straight through, both ways.
        assert_eq!(
            refract(-DVec3::Z, n, 1.5),
            Refraction::Transmitted(-DVec3::Z)
        );
        assert_eq!(refract(DVec3::Z, n, 1.5), Refraction::Transmitted(DVec3::Z));
        // Entering glass at 45°: sin t = sin 45° / 1.5.
        let d = DVec3::new(1.0, 0.0, -1.0).normalize();
        let Refraction::Transmitted(t) = refract(d, n, 1.5) else {
            panic!("no TIR entering");
        };
        let sin_t = 0.5f64.sqrt() / 1.5;
        close3(t, DVec3::new(sin_t, 0.0, -(1.0 - sin_t * sin_t).sqrt()));
        // Leaving at 30°: sin t = 1.5 · 0.5.
        let d = DVec3::new(0.5, 0.0, 0.75f64.sqrt());
        let Refraction::Transmitted(t) = refract(d, n, 1.5) else {
            panic!("30° is below the critical angle");
        };
        close3(t, DVec3::new(0.75, 0.0, (1.0 - 0.5625f64).sqrt()));
        // Leaving at 45° > the critical angle (41.8°): total internal
        // reflection, back into the object.
        let d = DVec3::new(1.0, 0.0, 1.0).normalize();
        let r = refract(d, n, 1.5);
        assert!(matches!(r, Refraction::TotalInternalReflection(_)));
        close3(r.dir(), DVec3::new(1.0, 0.0, -1.0).normalize());
        // Index 1: unchanged.
        let d = DVec3::new(0.3, 0.4, -0.5).normalize();
        close3(refract(d, n, 1.0).dir(), d);
        // Entering then leaving through a parallel slab restores the
        // direction.
        let inside = refract(d, n, 1.7).dir();
        close3(refract(inside, -n, 1.7).dir(), d);
    }

    #[test]
    fn eight_bits_round_to_nearest() {
        assert_eq!(to_rgb8(DVec3::new(0.0, 1.0, 0.5)), [0, 255, 128]);
        assert_eq!(to_rgb8(DVec3::new(-3.0, 3.0, f64::NAN)), [0, 255, 0]);
        // Rounding boundaries: k/255 maps to k; just below (k − 0.5)/255
        // rounds down.
        for k in 0..=255u8 {
            assert_eq!(channel_to_u8(f64::from(k) / 255.0), k);
        }
        assert_eq!(channel_to_u8(0.5 / 255.0), 1);
        assert_eq!(channel_to_u8(0.4999 / 255.0), 0);
        assert_eq!(channel_to_u8(254.6 / 255.0), 255);
    }
}
