//! The process's peak resident memory (Linux: `VmHWM` in /proc/self/status), reset before each
//! size so that each row shows what that size needed rather than the largest so far.

/// Resets the peak to the current resident size (writing 5 to /proc/self/clear_refs, Linux
/// 4.0 and later). Returns false where that is not possible: the peak then covers everything
/// the process did so far.
pub fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Peak resident set size of this process in bytes, where the system reports it.
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
