//! A 64-bit digest of a stream of integers, the same on every target.
//!
//! Values are fed as 64-bit words (`h = (h ^ w) · P`, FNV-1a's prime over
//! words, not bytes); each step is a bijection of `h` for a fixed word, so
//! changing any single word of a stream always changes the digest. Text fed
//! through [`core::fmt::Write`] (the `Debug` form of a value, which holds
//! its whole private state) is packed eight bytes to a word, so the digest
//! does not depend on how the formatter splits its output.

use core::fmt::{self, Debug, Write};

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0000_0100_0000_01b3;

/// A running digest and the number of items fed into it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Digest {
    h: u64,
    items: u64,
    /// Bytes of text not yet folded into `h`, and how many.
    acc: u64,
    fill: u32,
}

impl Default for Digest {
    fn default() -> Self {
        Self::new()
    }
}

impl Digest {
    /// An empty digest.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            h: OFFSET,
            items: 0,
            acc: 0,
            fill: 0,
        }
    }

    /// Feeds one word.
    pub fn word(&mut self, w: u64) {
        self.flush();
        self.h = (self.h ^ w).wrapping_mul(PRIME);
    }

    /// Feeds a signed value (sign-extended to 64 bits).
    pub fn int(&mut self, v: i64) {
        self.word(v as u64);
    }

    /// Feeds several unsigned values.
    pub fn words(&mut self, ws: &[u64]) {
        for &w in ws {
            self.word(w);
        }
    }

    /// Feeds a `usize` (an index: the same number on 32- and 64-bit
    /// targets).
    pub fn index(&mut self, i: usize) {
        self.word(i as u64);
    }

    /// Feeds the `Debug` text of `v`, followed by its length.
    pub fn debug(&mut self, v: &impl Debug) {
        let mut w = TextWriter { d: self, len: 0 };
        // Writing into a digest cannot fail.
        let _ = write!(w, "{v:?}");
        let len = w.len;
        self.word(len);
    }

    /// Counts one item (a voxel, a hit, a record) for the report.
    pub fn item(&mut self) {
        self.items = self.items.wrapping_add(1);
    }

    /// Counts `n` items.
    pub fn add_items(&mut self, n: u64) {
        self.items = self.items.wrapping_add(n);
    }

    /// Items counted so far.
    #[must_use]
    pub const fn items(&self) -> u64 {
        self.items
    }

    /// The digest value (finalized with a 64-bit avalanche mix).
    #[must_use]
    pub fn value(&self) -> u64 {
        let mut d = *self;
        d.flush();
        let mut z = d.h ^ d.items.rotate_left(32);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn byte(&mut self, b: u8) {
        self.acc |= u64::from(b) << (8 * self.fill);
        self.fill += 1;
        if self.fill == 8 {
            let w = self.acc;
            self.acc = 0;
            self.fill = 0;
            self.h = (self.h ^ w).wrapping_mul(PRIME);
        }
    }

    fn flush(&mut self) {
        if self.fill > 0 {
            let w = self.acc | (1 << 63);
            self.acc = 0;
            self.fill = 0;
            self.h = (self.h ^ w).wrapping_mul(PRIME);
        }
    }
}

struct TextWriter<'a> {
    d: &'a mut Digest,
    len: u64,
}

impl Write for TextWriter<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for &b in s.as_bytes() {
            self.d.byte(b);
        }
        self.len = self.len.wrapping_add(s.len() as u64);
        Ok(())
    }
}

/// One reported digest: a name, the value and the number of items.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    /// What was digested (`ray.six.voxels`, `scene.records`, ...).
    pub name: &'static str,
    /// The digest value.
    pub value: u64,
    /// Items digested.
    pub items: u64,
}

impl Line {
    /// The line for `digest` under `name`.
    #[must_use]
    pub fn of(name: &'static str, digest: &Digest) -> Self {
        Self {
            name,
            value: digest.value(),
            items: digest.items(),
        }
    }
}

impl fmt::Display for Line {
    /// `digest <name> <value, 16 hex digits> <items>`: the format the run
    /// script compares.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "digest {} {:016x} {}", self.name, self.value, self.items)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_does_not_depend_on_chunking() {
        let mut a = Digest::new();
        let mut w = TextWriter { d: &mut a, len: 0 };
        w.write_str("hello, ").unwrap();
        w.write_str("world").unwrap();
        let mut b = Digest::new();
        let mut w = TextWriter { d: &mut b, len: 0 };
        w.write_str("hello, world").unwrap();
        assert_eq!(a.value(), b.value());
    }

    #[test]
    fn any_single_word_change_changes_the_digest() {
        let base = [1u64, 2, 3, 4, 5];
        let mut d0 = Digest::new();
        d0.words(&base);
        for i in 0..base.len() {
            let mut w = base;
            w[i] ^= 1 << (i * 13);
            let mut d = Digest::new();
            d.words(&w);
            assert_ne!(d.value(), d0.value());
        }
    }
}
