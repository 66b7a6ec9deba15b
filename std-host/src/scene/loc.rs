//! Source locations: where in which file a token was read.

use std::fmt;
use std::sync::Arc;

/// A position in a scene file: the file's name as the caller gave it, and a
/// 1-based line and column (columns count characters, not bytes).
///
/// Every token the NFF parser reads is located, and every object it builds
/// keeps the location of its directive, so that later stages (fitting,
/// rendering) can point back into the file too.
///
/// A location with line 0 stands for a whole file that has no lines (a
/// saved raster, which carries its scene's objects and view): it is shown
/// as the file's name alone.
///
/// ```
/// use rrt_host::scene::SourceLoc;
/// let loc = SourceLoc::new("scene.nff", 12, 3);
/// assert_eq!(loc.to_string(), "scene.nff:12:3");
/// assert_eq!(SourceLoc::new("balls.rrt", 0, 0).to_string(), "balls.rrt");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct SourceLoc {
    /// The file's name (shared by all locations in one file).
    pub file: Arc<str>,
    /// Line, from 1 (0: the whole file).
    pub line: u32,
    /// Column, from 1.
    pub column: u32,
}

impl SourceLoc {
    /// A location in `file`.
    #[must_use]
    pub fn new(file: impl Into<Arc<str>>, line: u32, column: u32) -> Self {
        Self {
            file: file.into(),
            line,
            column,
        }
    }
}

impl fmt::Display for SourceLoc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file)
        } else {
            write!(f, "{}:{}:{}", self.file, self.line, self.column)
        }
    }
}
