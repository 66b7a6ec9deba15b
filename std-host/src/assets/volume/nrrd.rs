//! NRRD reader: attached (`.nrrd`) and detached (`.nhdr` + data file)
//! headers, `raw`, `gzip` and `ascii` encodings, 3D grids of `uint8`,
//! `int16`, `uint16` and `float`.
//!
//! ```
//! use rrt_host::assets::volume::{nrrd, Limits, SampleType};
//! let mut file = b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\n\
//!                  spacings: 0.5 0.5 2\nencoding: raw\n\n".to_vec();
//! file.extend_from_slice(&[7, 9]);
//! let v = nrrd::parse_bytes("tiny.nrrd", &file, &Limits::default()).unwrap();
//! assert_eq!(v.dims(), [2, 1, 1]);
//! assert_eq!(v.sample_type(), SampleType::U8);
//! assert_eq!(v.spacing(), [0.5, 0.5, 2.0]);
//! assert_eq!(v.value(1, 0, 0), Some(9.0));
//! ```
//!
//! # What is read
//! * magic `NRRD0001` to `NRRD0005`; `#` comment lines; `key:=value`
//!   pairs (ignored);
//! * `type`: `uint8` (`uchar`, `unsigned char`, `uint8_t`), `int16`
//!   (`short`, `short int`, `signed short`, `signed short int`, `int16_t`),
//!   `uint16` (`ushort`, `unsigned short`, `unsigned short int`,
//!   `uint16_t`), `float`; other NRRD types are named in the error;
//! * `dimension: 3` and `sizes` (x fastest);
//! * `encoding`: `raw`, `gzip` (`gz`), `ascii` (`text`, `txt`); `hex`,
//!   `bzip2` and `zrl` are refused by name;
//! * `endian` (required for multi-byte samples in binary encodings);
//! * geometry: `space`/`space dimension` (3D spaces only), `space
//!   directions`, `space origin`, or `spacings` (an axis-aligned grid; a
//!   `nan` spacing counts as unknown, 1); without any, unit spacing at the
//!   origin and [`Volume::geometry_known`] false;
//! * `byte skip` (`-1`: the data are the last bytes of a raw file; for
//!   gzip it skips decompressed bytes, as NRRD specifies) and `line skip`;
//! * `data file` (`datafile`) naming one file, relative to the header's
//!   folder (`LOCAL` means attached); lists and `%d` patterns are refused
//!   by name;
//! * the other standard fields (`kinds`, `space units`, `content`, `min`,
//!   `max`, `labels`, `centers`, …) are accepted and not used; a field NRRD
//!   does not define, or a field given twice, is an error.
//!
//! # Bad input
//! Every error names the file and the header line, or the byte offset in
//! the data file, at fault. The sample bytes are checked against
//! [`Limits::max_bytes`] before anything is allocated; the header is read
//! at most [`Limits::max_header_bytes`] bytes far. The data must hold
//! exactly the samples the header promises: short data and extra data are
//! both errors (a header whose `sizes` lie is caught either way).

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::{DimsFmt, Endian, Grid, Limits, SampleType, Samples, Volume, VolumeError, check_size};

/// How the data are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Raw bytes.
    Raw,
    /// One gzip stream of the raw bytes.
    Gzip,
    /// Whitespace-separated decimal numbers.
    Ascii,
}

/// A parsed NRRD header.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// The `N` of `NRRD000N`.
    pub version: u8,
    /// Sample type.
    pub sample_type: SampleType,
    /// `sizes`.
    pub dims: [u32; 3],
    /// Line of `sizes` (for errors).
    pub sizes_line: usize,
    /// `encoding`.
    pub encoding: Encoding,
    /// `endian`, if given.
    pub endian: Option<Endian>,
    /// The grid from `space directions`/`space origin` or `spacings`, if
    /// any was given.
    pub grid: Option<Grid>,
    /// The detached data file (resolved against the header's folder).
    pub data_file: Option<PathBuf>,
    /// `byte skip` (`-1`: data at the end of a raw file).
    pub byte_skip: i64,
    /// `line skip`.
    pub line_skip: u64,
    /// Bytes of the header, including the empty line that ends it.
    pub header_bytes: u64,
}

/// Reads the NRRD file at `path` (attached or detached header).
///
/// # Errors
/// [`VolumeError`] naming the file and the header line or byte offset at
/// fault (module docs).
pub fn read(path: impl AsRef<Path>, limits: &Limits) -> Result<Volume, VolumeError> {
    let path = path.as_ref();
    let (file, len) = VolumeError::open(path)?;
    let mut reader = BufReader::new(file);
    let header = parse_header(path, &mut reader, limits, true)?;
    match &header.data_file {
        None => decode(path, &mut reader, header.header_bytes, len, &header, limits),
        Some(data) => {
            let (f, dlen) = VolumeError::open(data)?;
            decode(data, &mut BufReader::new(f), 0, dlen, &header, limits)
        }
    }
}

