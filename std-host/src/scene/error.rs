//! Why a scene could not be read.

use std::fmt;
use std::io;
use std::path::PathBuf;
use std::sync::Arc;

use super::loc::SourceLoc;

/// `e`'s message followed by those of its causes, each after `: ` (an
/// I/O error's reason, a decoder's; a cause its error already ends with
/// once), for errors a TOML scene reports as text at the key that names
/// the file.
pub(crate) fn with_causes(e: &(dyn std::error::Error + 'static)) -> String {
    let mut msg = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        // A cause its error already quotes at its end is said once.
        let text = c.to_string();
        if !msg.ends_with(&text) {
            msg.push_str(": ");
            msg.push_str(&text);
        }
        cause = c.source();
    }
    msg
}

/// What stood where the parser expected a value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Found {
    /// A token, as written (shown quoted and escaped, cut to
    /// [`Found::MAX_SHOWN`] characters).
    Token(String),
    /// Nothing more on the line.
    EndOfLine,
    /// Nothing more in the file.
    EndOfFile,
}

impl Found {
    /// Longest token shown in a message, in characters.
    pub const MAX_SHOWN: usize = 40;

    /// The token `text`, cut to [`Found::MAX_SHOWN`] characters (binary
    /// garbage can make very long tokens).
    #[must_use]
    pub fn token(text: &str) -> Self {
        match text.char_indices().nth(Self::MAX_SHOWN) {
            Some((cut, _)) => Self::Token(format!("{}…", &text[..cut])),
            None => Self::Token(text.to_owned()),
        }
    }
}

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Token(t) => write!(f, "{t:?}"),
            Self::EndOfLine => f.write_str("end of line"),
            Self::EndOfFile => f.write_str("end of file"),
        }
    }
}

