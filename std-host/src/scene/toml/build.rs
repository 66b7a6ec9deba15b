//! The builder: a parsed TOML document into a [`Scene`], every value
//! checked, every error located at its key.

use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use ::toml::Spanned;
use glam::DVec3;

use super::Options;
use super::schema::{Doc, V3};
use super::spans::Spans;
use crate::scene::error::SceneError;
use crate::scene::loc::SourceLoc;
use crate::scene::objects::SceneVolume;
use crate::scene::polygon::CutBudget;
use crate::scene::text::byte_loc;
use crate::scene::{Light, Material, Polygon, Scene, View};

pub(super) struct Builder<'t> {
    pub(super) file: Arc<str>,
    pub(super) text: &'t str,
    /// Where each value is, for the errors.
    pub(super) spans: Spans<'t>,
    /// The `[[object]]` or `[[light]]` being built and its index: keys
    /// `object.…` in errors become `object[i].…`.
    pub(super) entry: Cell<Option<(&'static str, usize)>>,
    pub(super) dir: PathBuf,
    pub(super) opts: Options,
    pub(super) materials: BTreeMap<String, usize>,
    pub(super) volumes: BTreeMap<String, SceneVolume>,
    /// Bytes the samples of the volumes read so far take.
    pub(super) volume_bytes: Cell<u64>,
    /// Bytes the pixels of the image textures read so far take.
    pub(super) texture_bytes: Cell<u64>,
    /// What cutting non-convex polygons, the scene's and its meshes', may
    /// still cost.
    pub(super) cut_budget: Cell<CutBudget>,
}

/// The vector, if its numbers are finite and within
/// [`WORLD_LIMIT`](crate::world::WORLD_LIMIT).
pub(super) fn finite3(v: V3) -> Option<DVec3> {
    let d = DVec3::from(v.0);
    crate::world::within_world(d).then_some(d)
}

