//! The golden-image manifest, `scenes/references/golden.txt` (shared by the
//! golden test and `examples/make_references.rs`).

use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub enum Check {
    /// Converged pbrt-v3 reference `STEM-128-16384.pfm`.
    Pbrt(String),
    /// Converged pbrs reference `NAME-128-pbrs.pfm`.
    Pbrs(String),
    /// Converged pbrt-v3 reference, with bounds from the render's own noise
    /// (for settings whose noise differs from pbrt-v3's, e.g. another sampler).
    PbrtOwnNoise(String),
    /// Analytic answer asserted by a test file.
    Test(String),
}

#[derive(Clone, Debug)]
pub struct Entry {
    pub scene: String,
    pub check: Check,
}

/// Resolution and sample count of pbrs-made references.
pub const PBRS_REFERENCE_RES: u32 = 128;
pub const PBRS_REFERENCE_SPP: u32 = 4096;

pub fn manifest(repo: &Path) -> Vec<Entry> {
    let text =
        std::fs::read_to_string(repo.join("scenes/references/golden.txt")).expect("golden.txt");
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 3, "golden.txt: bad line {l:?}");
            let check = match f[1] {
                "pbrt" => Check::Pbrt(f[2].into()),
                "pbrs" => Check::Pbrs(f[2].into()),
                "pbrt-own-noise" => Check::PbrtOwnNoise(f[2].into()),
                "test" => Check::Test(f[2].into()),
                k => panic!("golden.txt: unknown kind {k}"),
            };
            Entry {
                scene: f[0].into(),
                check,
            }
        })
        .collect()
}
