//! MagicaVoxel `.vox` import: each model's voxels become raster voxels
//! with their palette colours and normals estimated from the occupancy
//! gradient, so voxel art renders with reflections and shadows.
//!
//! ```
//! use dot_vox::{DotVoxData, Model, Size, Voxel};
//! use rrt_host::assets::vox;
//! // A 2×1×1 model written with dot_vox, read back.
//! let data = DotVoxData {
//!     version: 150,
//!     index_map: vec![],
//!     models: vec![Model { size: Size { x: 2, y: 1, z: 1 },
//!                          voxels: vec![Voxel { x: 0, y: 0, z: 0, i: 0 },
//!                                       Voxel { x: 1, y: 0, z: 0, i: 1 }] }],
//!     palette: dot_vox::DEFAULT_PALETTE.to_vec(),
//!     materials: vec![], scenes: vec![], layers: vec![],
//! };
//! let mut bytes = Vec::new();
//! data.write_vox(&mut bytes).unwrap();
//! let scene = vox::parse_bytes("two.vox", &bytes).unwrap();
//! let voxels = scene.model_voxels(0).unwrap();
//! assert_eq!(voxels.len(), 2);
//! // The left voxel faces −x (its only open side along the row).
//! assert!(voxels[0].normal[0] < 0);
//! ```
//!
//! # What is read
//! * every `SIZE`/`XYZI` model, the `RGBA` palette (MagicaVoxel's default
//!   palette when there is none), colour index `i` meaning palette entry
//!   `i` (1-based, as in the file);
//! * the scene graph (`nTRN`/`nGRP`/`nSHP` from node 0), if present:
//!   nested translations (`_t`) and rotations (`_r`, MagicaVoxel's signed
//!   permutation byte), of the first animation frame; shapes on hidden
//!   layers are left out. A model used by several shapes becomes several
//!   instances. Without a scene graph each model is one instance at the
//!   origin. Materials (`MATL`), cameras and render settings are ignored.
//!
//! MagicaVoxel places a model so that its centre cell
//! `⌊size/2⌋` lands on the transform's translation. World cells are in
//! MagicaVoxel's frame (right-handed, z up): a scene that is y up rotates
//! it at placement.
//!
//! # Normals
//! Each voxel's normal is the negated occupancy gradient over its 3×3×3
//! neighbourhood within its model (Zucker–Hummel weights 1, 1/√2, 1/√3
//! for face, edge and corner neighbours, as for volumes): a voxel on a
//! flat face gets the face normal, one on an edge or corner the mean
//! direction of the open sides. Where the gradient cancels (a one-voxel
//! wall, an interior voxel) the normal is the first open face direction
//! (−x, +x, −y, +y, −z, +z), or +z for an interior voxel
//! ([`ModelVoxel::interior`]).
//!
//! # Bad input
//! The chunk structure is checked before decoding: a file that is not a
//! `.vox`, a chunk whose sizes run past its parent, a chunk inside `MAIN`
//! with child chunks of its own (only `MAIN` has children; nested chunks
//! would be decoded recursively, as deep as the file nests them), a
//! `SIZE` that is not 1 to 256 per axis, an `XYZI` whose count does not match its bytes or
//! whose voxel lies outside its model, a bad palette size, a scene node
//! (`nTRN`, `nGRP`, `nSHP`) or layer (`LAYR`) chunk that does not decode
//! or whose id is not its place among its kind (the decoder would drop it
//! and renumber the rest, placing the wrong nodes), or a scene
//! graph with missing nodes, cycles, bad `_t`/`_r` values or unknown
//! models: a [`VoxError`] naming the file and the byte offset (or scene
//! node). So is a scene graph that places more than [`MAX_INSTANCES`]
//! model instances, visits more than [`MAX_NODE_VISITS`] nodes (shared
//! nodes are visited once per path to them) or places more than
//! [`MAX_WORLD_VOXELS`] voxels in all: a file of a few bytes per node can
//! stand for far more, and each is refused before its voxels are made.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use rrt_core::voxelize::NORMAL_ONE;

