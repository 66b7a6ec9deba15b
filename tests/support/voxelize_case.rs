//! The fuzz case of the cargo-fuzz target `voxelize`
//! (`fuzz/fuzz_targets/voxelize.rs`), shared with the replay test in
//! `tests/fuzz_regressions.rs`, so a crash file replays under `cargo test`.
//!
//! Fuzz target `voxelize`: arbitrary bytes become a raster size, a
//! separation and one primitive with arbitrary parameters (huge
//! coordinates, degenerate triangles, zero or negative radii, shapes partly
//! or wholly outside the raster). The primitive is voxelized into a plane and
//! checked:
//!
//! * no panic (any input; refusals are error values);
//! * every offered voxel lies inside the raster and within one voxel of the
//!   object's bounding box (no runaway offers), and shapes that promise one
//!   offer per voxel never offer a voxel twice;
//! * closed shapes (sphere, box, torus, capped cone) lying inside the raster
//!   are tunnel-free along the probe rays of `rrt_core::check_voxelize` fired
//!   from a voxel inside them, in the connectivity matching the separation
//!   (and Adaptive over proximity flags for Six).

use arbitrary::Arbitrary;
use rrt_core::check_voxelize::{check_closed, probe_targets};
use rrt_core::discrete_ray::Connectivity;
use rrt_core::fixed::{VOXEL, voxel_centre};
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Segment, Sphere, Torus, Triangle};
use rrt_core::proximity::flag_neighbourhood;
use rrt_core::raster::{Extent, Raster, RasterMut, cell};
use rrt_core::voxelize::volume::Block;
use rrt_core::voxelize::{
    NORMAL_ONE, Separation, Surfel, VoxelSink, cone, cuboid, line, patch, sphere, torus, triangle,
    volume,
};

/// A coordinate: `mode` picks the raw value (mostly huge), a value near the
/// raster, or one on the voxel lattice / voxel centres near it.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub struct C {
    raw: i64,
    mode: u8,
}

/// The primitive to voxelize (a fuzz input: the variants' sizes do not matter).
#[allow(clippy::large_enum_variant, reason = "decoded once per fuzz input")]
#[derive(Arbitrary, Debug)]
pub enum Shape {
    Sphere {
        centre: [C; 3],
        radius: C,
        solid: bool,
    },
    Cuboid {
        min: [C; 3],
        max: [C; 3],
        solid: bool,
    },
    Triangle {
        v: [[C; 3]; 3],
        normals: Option<[[i32; 3]; 3]>,
    },
    Polygon {
        v: Vec<[C; 3]>,
    },
    Mesh {
        v: Vec<[C; 3]>,
        faces: Vec<[u8; 3]>,
    },
    Segment {
        a: [C; 3],
        b: [C; 3],
    },
    Cone {
        base: [C; 3],
        base_radius: C,
        apex: [C; 3],
        apex_radius: C,
        capped: bool,
    },
    Torus {
        centre: [C; 3],
        axis: [i32; 3],
        major: C,
        minor: C,
    },
    Patch {
        control: [[[C; 3]; 4]; 4],
    },
    Volume {
        dims: [u8; 3],
        offset: [i8; 3],
        threshold: u16,
        samples: Vec<u16>,
    },
}

#[derive(Arbitrary, Debug)]
pub struct Input {
    dims: [u8; 3],
    six: bool,
    shape: Shape,
}

/// Records offers: outside the raster, outside the allowed box, repeats.
struct Sink<'a> {
    extent: Extent,
    plane: &'a mut [u8],
    /// Voxel box `[lo, hi]` every offer must lie in.
    lo: [i64; 3],
    hi: [i64; 3],
    offers: u64,
    repeats: u64,
}

/// Bit marking "offered" in the scratch plane (the other bits are the
/// raster's).
const SEEN: u8 = 1 << 7;

impl VoxelSink for Sink<'_> {
    fn offer(&mut self, v: [u32; 3], s: Surfel) {
        self.offers += 1;
        let i = self
            .extent
            .index(v)
            .unwrap_or_else(|| panic!("offer outside the raster: {v:?}"));
        for k in 0..3 {
            let x = i64::from(v[k]);
            assert!(
                x >= self.lo[k] && x <= self.hi[k],
                "offer {v:?} far from the object ({:?}..{:?})",
                self.lo,
                self.hi
            );
        }
        let n = s.normal.map(i64::from);
        let len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        let one = i64::from(NORMAL_ONE);
        // Unit to within 2^-16 relative (normals of tiny offsets included).
        assert!(
            (len2 - one * one).abs() <= (one * one) >> 16,
            "normal not unit: {s:?}"
        );
        let c = &mut self.plane[i];
        if *c & SEEN != 0 {
            self.repeats += 1;
        }
        *c |= SEEN | cell::OPAQUE;
    }
}

/// A point in fixed units.
type Point = [i64; 3];
/// Whether a fixed-point point lies inside a closed shape.
type Inside = Box<dyn Fn(Point) -> bool>;

