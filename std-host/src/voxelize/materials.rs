//! The material table: a scene's materials without repeats (NFF files
//! repeat identical `f` lines), so that the record's 16-bit material index
//! names a distinct material; in `f64` for shading and in the core's fixed
//! point for the light pass.

use std::collections::HashMap;

use rrt_core::object_table::{self as table, Materials, SCALAR_ONE};
use rrt_core::store::ObjectAttrs;

use super::BuildError;
use crate::scene::{Material, Scene, SourceLoc};

/// Most distinct materials a scene may have (the record's index is 16
/// bits; the table is kept small enough to copy per render).
pub const MAX_MATERIALS: usize = 4096;

/// The distinct materials of a scene.
#[derive(Debug)]
pub(super) struct MaterialTable {
    /// The distinct materials, in order of first appearance (without
    /// their locations).
    pub list: Vec<Material>,
    /// Per scene material, its index in `list`.
    index: Vec<u16>,
}

impl MaterialTable {
    /// The table of `scene`'s materials.
    ///
    /// # Errors
    /// [`BuildError::TooManyMaterials`] beyond [`MAX_MATERIALS`].
    pub fn new(scene: &Scene) -> Result<Self, BuildError> {
        let mut seen: HashMap<[u64; 8], u16> = HashMap::new();
        let mut list = Vec::new();
        let mut index = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            let key = [
                m.colour.x,
                m.colour.y,
                m.colour.z,
                m.kd,
                m.ks,
                m.shine,
                m.transmittance,
                m.ior,
            ]
            .map(f64::to_bits);
            let i = match seen.get(&key) {
                Some(&i) => i,
                None => {
                    if list.len() >= MAX_MATERIALS {
                        return Err(BuildError::TooManyMaterials {
                            loc: m
                                .loc
                                .clone()
                                .unwrap_or_else(|| SourceLoc::new(scene.file.clone(), 0, 0)),
                            count: list.len() + 1,
                        });
                    }
                    // Below MAX_MATERIALS = 4096: fits u16.
                    let i = u16::try_from(list.len()).unwrap_or(u16::MAX);
                    seen.insert(key, i);
                    list.push(Material {
                        loc: None,
                        ..m.clone()
                    });
                    i
                }
            };
            index.push(i);
        }
        Ok(Self { list, index })
    }

    /// The record's material index of scene material `m`.
    pub fn of(&self, m: usize) -> u16 {
        self.index.get(m).copied().unwrap_or(0)
    }

    /// What the fill pass writes for object `id` of scene material `m`:
    /// the id, the material index and the material's 8-bit colour.
    pub fn attrs(&self, id: usize, m: usize) -> ObjectAttrs {
        let material = self.of(m);
        ObjectAttrs {
            object: u32::try_from(id).unwrap_or(u32::MAX),
            material,
            color: self
                .list
                .get(usize::from(material))
                .map_or([0; 3], record_colour),
        }
    }

    /// The table in the core's fixed point.
    pub fn core(&self) -> Box<Materials<MAX_MATERIALS>> {
        let mut core: Box<Materials<MAX_MATERIALS>> = Box::default();
        for m in &self.list {
            // At most MAX_MATERIALS: no push fails.
            let _ = core.push(core_material(m));
        }
        core
    }
}

/// The 8-bit colour the records of an untextured object of material `m`
/// hold.
pub fn record_colour(m: &Material) -> [u8; 3] {
    core_material(m).color_u8()
}

/// A scalar in `[0, ∞)` as the core's 16.16 fixed point, saturating.
pub(super) fn scalar(v: f64) -> u32 {
    let s = (v * f64::from(SCALAR_ONE)).round();
    if s.is_nan() || s <= 0.0 {
        0
    } else if s >= f64::from(u32::MAX) {
        u32::MAX
    } else {
        s as u32
    }
}

/// The core's fixed-point material.
fn core_material(m: &Material) -> table::Material {
    table::Material {
        color: [m.colour.x, m.colour.y, m.colour.z].map(scalar),
        kd: scalar(m.kd),
        ks: scalar(m.ks),
        shine: scalar(m.shine),
        // Any transmission at all lets light through: the renderer's
        // shadow rays attenuate by it, so the light pass must not count
        // the object as opaque.
        transmission: if m.transmittance > 0.0 {
            scalar(m.transmittance).max(1)
        } else {
            0
        },
        ior: scalar(m.ior),
    }
}