/// Largest model edge MagicaVoxel writes (voxel coordinates are bytes).
pub const MAX_MODEL_EDGE: u32 = 256;
/// Deepest scene graph accepted (nodes on one path from the root).
pub const MAX_DEPTH: usize = 256;
/// Most model instances a scene graph may produce.
pub const MAX_INSTANCES: usize = 1 << 16;
/// Most scene-graph nodes visited while placing the instances: a node
/// that several groups share is visited once per path to it, so a small
/// graph of shared nodes can stand for very many paths.
pub const MAX_NODE_VISITS: usize = 1 << 20;
/// Most voxels the instances may place in all (each instance places its
/// model's voxels): two full 256³ models.
pub const MAX_WORLD_VOXELS: u64 = 1 << 25;

/// Why a `.vox` file cannot be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VoxError {
    /// The file cannot be read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A chunk or field at a byte offset is wrong.
    #[error("{}: byte {offset}: {msg}", path.display())]
    Chunk {
        /// The file.
        path: PathBuf,
        /// Byte offset of the chunk or field at fault.
        offset: u64,
        /// What is wrong.
        msg: String,
    },
    /// The scene graph is wrong.
    #[error("{}: scene node {node}: {msg}", path.display())]
    Scene {
        /// The file.
        path: PathBuf,
        /// The node's index.
        node: u32,
        /// What is wrong.
        msg: String,
    },
}

/// One model: its size and voxels (`(x, y, z, palette index)`, index
/// 1..=255).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VoxModel {
    /// Cells per axis.
    pub size: [u32; 3],
    /// The voxels as in the file.
    pub voxels: Vec<[u8; 4]>,
}

/// One placed copy of a model: world cell of local cell `v` is
/// `rotation · (v − ⌊size/2⌋) + translation` (cell-exact, see
/// [`VoxInstance::to_world`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VoxInstance {
    /// Index into [`VoxScene::models`].
    pub model: usize,
    /// Signed permutation matrix, rows.
    pub rotation: [[i32; 3]; 3],
    /// World cell of the model's centre cell.
    pub translation: [i32; 3],
}

impl VoxInstance {
    /// The world cell of local cell `v` of a model of `size`: the cell
    /// whose centre is the rotated centre of `v`.
    #[must_use]
    pub fn to_world(&self, v: [u32; 3], size: [u32; 3]) -> [i64; 3] {
        // Doubled centre relative to the pivot: odd, so the rotated centre
        // is again a half-integer and (r − 1)/2 its cell, exactly.
        let c: [i64; 3] =
            std::array::from_fn(|a| 2 * (i64::from(v[a]) - i64::from(size[a] / 2)) + 1);
        std::array::from_fn(|r| {
            let rc: i64 = (0..3).map(|k| i64::from(self.rotation[r][k]) * c[k]).sum();
            (rc - 1).div_euclid(2) + i64::from(self.translation[r])
        })
    }

    /// A local direction (e.g. a normal) in the world.
    #[must_use]
    pub fn rotate(&self, n: [i32; 3]) -> [i32; 3] {
        std::array::from_fn(|r| (0..3).map(|k| self.rotation[r][k] * n[k]).sum())
    }
}

/// A voxel of a model in its local frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelVoxel {
    /// Local cell.
    pub local: [u32; 3],
    /// Palette index (1..=255).
    pub index: u8,
    /// RGB colour from the palette.
    pub color: [u8; 3],
    /// Unit normal scaled by [`NORMAL_ONE`] (local frame).
    pub normal: [i32; 3],
    /// All 26 neighbours are occupied (invisible unless cut open).
    pub interior: bool,
}

