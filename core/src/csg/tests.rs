//! Unit tests of CSG by voxel Booleans.

use std::boxed::Box;
use std::collections::{HashMap, HashSet};
use std::vec;
use std::vec::Vec;

use super::*;
use crate::discrete_ray::{Connectivity, DiscreteRay};
use crate::raster::{Raster, RasterMut};
use crate::store::{Counter, Limits, RecordStore, directory_len};
use crate::testkit::Rng;
use crate::voxel::{VoxelRecord, dot_unit};

const V: i64 = VOXEL;

#[derive(Default)]
struct Collect(HashMap<[u32; 3], (u16, Surfel)>);

impl CsgSink for Collect {
    fn offer_leaf(&mut self, leaf: u16, voxel: [u32; 3], surfel: Surfel) {
        assert!(
            self.0.insert(voxel, (leaf, surfel)).is_none(),
            "{voxel:?} offered twice"
        );
    }
}

const BALL: Sphere = Sphere {
    centre: [32 * V + V / 2; 3],
    radius: 20 * V,
};

const CUTTER: Cuboid = Cuboid {
    min: [40 * V, 0, 0],
    max: [80 * V; 3],
};

/// The tree of the paper's cut: leaf 0 minus leaf 1.
const CUT: [CsgNode; 3] = [
    CsgNode::Leaf(0),
    CsgNode::Leaf(1),
    CsgNode::Difference(0, 1),
];

/// The paper's cut as a tree: [`BALL`] minus [`CUTTER`].
fn cut() -> CsgTree<'static> {
    CsgTree::new(&CUT, &[&BALL, &CUTTER]).unwrap()
}

/// Every voxel `tree` offers in `e`, and the report.
fn collect(tree: &CsgTree<'_>, e: Extent) -> (CsgReport, Collect) {
    let mut got = Collect::default();
    let rep = voxelize(tree, e, &mut got);
    (rep, got)
}

/// The paper's cut: a sphere minus a box. Cut-face voxels carry the box's
/// normal flipped (and the box's leaf), all others the sphere's.
#[test]
fn sphere_minus_box_normals() {
    let e = Extent::cube(64).unwrap();
    let (s, b) = (BALL, CUTTER);
    let tree = cut();
    let (rep, got) = collect(&tree, e);
    assert_eq!(rep.voxels as usize, got.0.len());
    let (mut cut, mut round) = (0, 0);
    for (v, (leaf, sf)) in &got.0 {
        let c = v.map(voxel_centre);
        assert!(c[0] < 40 * V, "{v:?} lies in the removed part");
        let ds = s.sample(c).unwrap().distance;
        let db = b.sample(c).unwrap().distance;
        if -db > ds {
            assert_eq!(*leaf, 1, "{v:?}");
            assert_eq!(sf.normal, [NORMAL_ONE, 0, 0], "{v:?}: box normal flipped");
            assert_eq!(sf.distance as i64, db);
            cut += 1;
        } else {
            assert_eq!(*leaf, 0, "{v:?}");
            let want = normalize(sub(c, s.centre)).unwrap();
            assert_eq!(sf.normal, want, "{v:?}: sphere normal");
            round += 1;
        }
    }
    // The cut disk at x = 40 has radius ~18.6 voxels: ~1000 voxels in the
    // x = 39 layer.
    assert!(cut > 900, "{cut} cut voxels");
    assert!(round > 2000, "{round} sphere voxels");
    // Every x = 39 voxel well inside the disk is a cut voxel.
    for y in 20..45u32 {
        for z in 20..45u32 {
            let (dy, dz) = (i64::from(y) - 32, i64::from(z) - 32);
            if dy * dy + dz * dz < 15 * 15 {
                let (leaf, sf) = got.0[&[39, y, z]];
                assert_eq!((leaf, sf.normal), (1, [NORMAL_ONE, 0, 0]));
                assert!(
                    !got.0.contains_key(&[38, y, z]),
                    "cut layer is one voxel thick"
                );
            }
        }
    }
}

