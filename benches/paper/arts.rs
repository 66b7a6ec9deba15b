//! An ARTS-style baseline (Fujimoto et al. 1986, as the paper compared
//! against): a uniform grid of object lists over the world box, walked by a
//! float 3D-DDA (Amanatides & Woo 1987), with exact ray-sphere tests and a
//! mailbox per sphere so that a sphere spanning several cells is tested
//! once per ray.
//!
//! Hit semantics: a ray's result is the nearest exact intersection
//! `t > 0` with any sphere (or none). The walk stops in the first cell whose
//! exit lies beyond the nearest intersection found so far.

use glam::DVec3;

/// A sphere in world units.
#[derive(Clone, Copy, Debug)]
pub struct Sphere {
    /// Centre.
    pub centre: DVec3,
    /// Radius.
    pub radius: f64,
}

/// A uniform grid of `g³` cells over `[lo, lo + size]³`, object lists in
/// compressed rows.
#[derive(Debug)]
pub struct Grid {
    g: usize,
    lo: DVec3,
    cell: f64,
    /// `start[c]..start[c + 1]` are cell `c`'s entries in `items`.
    start: Vec<u32>,
    items: Vec<u32>,
    spheres: Vec<Sphere>,
}

/// Cell range `[a, b]` covered by `[lo, hi]` on one axis.
fn cell_range(lo: f64, hi: f64, origin: f64, cell: f64, g: usize) -> (usize, usize) {
    let top = g as f64 - 1.0;
    let a = ((lo - origin) / cell).floor().clamp(0.0, top) as usize;
    let b = ((hi - origin) / cell).floor().clamp(0.0, top) as usize;
    (a, b)
}

