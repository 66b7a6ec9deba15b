//! The rendered image in the format its file name asks for.
//!
//! | extension | format | values |
//! |---|---|---|
//! | `.png` | PNG, 8 or 16 bits per channel | sRGB-encoded with an `sRGB` chunk; `linear`: the linear values, no colour chunk |
//! | `.ppm` | binary PPM (`P6`), 8 or 16 bits | as PNG (no chunk to say which) |
//! | `.exr` | OpenEXR, 32-bit float RGB | linear, unclamped |
//! | `.pfm` | Portable Float Map, 32-bit float RGB | linear, unclamped |
//! | `-` | PNG on standard output | as `.png` |
//!
//! Any other extension is refused before any work is done. sRGB encoding
//! is the exact IEC 61966-2-1 transfer function on the clamped linear
//! value, rounded to nearest ([`super::encoding`]); all encoders are deterministic, so the bytes
//! depend only on the image. Files go through [`AtomicFile`]: a failed or
//! interrupted run leaves the old file, never a partial one.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::atomic::AtomicFile;
pub use super::encoding::Encoding;
use super::encoding::{Codes, SampleKind, Samples};
use crate::render::Image;

/// Why the image could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// The output path names a directory.
    #[error("{}: is a directory, not an image file", path.display())]
    IsDirectory {
        /// The path.
        path: PathBuf,
    },
    /// The extension names no format rrt writes.
    #[error(
        "{}: cannot write {what}; the image formats are .png (8- or 16-bit), .ppm (8- or 16-bit), .exr and .pfm (32-bit float), or - for PNG on standard output",
        path.display()
    )]
    Format {
        /// The path.
        path: PathBuf,
        /// The extension found.
        what: String,
    },
    /// The options do not fit the format.
    #[error("{}: {message}", path.display())]
    Options {
        /// The path.
        path: PathBuf,
        /// What does not fit.
        message: String,
    },
    /// Creating, writing or renaming failed.
    #[error("cannot write {}", path.display())]
    Io {
        /// The output path.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The encoder failed.
    #[error("cannot encode {} as {format}", path.display())]
    Encode {
        /// The output path.
        path: PathBuf,
        /// The format.
        format: &'static str,
        /// Why.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// An image file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// PNG, 8 or 16 bits per channel.
    Png,
    /// Binary PPM (`P6`), 8 or 16 bits per channel.
    Ppm,
    /// OpenEXR, 32-bit float, linear.
    Exr,
    /// Portable Float Map, 32-bit float, linear.
    Pfm,
}

impl Format {
    /// The format for `path`'s extension (case-insensitive); `-` is PNG.
    ///
    /// # Errors
    /// [`OutputError::Format`] for a missing or unknown extension.
    pub fn from_path(path: &Path) -> Result<Self, OutputError> {
        if path.as_os_str() == "-" {
            return Ok(Self::Png);
        }
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("ppm") => Ok(Self::Ppm),
            Some("exr") => Ok(Self::Exr),
            Some("pfm") => Ok(Self::Pfm),
            other => Err(OutputError::Format {
                path: path.to_path_buf(),
                what: other.map_or_else(
                    || "an image without an extension".to_string(),
                    |e| format!(".{e} images"),
                ),
            }),
        }
    }

    /// The format's name in messages.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Png => "PNG",
            Self::Ppm => "PPM",
            Self::Exr => "OpenEXR",
            Self::Pfm => "PFM",
        }
    }

    /// Whether the format holds floats (linear, unclamped).
    #[must_use]
    pub fn is_float(self) -> bool {
        matches!(self, Self::Exr | Self::Pfm)
    }
}

/// Where the image goes.
#[derive(Debug)]
enum Target {
    /// A file, through its temporary.
    File(AtomicFile),
    /// Standard output (the writer given to [`ImageOutput::write`]).
    Stdout,
}

/// An image output opened ahead of the render, so that an unwritable path
/// or an unknown format is reported before any work.
#[derive(Debug)]
pub struct ImageOutput {
    path: PathBuf,
    format: Format,
    encoding: Encoding,
    target: Target,
}