/// The same cut through the scene builder; rays fired at the cut face from
/// outside hit it, with its attributes, for every connectivity.
#[test]
fn rays_from_outside_hit_the_cut() {
    let e = Extent::cube(64).unwrap();
    let tree = cut();

    let mut plane = vec![0u8; e.len()];
    let mut dir = vec![0u32; directory_len(e).unwrap()];
    let mut counter = Counter::new(RasterMut::new(e, &mut plane).unwrap(), &mut dir).unwrap();
    voxelize(&tree, e, &mut IgnoreLeaf(&mut counter));
    let sizing = counter.finish().unwrap();
    let mut records = vec![VoxelRecord::default(); sizing.records()];
    let mut lists = vec![0u32; sizing.list_entries()];
    let mut filler = sizing
        .fill_with_lists(
            &mut records,
            &mut lists,
            Limits {
                objects: 2,
                materials: 2,
            },
        )
        .unwrap();
    let attrs = [
        ObjectAttrs {
            object: 0,
            material: 0,
            color: [255, 0, 0],
        },
        ObjectAttrs {
            object: 1,
            material: 1,
            color: [0, 0, 255],
        },
    ];
    {
        let mut sink = LeafFill::new(&mut filler, &attrs).unwrap();
        voxelize(&tree, e, &mut sink);
        assert_eq!(sink.missing(), 0);
    }
    let used = filler.finish().unwrap().lists().len();
    let raster = Raster::new(e, &plane).unwrap();
    let store = RecordStore::with_lists(e, &dir, &records, &lists[..used]).unwrap();

    let mut rng = Rng(4);
    let mut fired = 0;
    while fired < 600 {
        let (ty, tz) = (rng.range(-15 * V, 15 * V), rng.range(-15 * V, 15 * V));
        if ty * ty + tz * tz > 15 * 15 * V * V {
            continue;
        }
        let centre = 32 * V + V / 2;
        let target = [40 * V, centre + ty, centre + tz];
        let origin = [
            70 * V + rng.range(0, 30 * V),
            target[1] + rng.range(-25 * V, 25 * V),
            target[2] + rng.range(-25 * V, 25 * V),
        ];
        let d: [i32; 3] = core::array::from_fn(|k| (target[k] - origin[k]) as i32);
        for mode in [
            Connectivity::Six,
            Connectivity::TwentySix,
            Connectivity::Adaptive,
        ] {
            let mut ray = DiscreteRay::new(e, origin, d).unwrap().unwrap();
            let hit = ray
                .first_hit(&raster, mode)
                .unwrap()
                .unwrap_or_else(|| panic!("{mode:?} ray {origin:?} -> {target:?} missed"));
            let r = store.get(hit.index).unwrap();
            assert_eq!(
                store.owner(r),
                1,
                "{mode:?} hit {:?} not on the cut",
                hit.voxel
            );
            assert_eq!(r.color, [0, 0, 255]);
            assert!(dot_unit(r.normal_vector(), [NORMAL_ONE, 0, 0]) > NORMAL_ONE - 100);
            assert!((38..=39).contains(&hit.voxel[0]), "{:?}", hit.voxel);
        }
        fired += 1;
    }
}