/// Reads an NRRD file held in memory, named `name` in errors. Detached
/// headers are refused (no file is opened).
///
/// # Errors
/// As [`read`].
pub fn parse_bytes(name: &str, bytes: &[u8], limits: &Limits) -> Result<Volume, VolumeError> {
    let path = Path::new(name);
    let mut reader = bytes;
    let header = parse_header(path, &mut reader, limits, false)?;
    let len = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    decode(path, &mut reader, header.header_bytes, len, &header, limits)
}

/// Reads only the header of the NRRD file at `path`.
///
/// # Errors
/// As [`read`], for the header.
pub fn read_header(path: impl AsRef<Path>, limits: &Limits) -> Result<Header, VolumeError> {
    let path = path.as_ref();
    let (file, _) = VolumeError::open(path)?;
    parse_header(path, &mut BufReader::new(file), limits, true)
}

/// Every field name NRRD defines (NRRD0005), with the ones this reader
/// uses listed too.
const KNOWN_FIELDS: &[&str] = &[
    "type",
    "dimension",
    "sizes",
    "encoding",
    "endian",
    "space",
    "space dimension",
    "space directions",
    "space origin",
    "spacings",
    "byte skip",
    "byteskip",
    "line skip",
    "lineskip",
    "data file",
    "datafile",
    "content",
    "min",
    "max",
    "old min",
    "oldmin",
    "old max",
    "oldmax",
    "units",
    "space units",
    "axis mins",
    "axismins",
    "axis maxs",
    "axismaxs",
    "centers",
    "centerings",
    "labels",
    "kinds",
    "thicknesses",
    "measurement frame",
    "sample units",
    "sampleunits",
    "block size",
    "blocksize",
    "number",
];

struct Field {
    line: usize,
    value: String,
}

#[derive(Default)]
struct Fields(Vec<(&'static str, Field)>);

impl Fields {
    fn get(&self, name: &str) -> Option<&Field> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, f)| f)
    }
}

/// Canonical name for the aliases NRRD allows.
fn canonical(name: &str) -> Option<&'static str> {
    let n = match name {
        "byteskip" => "byte skip",
        "lineskip" => "line skip",
        "datafile" => "data file",
        "oldmin" => "old min",
        "oldmax" => "old max",
        "axismins" => "axis mins",
        "axismaxs" => "axis maxs",
        "centerings" => "centers",
        "sampleunits" => "sample units",
        "blocksize" => "block size",
        other => other,
    };
    KNOWN_FIELDS.iter().copied().find(|k| *k == n)
}

fn parse_header<R: BufRead>(
    path: &Path,
    reader: &mut R,
    limits: &Limits,
    may_open_files: bool,
) -> Result<Header, VolumeError> {
    let herr = |line, msg| VolumeError::header(path, line, msg);
    let mut consumed: u64 = 0;
    let mut lineno = 0usize;
    let mut buf = Vec::new();
    let mut fields = Fields::default();
    let mut version = 0u8;
    let mut ended = false;
    loop {
        buf.clear();
        let room = limits.max_header_bytes.saturating_sub(consumed);
        let n = reader
            .by_ref()
            .take(room.saturating_add(1))
            .read_until(b'\n', &mut buf)
            .map_err(VolumeError::io(path))?;
        if n == 0 {
            break;
        }
        lineno += 1;
        consumed = consumed.saturating_add(u64::try_from(n).unwrap_or(u64::MAX));
        if consumed > limits.max_header_bytes {
            return Err(herr(
                lineno,
                format!(
                    "the header runs past {} bytes without an empty line; not a NRRD header",
                    limits.max_header_bytes
                ),
            ));
        }
        let complete = buf.last() == Some(&b'\n');
        let mut text = &buf[..];
        if complete {
            text = &text[..text.len() - 1];
        }
        if text.last() == Some(&b'\r') {
            text = &text[..text.len() - 1];
        }
        if lineno == 1 {
            version = magic(text).ok_or_else(|| {
                herr(
                    1,
                    format!(
                        "not a NRRD file: expected the magic `NRRD0001` to `NRRD0005`, found `{}`",
                        shown(text)
                    ),
                )
            })?;
            continue;
        }
        if text.is_empty() {
            if complete {
                ended = true;
                break;
            }
            break;
        }
        let Ok(line) = std::str::from_utf8(text) else {
            return Err(herr(lineno, "header line is not text (UTF-8)".into()));
        };
        if line.starts_with('#') {
            continue;
        }
        // `key:=value` pairs are free-form and not used: the first colon
        // followed by `=` marks one.
        if let Some(i) = line.find(':')
            && line[i + 1..].starts_with('=')
        {
            continue;
        }
        let Some((name, value)) = line.split_once(": ") else {
            return Err(herr(
                lineno,
                format!("expected `field: value`, found `{}`", shown(text)),
            ));
        };
        let Some(canon) = canonical(name) else {
            return Err(herr(lineno, format!("unknown NRRD field `{name}`")));
        };
        if let Some(prev) = fields.get(canon) {
            return Err(herr(
                lineno,
                format!("{canon}: given twice (first on line {})", prev.line),
            ));
        }
        fields.0.push((
            canon,
            Field {
                line: lineno,
                value: value.trim().to_owned(),
            },
        ));
    }
    if lineno == 0 {
        return Err(herr(1, "empty file: not a NRRD file".into()));
    }
    build_header(
        path,
        &fields,
        version,
        consumed,
        ended,
        may_open_files,
        limits,
    )
}

