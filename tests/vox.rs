//! MagicaVoxel import: a `.vox` written here with dot_vox (two models, a
//! scene graph with a translation and a rotation, a custom palette) read
//! back, with colours and normals at known voxels, voxelized into the
//! core's builder, and damaged files.

use dot_vox::{Color, Dict, DotVoxData, Frame, Model, SceneNode, ShapeModel, Size, Voxel};
use rrt_core::raster::Extent;
use rrt_core::voxelize::NORMAL_ONE;
use rrt_host::assets::vox::{self, VoxError};
use rrt_host::voxelize::vox::VoxPlacement;
use rrt_tests::store::OneObject;

const RED: [u8; 3] = [255, 0, 0];
const GREEN: [u8; 3] = [0, 255, 0];

fn dict(pairs: &[(&str, &str)]) -> Dict {
    pairs
        .iter()
        .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
        .collect()
}

/// A transform node: node `child` placed by the frame attributes `frame`,
/// on layer `layer_id`.
fn transform(frame: &[(&str, &str)], child: u32, layer_id: u32) -> SceneNode {
    SceneNode::Transform {
        attributes: dict(&[]),
        frames: vec![Frame::new(dict(frame))],
        child,
        layer_id,
    }
}

/// A shape node of model `model_id`.
fn shape(model_id: u32) -> SceneNode {
    SceneNode::Shape {
        attributes: dict(&[]),
        models: vec![ShapeModel {
            model_id,
            attributes: dict(&[]),
        }],
    }
}

/// Model 0: a full 3×3×3 cube, red except a green centre of the top face
/// (1, 1, 2). Model 1: a 3×3×1 green wall. Scene: the cube at (10, 0, 0);
/// the wall at (0, 20, 5) turned 90° about z (`_r` = 17: rows
/// (0, −1, 0), (1, 0, 0), (0, 0, 1)).
fn data(scene: bool) -> DotVoxData {
    let mut cube = Vec::new();
    for z in 0..3u8 {
        for y in 0..3u8 {
            for x in 0..3u8 {
                let i = if (x, y, z) == (1, 1, 2) { 4 } else { 0 };
                cube.push(Voxel { x, y, z, i });
            }
        }
    }
    let mut wall = Vec::new();
    for y in 0..3u8 {
        for x in 0..3u8 {
            wall.push(Voxel { x, y, z: 0, i: 4 });
        }
    }
    let mut palette = dot_vox::DEFAULT_PALETTE.to_vec();
    palette[0] = Color {
        r: 255,
        g: 0,
        b: 0,
        a: 255,
    };
    palette[4] = Color {
        r: 0,
        g: 255,
        b: 0,
        a: 255,
    };
    let scenes = if scene {
        vec![
            transform(&[], 1, u32::MAX),
            SceneNode::Group {
                attributes: dict(&[]),
                children: vec![2, 4],
            },
            transform(&[("_t", "10 0 0")], 3, 0),
            shape(0),
            transform(&[("_t", "0 20 5"), ("_r", "17")], 5, 0),
            shape(1),
        ]
    } else {
        vec![]
    };
    DotVoxData {
        version: 150,
        index_map: vec![],
        models: vec![
            Model {
                size: Size { x: 3, y: 3, z: 3 },
                voxels: cube,
            },
            Model {
                size: Size { x: 3, y: 3, z: 1 },
                voxels: wall,
            },
        ],
        palette,
        materials: vec![],
        scenes,
        layers: vec![],
    }
}

fn bytes(scene: bool) -> Vec<u8> {
    let mut out = Vec::new();
    data(scene).write_vox(&mut out).unwrap();
    out
}

fn unit(v: [f64; 3]) -> [i32; 3] {
    let l = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    v.map(|x| (x / l * f64::from(NORMAL_ONE)).round() as i32)
}

#[track_caller]
fn assert_normal(got: [i32; 3], want: [f64; 3]) {
    let w = unit(want);
    for (a, b) in got.iter().zip(w) {
        assert!((a - b).abs() <= 2, "normal {got:?}, want {w:?}");
    }
}

