//! Solid textures, functions of the world position: a checkerboard, and
//! marble and wood from Perlin noise.

use std::f64::consts::TAU;

use glam::DVec3;

use super::{TextureError, WorldTexture, invalid};

/// A 3D checkerboard: cubes of edge `size` alternating two colours, the
/// cube with its low corner at `origin` taking the first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checker {
    origin: DVec3,
    size: f64,
    colors: [[u8; 3]; 2],
}

impl Checker {
    /// A checkerboard.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] unless `origin` is finite and `size`
    /// finite and positive.
    pub fn new(origin: DVec3, size: f64, colors: [[u8; 3]; 2]) -> Result<Self, TextureError> {
        if !(origin.is_finite() && size.is_finite() && size > 0.0) {
            return Err(invalid(
                "checker",
                format!("origin {origin} / size {size}: expected finite, size positive"),
            ));
        }
        Ok(Self {
            origin,
            size,
            colors,
        })
    }
}

impl WorldTexture for Checker {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        let c = ((p - self.origin) / self.size).floor();
        let parity = (c.x + c.y + c.z).rem_euclid(2.0);
        self.colors[usize::from(parity >= 1.0)]
    }
}

/// Ken Perlin's improved gradient noise (2002) with a seeded permutation:
/// values in about `[-1, 1]`, 0 at integer lattice points.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Perlin {
    perm: [u8; 512],
}

impl Perlin {
    /// The noise for `seed` (a SplitMix64-driven Fisher–Yates shuffle of
    /// 0..256).
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut p: [u8; 256] = std::array::from_fn(|i| i as u8);
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        for i in (1..256usize).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            p.swap(i, j);
        }
        let mut perm = [0u8; 512];
        for (i, slot) in perm.iter_mut().enumerate() {
            *slot = p[i & 255];
        }
        Self { perm }
    }

    fn grad(hash: u8, x: f64, y: f64, z: f64) -> f64 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let v = if h < 4 {
            y
        } else if h == 12 || h == 14 {
            x
        } else {
            z
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    }

    /// The noise at `p` (0 for a non-finite point).
    #[must_use]
    pub fn noise(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return 0.0;
        }
        let f = p.floor();
        // Lattice cell modulo 256 (rem_euclid keeps it in 0..256).
        let cell = |v: f64| (v.rem_euclid(256.0)) as usize & 255;
        let (xi, yi, zi) = (cell(f.x), cell(f.y), cell(f.z));
        let (x, y, z) = (p.x - f.x, p.y - f.y, p.z - f.z);
        let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
        let (u, v, w) = (fade(x), fade(y), fade(z));
        let pm = |i: usize| usize::from(self.perm[i & 511]);
        let a = pm(xi) + yi;
        let (aa, ab) = (pm(a) + zi, pm(a + 1) + zi);
        let b = pm(xi + 1) + yi;
        let (ba, bb) = (pm(b) + zi, pm(b + 1) + zi);
        let h = |i: usize| self.perm[i & 511];
        let lerp = |t: f64, a: f64, b: f64| a + t * (b - a);
        lerp(
            w,
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(h(aa), x, y, z),
                    Self::grad(h(ba), x - 1.0, y, z),
                ),
                lerp(
                    u,
                    Self::grad(h(ab), x, y - 1.0, z),
                    Self::grad(h(bb), x - 1.0, y - 1.0, z),
                ),
            ),
            lerp(
                v,
                lerp(
                    u,
                    Self::grad(h(aa + 1), x, y, z - 1.0),
                    Self::grad(h(ba + 1), x - 1.0, y, z - 1.0),
                ),
                lerp(
                    u,
                    Self::grad(h(ab + 1), x, y - 1.0, z - 1.0),
                    Self::grad(h(bb + 1), x - 1.0, y - 1.0, z - 1.0),
                ),
            ),
        )
    }

    /// Turbulence: `Σ |noise(p·2ⁱ)| / 2ⁱ` over `octaves` octaves.
    #[must_use]
    pub fn turbulence(&self, p: DVec3, octaves: u32) -> f64 {
        let mut sum = 0.0;
        let mut f = 1.0;
        for _ in 0..octaves {
            sum += self.noise(p * f).abs() / f;
            f *= 2.0;
        }
        sum
    }
}

fn mix(a: [u8; 3], b: [u8; 3], t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let mut out = [0u8; 3];
    for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
        // Between two u8 values.
        *o = (f64::from(x) + (f64::from(y) - f64::from(x)) * t)
            .round()
            .clamp(0.0, 255.0) as u8;
    }
    out
}

fn check_noise_params(
    what: &'static str,
    period: f64,
    turbulence: f64,
    octaves: u32,
    scale: f64,
) -> Result<(), TextureError> {
    if !(period.is_finite() && period > 0.0 && scale.is_finite() && scale > 0.0) {
        return Err(invalid(
            what,
            format!("period {period} / noise scale {scale}: expected finite positive numbers"),
        ));
    }
    if !turbulence.is_finite() || !(1..=16).contains(&octaves) {
        return Err(invalid(
            what,
            format!(
                "turbulence {turbulence} / octaves {octaves}: expected a finite turbulence and 1 to 16 octaves"
            ),
        ));
    }
    Ok(())
}

