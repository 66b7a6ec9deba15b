//! Bézier patch files (`.bpt`): the classic text format of the Newell
//! teapot's 32 patches.
//!
//! ```text
//! 32               number of patches
//! 3 3              degrees in u and v (only bicubic patches: 3 3)
//! 1.4 0.0 2.4      (3 + 1) × (3 + 1) control points x y z, row by row:
//! 1.4 -0.784 2.4   point k is control[k / 4][k % 4]
//! …
//! 3 3              the next patch
//! …
//! ```
//!
//! Numbers are separated by any white space (one point per line is
//! customary, not required); `#` starts a comment to the end of the line;
//! a UTF-8 byte-order mark at the start is skipped.
//! Every number must be finite and within ±1e60 (the world's limit,
//! [`WORLD_LIMIT`](crate::world::WORLD_LIMIT)); the file must hold exactly the announced
//! patches. Errors name the file, line and column of the offending token.
//!
//! ```
//! use rrt_host::scene::bpt;
//! let one = "1\n3 3\n".to_string()
//!     + &(0..16).map(|k| format!("{} {} 0\n", k / 4, k % 4)).collect::<String>();
//! let patches = bpt::parse("flat.bpt", &one).unwrap();
//! assert_eq!(patches.len(), 1);
//! assert_eq!(patches[0][2][1], glam::DVec3::new(2.0, 1.0, 0.0));
//! let e = bpt::parse("bad.bpt", "1\n2 2\n").unwrap_err();
//! assert_eq!(e.to_string(),
//!     "bad.bpt:2:1: patch 1 degrees: expected `3 3` (bicubic patches only), found \"2\"");
//! ```

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;

use super::error::{Found, SceneError};
use super::loc::SourceLoc;
use super::text::{read_text, without_bom};

/// Control points of one bicubic patch, `control[i][j]` for `u = i/3`,
/// `v = j/3`.
pub type Control = [[DVec3; 4]; 4];

/// Largest `.bpt` file read, in bytes.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Reads the patch file at `path`; `name` names it in messages.
///
/// # Errors
/// The file's I/O or text errors, and every error of [`parse`].
pub fn load(path: &Path, name: &str) -> Result<Vec<Control>, SceneError> {
    let name: Arc<str> = Arc::from(name);
    let text = read_text(path, &name, "a patch file", MAX_FILE_BYTES)?;
    parse(&name, &text)
}

struct Tokens<'a> {
    file: Arc<str>,
    lines: std::iter::Peekable<std::iter::Enumerate<std::str::Lines<'a>>>,
    current: Option<(usize, &'a str, usize)>,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    /// The next token with its line (from 0) and byte column.
    fn next(&mut self) -> Option<(&'a str, usize, usize)> {
        loop {
            if let Some((line, text, at)) = self.current.as_mut() {
                let rest = text.get(*at..).unwrap_or("");
                if let Some(skip) = rest.find(|c: char| !c.is_whitespace()) {
                    let start = *at + skip;
                    let tail = text.get(start..).unwrap_or("");
                    let len = tail.find(char::is_whitespace).unwrap_or(tail.len());
                    *at = start + len;
                    return Some((tail.get(..len).unwrap_or(""), *line, start));
                }
            }
            let (n, raw) = self.lines.next()?;
            self.last_line = n;
            let content = raw.find('#').map_or(raw, |h| raw.get(..h).unwrap_or(raw));
            self.current = Some((n, content, 0));
        }
    }

    fn loc(&self, line: usize, byte: usize, text: &str) -> SourceLoc {
        let column = text.get(..byte).map_or(byte, |s| s.chars().count());
        SourceLoc::new(
            Arc::clone(&self.file),
            u32::try_from(line + 1).unwrap_or(u32::MAX),
            u32::try_from(column + 1).unwrap_or(u32::MAX),
        )
    }

    fn end(&self) -> SourceLoc {
        SourceLoc::new(
            Arc::clone(&self.file),
            u32::try_from(self.last_line + 1).unwrap_or(u32::MAX),
            1,
        )
    }
}

