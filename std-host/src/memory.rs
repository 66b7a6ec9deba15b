//! The machine's memory (`/proc/meminfo`), the default memory limit that
//! scenes, rasters and images are checked against, and byte counts as
//! messages print them.

/// Machine memory assumed when `/proc/meminfo` cannot be read.
pub const FALLBACK_TOTAL_MEMORY: u64 = 8 << 30;

/// `MemTotal` from the text of `/proc/meminfo`, in bytes.
///
/// ```
/// use rrt_host::fit::parse_meminfo;
/// let text = "MemTotal:       24554812 kB\nMemFree:         1000 kB\n";
/// assert_eq!(parse_meminfo(text), Some(24554812 * 1024));
/// assert_eq!(parse_meminfo("nonsense"), None);
/// ```
#[must_use]
pub fn parse_meminfo(text: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let mut words = line["MemTotal:".len()..].split_whitespace();
    let value: u64 = words.next()?.parse().ok()?;
    let scale = match words.next() {
        Some("kB") => 1024,
        None => 1,
        Some(_) => return None,
    };
    value.checked_mul(scale)
}

/// The machine's memory from `/proc/meminfo`, if readable.
#[must_use]
pub fn total_memory() -> Option<u64> {
    parse_meminfo(&std::fs::read_to_string("/proc/meminfo").ok()?)
}

/// The default memory limit: half the machine's memory, or half of
/// [`FALLBACK_TOTAL_MEMORY`] where it cannot be read.
#[must_use]
pub fn default_max_memory() -> u64 {
    total_memory().unwrap_or(FALLBACK_TOTAL_MEMORY) / 2
}

/// A byte count printed with a binary unit (`1.5 GiB`).
///
/// ```
/// use rrt_host::memory::Bytes;
/// assert_eq!(Bytes(1536 << 20).to_string(), "1.5 GiB");
/// assert_eq!(Bytes(100).to_string(), "100 B");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl std::fmt::Display for Bytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
        if self.0 < 1024 {
            return write!(f, "{} B", self.0);
        }
        let mut v = self.0 as f64 / 1024.0;
        let mut unit = UNITS[0];
        for u in &UNITS[1..] {
            if v < 1024.0 {
                break;
            }
            v /= 1024.0;
            unit = u;
        }
        write!(f, "{v:.1} {unit}")
    }
}
