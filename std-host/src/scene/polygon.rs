//! Polygons as triangles.
//!
//! An NFF polygon is the region its outline bounds: its vertices are
//! coplanar and wind counter-clockwise about the side they face, and the
//! outline may be non-convex (the SPD gears' faces, with their teeth, are
//! 144-gons). Its triangles ([`Scene::polygon_triangles`]) cover that region
//! exactly, once:
//!
//! * where the fan from vertex 0 does (every fan triangle winds like the
//!   polygon, as for every convex polygon), the fan: triangles 0, `t + 1`,
//!   `t + 2`;
//! * otherwise the polygon is cut into ears (`earcut`, the ear-clipping
//!   triangulation of mapbox/earcut) in the plane across its normal's
//!   largest component. A fan would fold back there, covering the notches
//!   between the teeth and covering much of the polygon twice.
//!
//! Each triangle is given as three vertex indices that wind like the
//! polygon (its normal on the side of the polygon's Newell normal), which
//! decides whether a refracted ray enters or leaves. A polygon whose
//! outline crosses itself has no inside the NFF format defines; its ears
//! are what ear clipping makes of it.
//!
//! The front-ends cut each polygon once, as they read it, and refuse a
//! non-convex one of more than [`MAX_NONCONVEX_VERTICES`] vertices, or one
//! that would take the scene's non-convex polygons past their
//! [`CutBudget`]: ear clipping may take time quadratic in the vertex count
//! (an outline that winds as a spiral does), so the budget bounds the time
//! a scene file can ask for.
//!
//! [`Scene::polygon_triangles`]: super::Scene::polygon_triangles

use glam::DVec3;

/// The most vertices a non-convex polygon may have.
pub const MAX_NONCONVEX_VERTICES: usize = 1 << 16;

/// The ear-clipping work one scene's non-convex polygons may ask for: the
/// squares of their vertex counts add up to at most [`CutBudget::SCENE`]
/// (one polygon of [`MAX_NONCONVEX_VERTICES`] vertices), a bound on the
/// ear clipping's steps whatever the outlines. Convex polygons, whose fan
/// is their cut, cost nothing.
/// One budget covers a whole scene: an NFF file, or a TOML scene with its
/// polygons and every OBJ mesh it loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CutBudget {
    left: u64,
}

impl Default for CutBudget {
    fn default() -> Self {
        Self::scene()
    }
}

impl CutBudget {
    /// The whole budget of one scene (2^32).
    pub const SCENE: u64 = 1 << 32;

    /// A scene's whole budget.
    #[must_use]
    pub const fn scene() -> Self {
        Self { left: Self::SCENE }
    }

    /// A budget with `left` to spend (for tests of the refusal).
    #[cfg(test)]
    pub(crate) const fn with_left(left: u64) -> Self {
        Self { left }
    }

    /// Spends the work of cutting a non-convex polygon of `n` vertices.
    fn spend(&mut self, n: usize) -> Result<(), &'static str> {
        let n = u64::try_from(n).unwrap_or(u64::MAX);
        match self.left.checked_sub(n.saturating_mul(n)) {
            Some(left) => {
                self.left = left;
                Ok(())
            }
            None => Err(
                "non-convex, and cutting it into triangles would take the scene's non-convex \
                 polygons past their budget (the squares of their vertex counts may add up to \
                 2^32, one polygon of 65536 vertices): split them into smaller polygons",
            ),
        }
    }
}

/// The polygon's normal by Newell's method (twice its area vector): the
/// side its vertices wind counter-clockwise about, for a non-convex
/// polygon too; zero for a polygon without area.
fn newell_normal(v: &[DVec3]) -> DVec3 {
    v.iter()
        .zip(v.iter().cycle().skip(1))
        .map(|(a, b)| {
            DVec3::new(
                (a.y - b.y) * (a.z + b.z),
                (a.z - b.z) * (a.x + b.x),
                (a.x - b.x) * (a.y + b.y),
            )
        })
        .sum()
}

/// Whether fan triangle `t` (vertices 0, `t + 1`, `t + 2`) winds against
/// `normal`: where the fan folds back.
fn folds(v: &[DVec3], t: usize, normal: DVec3) -> bool {
    let (a, b, c) = (v[0], v[t + 1], v[t + 2]);
    (b - a).cross(c - a).dot(normal) < 0.0
}

/// Whether the fan from vertex 0 covers the polygon `v` exactly once: no
/// fan triangle winds against the polygon.
fn fan_is_exact(v: &[DVec3], normal: DVec3) -> bool {
    (0..v.len().saturating_sub(2)).all(|t| !folds(v, t, normal))
}