/// Parses `.bpt` text; `file` names it in messages.
///
/// # Errors
/// [`SceneError::BadField`] for a missing, malformed or non-finite number,
/// a patch that is not bicubic, or a patch count the file cannot hold
/// (checked before allocating); [`SceneError::Invalid`] for trailing data.
pub fn parse(file: &str, text: &str) -> Result<Vec<Control>, SceneError> {
    let text = without_bom(text);
    let lines: Vec<&str> = text.lines().collect();
    let mut t = Tokens {
        file: Arc::from(file),
        lines: text.lines().enumerate().peekable(),
        current: None,
        last_line: 0,
    };
    let line_text = |l: usize| lines.get(l).copied().unwrap_or("");
    let bad = |t: &Tokens<'_>, tok: Option<(&str, usize, usize)>, field, expected| match tok {
        Some((s, l, b)) => SceneError::BadField {
            loc: t.loc(l, b, line_text(l)),
            field,
            expected,
            found: Found::token(s),
        },
        None => SceneError::BadField {
            loc: t.end(),
            field,
            expected,
            found: Found::EndOfFile,
        },
    };
    let tok = t.next();
    let count: usize = match tok.and_then(|(s, _, _)| s.parse::<u64>().ok()) {
        Some(n) if n >= 1 => {
            // Each patch takes 2 + 48 tokens of at least one character and
            // a separator: refuse counts the text cannot hold.
            let room = (text.len() as u64) / 100 + 1;
            if n > room {
                return Err(bad(
                    &t,
                    tok,
                    "patch count",
                    "a patch count the file has room for (each patch takes 50 numbers)",
                ));
            }
            usize::try_from(n).unwrap_or(0)
        }
        _ => {
            return Err(bad(
                &t,
                tok,
                "patch count",
                "a whole number of patches, at least 1",
            ));
        }
    };
    let mut patches = Vec::with_capacity(count);
    for p in 0..count {
        for _ in 0..2 {
            let tok = t.next();
            if tok.map(|(s, _, _)| s) != Some("3") {
                return Err(bad(
                    &t,
                    tok,
                    if p == 0 {
                        "patch 1 degrees"
                    } else {
                        "patch degrees"
                    },
                    "`3 3` (bicubic patches only)",
                ));
            }
        }
        let mut control = [[DVec3::ZERO; 4]; 4];
        for row in &mut control {
            for point in row.iter_mut() {
                let mut xyz = [0.0; 3];
                for c in &mut xyz {
                    let tok = t.next();
                    match tok.and_then(|(s, _, _)| s.parse::<f64>().ok()) {
                        Some(v) if v.abs() <= crate::world::WORLD_LIMIT => *c = v,
                        Some(v) if v.is_finite() => {
                            return Err(bad(&t, tok, "control point", "a number within ±1e60"));
                        }
                        _ => {
                            return Err(bad(&t, tok, "control point", "a finite number"));
                        }
                    }
                }
                *point = DVec3::from(xyz);
            }
        }
        patches.push(control);
    }
    if let Some((s, l, b)) = t.next() {
        return Err(SceneError::BadField {
            loc: t.loc(l, b, line_text(l)),
            field: "patch file",
            expected: "the end of the file after the announced patches",
            found: Found::token(s),
        });
    }
    Ok(patches)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A byte-order mark before the patch count is skipped, not a
    /// malformed count.
    #[test]
    fn a_byte_order_mark_is_skipped() {
        let one = "1\n3 3\n".to_string()
            + &(0..16)
                .map(|k| format!("{} {} 0\n", k / 4, k % 4))
                .collect::<String>();
        let plain = parse("t.bpt", &one).unwrap();
        assert_eq!(parse("t.bpt", &format!("\u{feff}{one}")).unwrap(), plain);
        let e = parse("t.bpt", "\u{feff}x").unwrap_err().to_string();
        assert!(e.starts_with("t.bpt:1:1: patch count:"), "{e}");
    }

    #[test]
    fn errors_are_located() {
        let e = parse("t.bpt", "").unwrap_err().to_string();
        assert_eq!(
            e,
            "t.bpt:1:1: patch count: expected a whole number of patches, at least 1, found end of file"
        );
        let e = parse("t.bpt", "99999\n3 3\n").unwrap_err().to_string();
        assert!(
            e.starts_with("t.bpt:1:1: patch count: expected a patch count"),
            "{e}"
        );
        let mut text = "1\n3 3 # bicubic\n".to_string();
        for k in 0..15 {
            text += &format!("{k} 0 0\n");
        }
        let e = parse("t.bpt", &(text.clone() + "1 nan 0\n"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.bpt:18:3: control point: expected a finite number, found \"nan\""
        );
        let e = parse("t.bpt", &(text.clone() + "1 -2e60 0\n"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.bpt:18:3: control point: expected a number within ±1e60, found \"-2e60\""
        );
        let e = parse("t.bpt", &(text.clone() + "1 2\n"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.bpt:18:1: control point: expected a finite number, found end of file"
        );
        let e = parse("t.bpt", &(text.clone() + "1 2 3 4\n"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.bpt:18:7: patch file: expected the end of the file after the announced patches, found \"4\""
        );
        assert_eq!(parse("t.bpt", &(text + "1 2 3\n")).unwrap().len(), 1);
    }
}
