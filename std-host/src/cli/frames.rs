//! The frames and bands of `rrt render`: `--orbit N` and `--path FILE`
//! (the views of an animation), `--frame K` (one of them), the output
//! file name pattern (`-o frame-%04d.png`) and `--tile I/N` (one band).

use std::path::{Path, PathBuf};

use super::CliError;
use crate::render::band::Band;
use crate::scene::View;
use crate::scene::path::PathView;

/// The views a render writes.
#[derive(Debug, Clone)]
pub enum Frames {
    /// One image of the (overridden) scene view, no animation.
    Still,
    /// `--orbit N`: frame `k` is [`View::orbit`]`(k, N)` of the base
    /// view.
    Orbit(u64),
    /// `--path FILE`: frame `k` is line `k` of the file's views.
    Path(Vec<PathView>),
}

impl Frames {
    /// How many frames the animation has (1 for a still).
    #[must_use]
    pub fn count(&self) -> u64 {
        match self {
            Self::Still => 1,
            Self::Orbit(n) => *n,
            Self::Path(v) => u64::try_from(v.len()).unwrap_or(u64::MAX),
        }
    }

    /// Whether this is an animation (`--orbit` or `--path`).
    #[must_use]
    pub fn animated(&self) -> bool {
        !matches!(self, Self::Still)
    }

    /// Frame `k`'s view of `base` (the scene's view with the overrides).
    #[must_use]
    pub fn view(&self, k: u64, base: &View) -> View {
        match self {
            Self::Still => base.clone(),
            Self::Orbit(n) => base.orbit(k, *n),
            Self::Path(v) => usize::try_from(k)
                .ok()
                .and_then(|i| v.get(i))
                .map_or_else(|| base.clone(), |p| p.view(base)),
        }
    }

    /// The frames to write: `--frame K` alone (checked against the
    /// count), else all of them.
    ///
    /// # Errors
    /// [`CliError::Arg`] for `K` not below the count.
    pub fn chosen(&self, frame: Option<u64>) -> Result<std::ops::Range<u64>, CliError> {
        let n = self.count();
        match frame {
            None => Ok(0..n),
            Some(k) if k < n => Ok(k..k + 1),
            Some(k) => Err(CliError::Arg {
                arg: "--frame",
                message: format!(
                    "frame {k} of {n} does not exist: frames are numbered 0 to {}",
                    n - 1
                ),
            }),
        }
    }
}

/// Parses `--orbit`: a number of frames, 1 to 2^64 − 1.
///
/// # Errors
/// A message for anything else.
pub fn parse_frame_count(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(0) => Err("expected at least 1 frame, found 0".to_string()),
        Ok(n) => Ok(n),
        Err(_) => Err(format!(
            "expected a whole number of frames from 1 to {}, found {s:?}",
            u64::MAX
        )),
    }
}

/// `--tile I/N` as given: band `index` of `count`, checked against the
/// image's height once it is known ([`TileArg::band`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileArg {
    /// The band, from 0 (the top one).
    pub index: u32,
    /// How many bands.
    pub count: u32,
}

impl TileArg {
    /// The band of an image `height` rows high.
    ///
    /// # Errors
    /// [`CliError::Arg`] naming `--tile`: no bands, the index out of
    /// range, more bands than rows.
    pub fn band(self, height: u32) -> Result<Band, CliError> {
        Band::new(self.index, self.count, height).map_err(|e| CliError::Arg {
            arg: "--tile",
            message: e.to_string(),
        })
    }
}