#[test]
fn models_colours_and_normals() {
    let scene = vox::parse_bytes("two.vox", &bytes(true)).unwrap();
    assert_eq!(scene.models().len(), 2);
    assert_eq!(scene.models()[0].size, [3, 3, 3]);
    assert_eq!(scene.color(1), RED);
    assert_eq!(scene.color(5), GREEN);
    let cube = scene.model_voxels(0).unwrap();
    assert_eq!(cube.len(), 27);
    let at = |l: [u32; 3]| *cube.iter().find(|v| v.local == l).unwrap();
    // Corner: the diagonal; face centre: the face normal; edge: between.
    assert_normal(at([0, 0, 0]).normal, [-1.0, -1.0, -1.0]);
    assert_normal(at([2, 2, 2]).normal, [1.0, 1.0, 1.0]);
    assert_normal(at([1, 1, 0]).normal, [0.0, 0.0, -1.0]);
    assert_normal(at([2, 1, 1]).normal, [1.0, 0.0, 0.0]);
    assert_normal(at([0, 2, 1]).normal, [-1.0, 1.0, 0.0]);
    assert_eq!(at([1, 1, 2]).color, GREEN);
    assert_eq!(at([1, 1, 2]).index, 5);
    assert_eq!(at([0, 0, 0]).color, RED);
    // The centre is interior.
    assert!(at([1, 1, 1]).interior);
    assert_eq!(at([1, 1, 1]).normal, [0, 0, NORMAL_ONE]);
    assert_eq!(cube.iter().filter(|v| v.interior).count(), 1);
    // The one-voxel wall: edge voxels face outward in the plane; the
    // centre's gradient cancels and it takes its first open face (−z).
    let wall = scene.model_voxels(1).unwrap();
    let w = |l: [u32; 3]| *wall.iter().find(|v| v.local == l).unwrap();
    assert_normal(w([2, 0, 0]).normal, [1.0, -1.0, 0.0]);
    assert_normal(w([1, 1, 0]).normal, [0.0, 0.0, -1.0]);
    assert!(scene.model_voxels(2).is_none());
}

#[test]
fn scene_graph_places_models() {
    let scene = vox::parse_bytes("two.vox", &bytes(true)).unwrap();
    let inst = scene.instances();
    assert_eq!(inst.len(), 2);
    assert_eq!((inst[0].model, inst[0].translation), (0, [10, 0, 0]));
    assert_eq!(inst[0].rotation, [[1, 0, 0], [0, 1, 0], [0, 0, 1]]);
    assert_eq!((inst[1].model, inst[1].translation), (1, [0, 20, 5]));
    assert_eq!(inst[1].rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]]);
    let world = scene.world_voxels();
    assert_eq!(world.len(), 36);
    let find = |c: [i64; 3]| *world.iter().find(|v| v.cell == c).unwrap();
    // The cube's centre cell (1, 1, 1) lands on the translation.
    assert!(find([10, 0, 0]).interior);
    assert_eq!(find([10, 0, 1]).color, GREEN);
    assert_normal(find([9, -1, -1]).normal, [-1.0, -1.0, -1.0]);
    // The wall turned 90° about z: local (2, 0, 0) has its centre
    // (1.5, −0.5, 0.5) from the pivot (1, 1, 0); turned: (0.5, 1.5, 0.5),
    // cell (0, 1, 0) + (0, 20, 5). Its normal (1, −1, 0) turns to (1, 1, 0).
    let corner = find([0, 21, 5]);
    assert_normal(corner.normal, [1.0, 1.0, 0.0]);
    assert_eq!(corner.color, GREEN);
    assert_eq!(scene.world_bounds(), Some(([-2, -1, -1], [11, 21, 5])));

    // Without a scene graph every model sits at the origin, unturned.
    let flat = vox::parse_bytes("flat.vox", &bytes(false)).unwrap();
    assert_eq!(flat.instances().len(), 2);
    assert!(flat.instances().iter().all(|i| i.translation == [0; 3]));
}

