//! Volume data: NRRD and raw files and computed metaballs, classified and
//! placed in the world.

use std::ops::Range;
use std::sync::Arc;

use ::toml::Spanned;

use glam::DVec3;

use super::build::Builder;
use super::schema::VolumeDef;
use crate::assets::volume::computed::{self, Metaball, Metaballs};
use crate::assets::volume::raw::{self, RawSpec};
use crate::assets::volume::{
    self, Classifier, ColorRamp, Endian, Grid, Placement, Ramp, Render, SampleType, Volume,
};
use crate::scene::error::SceneError;
use crate::scene::objects::SceneVolume;

impl Builder<'_> {
    pub(super) fn volume(
        &self,
        name: &str,
        v: &Spanned<VolumeDef>,
    ) -> Result<SceneVolume, SceneError> {
        let s = v.span();
        let d = v.get_ref();
        let key = |k: &str| format!("volume.{name}.{k}");
        let given = [d.file.is_some(), d.raw.is_some(), d.metaballs.is_some()];
        self.exactly_one(&given, &s, &key("file"), "file (NRRD), raw, metaballs")?;
        let data = self.volume_data(d, &s, &key)?;
        let classifier = self.classifier(d, &s, &key)?;
        let placement = self.placement(d, &data, &s, &key)?;
        Ok(SceneVolume {
            volume: Arc::new(data),
            placement,
            classifier,
        })
    }

    /// The samples of a volume: an NRRD file, a raw file or metaballs.
    fn volume_data(
        &self,
        d: &VolumeDef,
        s: &Range<usize>,
        key: &dyn Fn(&str) -> String,
    ) -> Result<Volume, SceneError> {
        let s = s.clone();
        if let Some(f) = &d.file {
            let (path, _) = self.path(f, &key("file"))?;
            volume::nrrd::read(&path, &self.opts.volume)
                .map_err(|e| self.err(f.span(), &key("file"), e.to_string()))
        } else if let Some(r) = &d.raw {
            let sample_type = match r.sample_type.as_str() {
                "uint8" | "u8" => SampleType::U8,
                "int16" | "i16" => SampleType::I16,
                "uint16" | "u16" => SampleType::U16,
                "float" | "float32" | "f32" => SampleType::F32,
                _ => {
                    return Err(self.err(
                        s,
                        &key("raw.type"),
                        "expected uint8 (u8), int16 (i16), uint16 (u16) or float (float32, f32)",
                    ));
                }
            };
            if let Some(&n) = r.dims.iter().find(|&&n| n == 0 || n > volume::MAX_AXIS) {
                return Err(self.err(
                    s,
                    &key("raw.dims"),
                    format!(
                        "expected 1 to {} samples per axis, found {n}",
                        volume::MAX_AXIS
                    ),
                ));
            }
            if !r.spacing.iter().all(|&x| x.is_finite() && x > 0.0) {
                return Err(self.err(s, &key("raw.spacing"), "expected numbers > 0"));
            }
            let (path, _) = self.path(&r.file, &key("raw.file"))?;
            let spec = RawSpec {
                dims: r.dims,
                sample_type,
                endian: if r.big_endian {
                    Endian::Big
                } else {
                    Endian::Little
                },
                grid: Grid::axis_aligned(r.spacing, DVec3::ZERO),
                skip: r.skip,
            };
            raw::read(&path, &spec, &self.opts.volume)
                .map_err(|e| self.err(r.file.span(), &key("raw.file"), e.to_string()))
        } else if let Some(m) = &d.metaballs {
            let lo = self.vec3(&s, &key("metaballs.min"), m.min)?;
            let hi = self.vec3(&s, &key("metaballs.max"), m.max)?;
            let n = m.dims.map(|d| f64::from(d.max(2) - 1));
            let spacing = [
                (hi.x - lo.x) / n[0],
                (hi.y - lo.y) / n[1],
                (hi.z - lo.z) / n[2],
            ];
            let mut balls = Vec::with_capacity(m.balls.len().min(1024));
            for (i, b) in m.balls.iter().enumerate() {
                if !(b.iter().all(|x| x.is_finite()) && b[3] > 0.0) {
                    return Err(self.err(
                        s,
                        &key(&format!("metaballs.balls[{i}]")),
                        "expected finite [x, y, z, radius > 0, strength]",
                    ));
                }
                balls.push(Metaball {
                    centre: DVec3::new(b[0], b[1], b[2]),
                    radius: b[3],
                    strength: b[4],
                });
            }
            computed::sample(
                &Metaballs(balls),
                m.dims,
                Grid::axis_aligned(spacing, lo),
                &self.opts.volume,
            )
            .map_err(|e| self.err(s.clone(), &key("metaballs.dims"), e.to_string()))
        } else {
            Err(self.err(s.clone(), &key("file"), "no data"))
        }
    }

    /// The iso-value and the optional opacity and colour ramps.
    fn classifier(
        &self,
        d: &VolumeDef,
        s: &Range<usize>,
        key: &dyn Fn(&str) -> String,
    ) -> Result<Classifier, SceneError> {
        let s = s.clone();
        // With an opacity ramp and no iso-value, the ramp alone decides.
        let iso = match (d.iso, &d.opacity) {
            (Some(iso), _) => iso,
            (None, Some(_)) => f64::MIN,
            (None, None) => {
                return Err(self.err(
                    s,
                    &key("iso"),
                    "missing: give an iso-value, an opacity ramp, or both",
                ));
            }
        };
        let mut classifier = Classifier::iso(iso);
        if let Some(o) = &d.opacity {
            for (i, p) in o.iter().enumerate() {
                if !(p[0].is_finite() && (0.0..=1.0).contains(&p[1])) {
                    return Err(self.err(
                        s,
                        &key(&format!("opacity[{i}]")),
                        "expected [value, alpha] with alpha in [0, 1]",
                    ));
                }
                if i > 0 && !(p[0] > o[i - 1][0]) {
                    return Err(self.err(
                        s,
                        &key(&format!("opacity[{i}][0]")),
                        "expected values that increase along the ramp",
                    ));
                }
            }
            let ramp = Ramp::new(o.iter().map(|p| (p[0], p[1])).collect())
                .map_err(|e| self.err(s.clone(), &key("opacity"), e.to_string()))?;
            classifier = classifier.with_opacity(ramp);
        }
        if let Some(c) = &d.colours {
            let mut pts = Vec::with_capacity(c.len().min(4096));
            for (i, p) in c.iter().enumerate() {
                if !p.iter().all(|x| x.is_finite())
                    || p[1..].iter().any(|&x| !(0.0..=1.0).contains(&x))
                {
                    return Err(self.err(
                        s,
                        &key(&format!("colours[{i}]")),
                        "expected [value, r, g, b] with channels in [0, 1]",
                    ));
                }
                if i > 0 && !(p[0] > c[i - 1][0]) {
                    return Err(self.err(
                        s,
                        &key(&format!("colours[{i}][0]")),
                        "expected values that increase along the ramp",
                    ));
                }
                let ch = |x: f64| (x * 255.0).round() as u8;
                pts.push((p[0], [ch(p[1]), ch(p[2]), ch(p[3])]));
            }
            let ramp = ColorRamp::new(pts)
                .map_err(|e| self.err(s.clone(), &key("colours"), e.to_string()))?;
            classifier = classifier.with_color(ramp);
        }
        classifier
            .validate()
            .map_err(|e| self.err(s.clone(), &key("iso"), e.to_string()))?;
        // Direct volume rendering where the opacity ramp has partial
        // opacities (a point strictly between 0 and 1), unless `render`
        // says otherwise: a ramp of only 0 and 1 is a cut of the
        // iso-surface, as it always was.
        let partial = d
            .opacity
            .as_ref()
            .is_some_and(|o| o.iter().any(|p| p[1] > 0.0 && p[1] < 1.0));
        let render = match d.render.as_deref() {
            None if partial => Render::Direct,
            None | Some("iso") => Render::Iso,
            Some("direct") => Render::Direct,
            Some(other) => {
                return Err(self.err(
                    s,
                    &key("render"),
                    format!("expected \"iso\" or \"direct\", found \"{other}\""),
                ));
            }
        };
        if render == Render::Direct && d.opacity.is_none() {
            return Err(self.err(
                s,
                &key("render"),
                "direct volume rendering needs a transfer function: give opacity = [[value, alpha], …]",
            ));
        }
        Ok(classifier.with_render(render))
    }

    /// Where the volume goes: fitted into a box, or translated and scaled.
    fn placement(
        &self,
        d: &VolumeDef,
        data: &Volume,
        s: &Range<usize>,
        key: &dyn Fn(&str) -> String,
    ) -> Result<Placement, SceneError> {
        let s = s.clone();
        match (&d.fit, d.translate, d.scale) {
            (Some(b), None, None) => {
                let min = self.vec3(&s, &key("fit.min"), b.min)?;
                let max = self.vec3(&s, &key("fit.max"), b.max)?;
                if !min.cmplt(max).all() {
                    return Err(self.err(s, &key("fit.max"), "expected min < max on every axis"));
                }
                Placement::fit_into(data, crate::world::Bounds { min, max })
                    .map_err(|e| self.err(s.clone(), &key("fit"), e.to_string()))
            }
            (None, t, sc) => {
                let translate = self.vec3(&s, &key("translate"), t.unwrap_or_default())?;
                let scale = sc.unwrap_or(1.0);
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(self.err(s, &key("scale"), "expected a number > 0"));
                }
                Placement::new(translate, scale)
                    .map_err(|e| self.err(s.clone(), &key("translate"), e.to_string()))
            }
            _ => Err(self.err(s, &key("fit"), "give fit, or translate and scale, not both")),
        }
    }
}