/// Marble: veins across `direction`, `sin(2π·(q·d)/period + turbulence ·
/// turb(q/noise_scale))` of `q = p − origin`, mapped from `[-1, 1]` onto
/// `vein` … `stone`.
#[derive(Clone, Debug, PartialEq)]
pub struct Marble {
    noise: Perlin,
    origin: DVec3,
    direction: DVec3,
    period: f64,
    noise_scale: f64,
    turbulence: f64,
    octaves: u32,
    colors: [[u8; 3]; 2],
}

impl Marble {
    /// Marble with veins repeating every `period` world units along
    /// `direction`, distorted by `turbulence` × the turbulence of the
    /// noise at scale `noise_scale` (world units per noise cell) over
    /// `octaves` octaves; colours `[vein, stone]`.
    ///
    /// # Errors
    /// [`TextureError::Invalid`] for a zero direction, non-positive period
    /// or scale, or octaves outside 1..=16.
    pub fn new(
        seed: u64,
        direction: DVec3,
        period: f64,
        noise_scale: f64,
        turbulence: f64,
        octaves: u32,
        colors: [[u8; 3]; 2],
    ) -> Result<Self, TextureError> {
        check_noise_params("marble", period, turbulence, octaves, noise_scale)?;
        let direction = direction.try_normalize().ok_or_else(|| {
            invalid(
                "marble",
                format!("direction {direction} is not a usable vector"),
            )
        })?;
        Ok(Self {
            noise: Perlin::new(seed),
            origin: DVec3::ZERO,
            direction,
            period,
            noise_scale,
            turbulence,
            octaves,
            colors,
        })
    }
}

impl Marble {
    /// The same marble with its pattern moved from the world origin to
    /// `origin` (the default is the world origin).
    ///
    /// # Errors
    /// [`TextureError::Invalid`] for an origin that is not finite.
    pub fn with_origin(mut self, origin: DVec3) -> Result<Self, TextureError> {
        if !origin.is_finite() {
            return Err(invalid("marble", format!("origin {origin} is not finite")));
        }
        self.origin = origin;
        Ok(self)
    }
}

impl WorldTexture for Marble {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        let q = p - self.origin;
        let t = self.noise.turbulence(q / self.noise_scale, self.octaves);
        let s = (TAU * q.dot(self.direction) / self.period + self.turbulence * t).sin();
        mix(self.colors[0], self.colors[1], (s + 1.0) / 2.0)
    }
}

/// Wood: rings around an axis every `period` world units, each ring a
/// ramp from `early` to `late` wood, the radius disturbed by noise.
#[derive(Clone, Debug, PartialEq)]
pub struct Wood {
    noise: Perlin,
    origin: DVec3,
    axis: DVec3,
    period: f64,
    noise_scale: f64,
    turbulence: f64,
    octaves: u32,
    colors: [[u8; 3]; 2],
}

impl Wood {
    /// Wood with rings around the line through `origin` along `axis`,
    /// `period` apart, their radius disturbed by `turbulence · period` ×
    /// the turbulence at scale `noise_scale`; colours `[early, late]`.
    ///
    /// # Errors
    /// As [`Marble::new`].
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        seed: u64,
        origin: DVec3,
        axis: DVec3,
        period: f64,
        noise_scale: f64,
        turbulence: f64,
        octaves: u32,
        colors: [[u8; 3]; 2],
    ) -> Result<Self, TextureError> {
        check_noise_params("wood", period, turbulence, octaves, noise_scale)?;
        let axis = axis
            .try_normalize()
            .ok_or_else(|| invalid("wood", format!("axis {axis} is not a usable vector")))?;
        if !origin.is_finite() {
            return Err(invalid("wood", format!("origin {origin} is not finite")));
        }
        Ok(Self {
            noise: Perlin::new(seed),
            origin,
            axis,
            period,
            noise_scale,
            turbulence,
            octaves,
            colors,
        })
    }

    /// Position within the ring at `p`, in `[0, 1)`.
    #[must_use]
    pub fn ring_phase(&self, p: DVec3) -> f64 {
        let d = p - self.origin;
        let r = (d - self.axis * d.dot(self.axis)).length();
        let t = r / self.period
            + self.turbulence * self.noise.turbulence(p / self.noise_scale, self.octaves);
        t - t.floor()
    }
}

impl WorldTexture for Wood {
    fn world_color(&self, p: DVec3, _n: DVec3, _base: [u8; 3]) -> [u8; 3] {
        // Early wood for the first three quarters of a ring, then a ramp
        // to late wood.
        let f = self.ring_phase(p);
        mix(self.colors[0], self.colors[1], (f - 0.75) / 0.25)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn perlin_is_zero_on_the_lattice_and_bounded() {
        let n = Perlin::new(7);
        assert_eq!(n.noise(DVec3::new(3.0, -2.0, 5.0)), 0.0);
        let mut max: f64 = 0.0;
        for i in 0..2000 {
            let p = DVec3::new(i as f64 * 0.137, i as f64 * 0.071 - 9.0, i as f64 * 0.019);
            max = max.max(n.noise(p).abs());
        }
        assert!(max > 0.2 && max <= 1.1, "{max}");
        assert_ne!(Perlin::new(1), Perlin::new(2));
    }
}
