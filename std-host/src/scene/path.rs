//! Camera paths: the views of an animation (`rrt render --path FILE`),
//! one per line.
//!
//! ```text
//! # from (x y z)   at (x y z)   up (x y z)   angle
//! 0 -4 1            0 0 0        0 0 1        45
//! 1 -4 1            0 0 0        0 0 1        40
//! ```
//!
//! Each line holds ten numbers separated by whitespace: the eye `from`,
//! the point looked at `at`, the `up` direction and the vertical angle in
//! degrees (as a scene's view: between the centres of the top and bottom
//! pixel rows, strictly between 0 and 180). `#` starts a comment; blank
//! lines and a UTF-8 byte-order mark at the start are skipped. Line `k` of views (from 0) is frame `k`. Every
//! error names the file, line and column and the field, as the scene
//! parsers' do; a view whose `at` equals its `from` or whose `up` is
//! parallel to the view direction is refused at its line.

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;

use super::error::{Found, SceneError};
use super::loc::SourceLoc;
use super::text::{read_text, without_bom};
use super::{View, ViewDefect};
use crate::world::WORLD_LIMIT;

/// Largest camera path file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// One view of a camera path.
#[derive(Clone, Debug, PartialEq)]
pub struct PathView {
    /// Eye position.
    pub from: DVec3,
    /// Point looked at.
    pub at: DVec3,
    /// Up direction.
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub angle: f64,
    /// Where its line is.
    pub loc: SourceLoc,
}

impl PathView {
    /// `base` (its resolution and hither) seen from this view.
    #[must_use]
    pub fn view(&self, base: &View) -> View {
        View {
            from: self.from,
            at: self.at,
            up: self.up,
            angle: self.angle,
            loc: self.loc.clone(),
            ..base.clone()
        }
    }
}

/// Reads the camera path file at `path`; `name` names it in messages.
///
/// # Errors
/// The file's I/O or text errors, and every error of [`parse`].
pub fn load(path: &Path, name: &str) -> Result<Vec<PathView>, SceneError> {
    let name: Arc<str> = Arc::from(name);
    let text = read_text(path, &name, "a camera path", MAX_FILE_BYTES)?;
    parse(&name, &text)
}

/// The fields of a line, in order.
const FIELDS: [&str; 10] = [
    "path view from x",
    "path view from y",
    "path view from z",
    "path view at x",
    "path view at y",
    "path view at z",
    "path view up x",
    "path view up y",
    "path view up z",
    ANGLE,
];

/// The last field.
const ANGLE: &str = "path view angle";

/// Parses a camera path; `file` names it in messages.
///
/// # Errors
/// [`SceneError::BadField`] for a missing, malformed or extra number or an
/// angle out of range, [`SceneError::Invalid`] for a degenerate view,
/// [`SceneError::NoViews`] for a file without views; each located.
pub fn parse(file: &str, text: &str) -> Result<Vec<PathView>, SceneError> {
    let file: Arc<str> = Arc::from(file);
    let mut views = Vec::new();
    for (n, raw) in without_bom(text).lines().enumerate() {
        let line_no = u32::try_from(n + 1).unwrap_or(u32::MAX);
        let content = raw.find('#').map_or(raw, |h| &raw[..h]);
        let loc = |byte: usize| {
            let column = content.get(..byte).map_or(byte, |s| s.chars().count()) + 1;
            SourceLoc::new(
                Arc::clone(&file),
                line_no,
                u32::try_from(column).unwrap_or(u32::MAX),
            )
        };
        let mut tokens = tokens(content);
        let Some(first) = tokens.next() else {
            continue;
        };
        let mut tokens = std::iter::once(first).chain(tokens);
        let mut v = [0f64; 10];
        let mut last_tok_at = 0;
        for (slot, field) in v.iter_mut().zip(FIELDS) {
            let Some((at, t)) = tokens.next() else {
                return Err(SceneError::BadField {
                    loc: loc(content.trim_end().len()),
                    field,
                    expected: "a number",
                    found: Found::EndOfLine,
                });
            };
            last_tok_at = at;
            let bad = |expected| SceneError::BadField {
                loc: loc(at),
                field,
                expected,
                found: Found::token(t),
            };
            *slot = match t.parse::<f64>() {
                Ok(x) if x.abs() <= WORLD_LIMIT => x,
                Ok(x) if x.is_finite() => return Err(bad("a number within ±1e60")),
                Ok(_) => return Err(bad("a finite number")),
                Err(_) => return Err(bad("a number")),
            };
            if field == ANGLE && !(*slot > 0.0 && *slot < 180.0) {
                return Err(bad("an angle in degrees between 0 and 180 (exclusive)"));
            }
        }
        if let Some((at, t)) = tokens.next() {
            return Err(SceneError::BadField {
                loc: loc(at),
                field: "path view",
                expected: "end of line after the angle",
                found: Found::token(t),
            });
        }
        let [fx, fy, fz, ax, ay, az, ux, uy, uz, angle] = v;
        let (from, at, up) = (
            DVec3::new(fx, fy, fz),
            DVec3::new(ax, ay, az),
            DVec3::new(ux, uy, uz),
        );
        if let Some(defect) = ViewDefect::of(from, at, up) {
            let (field, column_of) = match defect {
                ViewDefect::NoDirection => ("path view at", 3),
                ViewDefect::NoUp => ("path view up", 6),
            };
            let at_tok = tokens_at(content, column_of).unwrap_or(last_tok_at);
            return Err(SceneError::Invalid {
                loc: loc(at_tok),
                field,
                problem: defect.problem(),
            });
        }
        views.push(PathView {
            from,
            at,
            up,
            angle,
            loc: loc(0),
        });
    }
    if views.is_empty() {
        return Err(SceneError::NoViews { file });
    }
    Ok(views)
}