fn magic(text: &[u8]) -> Option<u8> {
    let rest = text.strip_prefix(b"NRRD000")?;
    match rest {
        [d @ b'1'..=b'5'] => Some(d - b'0'),
        _ => None,
    }
}

/// At most 60 characters of a line, lossy, for messages.
fn shown(text: &[u8]) -> String {
    let s = String::from_utf8_lossy(text);
    let mut out: String = s.chars().take(60).collect();
    if s.chars().count() > 60 {
        out.push('…');
    }
    out.escape_debug().to_string()
}

/// The header of the collected `fields`: every required field present,
/// every value in range.
fn build_header(
    path: &Path,
    fields: &Fields,
    version: u8,
    header_bytes: u64,
    ended: bool,
    may_open_files: bool,
    limits: &Limits,
) -> Result<Header, VolumeError> {
    let herr = |line, msg| VolumeError::header(path, line, msg);
    let missing = |field: &'static str, hint: &'static str| VolumeError::Missing {
        path: path.to_path_buf(),
        field,
        hint,
    };

    if !ended && fields.get("data file").is_none() {
        return Err(VolumeError::data(
            path,
            header_bytes,
            "the header has no empty line ending it and no `data file`: truncated, or no data"
                .into(),
        ));
    }
    let ty = fields.get("type").ok_or_else(|| missing("type", ""))?;
    let sample_type = parse_type(&ty.value).map_err(|m| herr(ty.line, m))?;
    let dim = fields
        .get("dimension")
        .ok_or_else(|| missing("dimension", ""))?;
    parse_dimension(&dim.value).map_err(|m| herr(dim.line, m))?;
    let sizes = fields.get("sizes").ok_or_else(|| missing("sizes", ""))?;
    let dims = parse_sizes(&sizes.value).map_err(|m| herr(sizes.line, m))?;
    let enc = fields
        .get("encoding")
        .ok_or_else(|| missing("encoding", ""))?;
    let encoding = parse_encoding(&enc.value).map_err(|m| herr(enc.line, m))?;
    let endian = match fields.get("endian") {
        None => None,
        Some(f) => Some(parse_endian(&f.value).map_err(|m| herr(f.line, m))?),
    };
    if endian.is_none() && sample_type.size() > 1 && encoding != Encoding::Ascii {
        return Err(missing(
            "endian",
            " (needed for multi-byte samples in raw or gzip data)",
        ));
    }
    let grid = parse_geometry(fields).map_err(|(line, m)| herr(line, m))?;
    let byte_skip = match fields.get("byte skip") {
        None => 0,
        Some(f) => parse_byte_skip(&f.value, encoding, limits).map_err(|m| herr(f.line, m))?,
    };
    let line_skip = match fields.get("line skip") {
        None => 0,
        Some(f) => f.value.parse::<u64>().map_err(|_| {
            herr(
                f.line,
                format!("line skip: expected a count ≥ 0, found `{}`", f.value),
            )
        })?,
    };
    let data_file = match fields.get("data file") {
        None => None,
        Some(f) => parse_data_file(&f.value, path, may_open_files).map_err(|m| herr(f.line, m))?,
    };
    if data_file.is_none() && !ended {
        // `data file: LOCAL` without the empty line.
        return Err(VolumeError::data(
            path,
            header_bytes,
            "the header has no empty line ending it: truncated, or no data".into(),
        ));
    }
    Ok(Header {
        version,
        sample_type,
        dims,
        sizes_line: sizes.line,
        encoding,
        endian,
        grid,
        data_file,
        byte_skip,
        line_skip,
        header_bytes,
    })
}

/// `dimension`: only 3.
fn parse_dimension(value: &str) -> Result<(), String> {
    match value.parse::<u32>() {
        Ok(3) => Ok(()),
        Ok(d) => Err(format!(
            "dimension: {d} axes; only 3D volumes (dimension: 3) are supported"
        )),
        Err(_) => Err(format!("dimension: expected an integer, found `{value}`")),
    }
}

