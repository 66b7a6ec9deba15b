//! Objects: an `[[object]]`'s one shape key into the scene's objects, with
//! its material, location and (for polygons, patches and meshes)
//! transform.

use std::ops::Range;
use std::sync::Arc;

use ::toml::Spanned;
use glam::{DAffine3, DQuat, DVec3};

use super::build::Builder;
use super::csg::single_leaf;
use super::schema::{
    BezierDef, BoxDef, ConeDef, Doc, MeshDef, ObjectDef, SHAPE_KEYS, ShapeDef, SphereDef, TorusDef,
    TransformDef, V3, VoxDef,
};
use crate::scene::error::{SceneError, with_causes};
use crate::scene::loc::SourceLoc;
use crate::scene::objects::{Solid, VolumeObject, VoxObject};
use crate::scene::{Object, Scene, bezier, bpt, nff, obj};
use crate::shape::Sphere;
use crate::world::WORLD_LIMIT;

/// What every shape of an object gets: where it is defined, its material
/// and its transform.
struct At {
    span: Range<usize>,
    loc: SourceLoc,
    material: usize,
    transform: DAffine3,
}

impl Builder<'_> {
    pub(super) fn object(
        &self,
        scene: &mut Scene,
        doc: &Doc,
        o: &Spanned<ObjectDef>,
    ) -> Result<(), SceneError> {
        let s = o.span();
        let d = o.get_ref();
        let [shape] = d.shapes()[..] else {
            return Err(self.err(s, "object", format!("expected exactly one of {SHAPE_KEYS}")));
        };
        let transform = match &d.transform {
            None => DAffine3::IDENTITY,
            Some(t) => self.transform(t, &s)?,
        };
        let takes_transform = matches!(
            shape,
            ShapeDef::Polygon(_) | ShapeDef::Bezier(_) | ShapeDef::Mesh(_)
        );
        if d.transform.is_some() && !takes_transform {
            return Err(self.err(
                s,
                "object.transform",
                "only polygons, bezier patches and meshes take a transform",
            ));
        }
        let material = match shape {
            ShapeDef::Nff(n) => {
                if d.material.is_some() {
                    return Err(self.err(
                        s,
                        "object.material",
                        "an NFF file brings its own materials",
                    ));
                }
                return self.nff(scene, n, &s);
            }
            ShapeDef::Csg(c) => {
                let loc = self.shape_loc(shape, &s);
                return self.csg(scene, doc, c, d.material.as_ref(), &s, loc);
            }
            _ => self.material_of(d.material.as_ref(), &s, "object.material")?,
        };
        let at = At {
            loc: self.shape_loc(shape, &s),
            span: s,
            material,
            transform,
        };
        match shape {
            ShapeDef::Sphere(sp) => self.sphere(scene, sp, at),
            ShapeDef::Cone(c) => self.cone_object(scene, c, at),
            ShapeDef::Polygon(p) => self.polygon(scene, p, &at),
            ShapeDef::Box(b) => self.cuboid(scene, b, &at),
            ShapeDef::Torus(t) => self.torus_object(scene, t, at),
            ShapeDef::Bezier(b) => self.bezier(scene, b, &at),
            ShapeDef::Mesh(m) => self.mesh(scene, m, &at),
            ShapeDef::Volume(v) => self.volume_object(scene, v, at),
            ShapeDef::Vox(v) => self.vox(scene, v, at),
            ShapeDef::Nff(_) | ShapeDef::Csg(_) => Ok(()),
        }
    }

    /// Where the object's shape is given (its shape key's value), which
    /// later refusals of the object (the voxelizers', the fit's) name.
    fn shape_loc(&self, shape: ShapeDef<'_>, s: &Range<usize>) -> SourceLoc {
        let key = self.full_key(&format!("object.{}", shape.key()));
        self.loc(self.spans.value(&key).unwrap_or_else(|| s.clone()))
    }

    /// Scale, then the rotations in x, y, z order (degrees), then the
    /// translation.
    fn transform(&self, t: &TransformDef, s: &Range<usize>) -> Result<DAffine3, SceneError> {
        let tr = self.vec3(s, "object.transform.translate", t.translate)?;
        if !(t.scale.is_finite() && t.scale > 0.0) {
            return Err(self.err(s.clone(), "object.transform.scale", "expected a number > 0"));
        }
        for (key, a) in [
            ("object.transform.rotate_x", t.rotate_x),
            ("object.transform.rotate_y", t.rotate_y),
            ("object.transform.rotate_z", t.rotate_z),
        ] {
            if !a.is_finite() {
                return Err(self.err(s.clone(), key, "expected a finite angle in degrees"));
            }
        }
        let q = DQuat::from_rotation_z(t.rotate_z.to_radians())
            * DQuat::from_rotation_y(t.rotate_y.to_radians())
            * DQuat::from_rotation_x(t.rotate_x.to_radians());
        Ok(DAffine3::from_scale_rotation_translation(
            DVec3::splat(t.scale),
            q,
            tr,
        ))
    }

    fn sphere(&self, scene: &mut Scene, sp: &SphereDef, at: At) -> Result<(), SceneError> {
        let centre = self.vec3(&at.span, "object.sphere.centre", sp.centre)?;
        if !(sp.radius > 0.0 && sp.radius <= WORLD_LIMIT) {
            return Err(self.err(
                at.span,
                "object.sphere.radius",
                "expected a number > 0, at most 1e60",
            ));
        }
        scene.spheres.push(Object {
            shape: Sphere {
                centre,
                radius: sp.radius,
            },
            material: at.material,
            loc: at.loc,
        });
        Ok(())
    }

    /// An open cone (NFF `c`), or a capped one: a one-solid CSG tree.
    fn cone_object(&self, scene: &mut Scene, c: &ConeDef, at: At) -> Result<(), SceneError> {
        let shape = self.cone(c, &at.span, "object.cone")?;
        if c.capped {
            scene
                .csgs
                .push(single_leaf(Solid::Cone(shape), at.material, at.loc));
        } else {
            scene.cones.push(Object {
                shape,
                material: at.material,
                loc: at.loc,
            });
        }
        Ok(())
    }

    fn polygon(&self, scene: &mut Scene, p: &[V3], at: &At) -> Result<(), SceneError> {
        let s = &at.span;
        if p.len() < 3 || p.len() > 1 << 16 {
            return Err(self.err(s.clone(), "object.polygon", "expected 3 to 65536 vertices"));
        }
        let v = p
            .iter()
            .enumerate()
            .map(|(i, &q)| {
                self.vec3(s, &format!("object.polygon[{i}]"), q)
                    .map(|q| at.transform.transform_point3(q))
            })
            .collect::<Result<Vec<_>, _>>()?;
        self.push_polygon(scene, &v, None, at.material, &at.loc, s)
    }

    /// A box as its six faces.
    fn cuboid(&self, scene: &mut Scene, b: &BoxDef, at: &At) -> Result<(), SceneError> {
        let s = &at.span;
        let lo = self.vec3(s, "object.box.min", b.min)?;
        let hi = self.vec3(s, "object.box.max", b.max)?;
        if !lo.cmplt(hi).all() {
            return Err(self.err(
                s.clone(),
                "object.box.max",
                "expected min < max on every axis",
            ));
        }
        for face in box_faces(lo, hi) {
            self.push_polygon(scene, &face, None, at.material, &at.loc, s)?;
        }
        Ok(())
    }

    fn torus_object(&self, scene: &mut Scene, t: &TorusDef, at: At) -> Result<(), SceneError> {
        scene.tori.push(Object {
            shape: self.torus(t, &at.span, "object.torus")?,
            material: at.material,
            loc: at.loc,
        });
        Ok(())
    }

    /// The patches of a `.bpt` file, each tessellated into `steps × steps`
    /// polygonal patches.
    fn bezier(&self, scene: &mut Scene, b: &BezierDef, at: &At) -> Result<(), SceneError> {
        let s = &at.span;
        if b.steps == 0 || b.steps > self.opts.max_patch_steps {
            return Err(self.err(
                s.clone(),
                "object.bezier.steps",
                format!("expected 1 to {}", self.opts.max_patch_steps),
            ));
        }
        let (path, shown) = self.path(&b.file, "object.bezier.file")?;
        let patches = bpt::load(&path, &shown)
            .map_err(|e| self.err(b.file.span(), "object.bezier.file", with_causes(&e)))?;
        // Each patch is steps² quads of 4 vertices.
        let quads = patches.len().saturating_mul((b.steps as usize).pow(2));
        let vertices = quads.saturating_mul(4);
        self.room_for_vertices(scene, vertices, s, "object.bezier")?;
        // Made fallibly: an allocation the machine refuses is an error.
        if scene.vertices.try_reserve(vertices).is_err()
            || scene.normals.try_reserve(vertices).is_err()
            || scene.polygons.try_reserve(quads).is_err()
        {
            return Err(self.err(
                s.clone(),
                "object.bezier",
                format!(
                    "cannot allocate {} for the {vertices} vertices of {quads} quads",
                    crate::memory::Bytes((vertices as u64).saturating_mul(super::VERTEX_BYTES))
                ),
            ));
        }
        for p in &patches {
            let c = p.map(|row| row.map(|q| at.transform.transform_point3(q)));
            for (quad, normals) in bezier::tessellate(&c, b.steps) {
                self.push_polygon(scene, &quad, Some(&normals), at.material, &at.loc, s)?;
            }
        }
        Ok(())
    }

    /// An OBJ mesh's triangles, flat or with the file's (or averaged)
    /// vertex normals.
    fn mesh(&self, scene: &mut Scene, m: &MeshDef, at: &At) -> Result<(), SceneError> {
        let s = &at.span;
        let transform = at.transform;
        let (path, shown) = self.path(&m.file, "object.mesh.file")?;
        // What the scene's volumes and vertices leave of the limit.
        let left = self.opts.max_memory.saturating_sub(self.data_bytes(scene));
        let mut budget = self.cut_budget.get();
        let mesh = obj::load_within(&path, &shown, left, &mut budget)
            .map_err(|e| self.err(m.file.span(), "object.mesh.file", with_causes(&e)))?;
        self.cut_budget.set(budget);
        self.room_for_vertices(
            scene,
            mesh.triangles.len().saturating_mul(3),
            s,
            "object.mesh",
        )?;
        let normals = if m.smooth {
            Some(
                mesh.normals
                    .clone()
                    .unwrap_or_else(|| obj::smooth_normals(&mesh)),
            )
        } else {
            None
        };
        let pos: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|&p| transform.transform_point3(p))
            .collect();
        for t in &mesh.triangles {
            let idx = t.map(|i| i as usize);
            let (Some(a), Some(b2), Some(c)) = (pos.get(idx[0]), pos.get(idx[1]), pos.get(idx[2]))
            else {
                return Err(self.err(
                    m.file.span(),
                    "object.mesh.file",
                    "a vertex index out of range",
                ));
            };
            let n = normals.as_ref().map(|n| {
                idx.map(|i| {
                    let v = n.get(i).copied().unwrap_or(DVec3::ZERO);
                    transform.transform_vector3(v).normalize_or_zero()
                })
            });
            // A vertex without a usable normal: the flat triangle.
            let n = n.filter(|n| n.iter().all(|v| v.length_squared() > 0.5));
            self.push_polygon(
                scene,
                &[*a, *b2, *c],
                n.as_ref().map(|n| &n[..]),
                at.material,
                &at.loc,
                s,
            )?;
        }
        Ok(())
    }

    fn volume_object(
        &self,
        scene: &mut Scene,
        v: &Spanned<String>,
        at: At,
    ) -> Result<(), SceneError> {
        let data = self.volumes.get(v.get_ref()).ok_or_else(|| {
            self.err(
                v.span(),
                "object.volume",
                format!("no [volume.{}] in this scene", v.get_ref()),
            )
        })?;
        scene.volumes.push(VolumeObject {
            data: data.clone(),
            material: at.material,
            loc: at.loc,
        });
        Ok(())
    }

    fn vox(&self, scene: &mut Scene, v: &VoxDef, at: At) -> Result<(), SceneError> {
        let (path, _) = self.path(&v.file, "object.vox.file")?;
        let size = std::fs::metadata(&path)
            .map(|m| m.len())
            .unwrap_or(u64::MAX);
        if size > self.opts.max_vox_bytes {
            return Err(self.err(
                v.file.span(),
                "object.vox.file",
                format!(
                    "{size} bytes, more than the limit of {}",
                    self.opts.max_vox_bytes
                ),
            ));
        }
        let vox = crate::assets::vox::read(&path)
            .map_err(|e| self.err(v.file.span(), "object.vox.file", with_causes(&e)))?;
        let position = self.vec3(&at.span, "object.vox.position", v.position)?;
        if !(v.cell.is_finite() && v.cell > 0.0) {
            return Err(self.err(at.span, "object.vox.cell", "expected a number > 0"));
        }
        scene.voxes.push(VoxObject {
            vox: Arc::new(vox),
            position,
            cell: v.cell,
            material: at.material,
            loc: at.loc,
        });
        Ok(())
    }

    /// Every object, light and material of an NFF file (its view is
    /// ignored). A mesh, patch, model or volume file named here is refused
    /// with the key that draws it, not parsed as NFF.
    fn nff(
        &self,
        scene: &mut Scene,
        n: &Spanned<String>,
        s: &Range<usize>,
    ) -> Result<(), SceneError> {
        let (path, shown) = self.path(n, "object.nff")?;
        if let Some((what, how)) = crate::scene::not_a_scene(&path, n.get_ref()) {
            return Err(self.err(
                n.span(),
                "object.nff",
                format!("{shown}: {what}, not an NFF scene: draw it with {how}"),
            ));
        }
        // Its view is ignored: it need not have one.
        let opts = nff::ParseOptions {
            view_required: false,
            ..nff::ParseOptions::default()
        };
        let inc = nff::load(&path, &opts)
            .map_err(|e| self.err(n.span(), "object.nff", with_causes(&e)))?;
        self.include(scene, inc, s)
    }

    fn include(
        &self,
        scene: &mut Scene,
        inc: Scene,
        s: &std::ops::Range<usize>,
    ) -> Result<(), SceneError> {
        self.room_for_vertices(scene, inc.vertices.len(), s, "object.nff")?;
        let m0 = scene.materials.len();
        let v0 = scene.vertices.len();
        scene.materials.extend(inc.materials);
        scene.lights.extend(inc.lights);
        scene.vertices.extend(inc.vertices);
        scene.normals.extend(inc.normals);
        scene.spheres.extend(inc.spheres.into_iter().map(|mut o| {
            o.material += m0;
            o
        }));
        scene.cones.extend(inc.cones.into_iter().map(|mut o| {
            o.material += m0;
            o
        }));
        scene.polygons.extend(inc.polygons.into_iter().map(|mut o| {
            o.material += m0;
            o.first += v0;
            o
        }));
        Ok(())
    }
}

/// The six faces of a box, wound counter-clockwise seen from outside.
fn box_faces(lo: DVec3, hi: DVec3) -> [[DVec3; 4]; 6] {
    let p = |x: bool, y: bool, z: bool| {
        DVec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    [
        [p(f, f, f), p(f, t, f), p(t, t, f), p(t, f, f)], // z = lo
        [p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)], // z = hi
        [p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)], // y = lo
        [p(f, t, f), p(f, t, t), p(t, t, t), p(t, t, f)], // y = hi
        [p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)], // x = lo
        [p(t, f, f), p(t, t, f), p(t, t, t), p(t, f, t)], // x = hi
    ]
}