/// The Lipschitz shortcut changes nothing: the emitted set equals the
/// definition (inside, with a 26-neighbour outside) evaluated everywhere.
#[test]
fn boundary_layer_matches_brute_force_on_random_trees() {
    let e = Extent::cube(24).unwrap();
    for seed in 0..30u64 {
        let mut rng = Rng(seed);
        let mut solids: Vec<Box<dyn Solid>> = Vec::new();
        for _ in 0..3 {
            let c = [0; 3].map(|_: i64| rng.range(4 * V, 20 * V));
            let solid: Box<dyn Solid> = match rng.next_u64() % 4 {
                0 => Box::new(Sphere {
                    centre: c,
                    radius: rng.range(2 * V, 9 * V),
                }),
                1 => {
                    let h = [0; 3].map(|_: i64| rng.range(V, 8 * V));
                    Box::new(Cuboid {
                        min: [c[0] - h[0], c[1] - h[1], c[2] - h[2]],
                        max: [c[0] + h[0], c[1] + h[1], c[2] + h[2]],
                    })
                }
                2 => Box::new(Torus {
                    centre: c,
                    axis: normalize([rng.range(-9, 9), rng.range(-9, 9), 10]).unwrap(),
                    major: rng.range(3 * V, 7 * V),
                    minor: rng.range(V, 3 * V),
                }),
                _ => Box::new(Cone {
                    base: c,
                    base_radius: rng.range(V, 6 * V),
                    apex: [0; 3].map(|_: i64| rng.range(2 * V, 22 * V)),
                    apex_radius: rng.range(0, 5 * V),
                }),
            };
            solids.push(solid);
        }
        let leaves: Vec<&dyn Solid> = solids.iter().map(|b| b.as_ref()).collect();
        let ops = [
            CsgNode::Union(0, 0),
            CsgNode::Intersection(0, 0),
            CsgNode::Difference(0, 0),
        ];
        let op = |k: u64, a: u16, b: u16| match ops[(k % 3) as usize] {
            CsgNode::Union(..) => CsgNode::Union(a, b),
            CsgNode::Intersection(..) => CsgNode::Intersection(a, b),
            _ => CsgNode::Difference(a, b),
        };
        let nodes = [
            CsgNode::Leaf(0),
            CsgNode::Leaf(1),
            CsgNode::Leaf(2),
            op(rng.next_u64(), 0, 1),
            op(rng.next_u64(), 3, 2),
        ];
        let tree = CsgTree::new(&nodes, &leaves).unwrap();
        let mut got = Collect::default();
        voxelize(&tree, e, &mut got);
        let mut want = HashSet::new();
        for i in 0..e.len() {
            let v = e.coord(i).unwrap();
            let c = v.map(voxel_centre);
            if tree.sample(c).distance > 0 {
                continue;
            }
            let mut outside = false;
            for dz in [-V, 0, V] {
                for dy in [-V, 0, V] {
                    for dx in [-V, 0, V] {
                        outside |= tree.sample([c[0] + dx, c[1] + dy, c[2] + dz]).distance > 0;
                    }
                }
            }
            if outside {
                want.insert(v);
            }
        }
        let got_set: HashSet<[u32; 3]> = got.0.keys().copied().collect();
        assert_eq!(got_set, want, "seed {seed}");
    }
}

/// The distances the solids report are 1-Lipschitz (what the shortcut
/// relies on), checked on random point pairs.
#[test]
fn solid_distances_are_lipschitz() {
    let solids: [&dyn Solid; 4] = [
        &BALL,
        &CUTTER,
        &Torus {
            centre: [10 * V; 3],
            axis: normalize([1, 2, 3]).unwrap(),
            major: 6 * V,
            minor: 2 * V,
        },
        &Cone {
            base: [3 * V; 3],
            base_radius: 5 * V,
            apex: [9 * V, 14 * V, 4 * V],
            apex_radius: V,
        },
    ];
    let mut rng = Rng(7);
    for s in solids {
        for _ in 0..20_000 {
            let p = [0; 3].map(|_: i64| rng.range(-5 * V, 30 * V));
            let q = [0; 3].map(|_: i64| rng.range(-V, V));
            let p2 = [p[0] + q[0], p[1] + q[1], p[2] + q[2]];
            let dd = (s.sample(p).unwrap().distance - s.sample(p2).unwrap().distance).abs();
            let len = ((q.iter().map(|c| (c * c) as i128).sum::<i128>()) as u128).isqrt() as i64;
            assert!(dd <= len + 8, "{p:?} {p2:?}: Δd {dd} > |Δp| {len}");
        }
    }
}

