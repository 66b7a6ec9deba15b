//! Reading the text files a scene is made of, with a size limit checked
//! before reading and located errors for binary data.

use std::fs;
use std::io::Read;
use std::path::Path;
use std::sync::Arc;

use super::error::SceneError;
use super::loc::SourceLoc;

/// Reads the file at `path` (at most `limit` bytes) as UTF-8 text; `name`
/// is what messages call it, `what` what the file is ("a camera path").
///
/// # Errors
/// [`SceneError::Io`], [`SceneError::IsDirectory`],
/// [`SceneError::FileTooLarge`], [`SceneError::NotText`] (a NUL byte or
/// invalid UTF-8, located).
pub(crate) fn read_text(
    path: &Path,
    name: &Arc<str>,
    what: &'static str,
    limit: u64,
) -> Result<String, SceneError> {
    let io = |source| SceneError::Io {
        path: path.to_owned(),
        source,
    };
    let meta = fs::metadata(path).map_err(io)?;
    if meta.is_dir() {
        return Err(SceneError::IsDirectory {
            path: path.to_owned(),
            what,
        });
    }
    if meta.len() > limit {
        return Err(SceneError::FileTooLarge {
            file: Arc::clone(name),
            what,
            size: meta.len(),
            limit,
        });
    }
    let bytes = read_until_binary(fs::File::open(path).map_err(io)?, limit).map_err(io)?;
    text(name, what, bytes, limit)
}

/// Reads `reader` to its end, at most `limit + 1` bytes (a file that grows
/// after its size was checked, or a device or pipe, which has no size),
/// stopping early after a piece that holds a NUL byte: binary data is
/// refused at its first megabyte, not after the limit's worth of memory.
///
/// # Errors
/// The reader's.
pub(crate) fn read_until_binary(reader: impl Read, limit: u64) -> std::io::Result<Vec<u8>> {
    const PIECE: u64 = 1 << 20;
    let mut reader = reader.take(limit.saturating_add(1));
    let mut bytes = Vec::new();
    loop {
        let start = bytes.len();
        let n = (&mut reader).take(PIECE).read_to_end(&mut bytes)?;
        if n == 0 || bytes.get(start..).is_some_and(|piece| piece.contains(&0)) {
            return Ok(bytes);
        }
    }
}

/// `bytes` as text (at most `limit` bytes) of `what` ("a camera path").
///
/// # Errors
/// [`SceneError::FileTooLarge`], [`SceneError::NotText`].
pub(crate) fn text(
    name: &Arc<str>,
    what: &'static str,
    bytes: Vec<u8>,
    limit: u64,
) -> Result<String, SceneError> {
    let size = u64::try_from(bytes.len()).unwrap_or(u64::MAX);
    if size > limit {
        return Err(SceneError::FileTooLarge {
            file: Arc::clone(name),
            what,
            size,
            limit,
        });
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        return Err(SceneError::NotText {
            loc: byte_loc(name, &bytes, at),
            what: "a NUL byte (binary data?)",
        });
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        SceneError::NotText {
            loc: byte_loc(name, e.as_bytes(), at),
            what: "invalid UTF-8 (binary data?)",
        }
    })
}

/// `text` without a UTF-8 byte-order mark at its start: editors write one
/// and do not show it, so columns on the first line count from after it.
pub(crate) fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// The line and column (from 1; columns count characters) of byte `at`.
pub(crate) fn byte_loc(file: &Arc<str>, bytes: &[u8], at: usize) -> SourceLoc {
    let before = bytes.get(..at).unwrap_or(bytes);
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |p| p + 1);
    let lines = before.iter().filter(|&&b| b == b'\n').count();
    let tail = before.get(line_start..).unwrap_or(&[]);
    let column = std::str::from_utf8(tail).map_or(tail.len(), |s| s.chars().count());
    SourceLoc::new(
        Arc::clone(file),
        u32::try_from(lines + 1).unwrap_or(u32::MAX),
        u32::try_from(column + 1).unwrap_or(u32::MAX),
    )
}

#[cfg(test)]
mod tests {
    use super::read_until_binary;
    use std::io::Read;

    /// Binary data (an endless stream of NUL bytes, as `/dev/zero`) is
    /// read only to the piece holding its first NUL; text is read whole,
    /// up to the limit and one byte more.
    #[test]
    fn binary_streams_stop_at_their_first_piece() {
        let zeros = read_until_binary(std::io::repeat(0), 1 << 30).unwrap();
        assert_eq!(zeros.len(), 1 << 20);
        let text = "s 0 0 0 1\n".repeat(300_000);
        let read = read_until_binary(text.as_bytes(), 1 << 30).unwrap();
        assert_eq!(read, text.as_bytes());
        let capped = read_until_binary(std::io::repeat(b'x').take(5_000_000), 3_000_000).unwrap();
        assert_eq!(capped.len(), 3_000_001);
    }
}
