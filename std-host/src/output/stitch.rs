//! Joining bands (`rrt render --tile I/N`) into the whole image: the
//! bands' samples, read back exactly, one after the other, written by the
//! same encoder as a whole render, so the result is byte for byte the
//! file one process writes.
//!
//! Each band file says which band of which image it is ([`BandTag`]).
//! Stitching checks, before reading any pixels, that the files are bands
//! of one image: each names itself, all have one format, kind of samples
//! (bit depth, sRGB or linear), whole image size, band count and render,
//! every band is there once, in order (band 0, the top one, first), and
//! each file holds its band's rows. Bands are PNG, PPM or OpenEXR; PFM has
//! no place to say which band a file is, so PFM bands are refused (the
//! same floats stitched from OpenEXR bands make the PFM file). The output
//! may be any format holding the bands' samples: PNG or PPM for integer
//! codes of the same bit depth and encoding, OpenEXR or PFM for floats.

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Seek, Write};
use std::path::{Path, PathBuf};

use super::band::BandTag;
use super::encoding::{Codes, Encoding, SampleKind, Samples};
use super::image::{Format, ImageOutput, OutputError};
use crate::fit::Bytes;

/// Why bands cannot be stitched.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StitchError {
    /// No band files given.
    #[error("no band files to stitch")]
    NoBands,
    /// A band file cannot be read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A file that is not a band, or not one of this image, or out of
    /// place.
    #[error("{}: {message}", path.display())]
    Band {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Writing the whole image.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// A band file's header: what it says it is.
#[derive(Debug, Clone)]
struct Header {
    path: PathBuf,
    format: Format,
    tag: BandTag,
}

fn band_error(path: &Path, message: impl Into<String>) -> StitchError {
    StitchError::Band {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn io_error(path: &Path) -> impl Fn(std::io::Error) -> StitchError + '_ {
    move |source| StitchError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// What was stitched.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Stitched {
    /// The whole image's width and height.
    pub size: [u32; 2],
    /// How many bands.
    pub bands: u32,
    /// The samples' kind.
    pub kind: SampleKind,
}

/// Joins the band files `inputs`, in order, into `output` (its extension
/// chooses the format; `-` is PNG on `stdout`), through
/// [`ImageOutput`]. The memory the image needs (`stitch_memory`) is
/// checked against `max_memory` from the bands' headers, before any
/// pixels are read or the output is created.
///
/// # Errors
/// [`StitchError`]: no inputs, an output that is one of the bands, an
/// unreadable file, a file that is not a band of the same image as the
/// first or not in its place (naming the file and what is wrong), an
/// image needing more memory than
/// `max_memory`, an output format that cannot hold the bands' samples,
/// or the output's error.
pub fn stitch(
    inputs: &[PathBuf],
    output: &Path,
    max_memory: u64,
    stdout: &mut impl Write,
) -> Result<Stitched, StitchError> {
    let Some(first_path) = inputs.first() else {
        return Err(StitchError::NoBands);
    };
    let out_format = Format::from_path(output)?;
    // The whole image written over one of its bands would lose the band.
    if let Ok(out) = std::fs::canonicalize(output)
        && let Some(band) = inputs
            .iter()
            .find(|p| std::fs::canonicalize(p).is_ok_and(|p| p == out))
    {
        return Err(band_error(
            output,
            format!(
                "is the band {} too: the whole image would replace it; write it to another file",
                band.display()
            ),
        ));
    }
    let headers = inputs
        .iter()
        .map(|p| header(p))
        .collect::<Result<Vec<_>, _>>()?;
    check_bands(&headers)?;
    let needed = stitch_memory(&headers, out_format);
    if needed > max_memory {
        let t = &headers[0].tag;
        return Err(band_error(
            first_path,
            format!(
                "a {}x{} image of {} needs about {} to stitch, more than the memory limit of {} (--max-memory)",
                t.width,
                t.height,
                t.kind,
                Bytes(needed),
                Bytes(max_memory)
            ),
        ));
    }
    let first = &headers[0].tag;
    let encoding = match first.kind {
        SampleKind::Codes(e) => e,
        SampleKind::Float => Encoding::default(),
    };
    if out_format.is_float() != (first.kind == SampleKind::Float) {
        let want = if first.kind == SampleKind::Float {
            ".exr or .pfm"
        } else {
            ".png or .ppm"
        };
        return Err(band_error(
            output,
            format!(
                "cannot hold the bands' samples ({} in {}); stitch them into {want}",
                first.kind,
                first_path.display()
            ),
        ));
    }
    let out = ImageOutput::create(output, encoding)?;
    let mut all: Option<Samples<'static>> = None;
    for h in &headers {
        let samples = pixels(h)?;
        match &mut all {
            None => all = Some(samples),
            Some(a) => {
                if !a.append(samples) {
                    return Err(band_error(&h.path, "samples of another kind"));
                }
            }
        }
    }
    let all = all.ok_or(StitchError::NoBands)?;
    out.write_samples(first.width, first.height, &all, None, stdout)?;
    Ok(Stitched {
        size: [first.width, first.height],
        bands: first.band.count,
        kind: first.kind,
    })
}

/// Bytes of memory stitching the bands `headers` (checked to be bands of
/// one image) into `out` needs at most: the whole image's samples, the
/// largest band's as read (twice: the file's bytes and the samples made
/// of them), and the encoder's copies, counted as `rrt render` counts
/// them (two copies of the codes; 24 bytes a pixel for OpenEXR).
fn stitch_memory(headers: &[Header], out: Format) -> u64 {
    let Some(first) = headers.first() else {
        return 0;
    };
    let t = &first.tag;
    let per_pixel = match t.kind {
        SampleKind::Codes(e) => 3 * u64::from(e.bits.div_ceil(8)),
        SampleKind::Float => 12,
    };
    let pixels = u64::from(t.width) * u64::from(t.height);
    let rows = headers
        .iter()
        .map(|h| {
            let r = h.tag.rows();
            u64::from(r.end - r.start)
        })
        .max()
        .unwrap_or(0);
    let band = u64::from(t.width) * rows * per_pixel;
    let encoding = match out {
        Format::Exr => pixels * 24,
        _ => pixels * 2 * per_pixel,
    };
    (pixels * per_pixel)
        .saturating_add(band.saturating_mul(2))
        .saturating_add(encoding)
}

/// Checks that the headers are the bands of one image, each once, in
/// order.
fn check_bands(headers: &[Header]) -> Result<(), StitchError> {
    let Some(first) = headers.first() else {
        return Err(StitchError::NoBands);
    };
    let (f, ft) = (&first.path, &first.tag);
    for h in headers {
        let (p, t) = (&h.path, &h.tag);
        let differs = |what: &str, this: String, that: String| {
            Err(band_error(
                p,
                format!(
                    "{what} {this}, but {} has {that}: not bands of one image",
                    f.display()
                ),
            ))
        };
        if h.format != first.format {
            return differs("format", h.format.name().into(), first.format.name().into());
        }
        if t.kind != ft.kind {
            return differs("samples", t.kind.to_string(), ft.kind.to_string());
        }
        if (t.width, t.height) != (ft.width, ft.height) {
            return differs(
                "image size",
                format!("{}x{}", t.width, t.height),
                format!("{}x{}", ft.width, ft.height),
            );
        }
        if t.band.count != ft.band.count {
            return differs(
                "a split into",
                format!("{} bands", t.band.count),
                format!("{} (bands of different splits overlap)", ft.band.count),
            );
        }
        if t.render != ft.render {
            // Name the first part of the render that differs (the view,
            // the sampling, ..., the scene's fingerprint).
            let (this, that) = t
                .render
                .split("; ")
                .zip(ft.render.split("; "))
                .find(|(a, b)| a != b)
                .unwrap_or((&t.render, &ft.render));
            return differs("render", format!("\"{this}\""), format!("\"{that}\""));
        }
    }
    let count = ft.band.count;
    for (j, h) in headers.iter().enumerate() {
        let index = h.tag.band.index;
        let j = u32::try_from(j).unwrap_or(u32::MAX);
        if index == j {
            continue;
        }
        let place = |i: u32| headers.iter().position(|o| o.tag.band.index == i);
        let message = if index < j {
            let at = place(index).map_or(0, |k| k);
            format!(
                "band {index} of {count} again: {} holds it already",
                headers[at].path.display()
            )
        } else if let Some(k) = place(j) {
            format!(
                "band {index} of {count} given before band {j} ({}): list the bands in order, band 0 (the top one) first",
                headers[k].path.display()
            )
        } else {
            format!("band {index} of {count}, but band {j} is missing")
        };
        return Err(band_error(&h.path, message));
    }
    let given = u32::try_from(headers.len()).unwrap_or(u32::MAX);
    if given < count {
        let last = &headers[headers.len() - 1].path;
        return Err(band_error(
            last,
            format!(
                "the last band given is {} of {count}: bands {given} to {} are missing",
                given - 1,
                count - 1
            ),
        ));
    }
    Ok(())
}

/// A band file's format and tag, without its pixels.
fn header(path: &Path) -> Result<Header, StitchError> {
    let format = Format::from_path(path).map_err(|_| {
        band_error(
            path,
            "not a band file: bands are .png, .ppm or .exr images written by `rrt render --tile`",
        )
    })?;
    let text = match format {
        Format::Png => {
            let reader = png_reader(path)?;
            let mut tags = reader
                .info()
                .uncompressed_latin1_text
                .iter()
                .filter(|t| t.keyword == super::png::BAND_KEYWORD);
            let text = tags.next().map(|t| t.text.clone());
            if tags.next().is_some() {
                return Err(band_error(
                    path,
                    format!(
                        "two `{}` descriptions: a band says once which band it is",
                        super::png::BAND_KEYWORD
                    ),
                ));
            }
            text
        }
        Format::Ppm => ppm_header(path)?.band,
        Format::Exr => {
            let meta = exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| band_error(path, format!("not a readable OpenEXR file: {e}")))?;
            meta.headers.first().and_then(|h| {
                match h
                    .own_attributes
                    .other
                    .get(&exr::meta::attribute::Text::from(
                        super::exr::BAND_ATTRIBUTE,
                    )) {
                    Some(exr::meta::attribute::AttributeValue::Text(t)) => Some(t.to_string()),
                    _ => None,
                }
            })
        }
        Format::Pfm => {
            return Err(band_error(
                path,
                "a PFM file has no place to say which band it is, so PFM bands cannot be stitched; render the bands as .exr (the same 32-bit floats) and stitch them into a .pfm",
            ));
        }
    };
    let Some(text) = text else {
        return Err(band_error(
            path,
            "not a band: the file does not say which band of which image it is (write bands with `rrt render --tile I/N`)",
        ));
    };
    let tag = BandTag::parse(&text)
        .ok_or_else(|| band_error(path, format!("unreadable band description {text:?}")))?;
    // OpenEXR bands hold floats, PNG and PPM bands integer codes.
    if (tag.kind == SampleKind::Float) != format.is_float() {
        return Err(band_error(
            path,
            format!(
                "says it holds {} samples, but {} bands hold {}",
                tag.kind,
                format.name(),
                if format.is_float() {
                    "32-bit floats"
                } else {
                    "integer codes"
                }
            ),
        ));
    }
    Ok(Header {
        path: path.to_path_buf(),
        format,
        tag,
    })
}

/// A PNG decoder past the header, for the raw samples (no
/// transformations), with the decoder's default limit on what it
/// allocates itself (the caller allocates the pixels, after checking
/// their size).
fn png_reader(path: &Path) -> Result<png::Reader<BufReader<File>>, StitchError> {
    let file = File::open(path).map_err(io_error(path))?;
    let mut d = png::Decoder::new(BufReader::new(file));
    d.set_transformations(png::Transformations::IDENTITY);
    d.read_info()
        .map_err(|e| band_error(path, format!("not a readable PNG file: {e}")))
}

/// The header of a PPM band: as `ppm::write_ppm_codes` writes it.
struct PpmHeader {
    band: Option<String>,
    width: u32,
    height: u32,
    max: u32,
    reader: BufReader<File>,
}

fn ppm_header(path: &Path) -> Result<PpmHeader, StitchError> {
    let file = File::open(path).map_err(io_error(path))?;
    let mut r = BufReader::new(file);
    let line = |r: &mut BufReader<File>| -> Result<String, StitchError> {
        let mut s = String::new();
        r.by_ref()
            .take(4096)
            .read_line(&mut s)
            .map_err(|_| band_error(path, "not a binary PPM file written by rrt"))?;
        Ok(s.trim_end_matches('\n').to_string())
    };
    let bad = || band_error(path, "not a binary PPM file written by rrt");
    if line(&mut r)? != "P6" {
        return Err(bad());
    }
    let mut size = line(&mut r)?;
    let mut band = None;
    if let Some(t) = size.strip_prefix(super::ppm::BAND_COMMENT) {
        band = Some(t.to_string());
        size = line(&mut r)?;
    }
    let (w, h) = size.split_once(' ').ok_or_else(bad)?;
    let num = |s: &str| s.parse::<u32>().map_err(|_| bad());
    let (width, height) = (num(w)?, num(h)?);
    let max = num(&line(&mut r)?)?;
    if !matches!(max, 255 | 65535) {
        return Err(bad());
    }
    Ok(PpmHeader {
        band,
        width,
        height,
        max,
        reader: r,
    })
}

/// The band's samples, checked against its tag.
fn pixels(h: &Header) -> Result<Samples<'static>, StitchError> {
    let path = &h.path;
    let rows = h.tag.rows();
    let (width, height) = (h.tag.width, rows.end - rows.start);
    let size_error = |w: u32, hh: u32| {
        band_error(
            path,
            format!(
                "{w}x{hh} pixels, but band {} of {} of a {}x{} image is {width}x{height}",
                h.tag.band.index, h.tag.band.count, h.tag.width, h.tag.height
            ),
        )
    };
    let kind_error = |found: String| {
        band_error(
            path,
            format!("holds {found} samples but says {}", h.tag.kind),
        )
    };
    let count = 3 * width as usize * height as usize;
    match h.format {
        Format::Png => {
            let mut reader = png_reader(path)?;
            let info = reader.info();
            if (info.width, info.height) != (width, height) {
                return Err(size_error(info.width, info.height));
            }
            let bits = match info.bit_depth {
                png::BitDepth::Eight => 8,
                png::BitDepth::Sixteen => 16,
                _ => 0,
            };
            let found = SampleKind::Codes(Encoding {
                bits,
                linear: info.srgb.is_none(),
            });
            if info.color_type != png::ColorType::Rgb || found != h.tag.kind {
                return Err(kind_error(format!("{:?} {found}", info.color_type)));
            }
            let mut buf = vec![0u8; reader.output_buffer_size().unwrap_or(0)];
            reader
                .next_frame(&mut buf)
                .map_err(|e| band_error(path, format!("not a readable PNG file: {e}")))?;
            codes(path, buf, bits, count)
        }
        Format::Ppm => {
            let mut p = ppm_header(path)?;
            if (p.width, p.height) != (width, height) {
                return Err(size_error(p.width, p.height));
            }
            let bits = if p.max == 255 { 8 } else { 16 };
            match h.tag.kind {
                SampleKind::Codes(e) if e.bits == bits => {}
                _ => return Err(kind_error(format!("{bits}-bit"))),
            }
            // The file's length says how many samples follow the header:
            // a file short of them (or longer) is refused before they are
            // allocated.
            let bytes = count * usize::from(bits / 8);
            let at = p.reader.stream_position().map_err(io_error(path))?;
            let len = p.reader.get_ref().metadata().map_err(io_error(path))?.len();
            let held = len.saturating_sub(at);
            if held != bytes as u64 {
                return Err(band_error(
                    path,
                    format!("{held} bytes of samples, expected {bytes}"),
                ));
            }
            let mut buf = Vec::with_capacity(bytes);
            p.reader
                .by_ref()
                .take(u64::try_from(bytes + 1).unwrap_or(u64::MAX))
                .read_to_end(&mut buf)
                .map_err(io_error(path))?;
            codes(path, buf, bits, count)
        }
        Format::Exr => exr_pixels(h, width, height),
        Format::Pfm => Err(band_error(path, "PFM bands cannot be stitched")),
    }
}