/// How polygon `v` is cut (module docs): `None` for the fan from vertex 0,
/// which covers it exactly once; else its triangles, as vertex indices
/// winding like the polygon (its ears; for an outline without area, the
/// fan with each triangle wound so).
///
/// # Errors
/// A non-convex polygon of more than [`MAX_NONCONVEX_VERTICES`]
/// vertices, or one that `budget` has no room for, with the problem for
/// the front-end's message at it.
pub(crate) fn cut(
    v: &[DVec3],
    budget: &mut CutBudget,
) -> Result<Option<Box<[[u32; 3]]>>, &'static str> {
    let normal = newell_normal(v);
    if fan_is_exact(v, normal) {
        return Ok(None);
    }
    if v.len() > MAX_NONCONVEX_VERTICES {
        return Err(
            "non-convex, with more than 65536 vertices (the most a non-convex \
                    polygon may have): split it into smaller polygons",
        );
    }
    budget.spend(v.len())?;
    // Indices fit in u32: at most MAX_NONCONVEX_VERTICES vertices.
    let index = |k: usize| u32::try_from(k).unwrap_or(u32::MAX);
    Ok(Some(match ears(v, normal) {
        Some(ears) if !ears.is_empty() => ears,
        _ => (0..v.len().saturating_sub(2))
            .map(|t| {
                if folds(v, t, normal) {
                    [0, t + 2, t + 1]
                } else {
                    [0, t + 1, t + 2]
                }
                .map(index)
            })
            .collect(),
    }))
}

/// The triangles of polygon `v` as vertex indices, from its [`cut`]: the
/// fan for `None`.
pub(crate) fn triangles<'a>(
    v: &[DVec3],
    cut: Option<&'a [[u32; 3]]>,
) -> impl Iterator<Item = [usize; 3]> + 'a {
    let fan = if cut.is_none() {
        v.len().saturating_sub(2)
    } else {
        0
    };
    cut.unwrap_or_default()
        .iter()
        .map(|t| t.map(|k| k as usize))
        .chain((0..fan).map(|t| [0, t + 1, t + 2]))
}