/// Parses `--tile I/N`: whole numbers, `I` from 0 to `N − 1`, `N` at
/// least 1.
///
/// # Errors
/// A message for anything else.
pub fn parse_tile(s: &str) -> Result<TileArg, String> {
    let bad = || {
        format!(
            "expected I/N, band I (from 0, the top band, to N − 1) of N horizontal bands, found {s:?}"
        )
    };
    let (i, n) = s.trim().split_once('/').ok_or_else(bad)?;
    let num = |t: &str| {
        let t = t.trim();
        if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
            return Err(bad());
        }
        t.parse::<u32>()
            .map_err(|_| format!("{t} is too large: at most {} bands", u32::MAX))
    };
    let (index, count) = (num(i)?, num(n)?);
    Band::new(index, count, u32::MAX).map_err(|e| e.to_string())?;
    Ok(TileArg { index, count })
}

/// Where each frame goes: `-o` as given, or a printf-style pattern with
/// the frame number (`%d`, or `%0Nd` zero-padded to `N` digits; `%%` is a
/// `%`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Names {
    /// One file name for every frame (one frame written).
    Fixed(PathBuf),
    /// `before`, the frame number padded to `width` digits, `after`.
    Numbered {
        /// The text before the number.
        before: String,
        /// Digits, zero-padded (0: as many as it takes).
        width: usize,
        /// The text after the number.
        after: String,
    },
}

/// The widest `%0Nd`.
const MAX_WIDTH: usize = 20;

impl Names {
    /// The names for `frames` frames written of `frames_total` from
    /// `output`: for a still, `output` as given; for an animation, `output`
    /// read as a pattern, which must hold exactly one frame number when
    /// several frames are written.
    ///
    /// # Errors
    /// [`CliError::Arg`] naming `--output`: a `%` that starts neither
    /// `%d`, `%0Nd` nor `%%`; more than one number; none when several
    /// frames are written; several frames to standard output.
    pub fn new(output: &Path, animated: bool, written: u64) -> Result<Self, CliError> {
        let arg = |message: String| CliError::Arg {
            arg: "--output",
            message,
        };
        if !animated {
            return Ok(Self::Fixed(output.to_path_buf()));
        }
        if output.as_os_str() == "-" {
            if written > 1 {
                return Err(arg(format!(
                    "{written} frames cannot all go to standard output; give a file name pattern like frame-%04d.png"
                )));
            }
            return Ok(Self::Fixed(output.to_path_buf()));
        }
        let Some(text) = output.to_str() else {
            if written > 1 {
                return Err(arg(format!(
                    "{}: not UTF-8, so not a pattern for {written} frames",
                    output.display()
                )));
            }
            return Ok(Self::Fixed(output.to_path_buf()));
        };
        // The texts between the numbers, and the numbers' widths.
        let (mut parts, mut current) = (Vec::new(), String::new());
        let mut widths = Vec::new();
        let mut chars = text.char_indices().peekable();
        while let Some((at, c)) = chars.next() {
            if c != '%' {
                current.push(c);
                continue;
            }
            let mut spec = String::new();
            while let Some(&(_, d)) = chars.peek()
                && d.is_ascii_digit()
            {
                spec.push(d);
                chars.next();
            }
            let garbage = || {
                arg(format!(
                    "{text:?}: the % at character {} starts neither %d, %0Nd (the frame number, zero-padded to N digits) nor %% (a %)",
                    text[..at].chars().count() + 1
                ))
            };
            match chars.next() {
                Some((_, '%')) if spec.is_empty() => {
                    current.push('%');
                }
                Some((_, 'd')) if spec.is_empty() => {
                    widths.push(0);
                    parts.push(std::mem::take(&mut current));
                }
                Some((_, 'd')) if spec.starts_with('0') && spec.len() > 1 => {
                    let w = spec[1..].parse::<usize>().unwrap_or(usize::MAX);
                    if !(1..=MAX_WIDTH).contains(&w) {
                        return Err(arg(format!(
                            "{text:?}: %{spec}d pads to {} digits; expected 1 to {MAX_WIDTH}",
                            &spec[1..]
                        )));
                    }
                    widths.push(w);
                    parts.push(std::mem::take(&mut current));
                }
                _ => return Err(garbage()),
            }
        }
        parts.push(current);
        match (widths.as_slice(), written) {
            ([], 0 | 1) => Ok(Self::Fixed(PathBuf::from(parts.concat()))),
            ([], n) => Err(arg(format!(
                "{text:?} has no frame number, but {n} frames are written: give a pattern with one %d or %0Nd, like frame-%04d.png"
            ))),
            ([w], _) => Ok(Self::Numbered {
                before: parts[0].clone(),
                width: *w,
                after: parts[1].clone(),
            }),
            (ws, _) => Err(arg(format!(
                "{text:?} has {} frame numbers; expected one %d or %0Nd",
                ws.len()
            ))),
        }
    }