impl Grid {
    /// Inserts every sphere into each cell its surface may touch (the
    /// cell box's distance to the centre is at most the radius).
    #[must_use]
    pub fn build(spheres: &[Sphere], g: usize, lo: DVec3, size: f64) -> Self {
        let cell = size / g as f64;
        let mut counts = vec![0u32; g * g * g + 1];
        let visit = |s: &Sphere, f: &mut dyn FnMut(usize)| {
            let r = DVec3::splat(s.radius);
            let (x0, x1) = cell_range(s.centre.x - r.x, s.centre.x + r.x, lo.x, cell, g);
            let (y0, y1) = cell_range(s.centre.y - r.y, s.centre.y + r.y, lo.y, cell, g);
            let (z0, z1) = cell_range(s.centre.z - r.z, s.centre.z + r.z, lo.z, cell, g);
            for z in z0..=z1 {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let cmin = lo + DVec3::new(x as f64, y as f64, z as f64) * cell;
                        let cmax = cmin + DVec3::splat(cell);
                        let d = s.centre.clamp(cmin, cmax) - s.centre;
                        if d.length_squared() <= s.radius * s.radius {
                            f(x + g * (y + g * z));
                        }
                    }
                }
            }
        };
        for s in spheres {
            visit(s, &mut |c| counts[c + 1] += 1);
        }
        for i in 1..counts.len() {
            counts[i] += counts[i - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[g * g * g] as usize];
        for (i, s) in spheres.iter().enumerate() {
            visit(s, &mut |c| {
                items[fill[c] as usize] = i as u32;
                fill[c] += 1;
            });
        }
        Self {
            g,
            lo,
            cell,
            start: counts,
            items,
            spheres: spheres.to_vec(),
        }
    }

    /// A fresh mailbox for [`Grid::trace`] (one slot per sphere).
    #[must_use]
    pub fn mailbox(&self) -> Vec<u32> {
        vec![u32::MAX; self.spheres.len()]
    }

    /// The nearest intersection `t > 0` of `o + t·d` (`d` unit) with a
    /// sphere, walking the grid; `ray_id` must differ between rays that
    /// share `mailbox`. Returns `(t, cells visited, sphere tests)`.
    pub fn trace(
        &self,
        o: DVec3,
        d: DVec3,
        ray_id: u32,
        mailbox: &mut [u32],
    ) -> (Option<f64>, u32, u32) {
        let g = self.g as i64;
        let hi = self.lo + DVec3::splat(self.cell * self.g as f64);
        // Clip to the grid box.
        let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
        for k in 0..3 {
            if d[k] == 0.0 {
                if o[k] < self.lo[k] || o[k] > hi[k] {
                    return (None, 0, 0);
                }
            } else {
                let a = (self.lo[k] - o[k]) / d[k];
                let b = (hi[k] - o[k]) / d[k];
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if t0 > t1 {
            return (None, 0, 0);
        }
        let p = o + d * t0;
        let mut cellc = [0i64; 3];
        let mut step = [0i64; 3];
        let mut t_max = [f64::INFINITY; 3];
        let mut t_delta = [f64::INFINITY; 3];
        for k in 0..3 {
            let c = (((p[k] - self.lo[k]) / self.cell).floor() as i64).clamp(0, g - 1);
            cellc[k] = c;
            if d[k] > 0.0 {
                step[k] = 1;
                let edge = self.lo[k] + (c + 1) as f64 * self.cell;
                t_max[k] = (edge - o[k]) / d[k];
                t_delta[k] = self.cell / d[k];
            } else if d[k] < 0.0 {
                step[k] = -1;
                let edge = self.lo[k] + c as f64 * self.cell;
                t_max[k] = (edge - o[k]) / d[k];
                t_delta[k] = -self.cell / d[k];
            }
        }
        let mut best = f64::INFINITY;
        let (mut cells, mut tests) = (0u32, 0u32);
        loop {
            cells += 1;
            let c = (cellc[0] + g * (cellc[1] + g * cellc[2])) as usize;
            let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
            for &i in &self.items[a..b] {
                let slot = &mut mailbox[i as usize];
                if *slot == ray_id {
                    continue;
                }
                *slot = ray_id;
                tests += 1;
                let s = self.spheres[i as usize];
                if let Some(t) = hit_sphere(o, d, s) {
                    best = best.min(t);
                }
            }
            // Axis of the nearest boundary.
            let k = if t_max[0] < t_max[1] {
                if t_max[0] < t_max[2] { 0 } else { 2 }
            } else if t_max[1] < t_max[2] {
                1
            } else {
                2
            };
            let exit = t_max[k];
            if best <= exit || exit > t1 {
                break;
            }
            cellc[k] += step[k];
            if cellc[k] < 0 || cellc[k] >= g {
                break;
            }
            t_max[k] += t_delta[k];
        }
        (best.is_finite().then_some(best), cells, tests)
    }
}

/// The nearest `t > 0` where `o + t·d` (`d` unit) meets the sphere.
#[inline]
fn hit_sphere(o: DVec3, d: DVec3, s: Sphere) -> Option<f64> {
    let oc = o - s.centre;
    let b = oc.dot(d);
    let c = oc.length_squared() - s.radius * s.radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let q = disc.sqrt();
    let t = -b - q;
    if t > 1e-9 {
        return Some(t);
    }
    let t = -b + q;
    (t > 1e-9).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grid walk finds the same nearest hit as testing every sphere.
    #[test]
    fn grid_matches_brute_force() {
        let mut state = 7u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let spheres: Vec<Sphere> = (0..200)
            .map(|_| Sphere {
                centre: DVec3::new(rnd(), rnd(), rnd()) * 236.0 + 10.0,
                radius: 10.0,
            })
            .collect();
        for g in [1, 7, 40] {
            let grid = Grid::build(&spheres, g, DVec3::ZERO, 256.0);
            let mut mb = grid.mailbox();
            for id in 0..2000u32 {
                let o = DVec3::new(rnd(), rnd(), rnd()) * 600.0 - 172.0;
                let d = (DVec3::new(rnd(), rnd(), rnd()) - 0.5).normalize();
                let (t, _, _) = grid.trace(o, d, id, &mut mb);
                let brute = spheres
                    .iter()
                    .filter_map(|s| hit_sphere(o, d, *s))
                    .fold(f64::INFINITY, f64::min);
                match t {
                    Some(t) => assert!((t - brute).abs() < 1e-9, "g {g} ray {id}"),
                    None => {
                        // Only hits outside the grid box may be missed.
                        if brute.is_finite() {
                            let p = o + d * brute;
                            assert!(
                                p.min_element() < -1e-6 || p.max_element() > 256.0 + 1e-6,
                                "g {g} ray {id}"
                            );
                        }
                    }
                }
            }
        }
    }
}
