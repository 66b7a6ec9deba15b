//! Writing the image as PNG.
//!
//! [`PngOutput::create`] opens `OUT.png.tmp` beside the output before any
//! work is done, so an unwritable path is reported at once rather than
//! after a long render; [`PngOutput::write`] encodes the image into it
//! (8-bit RGB, the `image` crate's PNG encoder, deterministic) and renames
//! it over `OUT.png`, so a failed or interrupted run never leaves a
//! truncated image under the output's name.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use image::ImageEncoder;
use image::codecs::png::PngEncoder;

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
    #[error("cannot encode {} as PNG", path.display())]
    Encode {
        /// The output path.
        path: PathBuf,
        /// Why.
        #[source]
        source: image::ImageError,
    },
}

/// A PNG output opened ahead of the render.
#[derive(Debug)]
pub struct PngOutput {
    path: PathBuf,
    tmp: PathBuf,
    file: Option<File>,
}

impl PngOutput {
    /// Opens `path.tmp` for writing.
    ///
    /// # Errors
    /// [`OutputError`]: `path` is a directory, or the temporary file cannot
    /// be created (missing folder, no permission).
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        if path.is_dir() {
            return Err(OutputError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let mut tmp = path.as_os_str().to_owned();
        tmp.push(".tmp");
        let tmp = PathBuf::from(tmp);
        let file = File::create(&tmp).map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            file: Some(file),
        })
    }

    /// The output path.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Encodes `image` and moves it to the output path.
    ///
    /// # Errors
    /// [`OutputError`] for an encoder or file-system failure.
    pub fn write(mut self, image: &Image) -> Result<(), OutputError> {
        let io = |source| OutputError::Io {
            path: self.path.clone(),
            source,
        };
        let Some(file) = self.file.take() else {
            return Err(io(std::io::Error::other("output already written")));
        };
        let mut w = BufWriter::new(file);
        PngEncoder::new(&mut w)
            .write_image(
                &image.rgb,
                image.width,
                image.height,
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|source| OutputError::Encode {
                path: self.path.clone(),
                source,
            })?;
        w.flush().map_err(io)?;
        w.into_inner()
            .map_err(|e| io(e.into_error()))?
            .sync_all()
            .map_err(io)?;
        std::fs::rename(&self.tmp, &self.path).map_err(io)
    }
}

impl Drop for PngOutput {
    fn drop(&mut self) {
        // Not written (an error on the way): remove the temporary file.
        if self.file.is_some() {
            self.file = None;
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Encodes `image` as PNG bytes in memory (for tests and comparisons).
///
/// # Errors
/// The encoder's error.
pub fn png_bytes(image: &Image) -> Result<Vec<u8>, image::ImageError> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out).write_image(
        &image.rgb,
        image.width,
        image.height,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(out)
}