    /// Frame `k`'s file.
    #[must_use]
    pub fn path(&self, k: u64) -> PathBuf {
        match self {
            Self::Fixed(p) => p.clone(),
            Self::Numbered {
                before,
                width,
                after,
            } => PathBuf::from(format!("{before}{k:0width$}{after}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(s: &str, written: u64) -> Result<Names, String> {
        Names::new(Path::new(s), true, written).map_err(|e| e.to_string())
    }

    #[test]
    fn patterns() {
        for (pattern, written, k, want) in [
            ("out/frame-%04d.png", 10, 7, "out/frame-0007.png"),
            ("out/frame-%04d.png", 10, 123_456, "out/frame-123456.png"),
            ("f%d.exr", 3, 12, "f12.exr"),
            ("100%%-%02d.png", 3, 5, "100%-05.png"),
            ("one.png", 1, 9, "one.png"),
            ("a%%b.png", 1, 0, "a%b.png"),
        ] {
            let n = names(pattern, written).unwrap();
            assert_eq!(n.path(k), PathBuf::from(want), "{pattern}");
        }
        for (bad, want) in [
            ("frame.png", "has no frame number, but 4 frames"),
            ("a%d-%d.png", "has 2 frame numbers"),
            ("a%s.png", "the % at character 2 starts neither"),
            ("a%4d.png", "starts neither"),
            ("a%", "starts neither"),
            ("a%00d.png", "expected 1 to 20"),
            ("a%021d.png", "expected 1 to 20"),
            ("-", "cannot all go to standard output"),
        ] {
            let e = names(bad, 4).unwrap_err();
            assert!(e.contains(want), "{bad}: {e}");
        }
        // A still's name is never a pattern.
        assert_eq!(
            Names::new(Path::new("a%s.png"), false, 1).unwrap().path(0),
            PathBuf::from("a%s.png")
        );
    }

    #[test]
    fn tiles_and_frame_counts() {
        assert_eq!(parse_tile("0/4"), Ok(TileArg { index: 0, count: 4 }));
        assert_eq!(parse_tile(" 3/4 "), Ok(TileArg { index: 3, count: 4 }));
        for (bad, want) in [
            ("4/4", "band 4 of 4 does not exist"),
            ("0/0", "at least 1 band"),
            ("1", "expected I/N"),
            ("-1/4", "expected I/N"),
            ("a/b", "expected I/N"),
            ("0/99999999999", "too large"),
        ] {
            let e = parse_tile(bad).unwrap_err();
            assert!(e.contains(want), "{bad}: {e}");
        }
        let e = TileArg {
            index: 0,
            count: 40,
        }
        .band(30)
        .unwrap_err()
        .to_string();
        assert!(e.contains("40 bands of an image 30 rows high"), "{e}");
        assert!(parse_frame_count("0").unwrap_err().contains("at least 1"));
        assert_eq!(parse_frame_count("18446744073709551615"), Ok(u64::MAX));
        assert!(parse_frame_count("18446744073709551616").is_err());
        let e = Frames::Orbit(100)
            .chosen(Some(100))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("frame 100 of 100 does not exist: frames are numbered 0 to 99"),
            "{e}"
        );
        assert_eq!(Frames::Orbit(u64::MAX).chosen(Some(5)).unwrap(), 5..6);
    }
}
