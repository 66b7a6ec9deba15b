//! Volume data: NRRD and raw files and computed metaballs, classified and
//! placed in the world.

use std::ops::Range;
use std::sync::Arc;

use ::toml::Spanned;

use glam::DVec3;

use super::build::Builder;
use super::schema::{Exact, VolumeDef};
use crate::assets::volume::computed::{Metaball, Metaballs};
use crate::assets::volume::raw::{self, RawSpec};
use crate::assets::volume::{self, Classifier, Endian, Grid, Placement, SampleType, Volume};
use crate::scene::error::{SceneError, with_causes};
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
        let bytes = data.samples().len() as u64 * data.sample_type().size();
        self.volume_bytes
            .set(self.volume_bytes.get().saturating_add(bytes));
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
        // What the volumes and textures read before leave of the memory
        // limit.
        let left = self.opts.max_memory.saturating_sub(self.asset_bytes());
        let limits = volume::Limits {
            max_bytes: self.opts.volume.max_bytes.min(left),
            ..self.opts.volume
        };
        let limits = &limits;
        // Beyond what the memory limit leaves, the reader's refusal is
        // said against that limit.
        let over = |e: volume::VolumeError| -> String {
            match &e {
                volume::VolumeError::TooLarge {
                    path,
                    at,
                    dims,
                    ty,
                    bytes,
                    ..
                } if left < self.opts.volume.max_bytes => {
                    let held = self.asset_bytes();
                    format!(
                        "{}{at}: sizes {dims} of {ty} take {}{}, more than the memory limit of {} (--max-memory)",
                        path.display(),
                        crate::memory::Bytes(*bytes),
                        if held > 0 {
                            format!(
                                " beside the {} of the volumes and textures read before",
                                crate::memory::Bytes(held)
                            )
                        } else {
                            String::new()
                        },
                        crate::memory::Bytes(self.opts.max_memory)
                    )
                }
                _ => with_causes(&e),
            }
        };
        if let Some(f) = &d.file {
            let (path, _) = self.path(f, &key("file"))?;
            volume::nrrd::read(&path, limits).map_err(|e| self.err(f.span(), &key("file"), over(e)))
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
            // A grid step below 1e-12 is degenerate (`Grid::validate`), one
            // above the world's limit cannot be placed.
            if !r
                .spacing
                .iter()
                .all(|&x| (1e-12..=crate::world::WORLD_LIMIT).contains(&x))
            {
                return Err(self.err(
                    s,
                    &key("raw.spacing"),
                    "expected numbers from 1e-12 to 1e60",
                ));
            }
            let (path, _) = self.path(&r.file, &key("raw.file"))?;
            let spec = RawSpec {
                dims: r.dims.0,
                sample_type,
                endian: if r.big_endian {
                    Endian::Big
                } else {
                    Endian::Little
                },
                grid: Grid::axis_aligned(r.spacing.0, DVec3::ZERO),
                skip: r.skip,
            };
            raw::read(&path, &spec, limits)
                .map_err(|e| self.err(r.file.span(), &key("raw.file"), over(e)))
        } else if let Some(m) = &d.metaballs {
            let lo = self.vec3(&s, &key("metaballs.min"), m.min)?;
            let hi = self.vec3(&s, &key("metaballs.max"), m.max)?;
            if !lo.cmplt(hi).all() || !(hi - lo).is_finite() {
                return Err(self.err(
                    s,
                    &key("metaballs.max"),
                    "expected a box: max above min on every axis",
                ));
            }
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
            Metaballs(balls)
                .sample(m.dims.0, Grid::axis_aligned(spacing, lo), limits)
                .map_err(|e| self.err(s.clone(), &key("metaballs.dims"), over(e)))
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
        let opacity = d.opacity.as_deref().map(Exact::plain);
        let colours = d.colours.as_deref().map(Exact::plain);
        Classifier::from_points(
            d.iso,
            opacity.as_deref(),
            colours.as_deref(),
            d.render.as_deref(),
        )
        .map_err(|e| self.err(s.clone(), &key(&e.key), e.message))
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
                // Named by the key that breaks it: the scale alone, else the
                // translation.
                let culprit = if Placement::new(glam::DVec3::ZERO, scale).is_err() {
                    "scale"
                } else {
                    "translate"
                };
                Placement::new(translate, scale)
                    .map_err(|e| self.err(s.clone(), &key(culprit), e.to_string()))
            }
            _ => Err(self.err(s, &key("fit"), "give fit, or translate and scale, not both")),
        }
    }
}
