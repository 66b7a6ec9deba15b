//! Materials and their textures.

use ::toml::Spanned;
use glam::DVec3;

use super::build::Builder;
use super::schema::{MaterialDef, NoiseDef, TextureDef};
use crate::assets::texture::{
    AnyTexture, Blend, Checker, ImageTexture, Mapping, Marble, TextureError, Wood, Wrap,
};
use crate::scene::error::{SceneError, with_causes};
use crate::scene::objects::{SceneTexture, TextureKind};
use crate::scene::{Material, Scene};

impl Builder<'_> {
    pub(super) fn material(
        &mut self,
        scene: &mut Scene,
        name: &str,
        m: &Spanned<MaterialDef>,
    ) -> Result<(), SceneError> {
        let s = m.span();
        let d = m.get_ref();
        let key = |k: &str| format!("material.{name}.{k}");
        let colour = self.vec3(&s, &key("colour"), d.colour)?;
        if !(colour.cmpge(DVec3::ZERO).all() && colour.cmple(DVec3::ONE).all()) {
            return Err(self.err(s, &key("colour"), "expected channels in [0, 1]"));
        }
        for (k, v) in [
            ("kd", d.kd),
            ("ks", d.ks),
            ("shine", d.shine),
            ("ior", d.ior),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(self.err(s, &key(k), "expected a finite number ≥ 0"));
            }
        }
        if !(0.0..=1.0).contains(&d.transmittance) || (d.transmittance > 0.0 && d.ior <= 0.0) {
            return Err(self.err(
                s,
                &key("transmittance"),
                "expected 0 to 1 (and ior > 0 when > 0)",
            ));
        }
        let index = scene.materials.len();
        scene.materials.push(Material {
            colour,
            kd: d.kd,
            ks: d.ks,
            shine: d.shine,
            transmittance: d.transmittance,
            ior: d.ior,
            loc: Some(self.loc(s)),
        });
        if let Some(t) = &d.texture {
            let tex = self.texture(&key("texture"), t)?;
            scene.material_textures.insert(index, scene.textures.len());
            scene.textures.push(tex);
        }
        self.materials.insert(name.to_owned(), index);
        Ok(())
    }

    pub(super) fn texture(
        &self,
        key: &str,
        t: &Spanned<TextureDef>,
    ) -> Result<SceneTexture, SceneError> {
        let s = t.span();
        let d = t.get_ref();
        let given = [
            d.checker.is_some(),
            d.marble.is_some(),
            d.wood.is_some(),
            d.image.is_some(),
        ];
        self.exactly_one(&given, &s, key, "checker, marble, wood, image")?;
        // Each value checked here, at its own key; the constructors' checks
        // are the same, so their errors (named after the texture) do not
        // happen.
        let k = |sub: &str| format!("{key}.{sub}");
        let positive = |v: f64, sub: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(self.err(s.clone(), &k(sub), "expected a number > 0"))
            }
        };
        let direction = |v, sub: &str| {
            let d = self.vec3(&s, &k(sub), v)?;
            if d.length_squared() > 0.0 {
                Ok(d)
            } else {
                Err(self.err(s.clone(), &k(sub), "expected a non-zero vector"))
            }
        };
        let noise = |n: &NoiseDef, kind: &str| -> Result<(), SceneError> {
            positive(n.period, &format!("{kind}.period"))?;
            positive(n.noise_scale, &format!("{kind}.noise_scale"))?;
            if !n.turbulence.is_finite() {
                return Err(self.err(
                    s.clone(),
                    &k(&format!("{kind}.turbulence")),
                    "expected a finite number",
                ));
            }
            if !(1..=16).contains(&n.octaves) {
                return Err(self.err(
                    s.clone(),
                    &k(&format!("{kind}.octaves")),
                    "expected 1 to 16",
                ));
            }
            Ok(())
        };
        let bad = |sub: &str| {
            let (at, span) = (k(sub), s.clone());
            move |e: crate::assets::texture::TextureError| self.err(span, &at, e.to_string())
        };
        let any = if let Some(c) = &d.checker {
            let origin = self.vec3(&s, &k("checker.origin"), c.origin)?;
            let size = positive(c.size, "checker.size")?;
            AnyTexture::Checker(
                Checker::new(origin, size, c.colours.map(|c| c.0)).map_err(bad("checker"))?,
            )
        } else if let Some(m) = &d.marble {
            let origin = self.vec3(&s, &k("marble.origin"), m.origin)?;
            let dir = direction(m.direction, "marble.direction")?;
            noise(m, "marble")?;
            AnyTexture::Marble(
                Marble::new(
                    m.seed,
                    dir,
                    m.period,
                    m.noise_scale,
                    m.turbulence,
                    m.octaves,
                    m.colours.map(|c| c.0),
                )
                .and_then(|m| m.with_origin(origin))
                .map_err(bad("marble"))?,
            )
        } else if let Some(w) = &d.wood {
            let origin = self.vec3(&s, &k("wood.origin"), w.origin)?;
            let dir = direction(w.direction, "wood.direction")?;
            noise(w, "wood")?;
            AnyTexture::Wood(
                Wood::new(
                    w.seed,
                    origin,
                    dir,
                    w.period,
                    w.noise_scale,
                    w.turbulence,
                    w.octaves,
                    w.colours.map(|c| c.0),
                )
                .map_err(bad("wood"))?,
            )
        } else if let Some(i) = &d.image {
            let v = |sub: &str, x| self.vec3(&s, &k(&format!("image.{sub}")), x);
            let (mapping, which) = match (&i.planar, &i.cylindrical, &i.spherical) {
                (Some(p), None, None) => (
                    Mapping::Planar {
                        origin: v("planar.origin", p.origin)?,
                        u_axis: v("planar.u", p.u)?,
                        v_axis: v("planar.v", p.v)?,
                    },
                    "image.planar",
                ),
                (None, Some(a), None) => (
                    Mapping::Cylindrical {
                        origin: v("cylindrical.centre", a.centre)?,
                        axis: v("cylindrical.axis", a.axis)?,
                        reference: v("cylindrical.reference", a.reference)?,
                    },
                    "image.cylindrical",
                ),
                (None, None, Some(a)) => (
                    Mapping::Spherical {
                        centre: v("spherical.centre", a.centre)?,
                        pole: v("spherical.axis", a.axis)?,
                        reference: v("spherical.reference", a.reference)?,
                    },
                    "image.spherical",
                ),
                _ => {
                    return Err(self.err(
                        s,
                        &k("image"),
                        "expected exactly one of planar, cylindrical, spherical",
                    ));
                }
            };
            mapping.validate().map_err(bad(which))?;
            let wrap = match i.wrap.as_deref() {
                None | Some("repeat") => Wrap::Repeat,
                Some("mirror") => Wrap::Mirror,
                Some("clamp") => Wrap::Clamp,
                Some(_) => {
                    return Err(self.err(s, &k("image.wrap"), "expected repeat, mirror or clamp"));
                }
            };
            let (path, _) = self.path(&i.file, &k("image.file"))?;
            // What the volumes and textures read before leave of the
            // memory limit.
            let left = self.opts.max_memory.saturating_sub(self.asset_bytes());
            let held = self.asset_bytes();
            let img = ImageTexture::open_within(&path, mapping, left).map_err(|e| {
                let msg = match &e {
                    // Said against the whole limit, beside what is held.
                    TextureError::TooMuchMemory {
                        path, what, bytes, ..
                    } if held > 0 => format!(
                        "{}: {what} takes about {} to read and decode, beside the {} of the \
                         volumes and textures read before: more than the memory limit of {} \
                         (--max-memory)",
                        path.display(),
                        crate::memory::Bytes(*bytes),
                        crate::memory::Bytes(held),
                        crate::memory::Bytes(self.opts.max_memory)
                    ),
                    _ => with_causes(&e),
                };
                self.err(i.file.span(), &k("image.file"), msg)
            })?;
            self.texture_bytes
                .set(self.texture_bytes.get().saturating_add(img.bytes()));
            AnyTexture::Image(img.with_wrap(wrap))
        } else {
            return Err(self.err(s, key, "no texture"));
        };
        Ok(SceneTexture {
            kind: TextureKind::World(any),
            blend: if d.modulate {
                Blend::Modulate
            } else {
                Blend::Replace
            },
            loc: self.loc(s),
        })
    }
}
