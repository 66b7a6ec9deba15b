//! The machine's memory (`/proc/meminfo`) and the default memory limit.

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