/// `encoding`: raw, gzip or ascii.
fn parse_encoding(value: &str) -> Result<Encoding, String> {
    match value {
        "raw" => Ok(Encoding::Raw),
        "gzip" | "gz" => Ok(Encoding::Gzip),
        "ascii" | "text" | "txt" => Ok(Encoding::Ascii),
        "hex" | "bzip2" | "bz2" | "zrl" => Err(format!(
            "encoding: `{value}` is not supported (raw, gzip or ascii)"
        )),
        other => Err(format!(
            "encoding: unknown encoding `{other}` (raw, gzip or ascii)"
        )),
    }
}

/// `endian`: little or big.
fn parse_endian(value: &str) -> Result<Endian, String> {
    match value {
        "little" => Ok(Endian::Little),
        "big" => Ok(Endian::Big),
        other => Err(format!(
            "endian: expected `little` or `big`, found `{other}`"
        )),
    }
}

/// `byte skip`: -1 (raw data at the end of the file) or a count, bounded
/// for gzip data like the samples (a gzip bomb cannot make the reader
/// spin).
fn parse_byte_skip(value: &str, encoding: Encoding, limits: &Limits) -> Result<i64, String> {
    let v: i64 = value
        .parse()
        .map_err(|_| format!("byte skip: expected an integer, found `{value}`"))?;
    if v < -1 {
        return Err(format!("byte skip: expected -1 or a count ≥ 0, found {v}"));
    }
    if encoding == Encoding::Gzip && v.unsigned_abs() > limits.max_bytes {
        return Err(format!(
            "byte skip: {v} decompressed bytes to skip, more than the limit of {} bytes",
            limits.max_bytes
        ));
    }
    if v == -1 && encoding != Encoding::Raw {
        return Err("byte skip: -1 (data at the end of the file) needs raw encoding".into());
    }
    Ok(v)
}

/// `data file`: `LOCAL` (`None`) or one file beside the header.
fn parse_data_file(
    value: &str,
    header: &Path,
    may_open_files: bool,
) -> Result<Option<PathBuf>, String> {
    if value == "LOCAL" {
        return Ok(None);
    }
    if value.starts_with("LIST") || value.contains('%') || value.split_whitespace().count() > 1 {
        return Err(format!(
            "data file: `{value}`: only a single data file is supported"
        ));
    }
    if !may_open_files {
        return Err(format!(
            "data file: `{value}`: a detached header read from memory cannot open its data file"
        ));
    }
    let base = header.parent().unwrap_or_else(|| Path::new(""));
    Ok(Some(base.join(value)))
}

fn parse_type(value: &str) -> Result<SampleType, String> {
    Ok(match value {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => SampleType::U8,
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            SampleType::I16
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            SampleType::U16
        }
        "float" => SampleType::F32,
        "signed char"
        | "int8"
        | "int8_t"
        | "int"
        | "signed int"
        | "int32"
        | "int32_t"
        | "uint"
        | "unsigned int"
        | "uint32"
        | "uint32_t"
        | "longlong"
        | "long long"
        | "long long int"
        | "signed long long"
        | "signed long long int"
        | "int64"
        | "int64_t"
        | "ulonglong"
        | "unsigned long long"
        | "unsigned long long int"
        | "uint64"
        | "uint64_t"
        | "double"
        | "block" => {
            return Err(format!(
                "type: `{value}` is not supported (uint8, int16, uint16 or float)"
            ));
        }
        other => {
            return Err(format!(
                "type: unknown type `{other}` (uint8, int16, uint16 or float)"
            ));
        }
    })
}

fn parse_sizes(value: &str) -> Result<[u32; 3], String> {
    let parts: Vec<&str> = value.split_whitespace().collect();
    if parts.len() != 3 {
        return Err(format!(
            "sizes: expected 3 sizes (dimension 3), found {} in `{value}`",
            parts.len()
        ));
    }
    let mut dims = [0u32; 3];
    for (slot, p) in dims.iter_mut().zip(&parts) {
        let n: u64 = p
            .parse()
            .map_err(|_| format!("sizes: expected positive integers, found `{p}`"))?;
        if n == 0 || n > u64::from(super::MAX_AXIS) {
            return Err(format!(
                "sizes: {n} samples along an axis; expected 1 to {}",
                super::MAX_AXIS
            ));
        }
        // n <= 2^16.
        *slot = u32::try_from(n).unwrap_or(super::MAX_AXIS);
    }
    Ok(dims)
}