/// Voxelized through the core's two-pass builder with the palette
/// colours as a texture: records carry colour and normal.
#[test]
fn voxelized_into_the_raster() {
    let scene = vox::parse_bytes("two.vox", &bytes(true)).unwrap();
    let placement = VoxPlacement {
        offset: [20, 10, 10],
        scale: 2,
    };
    let extent = Extent::cube(64).unwrap();
    let colors = scene.colors(placement);
    // The colours, made once and kept, are every world voxel's; the
    // scene's value does not include what it keeps.
    let cells = scene.world_colors();
    assert_eq!(cells.len(), scene.world_voxels().len());
    for v in scene.world_voxels() {
        assert_eq!(cells.get(&v.cell), Some(&v.color));
    }
    assert_eq!(scene.clone(), scene);
    assert_eq!(vox::parse_bytes("two.vox", &bytes(true)).unwrap(), scene);
    let offers = std::cell::RefCell::new(Vec::new());
    let built = OneObject::textured(extent, [9, 9, 9], &colors, |sink| {
        offers
            .borrow_mut()
            .push(scene.voxelize(placement, extent.dims(), sink));
    });
    // Both passes offer every voxel once.
    assert_eq!(*offers.borrow(), [36 * 8; 2]);
    assert_eq!(built.records.len(), 36 * 8);
    let store = built.store();
    // World cell (10, 0, 1) (green, top face centre: +z) is raster
    // 20 + 2·10 = 40.., 10.., 12..: all eight voxels.
    for d in 0..8u32 {
        let v = [40 + (d & 1), 10 + ((d >> 1) & 1), 12 + (d >> 2)];
        let r = store.get_voxel(v).unwrap();
        assert_eq!(r.color, GREEN, "{v:?}");
        assert_normal(r.normal_vector(), [0.0, 0.0, 1.0]);
    }
    // Corner cell (9, −1, −1): raster (38, 8, 8), red, diagonal normal.
    let r = store.get_voxel([38, 8, 8]).unwrap();
    assert_eq!(r.color, RED);
    let n = r.normal_vector();
    let want = unit([-1.0, -1.0, -1.0]);
    let dot: i64 = n
        .iter()
        .zip(want)
        .map(|(a, b)| i64::from(*a) * i64::from(b))
        .sum();
    assert!(dot as f64 > 0.999 * f64::from(NORMAL_ONE).powi(2), "{n:?}");
    assert!(store.get_voxel([37, 8, 8]).is_none());

    // A raster 41 voxels wide: the voxels at x ≥ 41 are not offered.
    struct Offers(Vec<[u32; 3]>);
    impl rrt_core::voxelize::VoxelSink for Offers {
        fn offer(&mut self, v: [u32; 3], _: rrt_core::voxelize::Surfel) {
            self.0.push(v);
        }
    }
    let mut all = Offers(Vec::new());
    scene.voxelize(placement, extent.dims(), &mut all);
    let mut narrow = Offers(Vec::new());
    let n = scene.voxelize(placement, [41, 64, 64], &mut narrow);
    let kept: Vec<[u32; 3]> = all.0.into_iter().filter(|v| v[0] < 41).collect();
    assert!(!kept.is_empty() && kept.len() < 36 * 8);
    assert_eq!(narrow.0, kept);
    assert_eq!(n, kept.len() as u64);
}

#[track_caller]
fn err(bytes: &[u8]) -> String {
    match vox::parse_bytes("bad.vox", bytes) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    }
}

fn find(hay: &[u8], needle: &[u8]) -> usize {
    hay.windows(needle.len()).position(|w| w == needle).unwrap()
}

