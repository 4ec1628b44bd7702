//! Whether a scene's build fits in memory, judged before it starts: a scene too big is one clear
//! error naming what it needs and what there is, never the kernel's out-of-memory kill (which
//! takes the editor and the user's unsaved work with it).
//!
//! The need is the build's measured peak per triangle ([`BUILD_BYTES_PER_TRIANGLE`]) plus the
//! texels; what there is comes from the system (`MemAvailable`, and a cgroup's limit where the
//! process runs in one, as under Slurm, Kubernetes or systemd).

use crate::error::{Error, Result};

/// Peak bytes a triangle takes while a scene builds (its box and (object, face) pair, the BVH
/// builder's arrays, the built triangle and shading records, the scene's mesh), measured on the
/// 871k-triangle dragon (2026-12-07, docs/performance-log.md session 32): 84 as the slope of peak
/// RSS from the 202k dragon for a glTF of positions only, about 180 by the heap's peak where
/// vertex normals add an 80-byte shading record a triangle (281 in session 21, 233 in session
/// 29), rounded up.
pub const BUILD_BYTES_PER_TRIANGLE: u64 = 200;

/// Peak bytes an instance takes while a scene builds (its object's packed material, its record,
/// boxes and share of the top level and its builder): measured over the scene already in memory,
/// 200,000 instances of a small mesh (2026-12-06: 873, 617 kept), rounded up.
pub const BUILD_BYTES_PER_INSTANCE: u64 = 900;

/// Makes the allocator give blocks of 1 MiB and more back to the system as they are freed, for
/// the whole process (the binaries call it first). glibc raises its threshold for that to the
/// largest block freed so far (up to 32 MiB); after the loader frees a file's bytes, a build's
/// large arrays then come from its heaps, and the holes they leave stay resident: the 871k dragon's
/// peak RSS stood 60–90 MB above its heap's peak (docs/performance-log.md, session 32).
#[allow(unsafe_code)] // one libc call; see SAFETY below
pub fn return_large_blocks_to_the_system() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a tuning parameter of glibc's allocator, valid at any time.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

/// Bytes the build of `triangles` stored triangles and `texels` texels needs at its peak.
pub fn build_bytes(triangles: u64, texels: u64) -> u64 {
    triangles
        .saturating_mul(BUILD_BYTES_PER_TRIANGLE)
        .saturating_add(texels.saturating_mul(8))
}

/// An error where `needed` bytes exceed `available` (`None`: unknown, so no limit is judged).
pub fn check_fits(triangles: u64, needed: u64, available: Option<u64>) -> Result<()> {
    match available {
        Some(available) if needed > available => {
            let gb = |b: u64| b as f64 / 1e9;
            Err(Error::Scene(format!(
                "the scene's {triangles} triangles need about {:.1} GB to build, and {:.1} GB of \
                 memory are available: simpler meshes would fit (copies of one mesh are stored \
                 once and cost little)",
                gb(needed),
                gb(available)
            )))
        }
        _ => Ok(()),
    }
}

/// Memory this process may still take: the system's `MemAvailable`, or less where a cgroup
/// limits the process; `None` where neither can be read (not Linux).
pub fn available_bytes() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
    let system = meminfo.as_deref().and_then(|text| {
        text.lines()
            .find_map(|l| l.strip_prefix("MemAvailable:"))
            .and_then(|rest| {
                rest.trim()
                    .trim_end_matches("kB")
                    .trim()
                    .parse::<u64>()
                    .ok()
            })
            .map(|kb| kb * 1024)
    });
    let read = |path: &str| {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.trim().parse::<u64>().ok())
    };
    // cgroup v2 (the limit "max" reads as none), then v1.
    let cgroup = match (
        read("/sys/fs/cgroup/memory.max"),
        read("/sys/fs/cgroup/memory.current"),
    ) {
        (Some(limit), Some(used)) => Some(limit.saturating_sub(used)),
        _ => match (
            read("/sys/fs/cgroup/memory/memory.limit_in_bytes"),
            read("/sys/fs/cgroup/memory/memory.usage_in_bytes"),
        ) {
            (Some(limit), Some(used)) if limit < 1 << 60 => Some(limit.saturating_sub(used)),
            _ => None,
        },
    };
    match (system, cgroup) {
        (Some(s), Some(c)) => Some(s.min(c)),
        (s, c) => s.or(c),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_over_the_budget_is_an_error_naming_both() {
        let needed = build_bytes(71_000_000, 0);
        assert_eq!(needed, 71_000_000 * BUILD_BYTES_PER_TRIANGLE);
        let message = check_fits(71_000_000, needed, Some(8_000_000_000))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("71000000 triangles")
                && message.contains(&format!("{:.1} GB", needed as f64 / 1e9))
                && message.contains("8.0 GB"),
            "{message}"
        );
        assert!(check_fits(71_000_000, needed, Some(needed)).is_ok());
        assert!(
            check_fits(71_000_000, needed, None).is_ok(),
            "unknown: not judged"
        );
    }

    #[test]
    fn this_machine_reports_some_memory() {
        if cfg!(target_os = "linux") {
            let available = available_bytes().unwrap_or(0);
            assert!(available > 1 << 26, "{available} bytes available");
        }
    }
}