/// A 3D space named by `space` (the 4D `…-time` spaces are refused).
fn space_is_3d(name: &str) -> Result<(), String> {
    match name {
        "right-anterior-superior"
        | "RAS"
        | "left-anterior-superior"
        | "LAS"
        | "left-posterior-superior"
        | "LPS"
        | "scanner-xyz"
        | "3D-right-handed"
        | "3D-left-handed" => Ok(()),
        "right-anterior-superior-time"
        | "RAST"
        | "left-anterior-superior-time"
        | "LAST"
        | "left-posterior-superior-time"
        | "LPST"
        | "scanner-xyz-time"
        | "3D-right-handed-time"
        | "3D-left-handed-time" => Err(format!(
            "space: `{name}` is 4D; only 3D spaces are supported"
        )),
        other => Err(format!("space: unknown space `{other}`")),
    }
}

/// Parses `(a,b,c)` vectors (and `none`) from a field value.
fn parse_vectors(field: &str, value: &str) -> Result<Vec<Option<DVec3>>, String> {
    let mut out = Vec::new();
    let mut rest = value.trim();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
            continue;
        }
        let Some(r) = rest.strip_prefix('(') else {
            return Err(format!(
                "{field}: expected vectors like `(1,0,0)`, found `{rest}`"
            ));
        };
        let Some(end) = r.find(')') else {
            return Err(format!("{field}: `(` without `)`"));
        };
        let comps: Vec<&str> = r[..end].split(',').map(str::trim).collect();
        if comps.len() != 3 {
            return Err(format!(
                "{field}: expected 3 components (a 3D space), found {} in `({})`",
                comps.len(),
                &r[..end]
            ));
        }
        let mut v = [0.0; 3];
        for (slot, c) in v.iter_mut().zip(&comps) {
            *slot = c
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("{field}: `{c}` is not a finite number"))?;
        }
        out.push(Some(DVec3::from(v)));
        rest = r[end + 1..].trim_start();
    }
    Ok(out)
}

fn parse_geometry(fields: &Fields) -> Result<Option<Grid>, (usize, String)> {
    if let Some(f) = fields.get("space") {
        space_is_3d(&f.value).map_err(|m| (f.line, m))?;
    }
    if let Some(f) = fields.get("space dimension") {
        if f.value != "3" {
            return Err((
                f.line,
                format!(
                    "space dimension: `{}`; only 3D spaces are supported",
                    f.value
                ),
            ));
        }
        if let Some(s) = fields.get("space") {
            return Err((
                f.line,
                format!(
                    "space dimension: given together with `space` (line {}); NRRD allows one",
                    s.line
                ),
            ));
        }
    }
    let dirs = fields.get("space directions");
    let spacings = fields.get("spacings");
    let origin = match fields.get("space origin") {
        None => None,
        Some(f) => {
            let v = parse_vectors("space origin", &f.value).map_err(|m| (f.line, m))?;
            match v.as_slice() {
                [Some(o)] => Some(*o),
                _ => {
                    return Err((
                        f.line,
                        format!("space origin: expected one vector, found `{}`", f.value),
                    ));
                }
            }
        }
    };
    match (dirs, spacings) {
        (Some(d), Some(s)) => Err((
            s.line,
            format!(
                "spacings: given together with `space directions` (line {}); NRRD allows one",
                d.line
            ),
        )),
        (Some(d), None) => {
            let v = parse_vectors("space directions", &d.value).map_err(|m| (d.line, m))?;
            if v.len() != 3 {
                return Err((
                    d.line,
                    format!(
                        "space directions: expected 3 vectors (one per axis), found {}",
                        v.len()
                    ),
                ));
            }
            let mut dirs = [DVec3::ZERO; 3];
            for (slot, x) in dirs.iter_mut().zip(v) {
                *slot = x.ok_or_else(|| {
                    (
                        d.line,
                        "space directions: `none` for a spatial axis of a 3D volume".to_string(),
                    )
                })?;
            }
            let grid = Grid {
                origin: origin.unwrap_or(DVec3::ZERO),
                directions: dirs,
            };
            grid.validate()
                .map_err(|m| (d.line, format!("space directions: {m}")))?;
            Ok(Some(grid))
        }
        (None, Some(s)) => {
            let parts: Vec<&str> = s.value.split_whitespace().collect();
            if parts.len() != 3 {
                return Err((
                    s.line,
                    format!("spacings: expected 3 values, found {}", parts.len()),
                ));
            }
            let mut sp = [1.0; 3];
            for (slot, p) in sp.iter_mut().zip(&parts) {
                let x: f64 = p
                    .parse()
                    .map_err(|_| (s.line, format!("spacings: `{p}` is not a number")))?;
                if x.is_nan() {
                    continue;
                }
                if !x.is_finite() || x == 0.0 {
                    return Err((
                        s.line,
                        format!("spacings: `{p}` is not a finite non-zero spacing"),
                    ));
                }
                *slot = x;
            }
            let grid = Grid::axis_aligned(sp, origin.unwrap_or(DVec3::ZERO));
            grid.validate()
                .map_err(|m| (s.line, format!("spacings: {m}")))?;
            Ok(Some(grid))
        }
        (None, None) => Ok(origin.map(|o| Grid::axis_aligned([1.0; 3], o))),
    }
}