#[test]
fn bad_files() {
    assert_eq!(
        err(b"\x89PNG\r\n\x1a\n"),
        "bad.vox: byte 0: not a MagicaVoxel file: it does not start with `VOX `"
    );
    assert_eq!(
        err(b"VOX \x96\0\0\0MAI"),
        "bad.vox: byte 11: the file ends inside the header"
    );
    let good = bytes(true);
    // Truncated: MAIN claims more than the file holds.
    let e = err(&good[..good.len() - 10]);
    assert!(
        e.starts_with("bad.vox: byte 8: chunk `MAIN` claims 0 + "),
        "{e}"
    );
    // Extra bytes after MAIN.
    let mut long = good.clone();
    long.extend_from_slice(b"junk");
    assert_eq!(
        err(&long),
        format!(
            "bad.vox: byte {}: 4 bytes after the `MAIN` chunk",
            good.len()
        )
    );
    // A child chunk whose size runs past MAIN.
    let at = find(&good, b"RGBA");
    let mut bad = good.clone();
    bad[at + 4..at + 8].copy_from_slice(&5000u32.to_le_bytes());
    let e = err(&bad);
    assert!(
        e.starts_with(&format!(
            "bad.vox: byte {at}: chunk `RGBA` claims 5000 + 0 bytes"
        )),
        "{e}"
    );
    // XYZI whose count does not match its bytes.
    let at = find(&good, b"XYZI");
    let mut bad = good.clone();
    bad[at + 12..at + 16].copy_from_slice(&26u32.to_le_bytes());
    assert_eq!(
        err(&bad),
        format!("bad.vox: byte {at}: `XYZI` claims 26 voxels (108 bytes) but holds 112 bytes")
    );
    // A voxel outside its model (x = 7 in a 3-wide model).
    let mut bad = good.clone();
    bad[at + 16 + 4 * 5] = 7;
    assert_eq!(
        err(&bad),
        format!(
            "bad.vox: byte {}: voxel (7, 1, 0) lies outside its 3×3×3 model",
            at + 36
        )
    );
    // SIZE 0 and SIZE beyond 256.
    let s = find(&good, b"SIZE");
    let mut bad = good.clone();
    bad[s + 12..s + 16].copy_from_slice(&0u32.to_le_bytes());
    assert!(err(&bad).contains("`SIZE` 0×3×3: each must be 1 to 256"));
    let mut bad = good.clone();
    bad[s + 16..s + 20].copy_from_slice(&100_000u32.to_le_bytes());
    assert!(err(&bad).contains("`SIZE` 3×100000×3"));
    // A chunk id that is not text.
    let mut bad = good.clone();
    bad[s] = 0;
    assert!(err(&bad).contains("is not text"), "{}", err(&bad));
    // A bad rotation byte and a bad translation.
    let text = |from: &[u8], to: &[u8]| {
        let mut b = good.clone();
        let i = find(&b, from);
        b.splice(i..i + from.len(), to.iter().copied());
        b
    };
    assert_eq!(
        err(&text(b"17", b"15")),
        "bad.vox: scene node 4: `_r` = `15` is not a rotation"
    );
    assert_eq!(
        err(&text(b"10 0 0", b"10 0 x")),
        "bad.vox: scene node 2: `_t` = `10 0 x` is not 3 integers"
    );
    // A cycle: node 2's child is node 0.
    let mut d = data(true);
    if let SceneNode::Transform { child, .. } = &mut d.scenes[2] {
        *child = 0;
    }
    let mut b = Vec::new();
    d.write_vox(&mut b).unwrap();
    assert!(
        err(&b).contains("deeper than 256 nodes (a cycle?)"),
        "{}",
        err(&b)
    );
    // A missing node and a missing model.
    let mut d = data(true);
    if let SceneNode::Group { children, .. } = &mut d.scenes[1] {
        children.push(42);
    }
    let mut b = Vec::new();
    d.write_vox(&mut b).unwrap();
    assert_eq!(err(&b), "bad.vox: scene node 42: no such node (6 nodes)");
    let mut d = data(true);
    if let SceneNode::Shape { models, .. } = &mut d.scenes[5] {
        models[0].model_id = 9;
    }
    let mut b = Vec::new();
    d.write_vox(&mut b).unwrap();
    assert_eq!(
        err(&b),
        "bad.vox: scene node 5: uses model 9; the file has 2"
    );
    // A missing file.
    let e = vox::read("/nonexistent/dir/x.vox").unwrap_err();
    assert!(matches!(e, VoxError::Io { .. }));
}