/// The ear-clipped triangles of `v` (non-convex, at most
/// [`MAX_NONCONVEX_VERTICES`] vertices), each winding like `normal`;
/// `None` where the outline cannot be projected (no finite normal).
fn ears(v: &[DVec3], normal: DVec3) -> Option<Box<[[u32; 3]]>> {
    let n = normal.abs();
    // The plane across the normal's largest component: the projection keeps
    // the outline simple (it is a shear and scale of the polygon's plane).
    let (i, j) = if n.x >= n.y && n.x >= n.z {
        (1, 2)
    } else if n.y >= n.z {
        (2, 0)
    } else {
        (0, 1)
    };
    // Coordinates relative to vertex 0, scaled into [-2, 2]: no overflow in
    // the ear tests whatever the polygon's size or place.
    let scale = v
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0f64, f64::max);
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let plane: Vec<[f64; 2]> = v
        .iter()
        .map(|p| {
            let q = *p / scale - v[0] / scale;
            [q[i], q[j]]
        })
        .collect();
    let mut indices: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(plane, &[] as &[u32], &mut indices);
    Some(
        indices
            .chunks_exact(3)
            .filter_map(|t| {
                let mut t = [t[0], t[1], t[2]];
                let [a, b, c] = t.map(|k| v.get(k as usize));
                let (a, b, c) = (a?, b?, c?);
                if (*b - *a).cross(*c - *a).dot(normal) < 0.0 {
                    t.swap(1, 2);
                }
                Some(t)
            })
            .collect(),
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A comb in the plane z = 0, counter-clockwise seen from +z: three
    /// teeth (x in [0, 0.5], [1, 2], [3, 4]) rising from y = 1 to 3 over a
    /// base from y = 0 to 1, with notches between them (x in (0.5, 1) and
    /// (2, 3) above y = 1). Area 9. The fan from its first vertex folds
    /// back at the notches and covers them. (The integration tests' copy:
    /// `rrt_tests::COMB`.)
    pub(crate) const COMB: [(f64, f64); 12] = [
        (0.0, 0.0),
        (4.0, 0.0),
        (4.0, 3.0),
        (3.0, 3.0),
        (3.0, 1.0),
        (2.0, 1.0),
        (2.0, 3.0),
        (1.0, 3.0),
        (1.0, 1.0),
        (0.5, 1.0),
        (0.5, 3.0),
        (0.0, 3.0),
    ];

    /// The triangles of `v` as the front-ends cut it.
    fn cut_into(v: &[DVec3]) -> Vec<[usize; 3]> {
        let c = cut(v, &mut CutBudget::scene()).unwrap();
        triangles(v, c.as_deref()).collect()
    }

    /// Twice the signed area of triangle `t` of `v` in the plane z = 0.
    fn area2(v: &[DVec3], t: [usize; 3]) -> f64 {
        let [a, b, c] = t.map(|k| v[k]);
        (b - a).cross(c - a).z
    }

    fn inside_triangle(v: &[DVec3], t: [usize; 3], p: DVec3) -> bool {
        let [a, b, c] = t.map(|k| v[k]);
        let s = |u: DVec3, w: DVec3| (w - u).cross(p - u).z;
        s(a, b) > 0.0 && s(b, c) > 0.0 && s(c, a) > 0.0
    }

    /// Even–odd point-in-polygon in the plane z = 0.
    fn inside_outline(v: &[DVec3], p: DVec3) -> bool {
        let mut inside = false;
        for (a, b) in v.iter().zip(v.iter().cycle().skip(1)) {
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
                inside = !inside;
            }
        }
        inside
    }

    /// A gear's outline in the plane z = 0, counter-clockwise: `teeth`
    /// teeth between radii 0.8 and 1, four vertices each.
    fn gear(teeth: usize) -> Vec<DVec3> {
        (0..teeth * 4)
            .map(|k| {
                let angle = std::f64::consts::TAU * (k as f64 + 0.5) / (teeth * 4) as f64;
                let r = if (k / 2) % 2 == 0 { 1.0 } else { 0.8 };
                DVec3::new(r * angle.cos(), r * angle.sin(), 0.0)
            })
            .collect()
    }

    /// Every sample point of the box is inside the polygon exactly when it
    /// is inside one triangle, and never inside two: the triangles tile the
    /// polygon.
    fn assert_tiles(v: &[DVec3], tris: &[[usize; 3]]) {
        let (lo, hi) = v
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), p| {
                (l.min(*p), h.max(*p))
            });
        let n = 97;
        for i in 0..n {
            for j in 0..n {
                // Points off the lattice of the outline's coordinates.
                let p = DVec3::new(
                    lo.x + (hi.x - lo.x) * (i as f64 + 0.37) / n as f64,
                    lo.y + (hi.y - lo.y) * (j as f64 + 0.61) / n as f64,
                    0.0,
                );
                let covering = tris.iter().filter(|t| inside_triangle(v, **t, p)).count();
                assert_eq!(
                    covering,
                    usize::from(inside_outline(v, p)),
                    "point {p}: covered {covering} times"
                );
            }
        }
    }

    #[test]
    fn a_convex_polygon_is_its_fan() {
        let v: Vec<DVec3> = (0..7)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 7.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let tris = cut_into(&v);
        let fan: Vec<_> = (0..5).map(|t| [0, t + 1, t + 2]).collect();
        assert_eq!(tris, fan);
        assert_tiles(&v, &tris);
    }

    #[test]
    fn a_gear_is_cut_into_ears_that_tile_it() {
        let v = gear(24);
        let normal = newell_normal(&v);
        assert!(normal.z > 0.0);
        assert!(!fan_is_exact(&v, normal), "the gear's fan folds");
        let tris = cut_into(&v);
        assert_eq!(tris.len(), v.len() - 2);
        for t in &tris {
            assert!(area2(&v, *t) > 0.0, "{t:?} winds against the polygon");
        }
        assert_tiles(&v, &tris);
    }

    #[test]
    fn a_clockwise_comb_winds_its_ears_like_itself() {
        // Seen from +z the comb runs clockwise: its normal is −z.
        let mut v: Vec<DVec3> = COMB.map(|(x, y)| DVec3::new(x, y, 0.0)).to_vec();
        v.reverse();
        let tris = cut_into(&v);
        for t in &tris {
            assert!(area2(&v, *t) < 0.0, "{t:?} winds against the polygon");
        }
        // The tiling test's triangles wind counter-clockwise.
        let flipped: Vec<_> = tris.iter().map(|[a, b, c]| [*a, *c, *b]).collect();
        assert_tiles(&v, &flipped);
    }

    #[test]
    fn a_polygon_in_any_plane_and_place_is_cut() {
        // The gear tilted, far from the origin and huge: the same ears.
        let flat = gear(9);
        let flat_tris = cut_into(&flat);
        let tilt = glam::DQuat::from_rotation_x(1.1) * glam::DQuat::from_rotation_z(0.3);
        for (scale, offset) in [(1.0, 0.0), (1e-9, 1e3), (1e12, -1e14)] {
            let v: Vec<DVec3> = flat
                .iter()
                .map(|p| tilt * (*p * scale) + DVec3::splat(offset))
                .collect();
            let normal = newell_normal(&v);
            let tris = cut_into(&v);
            assert_eq!(tris.len(), flat_tris.len());
            for t in &tris {
                let [a, b, c] = t.map(|k| v[k]);
                assert!((b - a).cross(c - a).dot(normal) > 0.0);
            }
        }
    }

    /// Random outlines, most of them crossing themselves, some with
    /// repeated or collinear vertices: never a panic; every triangle is of
    /// the polygon's vertices and winds like it; a simple (star-shaped)
    /// outline is tiled.
    #[test]
    fn random_outlines_are_cut_without_panic() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut unit = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..3000 {
            let n = 3 + (unit() * 40.0) as usize;
            let star = case % 3 == 0;
            let mut v: Vec<DVec3> = (0..n)
                .map(|k| {
                    if star {
                        // Simple: increasing angles, random radii.
                        let a = std::f64::consts::TAU * (k as f64 + 0.5 * unit()) / n as f64;
                        let r = 0.2 + unit();
                        DVec3::new(r * a.cos(), r * a.sin(), 0.0)
                    } else {
                        // Coarse lattice: repeats and collinear runs.
                        DVec3::new((unit() * 4.0).floor(), (unit() * 4.0).floor(), 0.0)
                    }
                })
                .collect();
            if !star && case % 7 == 1 {
                v.push(v[0]);
            }
            let normal = newell_normal(&v);
            let tris = cut_into(&v);
            for t in &tris {
                assert!(t.iter().all(|&k| k < v.len()), "case {case}: {t:?}");
                let [a, b, c] = t.map(|k| v[k]);
                assert!(
                    (b - a).cross(c - a).dot(normal) >= 0.0,
                    "case {case}: {t:?}"
                );
            }
            if star {
                assert_eq!(tris.len(), n - 2, "case {case}");
                assert_tiles(&v, &tris);
            }
        }
    }

    #[test]
    fn degenerate_and_huge_polygons_are_refused_or_fanned() {
        // Collinear: no area, the fan (whose triangles have none).
        let line: Vec<DVec3> = (0..5).map(|k| DVec3::new(k as f64, 0.0, 0.0)).collect();
        assert_eq!(cut_into(&line).len(), 3);
        // A large gear is cut; one past the limit is refused.
        let big = gear(MAX_NONCONVEX_VERTICES / 4);
        let tris = cut_into(&big);
        assert_eq!(tris.len(), big.len() - 2);
        let bigger = gear(MAX_NONCONVEX_VERTICES / 4 + 1);
        let e = cut(&bigger, &mut CutBudget::scene()).unwrap_err();
        assert!(
            e.contains(&format!("more than {MAX_NONCONVEX_VERTICES} vertices")),
            "{e}"
        );
        // A large convex polygon is fine: its fan.
        let round: Vec<DVec3> = (0..MAX_NONCONVEX_VERTICES + 10)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / (MAX_NONCONVEX_VERTICES + 10) as f64;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        assert_eq!(cut(&round, &mut CutBudget::scene()), Ok(None));
    }

    /// The budget is spent by the non-convex polygons only, by the square
    /// of their vertex counts, and refuses the first it has no room for.
    #[test]
    fn non_convex_polygons_spend_the_scene_budget() {
        let comb: Vec<DVec3> = COMB.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
        let square: Vec<DVec3> = COMB[..2]
            .iter()
            .chain(&[(4.0, 4.0), (0.0, 4.0)])
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        let mut budget = CutBudget { left: 3 * 12 * 12 };
        for _ in 0..3 {
            assert!(cut(&comb, &mut budget).unwrap().is_some());
            assert_eq!(cut(&square, &mut budget), Ok(None));
        }
        assert_eq!(budget.left, 0);
        let e = cut(&comb, &mut budget).unwrap_err();
        assert!(e.contains("budget") && e.contains("2^32"), "{e}");
        assert_eq!(cut(&square, &mut budget), Ok(None));
        // The whole budget holds one of the largest non-convex polygons.
        let mut budget = CutBudget::scene();
        budget.spend(MAX_NONCONVEX_VERTICES).unwrap();
        assert!(budget.spend(3).is_err());
    }
}