/// Reads the samples that follow `header` from `reader`, positioned
/// `start` bytes into a data source of `total` bytes.
fn decode<R: BufRead>(
    path: &Path,
    reader: &mut R,
    start: u64,
    total: u64,
    header: &Header,
    limits: &Limits,
) -> Result<Volume, VolumeError> {
    let count = check_size(
        path,
        header_at(header),
        header.dims,
        header.sample_type,
        limits,
    )?;
    let derr = |offset, msg| VolumeError::data(path, offset, msg);
    let io = VolumeError::io(path);
    let mut pos = start;
    for n in 0..header.line_skip {
        let skipped = reader.skip_until(b'\n').map_err(io)?;
        if skipped == 0 {
            return Err(derr(
                pos,
                format!(
                    "line skip: the data end after {n} of {} lines",
                    header.line_skip
                ),
            ));
        }
        pos = pos.saturating_add(u64::try_from(skipped).unwrap_or(u64::MAX));
    }
    let need = sample_count_bytes(header);
    // Skips `skip` bytes of the data at `pos`: the position after them.
    let skip_data = |reader: &mut R, pos: u64, skip: u64| {
        skip_bytes(reader, skip).map_err(|got| {
            derr(
                pos.saturating_add(got),
                format!("byte skip: the data end after {got} of {skip} bytes"),
            )
        })?;
        Ok::<_, VolumeError>(pos.saturating_add(skip))
    };
    let samples = match header.encoding {
        Encoding::Raw => {
            let skip = if header.byte_skip == -1 {
                let avail = total.saturating_sub(pos);
                if avail < need {
                    return Err(derr(
                        pos,
                        format!(
                            "{avail} bytes of data; sizes {} of {} need {need}",
                            DimsFmt(header.dims),
                            header.sample_type
                        ),
                    ));
                }
                avail - need
            } else {
                u64::try_from(header.byte_skip).unwrap_or(0)
            };
            pos = skip_data(reader, pos, skip)?;
            let s = read_binary(reader, header, count).map_err(|e| match e {
                ReadFail::Io(source) => VolumeError::io(path)(source),
                ReadFail::Short(got) => derr(
                    pos.saturating_add(got),
                    format!(
                        "the data end after {got} of {need} bytes (sizes {} of {}): truncated file or sizes that lie",
                        DimsFmt(header.dims),
                        header.sample_type
                    ),
                ),
            })?;
            let end = pos.saturating_add(need);
            if has_more(reader).map_err(io)? {
                return Err(derr(
                    end,
                    format!(
                        "data continue past the {need} bytes that sizes {} of {} describe: sizes that lie",
                        DimsFmt(header.dims),
                        header.sample_type
                    ),
                ));
            }
            s
        }
        Encoding::Gzip => {
            let mut gz = BufReader::new(flate2::bufread::GzDecoder::new(reader));
            let gzerr = |e: std::io::Error| {
                derr(
                    pos,
                    format!("gzip stream: {e}: damaged or not gzip-compressed"),
                )
            };
            let skip = u64::try_from(header.byte_skip).unwrap_or(0);
            skip_bytes(&mut gz, skip).map_err(|got| {
                derr(
                    pos,
                    format!("byte skip: the decompressed data end after {got} of {skip} bytes"),
                )
            })?;
            let s = read_binary(&mut gz, header, count).map_err(|e| match e {
                ReadFail::Io(e) => gzerr(e),
                ReadFail::Short(got) => derr(
                    pos,
                    format!(
                        "gzip stream: decompresses to {got} of {need} bytes (sizes {} of {}): truncated file or sizes that lie",
                        DimsFmt(header.dims),
                        header.sample_type
                    ),
                ),
            })?;
            if has_more(&mut gz).map_err(gzerr)? {
                return Err(derr(
                    pos,
                    format!(
                        "gzip stream: decompresses to more than the {need} bytes that sizes {} of {} describe: sizes that lie",
                        DimsFmt(header.dims),
                        header.sample_type
                    ),
                ));
            }
            s
        }
        Encoding::Ascii => {
            let skip = u64::try_from(header.byte_skip).unwrap_or(0);
            pos = skip_data(reader, pos, skip)?;
            read_ascii(path, reader, pos, header, count)?
        }
    };
    let (grid, known) = match header.grid {
        Some(g) => (g, true),
        None => (Grid::unit(), false),
    };
    Ok(Volume::new(header.dims, grid, samples)
        .map_err(|e| VolumeError::header(path, header.sizes_line, e.to_string()))?
        .with_geometry_known(known))
}

fn header_at(header: &Header) -> String {
    format!(":{}", header.sizes_line)
}