impl ImageOutput {
    /// Chooses the format by `path`'s extension (`-`: PNG on standard
    /// output) and, for a file, creates its temporary beside it.
    ///
    /// # Errors
    /// [`OutputError`]: unknown extension, `bits` not 8 or 16 or given
    /// for a float format, `path` a directory, or the temporary file cannot
    /// be created (missing folder, no permission).
    pub fn create(path: &Path, encoding: Encoding) -> Result<Self, OutputError> {
        if path.as_os_str() != "-" && path.is_dir() {
            return Err(OutputError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let format = Format::from_path(path)?;
        let options = |message: String| OutputError::Options {
            path: path.to_path_buf(),
            message,
        };
        if !matches!(encoding.bits, 8 | 16) {
            return Err(options(format!(
                "expected 8 or 16 bits per channel, found {}",
                encoding.bits
            )));
        }
        if format.is_float() && encoding.bits != 8 {
            return Err(options(format!(
                "{} holds 32-bit floats; --bits is for .png and .ppm",
                format.name()
            )));
        }
        let target = if path.as_os_str() == "-" {
            Target::Stdout
        } else {
            Target::File(AtomicFile::create(path).map_err(|source| OutputError::Io {
                path: path.to_path_buf(),
                source,
            })?)
        };
        Ok(Self {
            path: path.to_path_buf(),
            format,
            encoding,
            target,
        })
    }

    /// The output path (`-` for standard output).
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the image goes to standard output.
    #[must_use]
    pub fn is_stdout(&self) -> bool {
        matches!(self.target, Target::Stdout)
    }

    /// The format.
    #[must_use]
    pub fn format(&self) -> Format {
        self.format
    }

    /// What the file's samples are.
    #[must_use]
    pub fn kind(&self) -> SampleKind {
        if self.format.is_float() {
            SampleKind::Float
        } else {
            SampleKind::Codes(self.encoding)
        }
    }

    /// Encodes `image` and moves it to the output path, or writes it to
    /// `stdout` for `-`.
    ///
    /// # Errors
    /// [`OutputError`] for an encoder or file-system failure; a file
    /// target is then untouched.
    pub fn write(self, image: &Image, stdout: &mut impl Write) -> Result<(), OutputError> {
        self.write_band(image, None, stdout)
    }

    /// [`ImageOutput::write`], for a band of an image (`rrt render
    /// --tile`): `band` ([`super::band::BandTag`]'s text) goes where the
    /// format keeps text (a PNG `tEXt` chunk, a PPM header comment, an
    /// OpenEXR attribute; PFM has no place for it).
    ///
    /// # Errors
    /// As [`ImageOutput::write`].
    pub fn write_band(
        self,
        image: &Image,
        band: Option<&str>,
        stdout: &mut impl Write,
    ) -> Result<(), OutputError> {
        let samples = Samples::of(image, self.kind());
        self.write_samples(image.width, image.height, &samples, band, stdout)
    }

    /// Writes `width × height` pixels of `samples`, which must be of
    /// [`ImageOutput::kind`]: the bytes [`ImageOutput::write_band`]
    /// writes for an image with these samples.
    ///
    /// # Errors
    /// As [`ImageOutput::write`]; [`OutputError::Options`] for samples of
    /// another kind or number.
    pub fn write_samples(
        self,
        width: u32,
        height: u32,
        samples: &Samples<'_>,
        band: Option<&str>,
        stdout: &mut impl Write,
    ) -> Result<(), OutputError> {
        let fits = match (self.kind(), samples) {
            (SampleKind::Float, Samples::Float(_)) => true,
            (SampleKind::Codes(e), Samples::Codes(Codes::Eight(_))) => e.bits == 8,
            (SampleKind::Codes(e), Samples::Codes(Codes::Sixteen(_))) => e.bits == 16,
            _ => false,
        };
        let count = 3 * u64::from(width) * u64::from(height);
        if !fits || u64::try_from(samples.len()) != Ok(count) {
            let kind = self.kind();
            return Err(OutputError::Options {
                path: self.path,
                message: format!(
                    "{} samples of another kind or number than {width}×{height} pixels of {kind}",
                    samples.len(),
                ),
            });
        }
        let image = Encoded {
            width,
            height,
            samples,
            band,
        };
        let path = self.path;
        let io = |source| OutputError::Io {
            path: path.clone(),
            source,
        };
        match self.target {
            Target::Stdout => {
                encode(self.format, self.encoding, &image, &mut *stdout, &path)?;
                stdout.flush().map_err(io)
            }
            Target::File(mut file) => {
                let mut w = BufWriter::with_capacity(1 << 20, file.file().map_err(io)?);
                encode(self.format, self.encoding, &image, &mut w, &path)?;
                w.flush().map_err(io)?;
                drop(w);
                file.commit().map_err(io)
            }
        }
    }
}

/// What [`encode`] writes: pixels of samples of the output's kind, and
/// the band they are.
struct Encoded<'a, 's> {
    width: u32,
    height: u32,
    samples: &'a Samples<'s>,
    band: Option<&'a str>,
}

/// Encodes `image` in `format` into `w`.
fn encode(
    format: Format,
    enc: Encoding,
    image: &Encoded<'_, '_>,
    w: &mut impl Write,
    path: &Path,
) -> Result<(), OutputError> {
    let failed = |source: Box<dyn std::error::Error + Send + Sync>| OutputError::Encode {
        path: path.to_path_buf(),
        format: format.name(),
        source,
    };
    let io = |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    };
    let (width, height, band) = (image.width, image.height, image.band);
    match (format, image.samples) {
        // The encoders' I/O errors are the file's (their own messages
        // would repeat the system's).
        (Format::Png, Samples::Codes(c)) => super::png::write_codes(width, height, c, enc, band, w)
            .map_err(|e| match e {
                png::EncodingError::IoError(e) => io(e),
                e => failed(e.into()),
            }),
        (Format::Ppm, Samples::Codes(c)) => {
            super::ppm::write_ppm_codes(width, height, c, band, w).map_err(io)
        }
        (Format::Pfm, Samples::Float(v)) => {
            super::ppm::write_pfm_floats(width, height, v, w).map_err(io)
        }
        (Format::Exr, Samples::Float(v)) => super::exr::write_floats(width, height, v, band, w)
            .map_err(|e| match e {
                exr::error::Error::Io(e) => io(e),
                e => failed(e.into()),
            }),
        // `write_samples` checked the kind.
        _ => Err(failed("samples of another kind than the format's".into())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_by_extension() {
        for (p, f) in [
            ("a.png", Format::Png),
            ("b.PNG", Format::Png),
            ("-", Format::Png),
            ("c.ppm", Format::Ppm),
            ("d.exr", Format::Exr),
            ("e.pfm", Format::Pfm),
        ] {
            assert_eq!(Format::from_path(Path::new(p)).unwrap(), f, "{p}");
        }
        for p in ["a.jpg", "b", "c.png.bak", "d.tiff"] {
            let e = Format::from_path(Path::new(p)).unwrap_err().to_string();
            assert!(e.contains("the image formats are .png"), "{e}");
        }
    }

    /// A disk that is full.
    struct Full;

    impl Write for Full {
        fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
            Err(std::io::Error::from(std::io::ErrorKind::StorageFull))
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_full_disk_is_the_files_error_said_once() {
        let (w, h) = (64, 64);
        for (format, samples) in [
            (
                Format::Png,
                Samples::Codes(Codes::Eight(vec![7; w * h * 3])),
            ),
            (
                Format::Ppm,
                Samples::Codes(Codes::Sixteen(vec![7; w * h * 3])),
            ),
            (Format::Exr, Samples::Float(vec![0.5; w * h * 3].into())),
            (Format::Pfm, Samples::Float(vec![0.5; w * h * 3].into())),
        ] {
            let image = Encoded {
                width: w as u32,
                height: h as u32,
                samples: &samples,
                band: None,
            };
            let e = encode(
                format,
                Encoding::default(),
                &image,
                &mut Full,
                Path::new("o"),
            )
            .unwrap_err();
            assert!(matches!(e, OutputError::Io { .. }), "{format:?}: {e:?}");
            // The message and its sources, as `rrt` prints them.
            let mut text = e.to_string();
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                text = format!("{text}: {s}");
                source = s.source();
            }
            let full = std::io::Error::from(std::io::ErrorKind::StorageFull).to_string();
            assert_eq!(text, format!("cannot write o: {full}"), "{format:?}");
        }
    }
}