/// An error reading or parsing a scene file. Each message starts with the
/// file (and line and column, where there is one), then the field.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file could not be opened or read.
    #[error("cannot read {}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: io::Error,
    },
    /// The path names a directory (for any text file: an NFF or TOML
    /// scene, a camera path, a mesh or patch file).
    #[error("{}: is a directory, not {what}", path.display())]
    IsDirectory {
        /// The path.
        path: PathBuf,
        /// What the file should have been ("an NFF file").
        what: &'static str,
    },
    /// The file is larger than [`ParseOptions::max_file_bytes`](super::ParseOptions::max_file_bytes).
    #[error("{file}: {size} bytes, more than the limit of {limit} bytes for {what}")]
    FileTooLarge {
        /// The file.
        file: Arc<str>,
        /// What the file is ("an NFF file").
        what: &'static str,
        /// Its size in bytes.
        size: u64,
        /// The limit.
        limit: u64,
    },
    /// The file holds no directive (it is empty, or only blank lines and
    /// comments).
    #[error("{file}: empty file: no NFF directives")]
    Empty {
        /// The file.
        file: Arc<str>,
    },
    /// The file is not text: a NUL byte or invalid UTF-8.
    #[error("{loc}: not a text file: {what}")]
    NotText {
        /// Where the first offending byte is.
        loc: SourceLoc,
        /// What was found.
        what: &'static str,
    },
    /// A field's value is missing, malformed or out of range.
    #[error("{loc}: {field}: expected {expected}, found {found}")]
    BadField {
        /// Where the offending token (or the end of the line) is.
        loc: SourceLoc,
        /// The field, e.g. `sphere radius`.
        field: &'static str,
        /// What the field must hold.
        expected: &'static str,
        /// What was there.
        found: Found,
    },
    /// A line starts with a word that is not an NFF directive.
    #[error("{loc}: unknown directive {found}: NFF has b, v, l, f, c, s, p, pp and # comments")]
    UnknownDirective {
        /// Where the word is.
        loc: SourceLoc,
        /// The word.
        found: Found,
    },
    /// A view keyword (`from`, `at`, ...) outside a `v` block.
    #[error(
        "{loc}: `{keyword}` outside a view: it belongs on the lines after `v`, in the order from, at, up, angle, hither, resolution"
    )]
    Misplaced {
        /// Where the keyword is.
        loc: SourceLoc,
        /// The keyword.
        keyword: &'static str,
    },
    /// A polygon announces more vertices than the rest of the file can
    /// hold (each vertex takes a line); refused before allocating.
    #[error(
        "{loc}: {field}: {count} vertices announced, but only {remaining} lines remain in the file"
    )]
    CountExceedsInput {
        /// Where the count is.
        loc: SourceLoc,
        /// The field.
        field: &'static str,
        /// The count.
        count: u64,
        /// Lines after the count's line.
        remaining: u64,
    },
    /// The scene would hold more vertices than
    /// [`ParseOptions::max_vertices`](super::ParseOptions::max_vertices).
    #[error(
        "{loc}: {field}: {count} more vertices would make {total}, more than the limit of {limit} vertices per scene"
    )]
    TooManyVertices {
        /// Where the count is.
        loc: SourceLoc,
        /// The field.
        field: &'static str,
        /// The polygon's vertex count.
        count: u64,
        /// The scene's total with it.
        total: u64,
        /// The limit.
        limit: u64,
    },
    /// Well-formed numbers that do not make a valid object.
    #[error("{loc}: {field}: {problem}")]
    Invalid {
        /// Where the object (or its offending part) is.
        loc: SourceLoc,
        /// The field or object.
        field: &'static str,
        /// What is wrong.
        problem: &'static str,
    },
    /// Reading the file would take more memory than the limit.
    #[error("{file}: {what} take about {} to read, more than the memory limit of {} (--max-memory)", crate::memory::Bytes(*bytes), crate::memory::Bytes(*limit))]
    TooMuchMemory {
        /// The file.
        file: Arc<str>,
        /// What it holds, counted (`3 vertices and 3 face corners`).
        what: String,
        /// The bytes reading it takes.
        bytes: u64,
        /// The limit.
        limit: u64,
    },
    /// A directive that may appear once appears again.
    #[error("{loc}: {what}: a second one; the first is on line {first_line}")]
    Duplicate {
        /// Where the second one is.
        loc: SourceLoc,
        /// The directive, e.g. `view (v)`.
        what: &'static str,
        /// The line of the first one.
        first_line: u32,
    },
    /// No `v` block.
    #[error(
        "{file}: no view: an NFF scene needs a `v` block (v, from, at, up, angle, hither, resolution)"
    )]
    MissingView {
        /// The file.
        file: Arc<str>,
    },
    /// A TOML scene's error: a syntax error, an unknown key, a wrong type,
    /// a bad value or a file it refers to.
    #[error("{loc}: {key}{}{msg}", if key.is_empty() { "" } else { ": " })]
    Toml {
        /// Where in the scene file.
        loc: SourceLoc,
        /// The key (dotted path) concerned, empty when toml names it in
        /// the message.
        key: String,
        /// What is wrong.
        msg: String,
    },
    /// A camera path without views.
    #[error(
        "{file}: no views: a camera path has one view per line, from (3 numbers) at (3) up (3) angle"
    )]
    NoViews {
        /// The file.
        file: Arc<str>,
    },
    /// No object.
    #[error("{file}: no objects: the scene has no s, c, p or pp")]
    NoObjects {
        /// The file.
        file: Arc<str>,
    },
    /// A file a TOML scene refers to (a mesh, a model, a volume), given
    /// where a scene is expected.
    #[error("{file}: {what}, not a scene: a TOML scene draws it with {how}")]
    NotAScene {
        /// The file.
        file: Arc<str>,
        /// What it is.
        what: &'static str,
        /// The TOML that draws it.
        how: String,
    },
    /// A TOML scene without objects.
    #[error("{file}: no objects: the scene has no [[object]] table")]
    NoTomlObjects {
        /// The file.
        file: Arc<str>,
    },
}
