//! Bounds on the work of one sample, for scenes no sensible render gets
//! near: a medium whose largest density makes delta and ratio tracking
//! take tiny steps, or a specular tree of glass in a hall of mirrors. When
//! a bound stops a sample's work it is counted here (atomically, only when
//! it happens) and the render reports the count once, in a warning.

use std::sync::atomic::{AtomicU64, Ordering};

/// The most steps delta or ratio tracking takes along one ray through a
/// grid medium (an optical depth of 65536 through the majorant): past it
/// the ray is taken as absorbed.
pub const MAX_TRACKING_STEPS: u32 = 1 << 16;

/// The most vertices of `directlighting`'s and `whitted`'s specular tree
/// for one camera ray (twice the deepest `maxdepth`, so a hall of mirrors
/// is followed to its clamped depth): past it the tree is not expanded.
pub const MAX_TREE_VERTICES: u32 = 200_000;

/// What stopped a sample's work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cut {
    /// Tracking through a grid medium ([`MAX_TRACKING_STEPS`]).
    Tracking = 0,
    /// A specular tree ([`MAX_TREE_VERTICES`]).
    Tree = 1,
}

static CUTS: [AtomicU64; 2] = [AtomicU64::new(0), AtomicU64::new(0)];

/// Counts one sample's work stopped by `cut` (cold: never in a sensible scene).
#[cold]
pub fn note_cut(cut: Cut) {
    CUTS[cut as usize].fetch_add(1, Ordering::Relaxed);
}

/// The counts so far in this process, by [`Cut`] (a render reports the
/// difference between its start and its end).
pub fn cuts() -> [u64; 2] {
    [
        CUTS[0].load(Ordering::Relaxed),
        CUTS[1].load(Ordering::Relaxed),
    ]
}

/// The warnings for the counts of a render (`before` and `after` from
/// [`cuts`]).
pub fn cut_warnings(before: [u64; 2], after: [u64; 2]) -> Vec<String> {
    let mut out = Vec::new();
    let tracking = after[0] - before[0];
    if tracking > 0 {
        out.push(format!("{tracking} rays through a grid medium stopped after {MAX_TRACKING_STEPS} tracking steps (its largest density makes the steps tiny) and were taken as absorbed"));
    }
    let tree = after[1] - before[1];
    if tree > 0 {
        out.push(format!(
            "{tree} camera rays' specular trees stopped after {MAX_TREE_VERTICES} vertices"
        ));
    }
    out
}