/// The whitespace-separated tokens of a line, with their byte offsets.
fn tokens(line: &str) -> impl Iterator<Item = (usize, &str)> {
    line.split_ascii_whitespace()
        .map(move |t| (t.as_ptr() as usize - line.as_ptr() as usize, t))
}

/// The byte offset of token `i` of `line`.
fn tokens_at(line: &str, i: usize) -> Option<usize> {
    tokens(line).nth(i).map(|(at, _)| at)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A byte-order mark before the first view is skipped.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let text = "0 -4 1  0 0 0  0 0 1  45\n";
        let marked = parse("p.txt", &format!("\u{feff}{text}")).unwrap();
        assert_eq!(marked, parse("p.txt", text).unwrap());
        let e = parse("p.txt", "\u{feff}0 -4 x").unwrap_err().to_string();
        assert!(e.starts_with("p.txt:1:6: path view from z"), "{e}");
    }

    #[test]
    fn views_with_comments_and_blank_lines() {
        let text = "# a path\n\n0 -4 1  0 0 0  0 0 1  45\n  1 -4 1 0 0 0 0 0 1 40 # second\n";
        let v = parse("p.txt", text).unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].from, DVec3::new(0.0, -4.0, 1.0));
        assert_eq!(v[1].angle, 40.0);
        assert_eq!(v[1].loc.to_string(), "p.txt:4:1");
    }

    #[test]
    fn every_bad_line_is_located() {
        for (text, want) in [
            (
                "0 -4 1 0 0 0 0 0 1\n",
                "p:1:19: path view angle: expected a number, found end of line",
            ),
            (
                "0 -4 x 0 0 0 0 0 1 45\n",
                "p:1:6: path view from z: expected a number, found \"x\"",
            ),
            (
                "\n0 -4 1 0 0 0 0 0 1 180\n",
                "p:2:20: path view angle: expected an angle in degrees between 0 and 180 (exclusive), found \"180\"",
            ),
            (
                "0 -4 1 0 0 0 0 0 1 45 7\n",
                "p:1:23: path view: expected end of line after the angle, found \"7\"",
            ),
            (
                "0 0 0 0 0 0 0 0 1 45\n",
                "p:1:7: path view at: equals `from`",
            ),
            (
                "0 -4 0  0 0 0  0 2 0 45\n",
                "p:1:16: path view up: zero or parallel",
            ),
            (
                "0 -4 1 0 0 inf 0 0 1 45\n",
                "p:1:12: path view at z: expected a finite number",
            ),
            (
                "0 -4e70 1 0 0 0 0 0 1 45\n",
                "p:1:3: path view from y: expected a number within ±1e60",
            ),
            ("# nothing\n\n", "p: no views"),
        ] {
            let e = parse("p", text).unwrap_err().to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