fn sample_count_bytes(header: &Header) -> u64 {
    super::sample_count(header.dims).saturating_mul(header.sample_type.size())
}

/// Skips `n` bytes; on early end, the bytes skipped.
fn skip_bytes<R: Read>(reader: &mut R, n: u64) -> Result<(), u64> {
    let got = std::io::copy(&mut reader.by_ref().take(n), &mut std::io::sink()).unwrap_or(0);
    if got < n { Err(got) } else { Ok(()) }
}

fn has_more<R: Read>(reader: &mut R) -> std::io::Result<bool> {
    let mut one = [0u8; 1];
    loop {
        match reader.read(&mut one) {
            Ok(n) => return Ok(n > 0),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
}

enum ReadFail {
    Io(std::io::Error),
    /// The bytes read before the end.
    Short(u64),
}

/// Fills `buf` completely; on early end, the bytes read.
fn fill<R: Read>(reader: &mut R, buf: &mut [u8]) -> Result<(), ReadFail> {
    let mut done = 0usize;
    while done < buf.len() {
        match reader.read(&mut buf[done..]) {
            Ok(0) => return Err(ReadFail::Short(u64::try_from(done).unwrap_or(u64::MAX))),
            Ok(n) => done += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(ReadFail::Io(e)),
        }
    }
    Ok(())
}

/// Reads `count` binary samples of the header's type and byte order.
fn read_binary<R: Read>(
    reader: &mut R,
    header: &Header,
    count: usize,
) -> Result<Samples, ReadFail> {
    Samples::read_binary(
        header.sample_type,
        header.endian.unwrap_or(Endian::Little),
        count,
        |buf| fill(reader, buf),
    )
}

/// Reads `count` whitespace- (or comma-) separated numbers.
fn read_ascii<R: BufRead>(
    path: &Path,
    reader: &mut R,
    start: u64,
    header: &Header,
    count: usize,
) -> Result<Samples, VolumeError> {
    let derr = |offset, msg| VolumeError::data(path, offset, msg);
    let ty = header.sample_type;
    let mut out = match ty {
        SampleType::U8 => Samples::U8(Vec::with_capacity(count)),
        SampleType::I16 => Samples::I16(Vec::with_capacity(count)),
        SampleType::U16 => Samples::U16(Vec::with_capacity(count)),
        SampleType::F32 => Samples::F32(Vec::with_capacity(count)),
    };
    let mut pos = start;
    let mut token = Vec::with_capacity(32);
    let mut token_at = pos;
    let mut n = 0usize;
    let mut bytes = reader.bytes();
    loop {
        let b = match bytes.next() {
            None => None,
            Some(Ok(b)) => Some(b),
            Some(Err(source)) => {
                return Err(VolumeError::io(path)(source));
            }
        };
        let sep = b.is_none_or(|b| b.is_ascii_whitespace() || b == b',');
        if !sep {
            if token.is_empty() {
                token_at = pos;
            }
            if token.len() >= 64 {
                return Err(derr(
                    token_at,
                    "ascii data: a number longer than 64 characters".into(),
                ));
            }
            token.extend(b);
        } else if !token.is_empty() {
            if n == count {
                return Err(derr(
                    token_at,
                    format!(
                        "ascii data: more than the {count} values that sizes {} describe",
                        DimsFmt(header.dims)
                    ),
                ));
            }
            let text = String::from_utf8_lossy(&token);
            let x: f64 = text
                .parse()
                .map_err(|_| derr(token_at, format!("ascii data: `{text}` is not a number")))?;
            let bad = || derr(token_at, format!("ascii data: `{text}` does not fit {ty}"));
            match &mut out {
                Samples::U8(v) => v.push(int_fit(x).ok_or_else(bad)?),
                Samples::I16(v) => v.push(int_fit(x).ok_or_else(bad)?),
                Samples::U16(v) => v.push(int_fit(x).ok_or_else(bad)?),
                // Rounds to the nearest f32, as any float reader does.
                #[allow(clippy::cast_possible_truncation)]
                Samples::F32(v) => v.push(x as f32),
            }
            n += 1;
            token.clear();
        }
        match b {
            None => break,
            Some(_) => pos = pos.saturating_add(1),
        }
    }
    if n < count {
        return Err(derr(
            pos,
            format!(
                "ascii data: {n} of the {count} values that sizes {} describe",
                DimsFmt(header.dims)
            ),
        ));
    }
    Ok(out)
}

/// `x` as an integer of type `T` if it is one and fits.
fn int_fit<T: TryFrom<i64>>(x: f64) -> Option<T> {
    if x.fract() != 0.0 || !x.is_finite() || x.abs() > 1e15 {
        return None;
    }
    // |x| <= 1e15 and integral: exact in i64.
    #[allow(clippy::cast_possible_truncation)]
    T::try_from(x as i64).ok()
}

/// Writes `volume` as an attached NRRD0004 file: `gzip` or `raw`
/// encoding, little-endian, `space directions` and `space origin` (used by
/// the tests and for saving resampled or computed volumes).
///
/// # Errors
/// [`VolumeError::Io`] when the file cannot be written.
pub fn write(path: impl AsRef<Path>, volume: &Volume, gzip: bool) -> Result<(), VolumeError> {
    let path = path.as_ref();
    let bytes = to_bytes(volume, gzip);
    std::fs::write(path, bytes).map_err(VolumeError::io(path))
}

/// The bytes of [`write()`].
#[must_use]
pub fn to_bytes(volume: &Volume, gzip: bool) -> Vec<u8> {
    use std::io::Write;
    let g = volume.grid();
    let v = |d: DVec3| format!("({},{},{})", d.x, d.y, d.z);
    let [nx, ny, nz] = volume.dims();
    let mut out = format!(
        "NRRD0004\ntype: {}\ndimension: 3\nspace dimension: 3\nsizes: {nx} {ny} {nz}\n\
         space directions: {} {} {}\nendian: little\nencoding: {}\nspace origin: {}\n\n",
        volume.sample_type(),
        v(g.directions[0]),
        v(g.directions[1]),
        v(g.directions[2]),
        if gzip { "gzip" } else { "raw" },
        v(g.origin),
    )
    .into_bytes();
    let mut data = Vec::new();
    match volume.samples() {
        Samples::U8(s) => data.extend_from_slice(s),
        Samples::I16(s) => s.iter().for_each(|x| data.extend(x.to_le_bytes())),
        Samples::U16(s) => s.iter().for_each(|x| data.extend(x.to_le_bytes())),
        Samples::F32(s) => s.iter().for_each(|x| data.extend(x.to_le_bytes())),
    }
    if gzip {
        let mut enc = flate2::write::GzEncoder::new(out, flate2::Compression::default());
        // Writing to a Vec cannot fail.
        let _ = enc.write_all(&data);
        enc.finish().unwrap_or_default()
    } else {
        out.extend(data);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hdr(body: &str) -> Vec<u8> {
        format!("NRRD0004\n{body}\n").into_bytes()
    }

    fn err(bytes: &[u8]) -> String {
        parse_bytes("t.nrrd", bytes, &Limits::default())
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn big_endian_int16_and_ascii() {
        let mut b = hdr("type: short\ndimension: 3\nsizes: 2 1 1\nendian: big\nencoding: raw\n");
        b.extend_from_slice(&(-300i16).to_be_bytes());
        b.extend_from_slice(&(5i16).to_be_bytes());
        let v = parse_bytes("t.nrrd", &b, &Limits::default()).unwrap();
        assert_eq!(v.samples(), &Samples::I16(vec![-300, 5]));
        assert!(!v.geometry_known());
        let mut b = hdr("type: ushort\ndimension: 3\nsizes: 3 1 1\nencoding: ascii\n");
        b.extend_from_slice(b"1 2\n65535\n");
        let v = parse_bytes("t.nrrd", &b, &Limits::default()).unwrap();
        assert_eq!(v.samples(), &Samples::U16(vec![1, 2, 65535]));
        let mut b = hdr("type: ushort\ndimension: 3\nsizes: 3 1 1\nencoding: ascii\n");
        b.extend_from_slice(b"1 2 65536");
        assert!(err(&b).contains("does not fit uint16"), "{}", err(&b));
    }

    #[test]
    fn located_errors() {
        let e = err(b"P6\n");
        assert_eq!(
            e,
            "t.nrrd:1: not a NRRD file: expected the magic `NRRD0001` to `NRRD0005`, found `P6`"
        );
        let e = err(&hdr(
            "type: uchar\ndimension: 3\nsizes: 2 2\nencoding: raw\n",
        ));
        assert_eq!(
            e,
            "t.nrrd:4: sizes: expected 3 sizes (dimension 3), found 2 in `2 2`"
        );
        let e = err(&hdr(
            "type: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n",
        ));
        assert!(
            e.starts_with("t.nrrd:5: encoding: `bzip2` is not supported"),
            "{e}"
        );
        let e = err(&hdr(
            "type: double\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
        ));
        assert!(
            e.starts_with("t.nrrd:2: type: `double` is not supported"),
            "{e}"
        );
        let e = err(&hdr("type: uchar\nwhatever: 1\n"));
        assert_eq!(e, "t.nrrd:3: unknown NRRD field `whatever`");
        let e = err(&hdr("type: uchar\ndimension: 3\nencoding: raw\n"));
        assert_eq!(e, "t.nrrd: header: missing field `sizes`");
        let e = err(&hdr("type: uchar\ntype: uchar\n"));
        assert_eq!(e, "t.nrrd:3: type: given twice (first on line 2)");
    }
}
