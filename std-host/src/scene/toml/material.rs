//! Materials and their textures.

use ::toml::Spanned;
use glam::DVec3;

use super::build::Builder;
use super::schema::{MaterialDef, TextureDef};
use crate::assets::texture::{
    AnyTexture, Blend, Checker, ImageTexture, Mapping, Marble, Wood, Wrap,
};
use crate::scene::error::SceneError;
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
        let bad = |e: crate::assets::texture::TextureError| self.err(s.clone(), key, e.to_string());
        let any = if let Some(c) = &d.checker {
            AnyTexture::Checker(
                Checker::new(self.vec3(&s, key, c.origin)?, c.size, c.colours).map_err(bad)?,
            )
        } else if let Some(m) = &d.marble {
            AnyTexture::Marble(
                Marble::new(
                    m.seed,
                    self.vec3(&s, key, m.direction)?,
                    m.period,
                    m.noise_scale,
                    m.turbulence,
                    m.octaves,
                    m.colours,
                )
                .map_err(bad)?,
            )
        } else if let Some(w) = &d.wood {
            AnyTexture::Wood(
                Wood::new(
                    w.seed,
                    self.vec3(&s, key, w.origin)?,
                    self.vec3(&s, key, w.direction)?,
                    w.period,
                    w.noise_scale,
                    w.turbulence,
                    w.octaves,
                    w.colours,
                )
                .map_err(bad)?,
            )
        } else if let Some(i) = &d.image {
            let mapping = match (&i.planar, &i.cylindrical, &i.spherical) {
                (Some(p), None, None) => Mapping::Planar {
                    origin: self.vec3(&s, key, p.origin)?,
                    u_axis: self.vec3(&s, key, p.u)?,
                    v_axis: self.vec3(&s, key, p.v)?,
                },
                (None, Some(a), None) => Mapping::Cylindrical {
                    origin: self.vec3(&s, key, a.centre)?,
                    axis: self.vec3(&s, key, a.axis)?,
                    reference: self.vec3(&s, key, a.reference)?,
                },
                (None, None, Some(a)) => Mapping::Spherical {
                    centre: self.vec3(&s, key, a.centre)?,
                    pole: self.vec3(&s, key, a.axis)?,
                    reference: self.vec3(&s, key, a.reference)?,
                },
                _ => {
                    return Err(self.err(
                        s,
                        key,
                        "an image needs exactly one of planar, cylindrical, spherical",
                    ));
                }
            };
            let wrap = match i.wrap.as_deref() {
                None | Some("repeat") => Wrap::Repeat,
                Some("mirror") => Wrap::Mirror,
                Some("clamp") => Wrap::Clamp,
                Some(_) => {
                    return Err(self.err(s, key, "wrap: expected repeat, mirror or clamp"));
                }
            };
            let (path, _) = self.path(&i.file, &format!("{key}.image.file"))?;
            let img = ImageTexture::open(&path, mapping).map_err(|e| {
                self.err(i.file.span(), &format!("{key}.image.file"), e.to_string())
            })?;
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