#[test]
fn solid_normals_point_out() {
    let cone = Cone {
        base: [0, 0, 0],
        base_radius: 4 * V,
        apex: [0, 0, 10 * V],
        apex_radius: 4 * V,
    };
    // A cylinder: side normal radial, cap normals along the axis.
    let s = cone.sample([5 * V, 0, 5 * V]).unwrap();
    assert_eq!((s.distance, s.normal), (V, [NORMAL_ONE, 0, 0]));
    let s = cone.sample([0, 0, -V]).unwrap();
    assert_eq!((s.distance, s.normal), (V, [0, 0, -NORMAL_ONE]));
    let s = cone.sample([V, 0, 9 * V]).unwrap();
    assert_eq!((s.distance, s.normal), (-V, [0, 0, NORMAL_ONE]));
    let bx = CUTTER;
    let s = bx.sample([41 * V, 50 * V, 50 * V]).unwrap();
    assert_eq!((s.distance, s.normal), (-V, [-NORMAL_ONE, 0, 0]));
    let s = bx.sample([38 * V, 50 * V, 50 * V]).unwrap();
    assert_eq!((s.distance, s.normal), (2 * V, [-NORMAL_ONE, 0, 0]));
}

#[test]
fn bad_trees_and_degenerate_solids_are_refused() {
    let s = BALL;
    let zero = Sphere {
        centre: [0; 3],
        radius: 0,
    };
    let neg = Sphere {
        centre: [0; 3],
        radius: -5,
    };
    let inverted = Cuboid {
        min: [5; 3],
        max: [4; 3],
    };
    let leaves: [&dyn Solid; 4] = [&s, &zero, &neg, &inverted];
    assert_eq!(CsgTree::new(&[], &leaves).unwrap_err(), CsgError::Empty);
    assert_eq!(
        CsgTree::new(&[CsgNode::Leaf(4)], &leaves).unwrap_err(),
        CsgError::LeafOutOfRange { node: 0 }
    );
    for l in 1..4 {
        assert_eq!(
            CsgTree::new(&[CsgNode::Leaf(l)], &leaves).unwrap_err(),
            CsgError::Degenerate { leaf: l }
        );
    }
    assert_eq!(
        CsgTree::new(&[CsgNode::Leaf(0), CsgNode::Union(0, 1)], &leaves).unwrap_err(),
        CsgError::ChildOrder { node: 1 }
    );
    assert_eq!(
        CsgTree::new(&[CsgNode::Leaf(0), CsgNode::Difference(7, 0)], &leaves).unwrap_err(),
        CsgError::ChildOrder { node: 1 }
    );
    let many = [CsgNode::Leaf(0); MAX_NODES + 1];
    assert_eq!(
        CsgTree::new(&many, &leaves).unwrap_err(),
        CsgError::TooManyNodes
    );
    // Disjoint intersection: nothing to do, no panic.
    let far = Sphere {
        centre: [1000 * V; 3],
        radius: V,
    };
    let leaves2: [&dyn Solid; 2] = [&s, &far];
    let nodes = [
        CsgNode::Leaf(0),
        CsgNode::Leaf(1),
        CsgNode::Intersection(0, 1),
    ];
    let t = CsgTree::new(&nodes, &leaves2).unwrap();
    let (rep, mut got) = collect(&t, Extent::cube(64).unwrap());
    assert_eq!(rep.voxels, 0);
    // A solid wholly outside the raster: clipped to nothing.
    let t = CsgTree::new(&nodes[1..2], &leaves2).unwrap();
    assert_eq!(
        voxelize(&t, Extent::cube(64).unwrap(), &mut got).classified,
        0
    );
    // Partly outside: clipped, voxels inside only.
    let edge = Sphere {
        centre: [0; 3],
        radius: 10 * V,
    };
    let leaves3: [&dyn Solid; 1] = [&edge];
    let t = CsgTree::new(&[CsgNode::Leaf(0)], &leaves3).unwrap();
    let (rep, got) = collect(&t, Extent::cube(64).unwrap());
    assert!(rep.voxels > 100);
    assert!(got.0.keys().all(|v| v.iter().all(|c| *c < 12)));
}