/// A scene node the decoder cannot read, or whose id is not its place in
/// the file, is refused at its offset: the decoder would drop it (or
/// number it by its place) and silently place the wrong nodes, or none.
#[test]
fn damaged_or_misnumbered_scene_nodes_are_refused() {
    let good = bytes(true);
    let transforms: Vec<usize> = (0..good.len() - 4)
        .filter(|&i| &good[i..i + 4] == b"nTRN")
        .collect();
    // The first transform (node 0, the root) and the second (node 2).
    let (root, second) = (transforms[0], transforms[1]);
    // A frame count far beyond the chunk's bytes: the root does not decode.
    let mut bad = good.clone();
    bad[root + 32..root + 36].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
    assert_eq!(
        err(&bad),
        format!(
            "bad.vox: byte {root}: `nTRN` scene node 0 cannot be decoded (damaged or truncated)"
        )
    );
    // Node 2 claiming to be node 7.
    let mut bad = good.clone();
    bad[second + 12..second + 16].copy_from_slice(&7u32.to_le_bytes());
    assert_eq!(
        err(&bad),
        format!(
            "bad.vox: byte {second}: `nTRN` scene node 2 holds the id 7: ids must number the scene nodes in file order"
        )
    );
}

/// A chunk inside `MAIN` with children of its own is refused at its
/// offset: nested chunks, decoded recursively, would overflow the stack
/// (a `MAIN` nested 100,000 deep is a 1.2 MB file).
#[test]
fn nested_chunks_are_refused_not_recursed() {
    // The models' chunks inside 100,000 nested MAINs.
    let models = &bytes(false)[20..];
    let depth = 100_000;
    let mut file = b"VOX \x96\0\0\0".to_vec();
    for level in 0..depth {
        let children = models.len() + 12 * (depth - 1 - level);
        file.extend_from_slice(b"MAIN");
        file.extend_from_slice(&0u32.to_le_bytes());
        file.extend_from_slice(&u32::try_from(children).unwrap().to_le_bytes());
    }
    file.extend_from_slice(models);
    assert_eq!(
        err(&file),
        format!(
            "bad.vox: byte 20: chunk `MAIN` holds {} bytes of child chunks; only `MAIN` has children",
            file.len() - 32
        )
    );
    // Any other chunk with children, too.
    let good = bytes(false);
    let at = find(&good, b"RGBA");
    let mut bad = good[..at].to_vec();
    let rgba = &good[at..];
    bad.extend_from_slice(b"RGBA");
    bad.extend_from_slice(&0u32.to_le_bytes());
    bad.extend_from_slice(&u32::try_from(rgba.len()).unwrap().to_le_bytes());
    bad.extend_from_slice(rgba);
    let main = u32::try_from(bad.len() - 20).unwrap();
    bad[16..20].copy_from_slice(&main.to_le_bytes());
    assert!(
        err(&bad).starts_with(&format!("bad.vox: byte {at}: chunk `RGBA` holds ")),
        "{}",
        err(&bad)
    );
}

