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
        Some(avail) if need > budget(avail) => Err(refusal(what, need, avail)),
        _ => Ok(()),
    }
}

/// The most a need may be: 90% of the memory available.
fn budget(avail: u64) -> u64 {
    avail / 10 * 9
}

fn refusal(what: &str, need: u64, avail: u64) -> String {
    format!(
        "{what} needs {:.1} GiB, more than 90% of the {:.1} GiB of memory available",
        gib(need),
        gib(avail)
    )
}

/// [`check_budget`] for a need that grows in many small steps (a scene's
/// meshes, checked at each one): the machine's memory is read again only
/// once the need has grown by an eighth of the room that the last reading
/// left, so that thousands of small meshes do not each read `/proc` (a
/// scene of 2,300 one-triangle shapes spent 2% of its whole run there),
/// while a need approaching the limit is checked ever more often.
#[derive(Clone, Copy, Debug, Default)]
pub struct BudgetWatch {
    /// Needs up to this are within the last reading's limit by a margin.
    fits_below: u64,
}

impl BudgetWatch {
    /// Ok if `need` bytes fit (as [`check_budget`], whose reading it takes
    /// again once the need has outgrown the last reading's margin); `what`
    /// names the need in the error.
    pub fn check(&mut self, need: u64, what: impl FnOnce() -> String) -> Result<(), String> {
        if need < self.fits_below {
            return Ok(());
        }
        let Some(avail) = available_memory_bytes() else {
            // Not known here (not Linux): nothing to check, as check_budget.
            self.fits_below = u64::MAX;
            return Ok(());
        };
        let limit = budget(avail);
        if need > limit {
            return Err(refusal(&what(), need, avail));
        }
        self.fits_below = need + (limit - need) / 8;
        Ok(())
    }
}

#[cfg(test)]
mod watch_tests {
    use super::*;

    /// The first check reads the machine's memory; needs within an eighth
    /// of the room it left pass without another reading; a need past the
    /// limit is refused with check_budget's message whatever came before.
    #[test]
    fn rereads_past_its_margin_and_refuses_past_the_limit() {
        let Some(avail) = available_memory_bytes() else {
            return;
        };
        let mut w = BudgetWatch::default();
        assert_eq!(w.fits_below, 0);
        assert!(w.check(1000, || "small".into()).is_ok());
        let limit_then = budget(avail);
        assert!(w.fits_below > 1000 && w.fits_below <= 1000 + limit_then / 8 + 1);
        let margin = w.fits_below;
        assert!(w.check(margin - 1, || unreachable!()).is_ok());
        assert_eq!(w.fits_below, margin, "no reading within the margin");
        let huge = avail.saturating_mul(4).max(1 << 62);
        let err = w.check(huge, || "the huge thing".into()).unwrap_err();
        assert!(err.starts_with("the huge thing needs "), "{err}");
    }
}
