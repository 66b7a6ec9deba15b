//! The voxelizer digests: each voxelizer's offers (voxel, normal, distance,
//! in order) for seeded shapes in both separations, and its result.

use rrt_core::csg::{self, CsgNode, CsgSink, CsgTree, Solid};
use rrt_core::fixed::VOXEL;
use rrt_core::geometry::{BezierPatch, Cone, Cuboid, Point, Segment, Sphere, Torus, Triangle};
use rrt_core::raster::Extent;
use rrt_core::voxel::normalize;
use rrt_core::voxelize::volume::{self, Block};
use rrt_core::voxelize::{
    Separation, Surfel, VoxelSink, cone, cuboid, line, patch, sphere, torus, triangle,
};

use crate::digest::{Digest, Line};
use crate::rng::Rng;
use crate::traversal::SEED;

/// The voxelizers' raster (no plane: offers go straight into a digest).
pub const DIMS: [u32; 3] = [40, 36, 30];
/// Seeded shapes per voxelizer, in the order of [`digests`]: fewer of the
/// tessellated ones (cone, torus, patch), whose 128-bit setup arithmetic
/// is slow on a Cortex-M0 without a long multiply.
pub const SHAPES: [u64; 9] = [4, 4, 2, 2, 4, 2, 3, 6, 2];

/// A [`VoxelSink`] (and [`CsgSink`]) that digests every offer.
#[derive(Debug, Default)]
pub struct DigestSink(pub Digest);

impl VoxelSink for DigestSink {
    fn offer(&mut self, v: [u32; 3], s: Surfel) {
        let d = &mut self.0;
        d.item();
        d.word(u64::from(v[0]) | u64::from(v[1]) << 20 | u64::from(v[2]) << 40);
        d.words(&s.normal.map(|c| c as u64));
        d.word(u64::from(s.distance));
    }
}

impl CsgSink for DigestSink {
    fn offer_leaf(&mut self, leaf: u16, v: [u32; 3], s: Surfel) {
        self.0.word(u64::from(leaf));
        self.offer(v, s);
    }
}

const SEPARATIONS: [Separation; 2] = [Separation::Six, Separation::TwentySix];

/// A point in or around the raster (margin `m` voxels).
fn point(r: &mut Rng, n: [i64; 3], m: i64) -> Point {
    core::array::from_fn(|k| r.range(-m * VOXEL, n[k] + m * VOXEL))
}

/// A unit vector (never the zero vector).
fn unit(r: &mut Rng) -> [i32; 3] {
    let v: [i64; 3] = core::array::from_fn(|_| r.range(-1000, 1000));
    normalize(v).unwrap_or([0, 0, rrt_core::geometry::NORMAL_ONE])
}

fn radius(r: &mut Rng, lo: i64, hi: i64) -> i64 {
    r.range(lo * VOXEL, hi * VOXEL)
}