impl Builder<'_> {
    pub(super) fn loc(&self, span: std::ops::Range<usize>) -> SourceLoc {
        byte_loc(&self.file, self.text.as_bytes(), span.start)
    }

    /// An error about the value at `key` (a dotted path; `object.…` and
    /// `light.…` are the entry being built), located at the value itself
    /// when the document has it, else at `span`.
    pub(super) fn err(
        &self,
        span: std::ops::Range<usize>,
        key: &str,
        msg: impl Into<String>,
    ) -> SceneError {
        let key = self.full_key(key);
        let at = self.spans.value(&key).unwrap_or(span);
        SceneError::Toml {
            loc: self.loc(at),
            key,
            msg: msg.into(),
        }
    }

    /// `key` with the index of the `[[object]]` or `[[light]]` being built.
    pub(super) fn full_key(&self, key: &str) -> String {
        if let Some((list, i)) = self.entry.get()
            && let Some(rest) = key.strip_prefix(list)
            && (rest.is_empty() || rest.starts_with('.'))
        {
            return format!("{list}[{i}]{rest}");
        }
        key.to_owned()
    }

    pub(super) fn vec3(
        &self,
        span: &std::ops::Range<usize>,
        key: &str,
        v: V3,
    ) -> Result<DVec3, SceneError> {
        finite3(v)
            .ok_or_else(|| self.err(span.clone(), key, "expected finite numbers within ±1e60"))
    }

    pub(super) fn path(
        &self,
        p: &Spanned<String>,
        key: &str,
    ) -> Result<(PathBuf, String), SceneError> {
        if !self.opts.read_files {
            return Err(self.err(p.span(), key, "files are not read here"));
        }
        let full = self.dir.join(p.get_ref());
        if !full.is_file() {
            let why = match std::fs::metadata(&full) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => "no such file",
                Err(_) => "cannot be read",
                Ok(m) if m.is_dir() => "is a directory, not a file",
                Ok(_) => "is not a regular file",
            };
            return Err(self.err(p.span(), key, format!("{}: {why}", full.display())));
        }
        let shown = full.to_string_lossy().into_owned();
        Ok((full, shown))
    }

    pub(super) fn build(mut self, doc: &Doc) -> Result<Scene, SceneError> {
        let cs = doc.camera.span();
        let c = doc.camera.get_ref();
        let view = View {
            from: self.vec3(&cs, "camera.from", c.from)?,
            at: self.vec3(&cs, "camera.at", c.at)?,
            up: self.vec3(&cs, "camera.up", c.up)?,
            angle: c.angle,
            hither: c.hither,
            resolution: c.resolution.0,
            loc: self.loc(cs.clone()),
        };
        if view.from == view.at {
            return Err(self.err(cs, "camera.at", "equals camera.from"));
        }
        if view.up.cross(view.at - view.from).length_squared() == 0.0 {
            // A default `up` is not in the file: the view direction is
            // what the file sets.
            // (A key the file lacks is located at its table.)
            let given = self.spans.value("camera.up") != self.spans.value("camera");
            let msg = if given {
                "parallel to the view direction (camera.at − camera.from)"
            } else {
                "the default [0, 0, 1] is parallel to the view direction (camera.at − camera.from); give camera.up"
            };
            return Err(self.err(cs, "camera.up", msg));
        }
        if !(view.angle > 0.0 && view.angle < 180.0) {
            return Err(self.err(cs, "camera.angle", "expected 0 < angle < 180"));
        }
        if !(view.hither.is_finite() && view.hither >= 0.0) {
            return Err(self.err(cs, "camera.hither", "expected a distance ≥ 0"));
        }
        if view.resolution.contains(&0) || view.resolution.iter().any(|&r| r > 1 << 15) {
            return Err(self.err(cs, "camera.resolution", "expected 1 to 32768 pixels"));
        }
        let mut scene = Scene::empty(Arc::clone(&self.file), view);
        if let Some(b) = doc.background {
            scene.background = finite3(b)
                .filter(|b| b.cmpge(DVec3::ZERO).all() && b.cmple(DVec3::ONE).all())
                .ok_or_else(|| {
                    self.err(0..0, "background", "expected colour channels in [0, 1]")
                })?;
        }
        for (i, l) in doc.light.iter().enumerate() {
            self.entry.set(Some(("light", i)));
            let s = l.span();
            let d = l.get_ref();
            let position = self.vec3(&s, "light.position", d.position)?;
            let colour = d
                .colour
                .map(|c| self.vec3(&s, "light.colour", c))
                .transpose()?;
            if colour.is_some_and(|c| !c.cmpge(DVec3::ZERO).all()) {
                return Err(self.err(s, "light.colour", "expected channels ≥ 0"));
            }
            scene.lights.push(Light {
                position,
                colour,
                loc: self.loc(s),
            });
        }
        for (name, m) in &doc.material {
            self.material(&mut scene, name, m)?;
        }
        for (name, v) in &doc.volume {
            let sv = self.volume(name, v)?;
            self.volumes.insert(name.clone(), sv);
        }
        // Every [solid.NAME] is checked, whether a tree uses it or not (a
        // tree builds its leaves again where it names them). A solid
        // without a material takes its tree's: none is asked for here.
        for (name, def) in &doc.solid {
            self.solid(doc, name, (&def.span(), &format!("solid.{name}")), Some(0))?;
        }
        self.entry.set(None);
        for (i, o) in doc.object.iter().enumerate() {
            self.entry.set(Some(("object", i)));
            self.object(&mut scene, doc, o)?;
        }
        self.entry.set(None);
        if scene.has_no_objects() {
            return Err(SceneError::NoTomlObjects {
                file: Arc::clone(&self.file),
            });
        }
        if scene.materials.is_empty() {
            scene.materials.push(Material::DEFAULT);
        }
        Ok(scene)
    }

    /// Refuses anything but exactly one of the `given` keys, at `span`.
    pub(super) fn exactly_one(
        &self,
        given: &[bool],
        span: &std::ops::Range<usize>,
        key: &str,
        names: &str,
    ) -> Result<(), SceneError> {
        if given.iter().filter(|&&g| g).count() == 1 {
            Ok(())
        } else {
            Err(self.err(
                span.clone(),
                key,
                format!("expected exactly one of {names}"),
            ))
        }
    }

    pub(super) fn material_of(
        &self,
        m: Option<&Spanned<String>>,
        at: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<usize, SceneError> {
        let Some(m) = m else {
            return Err(self.err(at.clone(), key, "missing: every object names a material"));
        };
        self.materials.get(m.get_ref()).copied().ok_or_else(|| {
            self.err(
                m.span(),
                key,
                format!("no [material.{}] in this scene", m.get_ref()),
            )
        })
    }

    /// Refuses `more` vertices beside those `scene` holds when they pass
    /// [`Options::max_vertices`](super::Options::max_vertices), or when
    /// they and the volumes' samples would take more than
    /// [`Options::max_memory`](super::Options::max_memory); checked before
    /// they are made.
    /// The bytes the scene's data takes so far against the memory limit:
    /// its vertices and its volumes' samples.
    pub(super) fn data_bytes(&self, scene: &Scene) -> u64 {
        (scene.vertices.len() as u64)
            .saturating_mul(super::VERTEX_BYTES)
            .saturating_add(self.asset_bytes())
    }

    /// Bytes the samples of the volumes and the pixels of the image
    /// textures read so far take.
    pub(super) fn asset_bytes(&self) -> u64 {
        self.volume_bytes
            .get()
            .saturating_add(self.texture_bytes.get())
    }

    pub(super) fn room_for_vertices(
        &self,
        scene: &Scene,
        more: usize,
        span: &std::ops::Range<usize>,
        key: &str,
    ) -> Result<(), SceneError> {
        let total = scene.vertices.len().saturating_add(more);
        if total > self.opts.max_vertices {
            return Err(self.err(
                span.clone(),
                key,
                format!(
                    "{total} vertices, more than the scene's limit of {}",
                    self.opts.max_vertices
                ),
            ));
        }
        let held = self.asset_bytes();
        let bytes = (total as u64)
            .saturating_mul(super::VERTEX_BYTES)
            .saturating_add(held);
        if bytes > self.opts.max_memory {
            return Err(self.err(
                span.clone(),
                key,
                format!(
                    "{total} vertices take {}{}, more than the memory limit of {} (--max-memory)",
                    crate::memory::Bytes(bytes - held),
                    if held > 0 {
                        format!(
                            " beside the {} of the volumes and textures",
                            crate::memory::Bytes(held)
                        )
                    } else {
                        String::new()
                    },
                    crate::memory::Bytes(self.opts.max_memory)
                ),
            ));
        }
        Ok(())
    }

    pub(super) fn push_polygon(
        &self,
        scene: &mut Scene,
        vertices: &[DVec3],
        normals: Option<&[DVec3]>,
        material: usize,
        loc: &SourceLoc,
        span: &std::ops::Range<usize>,
    ) -> Result<(), SceneError> {
        self.room_for_vertices(scene, vertices.len(), span, "object")?;
        let mut budget = self.cut_budget.get();
        let cut = super::super::polygon::cut(vertices, &mut budget)
            .map_err(|problem| self.err(span.clone(), "object", problem))?;
        self.cut_budget.set(budget);
        let first = scene.vertices.len();
        scene.vertices.extend_from_slice(vertices);
        match normals {
            Some(n) => scene.normals.extend_from_slice(n),
            None => scene
                .normals
                .extend(std::iter::repeat_n(DVec3::ZERO, vertices.len())),
        }
        scene.polygons.push(Polygon {
            first,
            count: vertices.len(),
            patch: normals.is_some(),
            material,
            cut,
            loc: loc.clone(),
        });
        Ok(())
    }
}