/// A voxel of the whole scene in MagicaVoxel's world frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WorldVoxel {
    /// World cell.
    pub cell: [i64; 3],
    /// RGB colour.
    pub color: [u8; 3],
    /// Unit normal scaled by [`NORMAL_ONE`] (world frame).
    pub normal: [i32; 3],
    /// See [`ModelVoxel::interior`].
    pub interior: bool,
}

/// A `.vox` file: models, their instances and the palette.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VoxScene {
    models: Vec<VoxModel>,
    instances: Vec<VoxInstance>,
    palette: Vec<[u8; 4]>,
    made: Made,
}

/// What a scene's voxels need made once, when first needed, and kept for
/// every later use (the voxelizer's passes and pieces, on any thread):
/// each model's voxels with their normals, and the colour of every world
/// cell. Not part of the scene's value: clones start without it and
/// equality ignores it.
#[derive(Debug, Default)]
struct Made {
    /// [`VoxScene::model_voxels`] of each model an instance uses.
    local: OnceLock<Vec<Option<Vec<ModelVoxel>>>>,
    /// The palette colour of each world cell (the last instance's where
    /// several place a voxel in one cell).
    colors: OnceLock<Arc<HashMap<[i64; 3], [u8; 3]>>>,
}

impl Clone for Made {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl PartialEq for Made {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for Made {}

/// Reads the `.vox` file at `path`.
///
/// # Errors
/// [`VoxError`] naming the file and the byte offset or scene node at
/// fault.
pub fn read(path: impl AsRef<Path>) -> Result<VoxScene, VoxError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| VoxError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse(path, &bytes)
}

/// Reads a `.vox` held in memory, named `name` in errors.
///
/// # Errors
/// As [`read`].
pub fn parse_bytes(name: &str, bytes: &[u8]) -> Result<VoxScene, VoxError> {
    parse(Path::new(name), bytes)
}

fn le32(b: &[u8], at: usize) -> Option<u32> {
    let s = b.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

/// Walks the chunk tree and checks sizes; returns the number of models.
fn check_chunks(path: &Path, b: &[u8]) -> Result<usize, VoxError> {
    let err = |offset: usize, msg: String| VoxError::Chunk {
        path: path.to_path_buf(),
        offset: offset as u64,
        msg,
    };
    if b.get(..4) != Some(b"VOX ") {
        return Err(err(
            0,
            "not a MagicaVoxel file: it does not start with `VOX `".into(),
        ));
    }
    if b.len() < 20 {
        return Err(err(b.len(), "the file ends inside the header".into()));
    }
    if b.get(8..12) != Some(b"MAIN") {
        return Err(err(8, "expected the `MAIN` chunk".into()));
    }
    let main_end = chunk_end(b, 8, b.len()).map_err(|m| err(8, m))?;
    if main_end < b.len() {
        return Err(err(
            main_end,
            format!("{} bytes after the `MAIN` chunk", b.len() - main_end),
        ));
    }
    let content = le32(b, 12).unwrap_or(0) as usize;
    let mut at = 20 + content;
    let mut pending_size: Option<([u32; 3], usize)> = None;
    let mut models = 0usize;
    // Scene nodes and layers are numbered by their order in the file.
    let (mut nodes, mut layers) = (0u32, 0u32);
    while at < main_end {
        let end = chunk_end(b, at, main_end).map_err(|m| err(at, m))?;
        let id = &b[at..at + 4];
        let clen = le32(b, at + 4).unwrap_or(0) as usize;
        let children = le32(b, at + 8).unwrap_or(0);
        if children != 0 {
            return Err(err(
                at,
                format!(
                    "chunk `{}` holds {children} bytes of child chunks; only `MAIN` has children",
                    String::from_utf8_lossy(id).escape_debug()
                ),
            ));
        }
        let body = &b[at + 12..at + 12 + clen];
        let name = String::from_utf8_lossy(id);
        match id {
            b"SIZE" => {
                if clen != 12 {
                    return Err(err(at, format!("`SIZE` holds {clen} bytes, expected 12")));
                }
                let s = [le32(body, 0), le32(body, 4), le32(body, 8)].map(|v| v.unwrap_or(0));
                if s.iter().any(|&n| n == 0 || n > MAX_MODEL_EDGE) {
                    return Err(err(
                        at,
                        format!(
                            "`SIZE` {}×{}×{}: each must be 1 to {MAX_MODEL_EDGE}",
                            s[0], s[1], s[2]
                        ),
                    ));
                }
                if let Some((_, o)) = pending_size {
                    return Err(err(o, "`SIZE` without its `XYZI` chunk".into()));
                }
                pending_size = Some((s, at));
            }
            b"XYZI" => {
                let Some((size, _)) = pending_size.take() else {
                    return Err(err(at, "`XYZI` without a `SIZE` chunk before it".into()));
                };
                let n = le32(body, 0).ok_or_else(|| err(at, "`XYZI` holds no count".into()))?;
                let want = (n as u64).saturating_mul(4).saturating_add(4);
                if want != clen as u64 {
                    return Err(err(
                        at,
                        format!("`XYZI` claims {n} voxels ({want} bytes) but holds {clen} bytes"),
                    ));
                }
                for (k, v) in body[4..].chunks_exact(4).enumerate() {
                    if (0..3).any(|a| u32::from(v[a]) >= size[a]) {
                        return Err(err(
                            at + 16 + 4 * k,
                            format!(
                                "voxel ({}, {}, {}) lies outside its {}×{}×{} model",
                                v[0], v[1], v[2], size[0], size[1], size[2]
                            ),
                        ));
                    }
                    if v[3] == 0 {
                        return Err(err(at + 16 + 4 * k, "voxel with colour index 0".into()));
                    }
                }
                models += 1;
            }
            b"RGBA" => {
                if clen != 1024 {
                    return Err(err(at, format!("`RGBA` holds {clen} bytes, expected 1024")));
                }
            }
            b"nTRN" | b"nGRP" | b"nSHP" => {
                let id = match id {
                    b"nTRN" => dot_vox::parse_scene_transform(body).map(|(_, n)| n.header.id),
                    b"nGRP" => dot_vox::parse_scene_group(body).map(|(_, n)| n.header.id),
                    _ => dot_vox::parse_scene_shape(body).map(|(_, n)| n.header.id),
                };
                check_numbered(id, nodes, "scene node")
                    .map_err(|m| err(at, format!("`{name}` {m}")))?;
                nodes += 1;
            }
            b"LAYR" => {
                let id = dot_vox::parse_layer(body).map(|(_, l)| l.id);
                check_numbered(id, layers, "layer")
                    .map_err(|m| err(at, format!("`{name}` {m}")))?;
                layers += 1;
            }
            _ if id.iter().all(|c| c.is_ascii_graphic() || *c == b' ') => {}
            _ => {
                return Err(err(
                    at,
                    format!("chunk id `{}` is not text", name.escape_debug()),
                ));
            }
        }
        at = end;
    }
    if let Some((_, o)) = pending_size {
        return Err(err(o, "`SIZE` without its `XYZI` chunk".into()));
    }
    Ok(models)
}

/// Checks that a scene node or layer chunk decodes (`id` is its decoded
/// id) and that its id is `index`, its place among the chunks of its
/// kind: the decoder drops a chunk it cannot read and numbers the rest by
/// their order, so either would silently renumber the nodes (or layers)
/// after it.
fn check_numbered<E>(id: Result<u32, E>, index: u32, what: &str) -> Result<(), String> {
    match id {
        Err(_) => Err(format!(
            "{what} {index} cannot be decoded (damaged or truncated)"
        )),
        Ok(id) if id != index => Err(format!(
            "{what} {index} holds the id {id}: ids must number the {what}s in file order"
        )),
        Ok(_) => Ok(()),
    }
}

/// End of the chunk at `at` (header, content and children) if it fits in
/// `limit`.
fn chunk_end(b: &[u8], at: usize, limit: usize) -> Result<usize, String> {
    if at.checked_add(12).is_none_or(|e| e > limit) {
        return Err("the chunk header runs past its parent".into());
    }
    let id = String::from_utf8_lossy(&b[at..at + 4])
        .escape_debug()
        .to_string();
    let c = le32(b, at + 4).unwrap_or(0) as usize;
    let k = le32(b, at + 8).unwrap_or(0) as usize;
    at.checked_add(12)
        .and_then(|x| x.checked_add(c))
        .and_then(|x| x.checked_add(k))
        .filter(|&e| e <= limit)
        .ok_or_else(|| {
            format!(
                "chunk `{id}` claims {c} + {k} bytes, {} left in its parent",
                limit.saturating_sub(at + 12)
            )
        })
}

fn parse(path: &Path, bytes: &[u8]) -> Result<VoxScene, VoxError> {
    let count = check_chunks(path, bytes)?;
    let data = dot_vox::load_bytes(bytes).map_err(|m| VoxError::Chunk {
        path: path.to_path_buf(),
        offset: 0,
        msg: m.to_string(),
    })?;
    if data.models.len() != count {
        return Err(VoxError::Chunk {
            path: path.to_path_buf(),
            offset: 0,
            msg: format!(
                "{count} models in the chunk structure but {} decoded",
                data.models.len()
            ),
        });
    }
    let models: Vec<VoxModel> = data
        .models
        .iter()
        .map(|m| VoxModel {
            size: [m.size.x, m.size.y, m.size.z],
            // dot_vox stores index − 1; the file's index is 1..=255.
            voxels: m
                .voxels
                .iter()
                .map(|v| [v.x, v.y, v.z, v.i.saturating_add(1)])
                .collect(),
        })
        .collect();
    let mut palette: Vec<[u8; 4]> = data.palette.iter().map(|c| [c.r, c.g, c.b, c.a]).collect();
    palette.resize(256, [0, 0, 0, 255]);
    let instances = if data.scenes.is_empty() {
        (0..models.len())
            .map(|model| VoxInstance {
                model,
                rotation: IDENTITY,
                translation: [0; 3],
            })
            .collect()
    } else {
        walk_scene(path, &data, models.len())?
    };
    let scene = VoxScene {
        models,
        instances,
        palette,
        made: Made::default(),
    };
    let placed = scene.world_voxel_count();
    if placed > MAX_WORLD_VOXELS {
        return Err(VoxError::Scene {
            path: path.to_path_buf(),
            node: 0,
            msg: format!(
                "the {} model instances place {placed} voxels, more than the limit of \
                 {MAX_WORLD_VOXELS}",
                scene.instances.len()
            ),
        });
    }
    Ok(scene)
}

const IDENTITY: [[i32; 3]; 3] = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];

/// The `_r` byte as a signed permutation matrix (rows), or `None` if it
/// is not one.
fn rotation_of(byte: u8) -> Option<[[i32; 3]; 3]> {
    let c1 = usize::from(byte & 3);
    let c2 = usize::from((byte >> 2) & 3);
    if c1 == 3 || c2 == 3 || c1 == c2 || byte & 0x80 != 0 {
        return None;
    }
    let c3 = 3 - c1 - c2;
    let sign = |bit: u8| if byte & (1 << bit) == 0 { 1 } else { -1 };
    let mut m = [[0; 3]; 3];
    m[0][c1] = sign(4);
    m[1][c2] = sign(5);
    m[2][c3] = sign(6);
    Some(m)
}

fn mat_mul(a: [[i32; 3]; 3], b: [[i32; 3]; 3]) -> [[i32; 3]; 3] {
    std::array::from_fn(|r| std::array::from_fn(|c| (0..3).map(|k| a[r][k] * b[k][c]).sum()))
}

fn walk_scene(
    path: &Path,
    data: &dot_vox::DotVoxData,
    models: usize,
) -> Result<Vec<VoxInstance>, VoxError> {
    use dot_vox::SceneNode;
    let serr = |node: u32, msg: String| VoxError::Scene {
        path: path.to_path_buf(),
        node,
        msg,
    };
    let hidden = |layer: u32| {
        data.layers
            .get(layer as usize)
            .is_some_and(dot_vox::Layer::hidden)
    };
    let mut out = Vec::new();
    // (node, rotation, translation, depth)
    let mut stack = vec![(0u32, IDENTITY, [0i64; 3], 0usize)];
    let mut visits = 0usize;
    while let Some((node, rot, tr, depth)) = stack.pop() {
        visits += 1;
        if visits > MAX_NODE_VISITS {
            return Err(serr(
                node,
                format!(
                    "placing the models visits more than {MAX_NODE_VISITS} scene nodes \
                     (nodes shared by several groups are visited once per path)"
                ),
            ));
        }
        if depth > MAX_DEPTH {
            return Err(serr(
                node,
                format!("the scene graph is deeper than {MAX_DEPTH} nodes (a cycle?)"),
            ));
        }
        let Some(n) = data.scenes.get(node as usize) else {
            return Err(serr(
                node,
                format!("no such node ({} nodes)", data.scenes.len()),
            ));
        };
        match n {
            SceneNode::Transform {
                frames,
                child,
                layer_id,
                ..
            } => {
                if hidden(*layer_id) {
                    continue;
                }
                let (mut r, mut t) = (IDENTITY, [0i64; 3]);
                if let Some(f) = frames.first() {
                    if let Some(v) = f.attributes.get("_r") {
                        r = v
                            .trim()
                            .parse::<u8>()
                            .ok()
                            .and_then(rotation_of)
                            .ok_or_else(|| serr(node, format!("`_r` = `{v}` is not a rotation")))?;
                    }
                    if let Some(v) = f.attributes.get("_t") {
                        let p: Vec<i64> = v
                            .split_whitespace()
                            .map(|x| x.parse::<i32>().map(i64::from))
                            .collect::<Result<_, _>>()
                            .map_err(|_| serr(node, format!("`_t` = `{v}` is not 3 integers")))?;
                        let [x, y, z] = p[..] else {
                            return Err(serr(node, format!("`_t` = `{v}` is not 3 integers")));
                        };
                        t = [x, y, z];
                    }
                }
                // Parent ∘ this: p ↦ rot·(r·p + t) + tr.
                let rt: [i64; 3] = std::array::from_fn(|row| {
                    (0..3).map(|k| i64::from(rot[row][k]) * t[k]).sum::<i64>() + tr[row]
                });
                stack.push((*child, mat_mul(rot, r), rt, depth + 1));
            }
            SceneNode::Group { children, .. } => {
                for c in children.iter().rev() {
                    stack.push((*c, rot, tr, depth + 1));
                }
            }
            SceneNode::Shape { models: shapes, .. } => {
                for s in shapes {
                    let m = s.model_id as usize;
                    if m >= models {
                        return Err(serr(node, format!("uses model {m}; the file has {models}")));
                    }
                    let translation = tr.map(|x| i32::try_from(x).unwrap_or(i32::MAX));
                    if tr.iter().any(|x| i32::try_from(*x).is_err()) {
                        return Err(serr(node, "translation out of range".into()));
                    }
                    out.push(VoxInstance {
                        model: m,
                        rotation: rot,
                        translation,
                    });
                    if out.len() > MAX_INSTANCES {
                        return Err(serr(
                            node,
                            format!("more than {MAX_INSTANCES} model instances"),
                        ));
                    }
                }
            }
        }
    }
    Ok(out)
}

impl VoxScene {
    /// The models.
    #[must_use]
    pub fn models(&self) -> &[VoxModel] {
        &self.models
    }