/// Every voxelizer digest, in a fixed order.
pub fn digests(out: &mut impl FnMut(Line)) {
    let Ok(e) = Extent::new(DIMS[0], DIMS[1], DIMS[2]) else {
        return;
    };
    let n = DIMS.map(|d| i64::from(d) * VOXEL);
    let run = |name: &'static str,
               salt: u64,
               f: &mut dyn FnMut(&mut Rng, &mut DigestSink, Separation)| {
        let mut sink = DigestSink::default();
        let shapes = SHAPES.get(salt as usize - 1).copied().unwrap_or(1);
        for i in 0..shapes {
            for sep in SEPARATIONS {
                let mut r = Rng::new(SEED ^ salt, i);
                f(&mut r, &mut sink, sep);
            }
        }
        Line::of(name, &sink.0)
    };
    out(run("voxelize.sphere", 1, &mut |r, s, sep| {
        let ball = Sphere {
            centre: point(r, n, 2),
            radius: if r.chance(1, 8) {
                0
            } else {
                radius(r, 0, 14) + 1
            },
        };
        let res = sphere::surface(&ball, sep, e, s);
        s.0.debug(&res);
        let res = sphere::solid(&ball, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.triangle", 2, &mut |r, s, sep| {
        let vertices = [point(r, n, 3), point(r, n, 3), point(r, n, 3)];
        let normals = r.chance(1, 2).then(|| [unit(r), unit(r), unit(r)]);
        let res = triangle::triangle(&Triangle { vertices, normals }, sep, e, s);
        s.0.debug(&res);
        // A small mesh: a quad split in two, one triangle degenerate, and
        // a pentagon.
        let q: [Point; 5] = [
            point(r, n, 1),
            point(r, n, 1),
            point(r, n, 1),
            point(r, n, 1),
            [0; 3],
        ];
        let q4 = q[0];
        let idx = [[0u32, 1, 2], [0, 2, 3], [1, 1, 3]];
        let verts = [q[0], q[1], q[2], q[3]];
        let res = triangle::mesh(&verts, None, &idx, sep, e, s);
        s.0.debug(&res);
        let c = point(r, n, 0);
        let pent: [Point; 5] = core::array::from_fn(|k| {
            let off = [[6, 0, 1], [2, 6, 0], [-5, 4, 1], [-5, -4, 0], [2, -6, 1]][k];
            core::array::from_fn(|j| c[j] + off[j] * VOXEL + q4[j] / 64)
        });
        let res = triangle::polygon(&pent, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.cone", 3, &mut |r, s, sep| {
        let c = Cone {
            base: point(r, n, 1),
            base_radius: radius(r, 0, 5),
            apex: point(r, n, 1),
            apex_radius: if r.chance(1, 3) { 0 } else { radius(r, 0, 5) },
        };
        let res = cone::surface(&c, sep, e, s);
        s.0.debug(&res);
        let res = cone::capped(&c, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.torus", 4, &mut |r, s, sep| {
        let minor = radius(r, 1, 2);
        let t = Torus {
            centre: point(r, n, 0),
            axis: unit(r),
            major: minor + radius(r, 1, 4),
            minor,
        };
        let res = torus::surface(&t, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.box", 5, &mut |r, s, sep| {
        let a = point(r, n, 2);
        let b = point(r, n, 2);
        let bx = Cuboid {
            min: core::array::from_fn(|k| a[k].min(b[k])),
            max: core::array::from_fn(|k| a[k].max(b[k]) + if r.chance(1, 4) { 0 } else { 1 }),
        };
        let res = cuboid::surface(&bx, sep, e, s);
        s.0.debug(&res);
        let res = cuboid::solid(&bx, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.patch", 6, &mut |r, s, sep| {
        let o = point(r, n, 0);
        let span = r.range(2, 4);
        let control: [[Point; 4]; 4] = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let h = r.range(-4 * VOXEL, 4 * VOXEL);
                [
                    o[0] + (i as i64 - 2) * span * VOXEL,
                    o[1] + (j as i64 - 2) * span * VOXEL,
                    o[2] + h,
                ]
            })
        });
        let res = patch::surface(&BezierPatch { control }, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.volume", 7, &mut |r, s, sep| {
        let mut samples = [0u16; 12 * 10 * 9];
        let dims = [12u32, 10, 9];
        let c = [r.range(3, 8), r.range(3, 6), r.range(2, 6)];
        for (i, v) in samples.iter_mut().enumerate() {
            let p = [(i % 12) as i64, ((i / 12) % 10) as i64, (i / 120) as i64];
            let d2: i64 = (0..3).map(|k| (p[k] - c[k]) * (p[k] - c[k])).sum();
            *v = (4000 - 300 * d2).clamp(0, 4000) as u16 + r.range(0, 50) as u16;
        }
        let block = Block {
            samples: &samples,
            dims,
            offset: [r.range(-4, 34), r.range(-4, 30), r.range(-4, 24)],
        };
        let res = volume::boundary(&block, 2000u16, sep, e, s);
        s.0.debug(&res);
        let short = Block {
            samples: &samples[1..],
            ..block
        };
        let res = volume::boundary(&short, 2000u16, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("voxelize.line", 8, &mut |r, s, sep| {
        let seg = Segment {
            a: point(r, n, 3),
            b: point(r, n, 3),
        };
        let res = line::segment(&seg, sep, e, s);
        s.0.debug(&res);
    }));
    out(run("csg", 9, &mut |r, s, sep| {
        if sep == Separation::TwentySix {
            // CSG has no separation parameter: one pass per shape.
            return;
        }
        let ball = Sphere {
            centre: point(r, n, 0),
            radius: radius(r, 3, 8),
        };
        let c = ball.centre;
        let cut = Cuboid {
            min: [c[0], c[1] - 20 * VOXEL, c[2] - 20 * VOXEL],
            max: [
                c[0] + 20 * VOXEL,
                c[1] + 20 * VOXEL,
                c[2] + r.range(0, 4) * VOXEL,
            ],
        };
        let ring = Torus {
            centre: c,
            axis: unit(r),
            major: radius(r, 3, 7),
            minor: radius(r, 1, 3),
        };
        let leaves: [&dyn Solid; 3] = [&ball, &cut, &ring];
        let nodes = [
            CsgNode::Leaf(0),
            CsgNode::Leaf(1),
            CsgNode::Difference(0, 1),
            CsgNode::Leaf(2),
            CsgNode::Union(2, 3),
            CsgNode::Intersection(4, 0),
        ];
        for k in [3usize, 6] {
            match CsgTree::new(&nodes[..k], &leaves) {
                Ok(tree) => {
                    let report = csg::voxelize(&tree, e, s);
                    s.0.debug(&report);
                }
                Err(err) => s.0.debug(&err),
            }
        }
        s.0.debug(&CsgTree::new(&[CsgNode::Union(0, 1)], &leaves).err());
    }));
}
