//! Where each key and value of a TOML scene is: the document parsed a
//! second time into toml's spanned tree, so that an error names the
//! value's own line and column and its full key path
//! (`object[2].sphere.radius`, arrays counted from 0), inside inline
//! tables too.

use std::ops::Range;

use ::toml::Spanned;
use ::toml::de::{DeTable, DeValue};

/// The spanned tree of one document (empty if it does not parse: the
/// serde pass reports that error).
pub(super) struct Spans<'t> {
    root: Option<Spanned<DeTable<'t>>>,
}

/// One step of a key path.
enum Step<'p> {
    Key(&'p str),
    Index(usize),
}

/// `a.b[2].c` as steps.
fn steps(path: &str) -> Vec<Step<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = part.split_once('[').map_or((part, ""), |(n, r)| (n, r));
        if !name.is_empty() {
            out.push(Step::Key(name));
        }
        while let Some((i, r)) = rest.split_once(']') {
            if let Ok(i) = i.parse() {
                out.push(Step::Index(i));
            }
            rest = r.strip_prefix('[').unwrap_or("");
        }
    }
    out
}

impl<'t> Spans<'t> {
    pub(super) fn new(text: &'t str) -> Self {
        Self {
            root: DeTable::parse(text).ok(),
        }
    }

    /// Whether the document parsed (else every lookup finds nothing).
    pub(super) fn parsed(&self) -> bool {
        self.root.is_some()
    }

    /// The span of the value at `path`, or of the deepest value on the
    /// way that exists.
    pub(super) fn value(&self, path: &str) -> Option<Range<usize>> {
        let root = self.root.as_ref()?;
        let mut table = root.get_ref();
        let mut found: Option<&Spanned<DeValue<'t>>> = None;
        let mut array: Option<&[Spanned<DeValue<'t>>]> = None;
        for step in steps(path) {
            let next = match step {
                Step::Key(k) => {
                    if array.is_some() {
                        break;
                    }
                    table
                        .iter()
                        .find(|(key, _)| key.get_ref() == k)
                        .map(|(_, v)| v)
                }
                Step::Index(i) => array.and_then(|a| a.get(i)),
            };
            let Some(v) = next else { break };
            found = Some(v);
            array = None;
            match v.get_ref() {
                DeValue::Table(t) => table = t,
                DeValue::Array(a) => array = Some(a),
                _ => {}
            }
        }
        found.map(Spanned::span)
    }

    /// The full key path of the innermost key or value whose span holds
    /// all of `at` (for toml's own errors: an unknown key in an inline
    /// table, a wrong type, a missing key of a table), or empty for an
    /// empty span (toml's for an error about the whole document, such as
    /// a missing `[camera]`).
    pub(super) fn path_of(&self, at: Range<usize>) -> String {
        let Some(root) = self.root.as_ref() else {
            return String::new();
        };
        if at.is_empty() {
            return String::new();
        }
        let mut best: Option<(usize, String)> = None;
        walk_table(root.get_ref(), "", &at, &mut best);
        best.map(|(_, p)| p).unwrap_or_default()
    }
}

fn consider(span: Range<usize>, path: &str, at: &Range<usize>, best: &mut Option<(usize, String)>) {
    if span.start <= at.start && at.end <= span.end {
        let len = span.len();
        if best.as_ref().is_none_or(|(l, _)| len <= *l) {
            *best = Some((len, path.to_owned()));
        }
    }
}

fn walk_table(
    t: &DeTable<'_>,
    prefix: &str,
    at: &Range<usize>,
    best: &mut Option<(usize, String)>,
) {
    for (k, v) in t {
        let path = if prefix.is_empty() {
            k.get_ref().to_string()
        } else {
            format!("{prefix}.{}", k.get_ref())
        };
        consider(k.span(), &path, at, best);
        walk_value(v, &path, at, best);
    }
}

fn walk_value(
    v: &Spanned<DeValue<'_>>,
    path: &str,
    at: &Range<usize>,
    best: &mut Option<(usize, String)>,
) {
    consider(v.span(), path, at, best);
    match v.get_ref() {
        DeValue::Table(t) => walk_table(t, path, at, best),
        DeValue::Array(a) => {
            for (i, item) in a.iter().enumerate() {
                walk_value(item, &format!("{path}[{i}]"), at, best);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = "[camera]\nangle = 40\n[[object]]\nsphere = { r = 1 }\n[[object]]\nbox = { min = [0, 1, 2], max = { scale = 2 } }\n";

    #[test]
    fn values_by_path() {
        let s = Spans::new(DOC);
        let at = |p: &str| s.value(p).map(|r| &DOC[r]);
        assert_eq!(at("camera.angle"), Some("40"));
        assert_eq!(at("object[1].box.min"), Some("[0, 1, 2]"));
        assert_eq!(at("object[1].box.min[2]"), Some("2"));
        assert_eq!(at("object[0].sphere.r"), Some("1"));
        // The deepest value that exists.
        assert_eq!(at("object[0].sphere.nope"), Some("{ r = 1 }"));
        assert_eq!(at("nothing"), None);
    }

    #[test]
    fn paths_by_position() {
        let s = Spans::new(DOC);
        let at = |needle: &str| {
            let i = DOC.find(needle).unwrap();
            s.path_of(i..i + needle.len())
        };
        assert_eq!(at("scale"), "object[1].box.max.scale");
        assert_eq!(at("40"), "camera.angle");
        assert_eq!(at("{ scale = 2 }"), "object[1].box.max");
        // The whole document (a missing top-level table): no key.
        assert_eq!(s.path_of(0..0), "");
        assert_eq!(s.path_of(0..DOC.len()), "");
    }
}