    /// The placed copies of the models.
    #[must_use]
    pub fn instances(&self) -> &[VoxInstance] {
        &self.instances
    }

    /// The 256-entry RGBA palette; entry `i - 1` is colour index `i`.
    #[must_use]
    pub fn palette(&self) -> &[[u8; 4]] {
        &self.palette
    }

    /// RGB of colour index `i` (1..=255).
    #[must_use]
    pub fn color(&self, index: u8) -> [u8; 3] {
        let c = self
            .palette
            .get(usize::from(index.saturating_sub(1)))
            .copied()
            .unwrap_or([0, 0, 0, 255]);
        [c[0], c[1], c[2]]
    }

    /// The voxels of model `model` in its local frame, with colours and
    /// occupancy-gradient normals (module docs), in file order; `None`
    /// for a model that does not exist.
    #[must_use]
    pub fn model_voxels(&self, model: usize) -> Option<Vec<ModelVoxel>> {
        let m = self.models.get(model)?;
        let [sx, sy, sz] = m.size.map(|s| s as usize);
        // At most 256³ bytes, one model at a time.
        let mut occ = vec![false; sx * sy * sz];
        for v in &m.voxels {
            let [x, y, z, _] = v.map(usize::from);
            if let Some(o) = occ.get_mut(x + sx * (y + sy * z)) {
                *o = true;
            }
        }
        let filled = |x: i64, y: i64, z: i64| -> bool {
            if x < 0 || y < 0 || z < 0 {
                return false;
            }
            let (x, y, z) = (x as usize, y as usize, z as usize);
            x < sx && y < sy && z < sz && occ.get(x + sx * (y + sy * z)).copied().unwrap_or(false)
        };
        // Zucker–Hummel weights as integers (×256, as the core's volume
        // voxelizer): sums cancel exactly where the neighbourhood is
        // symmetric.
        let w: [i64; 3] = [256, 181, 148];
        let mut out = Vec::with_capacity(m.voxels.len());
        for v in &m.voxels {
            let p = [v[0], v[1], v[2]].map(i64::from);
            let mut g = [0i64; 3];
            let mut all = true;
            for dz in -1..=1i64 {
                for dy in -1..=1i64 {
                    for dx in -1..=1i64 {
                        if dx == 0 && dy == 0 && dz == 0 {
                            continue;
                        }
                        if filled(p[0] + dx, p[1] + dy, p[2] + dz) {
                            continue;
                        }
                        all = false;
                        let d = [dx, dy, dz];
                        let nz = d.iter().filter(|c| **c != 0).count();
                        // An empty neighbour pulls the normal toward it.
                        for (ga, da) in g.iter_mut().zip(d) {
                            *ga += da * w[nz - 1];
                        }
                    }
                }
            }
            let n = DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64)
                .try_normalize()
                .or_else(|| {
                    const FACES: [[i64; 3]; 6] = [
                        [-1, 0, 0],
                        [1, 0, 0],
                        [0, -1, 0],
                        [0, 1, 0],
                        [0, 0, -1],
                        [0, 0, 1],
                    ];
                    FACES
                        .iter()
                        .find(|d| !filled(p[0] + d[0], p[1] + d[1], p[2] + d[2]))
                        .map(|d| DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64))
                });
            let normal = n.map_or([0, 0, NORMAL_ONE], |n| {
                // |component| ≤ 1: fits after scaling.
                [n.x, n.y, n.z].map(|c| (c * f64::from(NORMAL_ONE)).round() as i32)
            });
            out.push(ModelVoxel {
                local: [v[0], v[1], v[2]].map(u32::from),
                index: v[3],
                color: self.color(v[3]),
                normal,
                interior: all,
            });
        }
        Some(out)
    }

    /// The voxels the instances place in all (at most
    /// [`MAX_WORLD_VOXELS`] for a scene read from a file).
    #[must_use]
    pub fn world_voxel_count(&self) -> u64 {
        self.instances
            .iter()
            .filter_map(|i| self.models.get(i.model))
            .map(|m| m.voxels.len() as u64)
            .fold(0, u64::saturating_add)
    }

    /// Calls `f` with every voxel of every instance in MagicaVoxel's world
    /// frame, instance by instance, each model's voxels in file order
    /// (each model's voxels and normals are made once per scene).
    pub fn for_each_world_voxel(&self, mut f: impl FnMut(WorldVoxel)) {
        let local = self.made.local.get_or_init(|| {
            let mut used = vec![false; self.models.len()];
            for i in &self.instances {
                if let Some(u) = used.get_mut(i.model) {
                    *u = true;
                }
            }
            used.iter()
                .enumerate()
                .map(|(m, &u)| u.then(|| self.model_voxels(m)).flatten())
                .collect()
        });
        for inst in &self.instances {
            let (Some(m), Some(Some(vs))) = (self.models.get(inst.model), local.get(inst.model))
            else {
                continue;
            };
            for v in vs {
                f(WorldVoxel {
                    cell: inst.to_world(v.local, m.size),
                    color: v.color,
                    normal: inst.rotate(v.normal),
                    interior: v.interior,
                });
            }
        }
    }

    /// The palette colour of every world cell that holds a voxel (of the
    /// last instance in [`VoxScene::for_each_world_voxel`]'s order where
    /// several do), made once per scene.
    #[must_use]
    pub fn world_colors(&self) -> Arc<HashMap<[i64; 3], [u8; 3]>> {
        Arc::clone(self.made.colors.get_or_init(|| {
            let mut cells = HashMap::new();
            self.for_each_world_voxel(|v| {
                cells.insert(v.cell, v.color);
            });
            Arc::new(cells)
        }))
    }

    /// Every voxel of every instance in MagicaVoxel's world frame, in the
    /// order of [`VoxScene::for_each_world_voxel`].
    #[must_use]
    pub fn world_voxels(&self) -> Vec<WorldVoxel> {
        let mut out = Vec::new();
        self.for_each_world_voxel(|v| out.push(v));
        out
    }

    /// The world cells' box `(min, max)` (inclusive), `None` without
    /// voxels.
    #[must_use]
    pub fn world_bounds(&self) -> Option<([i64; 3], [i64; 3])> {
        let mut b: Option<([i64; 3], [i64; 3])> = None;
        for inst in &self.instances {
            let Some(m) = self.models.get(inst.model) else {
                continue;
            };
            for v in &m.voxels {
                let c = inst.to_world([v[0], v[1], v[2]].map(u32::from), m.size);
                b = Some(match b {
                    None => (c, c),
                    Some((lo, hi)) => (
                        std::array::from_fn(|a| lo[a].min(c[a])),
                        std::array::from_fn(|a| hi[a].max(c[a])),
                    ),
                });
            }
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_bytes() {
        // The identity is byte 4 (row 0 → column 0, row 1 → column 1).
        assert_eq!(rotation_of(4), Some(IDENTITY));
        // The example of the format's documentation.
        let r = (1) | (2 << 2) | (1 << 5) | (1 << 6);
        assert_eq!(rotation_of(r), Some([[0, 1, 0], [0, 0, -1], [-1, 0, 0]]));
        assert_eq!(rotation_of(0), None);
        assert_eq!(rotation_of(3), None);
    }

    #[test]
    fn instance_cells_are_exact() {
        // Rotation by 90° about z: (x, y) ↦ (−y, x).
        let inst = VoxInstance {
            model: 0,
            rotation: [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
            translation: [10, 0, 0],
        };
        let size = [4, 2, 1];
        // Pivot (2, 1, 0). Cell (3, 1, 0): centre offset (1.5, 0.5, 0.5)
        // → (−0.5, 1.5, 0.5) → cell (−1, 1, 0) + (10, 0, 0).
        assert_eq!(inst.to_world([3, 1, 0], size), [9, 1, 0]);
        assert_eq!(inst.rotate([NORMAL_ONE, 0, 0]), [0, NORMAL_ONE, 0]);
    }
}