/// 8-bit codes, or 16-bit big-endian ones, exactly `count` of them.
fn codes(
    path: &Path,
    buf: Vec<u8>,
    bits: u8,
    count: usize,
) -> Result<Samples<'static>, StitchError> {
    let bytes = count * usize::from(bits / 8);
    if buf.len() != bytes {
        return Err(band_error(
            path,
            format!("{} bytes of samples, expected {bytes}", buf.len()),
        ));
    }
    Ok(Samples::Codes(if bits == 8 {
        Codes::Eight(buf)
    } else {
        Codes::Sixteen(
            buf.chunks_exact(2)
                .map(|b| u16::from_be_bytes([b[0], b[1]]))
                .collect(),
        )
    }))
}

/// An OpenEXR band's floats: one layer of 32-bit R, G, B.
fn exr_pixels(h: &Header, width: u32, height: u32) -> Result<Samples<'static>, StitchError> {
    use exr::prelude::{ReadChannels, ReadLayers, SampleType};
    let path = &h.path;
    let unreadable =
        |e: exr::error::Error| band_error(path, format!("not a readable OpenEXR file: {e}"));
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(unreadable)?;
    let [layer] = meta.headers.as_slice() else {
        return Err(band_error(path, "not one layer"));
    };
    let size = layer.layer_size;
    if (size.0, size.1) != (width as usize, height as usize) {
        return Err(band_error(
            path,
            format!(
                "{}x{} pixels, but band {} of {} of a {}x{} image is {width}x{height}",
                size.0, size.1, h.tag.band.index, h.tag.band.count, h.tag.width, h.tag.height
            ),
        ));
    }
    if layer.channels.list.len() != 3 || layer.channels.uniform_sample_type != Some(SampleType::F32)
    {
        return Err(band_error(path, "not three channels of 32-bit floats"));
    }
    let w = width as usize;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |res, _| vec![0f32; 3 * res.0 * res.1],
            move |px: &mut Vec<f32>, pos, (r, g, b): (f32, f32, f32)| {
                let i = 3 * (pos.1 * w + pos.0);
                px[i..i + 3].copy_from_slice(&[r, g, b]);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_file(path)
        .map_err(unreadable)?;
    Ok(Samples::Float(image.layer_data.channel_data.pixels.into()))
}
