//! Resident memory of this process: its peak, and the allocator's policy that keeps it low.

/// Fixes glibc's mmap threshold at 2 MiB, which glibc otherwise raises to the size of
/// each large buffer freed (up to 32 MiB): a build frees large buffers early (its
/// insertion rounds), after which every buffer below the raised threshold would come from
/// the heap and keep its pages resident once freed. Measured at 10⁶ points (peak RSS):
/// the square's build 169 → 150 MB, the cube's 442 → 420 MB and its Voronoi cells 960 →
/// 920 MB, in times within the noise (the initial 128 KiB saved as much, but mapped and
/// faulted the Voronoi cells' buffers afresh each time: 10 % slower). True when set (glibc
/// on Linux; elsewhere nothing to do, false).
pub fn keep_large_buffers_mapped() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets a parameter of the allocator (under its lock)
        unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, 2 << 20) == 1 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

/// `VmHWM` from `/proc/self/status`, in KiB (Linux), or `None` where unavailable.
pub fn peak_kb() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

#[cfg(test)]
mod tests {
    #[test]
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    fn the_threshold_is_accepted() {
        assert!(super::keep_large_buffers_mapped());
    }
}
