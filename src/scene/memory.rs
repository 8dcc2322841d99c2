//! The machine's memory, for budgets: an input that would need more memory
//! than is available (a film, a mesh, an image, a voxel grid) is an error
//! naming the amount before anything is allocated, not an abort later.

/// Memory available to new allocations, if known: Linux `MemAvailable`,
/// or less when an address-space limit (`ulimit -v`) leaves less room
/// (an allocation past it would abort the process).
pub fn available_memory_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    let avail = kb * 1024;
    Some(address_space_left().map_or(avail, |left| left.min(avail)))
}

/// The address space left under the process's `RLIMIT_AS`, if one is set.
fn address_space_left() -> Option<u64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits
        .lines()
        .find(|l| l.starts_with("Max address space"))?;
    // "Max address space  SOFT  HARD  bytes"; "unlimited" does not parse.
    let soft: u64 = line.split_whitespace().nth(3)?.parse().ok()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let vm = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let used_kb: u64 = vm.split_whitespace().nth(1)?.parse().ok()?;
    Some(soft.saturating_sub(used_kb * 1024))
}

fn gib(b: u64) -> f64 {
    b as f64 / (1u64 << 30) as f64
}

/// Ok if `need` bytes fit in 90% of the available memory (or it is not
/// known); else "WHAT needs N GiB, more than 90% of the M GiB of memory
/// available".
pub fn check_budget(what: &str, need: u64) -> Result<(), String> {
    match available_memory_bytes() {
        Some(avail) if need > avail / 10 * 9 => Err(format!(
            "{what} needs {:.1} GiB, more than 90% of the {:.1} GiB of memory available",
            gib(need),
            gib(avail)
        )),
        _ => Ok(()),
    }
}
