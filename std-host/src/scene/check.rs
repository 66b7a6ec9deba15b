//! The guarantees of a parsed [`Scene`], checked (feature `check`): for
//! tests and fuzzing.

use glam::DVec3;
use rrt_core::csg::{CsgNode, MAX_NODES};

use super::Scene;
use crate::shape::Primitive;

/// Checks the guarantees documented on [`Scene`]; for tests and fuzzing.
///
/// # Errors
/// A description of the first broken guarantee.
pub fn check_scene(s: &Scene) -> Result<(), String> {
    let finite = |v: DVec3, what: &str| {
        if v.is_finite() {
            Ok(())
        } else {
            Err(format!("{what} not finite: {v}"))
        }
    };
    if s.materials.is_empty() {
        return Err("no materials".into());
    }
    if s.vertices.len() != s.normals.len() {
        return Err("normals not parallel to vertices".into());
    }
    if s.has_no_objects() {
        return Err("no objects".into());
    }
    let v = &s.view;
    finite(v.from, "from")?;
    finite(v.at, "at")?;
    finite(v.up, "up")?;
    if !(v.angle > 0.0 && v.angle < 180.0) || v.resolution.contains(&0) {
        return Err(format!("bad view {v:?}"));
    }
    if (v.at - v.from).cross(v.up).length_squared() == 0.0 {
        return Err("degenerate view".into());
    }
    finite(s.background, "background")?;
    for l in &s.lights {
        finite(l.position, "light")?;
        finite(l.rgb(), "light colour")?;
    }
    for m in &s.materials {
        finite(m.colour, "material colour")?;
        let ok = [m.kd, m.ks, m.shine, m.transmittance, m.ior]
            .iter()
            .all(|x| x.is_finite() && *x >= 0.0);
        if !ok || m.transmittance > 1.0 || (m.transmittance > 0.0 && m.ior <= 0.0) {
            return Err(format!("bad material {m:?}"));
        }
    }
    let nm = s.materials.len();
    for o in &s.spheres {
        check_object(o, nm)?;
    }
    for o in &s.cones {
        check_object(o, nm)?;
    }
    for o in &s.tori {
        check_object(o, nm)?;
    }
    let mut budget = super::polygon::CutBudget::scene();
    for p in &s.polygons {
        if p.material >= nm || p.count < 3 || s.vertices.get(p.range()).is_none() {
            return Err(format!("bad polygon {p:?}"));
        }
        // The cut is the one `polygon::cut` makes of the outline.
        if super::polygon::cut(s.polygon_vertices(p), &mut budget).as_ref() != Ok(&p.cut) {
            return Err(format!("polygon cut not its outline's: {p:?}"));
        }
        for i in p.range() {
            finite(s.vertices[i], "vertex")?;
            let n = s.normals[i];
            if p.patch && n.try_normalize().is_none() {
                return Err(format!("bad patch normal {n}"));
            }
        }
    }
    check_objects(s)
}

fn finite(v: DVec3, what: &str) -> Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{what} not finite: {v}"))
    }
}

fn positive(x: f64) -> bool {
    x > 0.0 && x.is_finite()
}

/// An object's material index and its primitive's invariants (part of
/// [`check_scene`]).
fn check_object<S: Primitive + std::fmt::Debug>(
    o: &super::Object<S>,
    materials: usize,
) -> Result<(), String> {
    if o.material >= materials {
        return Err(format!(
            "{}: material {} of {materials}",
            S::KIND,
            o.material
        ));
    }
    o.shape
        .validate()
        .map_err(|e| format!("bad {} {:?}: {e}", S::KIND, o.shape))
}

/// The guarantees of [`Scene`] about volumes, `.vox` models, CSG trees and
/// textures.
fn check_objects(s: &Scene) -> Result<(), String> {
    let nm = s.materials.len();
    let mat = |m: usize, what: &str| {
        if m < nm {
            Ok(())
        } else {
            Err(format!("{what}: material {m} of {nm}"))
        }
    };
    for v in &s.volumes {
        mat(v.material, "volume")?;
        v.data.classifier.validate().map_err(|e| e.to_string())?;
    }
    for v in &s.voxes {
        mat(v.material, "vox")?;
        finite(v.position, "vox position")?;
        if !positive(v.cell) {
            return Err(format!("vox cell {}", v.cell));
        }
    }
    for c in &s.csgs {
        if c.nodes.is_empty() || c.nodes.len() > MAX_NODES {
            return Err(format!("CSG tree of {} nodes", c.nodes.len()));
        }
        for (i, n) in c.nodes.iter().enumerate() {
            let ok = match *n {
                CsgNode::Leaf(l) => usize::from(l) < c.leaves.len(),
                CsgNode::Union(a, b) | CsgNode::Intersection(a, b) | CsgNode::Difference(a, b) => {
                    usize::from(a) < i && usize::from(b) < i
                }
            };
            if !ok {
                return Err(format!("CSG node {i}: {n:?}"));
            }
        }
        for l in &c.leaves {
            mat(l.material, "CSG leaf")?;
            l.shape
                .validate()
                .map_err(|e| format!("bad solid {:?}: {e}", l.shape))?;
        }
    }
    for (&m, &t) in &s.material_textures {
        if m >= nm || t >= s.textures.len() {
            return Err(format!("material {m} → texture {t}"));
        }
    }
    Ok(())
}