/// Runs every check on one decoded input; panics on a violation (the fuzzer
/// reports the panic as a crash).
pub fn run(input: Input) {
    let dims = input.dims.map(|d| u32::from(d % 40) + 1);
    let extent = Extent::new(dims[0], dims[1], dims[2]).unwrap();
    let n = i64::from(*dims.iter().max().unwrap());
    let coord = |c: C| -> i64 {
        match c.mode % 5 {
            0 => c.raw,
            1 => c.raw % (1 << 42),
            2 => c.raw.rem_euclid(3 * n * VOXEL) - n * VOXEL,
            3 => (c.raw.rem_euclid(3 * n) - n) * VOXEL,
            _ => (c.raw.rem_euclid(3 * n) - n) * VOXEL + VOXEL / 2,
        }
    };
    let pt = |p: [C; 3]| p.map(coord);
    let sep = if input.six {
        Separation::Six
    } else {
        Separation::TwentySix
    };
    let mut plane = vec![0u8; extent.len()];
    // Object bounding box in fixed units; offers must lie within one voxel.
    let bbox = |pts: &[[i64; 3]], r: i64| -> ([i64; 3], [i64; 3]) {
        let lo = [0, 1, 2].map(|k| {
            pts.iter()
                .map(|p| p[k])
                .min()
                .unwrap_or(0)
                .saturating_sub(r.max(0))
        });
        let hi = [0, 1, 2].map(|k| {
            pts.iter()
                .map(|p| p[k])
                .max()
                .unwrap_or(0)
                .saturating_add(r.max(0))
        });
        (
            lo.map(|x| x.div_euclid(VOXEL) - 1),
            hi.map(|x| x.div_euclid(VOXEL) + 1),
        )
    };
    let mut closed: Option<(Point, Inside)> = None;
    let mut once = true;
    let (lo, hi);
    macro_rules! sink {
        () => {
            Sink {
                extent,
                plane: &mut plane,
                lo,
                hi,
                offers: 0,
                repeats: 0,
            }
        };
    }
    let (offers, repeats) = match input.shape {
        Shape::Sphere {
            centre,
            radius,
            solid,
        } => {
            let s = Sphere {
                centre: pt(centre),
                radius: coord(radius),
            };
            (lo, hi) = bbox(&[s.centre], s.radius);
            let mut k = sink!();
            let r = if solid {
                sphere::solid(&s, sep, extent, &mut k)
            } else {
                sphere::surface(&s, sep, extent, &mut k)
            };
            if r.is_ok() && !solid {
                let (c, rad) = (s.centre, s.radius);
                closed = Some((
                    c,
                    Box::new(move |p: [i64; 3]| {
                        (0..3).map(|k| i128::from(p[k] - c[k]).pow(2)).sum::<i128>()
                            < i128::from(rad).pow(2)
                    }),
                ));
            }
            (k.offers, k.repeats)
        }
        Shape::Cuboid { min, max, solid } => {
            let b = Cuboid {
                min: pt(min),
                max: pt(max),
            };
            (lo, hi) = bbox(&[b.min, b.max], 0);
            let mut k = sink!();
            let r = if solid {
                cuboid::solid(&b, sep, extent, &mut k)
            } else {
                cuboid::surface(&b, sep, extent, &mut k)
            };
            if r.is_ok() && !solid {
                let centre = [0, 1, 2].map(|k| b.min[k] / 2 + b.max[k] / 2);
                closed = Some((
                    centre,
                    Box::new(move |p: [i64; 3]| (0..3).all(|k| p[k] > b.min[k] && p[k] < b.max[k])),
                ));
            }
            (k.offers, k.repeats)
        }
        Shape::Triangle { v, normals } => {
            let t = Triangle {
                vertices: v.map(pt),
                normals,
            };
            (lo, hi) = bbox(&t.vertices, 0);
            let mut k = sink!();
            let _ = triangle::triangle(&t, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
        Shape::Polygon { v } => {
            let v: Vec<[i64; 3]> = v.into_iter().take(80).map(pt).collect();
            (lo, hi) = bbox(&v, 0);
            once = false;
            let mut k = sink!();
            let _ = triangle::polygon(&v, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
        Shape::Mesh { v, faces } => {
            let v: Vec<[i64; 3]> = v.into_iter().take(64).map(pt).collect();
            let f: Vec<[u32; 3]> = faces
                .into_iter()
                .take(128)
                .map(|f| f.map(u32::from))
                .collect();
            (lo, hi) = bbox(&v, 0);
            once = false;
            let mut k = sink!();
            let _ = triangle::mesh(&v, None, &f, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
        Shape::Segment { a, b } => {
            let s = Segment { a: pt(a), b: pt(b) };
            (lo, hi) = bbox(&[s.a, s.b], 0);
            let mut k = sink!();
            let _ = line::segment(&s, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            capped,
        } => {
            let c = Cone {
                base: pt(base),
                base_radius: coord(base_radius),
                apex: pt(apex),
                apex_radius: coord(apex_radius),
            };
            (lo, hi) = bbox(&[c.base, c.apex], c.base_radius.max(c.apex_radius));
            once = false;
            let mut k = sink!();
            let r = if capped {
                cone::capped(&c, sep, extent, &mut k)
            } else {
                cone::surface(&c, sep, extent, &mut k)
            };
            if r.is_ok() && capped {
                let (b, a, r0, r1) = (c.base, c.apex, c.base_radius as f64, c.apex_radius as f64);
                let axis = [0, 1, 2].map(|k| (a[k] - b[k]) as f64);
                let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
                let mid = [0, 1, 2].map(|k| b[k] / 2 + a[k] / 2);
                closed = Some((
                    mid,
                    Box::new(move |p: [i64; 3]| {
                        let w = [0, 1, 2].map(|k| (p[k] - b[k]) as f64);
                        let t = (w[0] * axis[0] + w[1] * axis[1] + w[2] * axis[2]) / len;
                        let rho = ((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) - t * t)
                            .max(0.0)
                            .sqrt();
                        let r = r0 + (r1 - r0) * t / len;
                        let m = VOXEL as f64 / 8.0;
                        t > m && t < len - m && rho < r - m
                    }),
                ));
            }
            (k.offers, k.repeats)
        }
        Shape::Torus {
            centre,
            axis,
            major,
            minor,
        } => {
            let t = Torus {
                centre: pt(centre),
                axis,
                major: coord(major),
                minor: coord(minor),
            };
            (lo, hi) = bbox(&[t.centre], t.major.saturating_add(t.minor));
            once = false;
            let mut k = sink!();
            let r = torus::surface(&t, sep, extent, &mut k);
            if r.is_ok() && t.major > t.minor {
                let a = axis.map(f64::from);
                let al = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                let a = a.map(|x| x / al);
                let (c, big, small) = (t.centre, t.major as f64, t.minor as f64);
                // A point on the tube's centre circle.
                let e = if a[0].abs() < 0.5 {
                    [1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                };
                let d = [0, 1, 2].map(|k| e[k] - a[k] * (e[0] * a[0] + e[1] * a[1] + e[2] * a[2]));
                let dl = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                let start = [0, 1, 2].map(|k| c[k] + (big * d[k] / dl) as i64);
                closed = Some((
                    start,
                    Box::new(move |p: [i64; 3]| {
                        let w = [0, 1, 2].map(|k| (p[k] - c[k]) as f64);
                        let h = w[0] * a[0] + w[1] * a[1] + w[2] * a[2];
                        let rho = ((w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) - h * h)
                            .max(0.0)
                            .sqrt();
                        ((rho - big).powi(2) + h * h).sqrt() < small - VOXEL as f64 / 8.0
                    }),
                ));
            }
            (k.offers, k.repeats)
        }
        Shape::Patch { control } => {
            let p = BezierPatch {
                control: control.map(|r| r.map(pt)),
            };
            let flat: Vec<[i64; 3]> = p.control.iter().flatten().copied().collect();
            (lo, hi) = bbox(&flat, 0);
            once = false;
            let mut k = sink!();
            let _ = patch::surface(&p, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
        Shape::Volume {
            dims: vd,
            offset,
            threshold,
            samples,
        } => {
            let vd = vd.map(|d| u32::from(d % 24));
            let count = vd.iter().map(|d| *d as usize).product::<usize>();
            let samples: Vec<u16> = samples
                .iter()
                .copied()
                .cycle()
                .take(if samples.is_empty() { 0 } else { count })
                .collect();
            let b = Block {
                samples: &samples,
                dims: vd,
                offset: offset.map(i64::from),
            };
            lo = b.offset;
            hi = [0, 1, 2].map(|k| b.offset[k] + i64::from(vd[k]));
            let mut k = sink!();
            let _ = volume::boundary(&b, threshold, sep, extent, &mut k);
            (k.offers, k.repeats)
        }
    };
    if once {
        assert_eq!(repeats, 0, "a voxel offered twice");
    }
    let _ = offers;
    // Tunnel check for closed shapes that fit inside the raster.
    let Some((origin, inside)) = closed else {
        return;
    };
    let size = dims.map(|d| i64::from(d) * VOXEL);
    if (0..3).any(|k| lo[k] < 1 || hi[k] > size[k] / VOXEL - 2) {
        return;
    }
    let ov = origin.map(|c| c.div_euclid(VOXEL));
    if (0..3).any(|k| ov[k] < 0 || ov[k] >= size[k] / VOXEL) {
        return;
    }
    if !inside(ov.map(|c| voxel_centre(c as u32))) {
        return;
    }
    for c in plane.iter_mut() {
        *c &= !SEEN;
    }
    let modes: &[Connectivity] = match sep {
        Separation::Six => &[Connectivity::Six, Connectivity::Adaptive],
        Separation::TwentySix => &[Connectivity::TwentySix],
    };
    flag_neighbourhood(&mut RasterMut::new(extent, &mut plane).unwrap());
    let raster = Raster::new(extent, &plane).unwrap();
    for &mode in modes {
        let r = check_closed(&raster, origin, mode, probe_targets(origin, 1), |v| {
            inside(v.map(voxel_centre))
        });
        if let Err(v) = r {
            panic!("tunnel: {v:?}");
        }
    }
}