/// A file of `levels` groups, each holding its next level twice (a node
/// shared by two parents), ending in the shape of a `side`³ model (or, with
/// `side` 0, in an empty group and no model): 2^levels paths through a
/// graph of 2·levels + 2 nodes.
fn shared_levels(levels: u32, side: u8) -> Vec<u8> {
    let mut scenes = Vec::new();
    for i in 0..levels {
        // Node 2i: a transform to the group 2i + 1, which holds node
        // 2i + 2 twice.
        scenes.push(transform(&[("_t", &format!("{i} 0 0"))], 2 * i + 1, 0));
        scenes.push(SceneNode::Group {
            attributes: dict(&[]),
            children: vec![2 * i + 2, 2 * i + 2],
        });
    }
    scenes.push(transform(&[], 2 * levels + 1, 0));
    let mut models = Vec::new();
    if side == 0 {
        scenes.push(SceneNode::Group {
            attributes: dict(&[]),
            children: vec![],
        });
    } else {
        scenes.push(shape(0));
        let mut voxels = Vec::new();
        for z in 0..side {
            for y in 0..side {
                for x in 0..side {
                    voxels.push(Voxel { x, y, z, i: 0 });
                }
            }
        }
        let n = u32::from(side);
        models.push(Model {
            size: Size { x: n, y: n, z: n },
            voxels,
        });
    }
    let d = DotVoxData {
        version: 150,
        index_map: vec![],
        models,
        palette: dot_vox::DEFAULT_PALETTE.to_vec(),
        materials: vec![],
        scenes,
        layers: vec![],
    };
    let mut out = Vec::new();
    d.write_vox(&mut out).unwrap();
    out
}

/// A small file can stand for very many instances, node visits or voxels
/// through shared scene nodes: each is refused, naming the file, before
/// anything is made (a 1 MB file placing 17 G voxels ran out of memory).
#[test]
fn shared_scene_nodes_cannot_blow_up() {
    // 2^12 instances of a 2³ model: read, every instance placed.
    let ok = vox::parse_bytes("ok.vox", &shared_levels(12, 2)).unwrap();
    assert_eq!(ok.instances().len(), 1 << 12);
    assert_eq!(ok.world_voxel_count(), 8 << 12);
    assert_eq!(ok.world_voxels().len(), 8 << 12);
    // 2^17 instances.
    let e = err(&shared_levels(17, 1));
    assert!(
        e.starts_with("bad.vox: scene node ")
            && e.ends_with(&format!("more than {} model instances", vox::MAX_INSTANCES)),
        "{e}"
    );
    // 2^16 instances (the most) of a 32³ model: 2^31 voxels.
    let e = err(&shared_levels(16, 32));
    assert_eq!(
        e,
        format!(
            "bad.vox: scene node 0: the 65536 model instances place 2147483648 voxels, more \
             than the limit of {}",
            vox::MAX_WORLD_VOXELS
        )
    );
    // 2^60 paths to an empty group: no instance, but the walk is bounded.
    let e = err(&shared_levels(60, 0));
    assert!(
        e.starts_with("bad.vox: scene node ")
            && e.contains(&format!(
                "visits more than {} scene nodes",
                vox::MAX_NODE_VISITS
            )),
        "{e}"
    );
}

/// A `.vox` cell wider than [`rrt_host::voxelize::vox::MAX_VOX_SCALE`]
/// raster voxels is refused at the model's key with the cell's width (not
/// as a model out of the raster's reach).
#[test]
fn a_cell_wider_than_the_limit_is_named() {
    use rrt_host::voxelize::{BuildOptions, build};
    let dir = std::env::temp_dir().join(format!("rrt-vox-cell-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.vox"), bytes(false)).unwrap();
    let p = dir.join("cell.toml");
    std::fs::write(
        &p,
        "[camera]\nfrom = [0, -6, 2]\nat = [0, 0, 0]\nangle = 40\nresolution = [8, 8]\n[material.m]\n[[object]]\nmaterial = \"m\"\nvox = { file = \"m.vox\", cell = 1000 }\n",
    )
    .unwrap();
    let scene = rrt_host::scene::Scene::load(&p).unwrap();
    let mut opts = BuildOptions::new(1024);
    opts.fit.bounds = Some(rrt_host::world::Bounds {
        min: glam::DVec3::ZERO,
        max: glam::DVec3::ONE,
    });
    let e = build(&scene, &opts, &indicatif::ProgressBar::hidden())
        .err()
        .unwrap()
        .to_string();
    assert_eq!(
        e,
        format!(
            "{}:9:7: vox cell: 1024000 raster voxels across, more than 4096; give a coarser --raster or a smaller cell",
            p.display()
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}
