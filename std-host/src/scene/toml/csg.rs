//! Solids and CSG trees (and the cone and torus shapes a solid or an
//! object may be).

use ::toml::Spanned;
use rrt_core::csg::{CsgNode, MAX_NODES};

use super::build::Builder;
use super::schema::{ConeDef, CsgExpr, CsgOp, Doc, TorusDef};
use crate::scene::Scene;
use crate::scene::error::SceneError;
use crate::scene::loc::SourceLoc;
use crate::scene::objects::{Csg, CsgLeaf, Solid};
use crate::shape::{Cone, Cuboid, Sphere, Torus};
use crate::world::WORLD_LIMIT;

impl Builder<'_> {
    pub(super) fn cone(
        &self,
        c: &ConeDef,
        s: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<Cone, SceneError> {
        let base = self.vec3(s, &format!("{key}.base"), c.base)?;
        let apex = self.vec3(s, &format!("{key}.apex"), c.apex)?;
        if base == apex {
            return Err(self.err(s.clone(), &format!("{key}.apex"), "equals the base"));
        }
        for (k, r) in [
            ("base_radius", c.base_radius),
            ("apex_radius", c.apex_radius),
        ] {
            if !(0.0..=WORLD_LIMIT).contains(&r) {
                return Err(self.err(
                    s.clone(),
                    &format!("{key}.{k}"),
                    "expected a number ≥ 0, at most 1e60",
                ));
            }
        }
        if c.base_radius + c.apex_radius <= 0.0 {
            return Err(self.err(
                s.clone(),
                &format!("{key}.base_radius"),
                "expected base_radius or apex_radius > 0",
            ));
        }
        Ok(Cone {
            base,
            base_radius: c.base_radius,
            apex,
            apex_radius: c.apex_radius,
        })
    }

    pub(super) fn torus(
        &self,
        t: &TorusDef,
        s: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<Torus, SceneError> {
        let centre = self.vec3(s, &format!("{key}.centre"), t.centre)?;
        let axis = self
            .vec3(s, &format!("{key}.axis"), t.axis)?
            .try_normalize()
            .ok_or_else(|| self.err(s.clone(), &format!("{key}.axis"), "zero axis"))?;
        for (k, r) in [("major", t.major), ("minor", t.minor)] {
            if !(r > 0.0 && r <= WORLD_LIMIT) {
                return Err(self.err(
                    s.clone(),
                    &format!("{key}.{k}"),
                    "expected a number > 0, at most 1e60",
                ));
            }
        }
        Ok(Torus {
            centre,
            axis,
            major: t.major,
            minor: t.minor,
        })
    }

    /// The `[solid.NAME]` a tree's leaf at `leaf_key` names.
    pub(super) fn solid(
        &self,
        doc: &Doc,
        name: &str,
        (at, leaf_key): (&std::ops::Range<usize>, &str),
        default_material: Option<usize>,
    ) -> Result<CsgLeaf, SceneError> {
        let Some(def) = doc.solid.get(name) else {
            return Err(self.err(
                at.clone(),
                leaf_key,
                format!("no [solid.{name}] in this scene"),
            ));
        };
        let s = def.span();
        let d = def.get_ref();
        let key = format!("solid.{name}");
        let material = match (&d.material, default_material) {
            (Some(m), _) => self.material_of(Some(m), &s, &format!("{key}.material"))?,
            (None, Some(m)) => m,
            (None, None) => {
                return Err(self.err(
                    s,
                    &format!("{key}.material"),
                    "missing: give the solid or the CSG object a material",
                ));
            }
        };
        let given = [
            d.sphere.is_some(),
            d.cuboid.is_some(),
            d.cone.is_some(),
            d.torus.is_some(),
            d.volume.is_some(),
        ];
        self.exactly_one(&given, &s, &key, "sphere, box, cone, torus, volume")?;
        let shape = if let Some(sp) = &d.sphere {
            let centre = self.vec3(&s, &format!("{key}.sphere.centre"), sp.centre)?;
            if !(sp.radius > 0.0 && sp.radius <= WORLD_LIMIT) {
                return Err(self.err(
                    s,
                    &format!("{key}.sphere.radius"),
                    "expected a number > 0, at most 1e60",
                ));
            }
            Solid::Sphere(Sphere {
                centre,
                radius: sp.radius,
            })
        } else if let Some(b) = &d.cuboid {
            let min = self.vec3(&s, &format!("{key}.box.min"), b.min)?;
            let max = self.vec3(&s, &format!("{key}.box.max"), b.max)?;
            if !min.cmplt(max).all() {
                return Err(self.err(
                    s,
                    &format!("{key}.box.max"),
                    "expected min < max on every axis",
                ));
            }
            Solid::Cuboid(Cuboid { min, max })
        } else if let Some(c) = &d.cone {
            Solid::Cone(self.cone(c, &s, &format!("{key}.cone"))?)
        } else if let Some(t) = &d.torus {
            Solid::Torus(self.torus(t, &s, &format!("{key}.torus"))?)
        } else if let Some(v) = &d.volume {
            let vol = self.volumes.get(v.get_ref()).cloned().ok_or_else(|| {
                self.err(
                    v.span(),
                    &format!("{key}.volume"),
                    format!("no [volume.{}] in this scene", v.get_ref()),
                )
            })?;
            if vol.classifier.is_direct() {
                return Err(self.err(
                    v.span(),
                    &format!("{key}.volume"),
                    format!(
                        "[volume.{}] is rendered directly (render = \"direct\"); a CSG leaf takes an iso-surface volume (render = \"iso\")",
                        v.get_ref()
                    ),
                ));
            }
            Solid::Volume(vol)
        } else {
            return Err(self.err(s, &key, "no shape"));
        };
        // Located at the shape's value, as an object's shape is.
        let which = match &shape {
            Solid::Sphere(_) => "sphere",
            Solid::Cuboid(_) => "box",
            Solid::Cone(_) => "cone",
            Solid::Torus(_) => "torus",
            Solid::Volume(_) => "volume",
        };
        let at = self.spans.value(&format!("{key}.{which}")).unwrap_or(s);
        Ok(CsgLeaf {
            shape,
            material,
            loc: self.loc(at),
        })
    }

    pub(super) fn csg(
        &self,
        scene: &mut Scene,
        doc: &Doc,
        root: &Spanned<CsgOp>,
        material: Option<&Spanned<String>>,
        s: &std::ops::Range<usize>,
        loc: SourceLoc,
    ) -> Result<(), SceneError> {
        let default_material = match material {
            Some(m) => Some(self.material_of(Some(m), s, "object.material")?),
            None => None,
        };
        let mut csg = Csg {
            nodes: Vec::new(),
            leaves: Vec::new(),
            loc,
        };
        self.csg_op(
            doc,
            root.get_ref(),
            (&root.span(), "object.csg"),
            default_material,
            &mut csg,
            0,
        )?;
        // The volume rule (module docs).
        let leaf_has_volume = |l: u16| {
            matches!(
                csg.leaves.get(usize::from(l)).map(|l| &l.shape),
                Some(Solid::Volume(_))
            )
        };
        let volumes = csg
            .leaves
            .iter()
            .filter(|l| matches!(l.shape, Solid::Volume(_)))
            .count();
        if volumes > 0 {
            let ok = volumes == 1
                && match csg.nodes.last() {
                    Some(CsgNode::Difference(a, _) | CsgNode::Intersection(a, _)) => matches!(
                        csg.nodes.get(usize::from(*a)),
                        Some(CsgNode::Leaf(l)) if leaf_has_volume(*l)
                    ),
                    _ => false,
                };
            if !ok {
                return Err(self.err(
                    root.span(),
                    "object.csg",
                    "a volume may only be the first operand of the tree's top difference or intersection (and only one volume per tree)",
                ));
            }
        }
        scene.csgs.push(csg);
        Ok(())
    }

    /// One operation of a tree, at key path `path` (`object.csg`, then
    /// `object.csg.difference[1]`, …).
    pub(super) fn csg_op(
        &self,
        doc: &Doc,
        d: &CsgOp,
        (at, path): (&std::ops::Range<usize>, &str),
        material: Option<usize>,
        csg: &mut Csg,
        depth: usize,
    ) -> Result<u16, SceneError> {
        let s = at.clone();
        let too_big = || {
            self.err(
                s.clone(),
                "object.csg",
                format!("more than {MAX_NODES} nodes"),
            )
        };
        if depth > MAX_NODES {
            return Err(too_big());
        }
        let (kind, op, args) = match (&d.union, &d.intersection, &d.difference) {
            (Some(a), None, None) => (0, "union", a),
            (None, Some(a), None) => (1, "intersection", a),
            (None, None, Some(a)) => (2, "difference", a),
            _ => {
                return Err(self.err(
                    s,
                    path,
                    "expected exactly one of union, intersection, difference",
                ));
            }
        };
        if args.len() < 2 {
            return Err(self.err(
                s,
                &format!("{path}.{op}"),
                "an operation takes 2 or more operands",
            ));
        }
        if args.len() > MAX_NODES {
            return Err(self.err(
                s,
                &format!("{path}.{op}"),
                format!(
                    "{} operands: a CSG tree holds at most {MAX_NODES} nodes",
                    args.len()
                ),
            ));
        }
        let mut acc: Option<u16> = None;
        for (i, a) in args.iter().enumerate() {
            let operand = format!("{path}.{op}[{i}]");
            let id = match a {
                CsgExpr::Leaf(name) => {
                    let leaf = self.solid(doc, name, (at, &operand), material)?;
                    let l = u16::try_from(csg.leaves.len()).map_err(|_| too_big())?;
                    csg.leaves.push(leaf);
                    if csg.nodes.len() >= MAX_NODES {
                        return Err(too_big());
                    }
                    csg.nodes.push(CsgNode::Leaf(l));
                    u16::try_from(csg.nodes.len() - 1).map_err(|_| too_big())?
                }
                CsgExpr::Op(inner) => {
                    self.csg_op(doc, inner, (at, &operand), material, csg, depth + 1)?
                }
            };
            acc = Some(match acc {
                None => id,
                Some(prev) => {
                    if csg.nodes.len() >= MAX_NODES {
                        return Err(too_big());
                    }
                    csg.nodes.push(match kind {
                        0 => CsgNode::Union(prev, id),
                        1 => CsgNode::Intersection(prev, id),
                        _ => CsgNode::Difference(prev, id),
                    });
                    u16::try_from(csg.nodes.len() - 1).map_err(|_| too_big())?
                }
            });
        }
        acc.ok_or_else(too_big)
    }
}

/// A CSG tree of one solid: a capped cone.
pub(super) fn single_leaf(shape: Solid, material: usize, loc: SourceLoc) -> Csg {
    Csg {
        nodes: vec![CsgNode::Leaf(0)],
        leaves: vec![CsgLeaf {
            shape,
            material,
            loc: loc.clone(),
        }],
        loc,
    }
}
