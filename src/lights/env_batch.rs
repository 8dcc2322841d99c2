//! Speed only: an environment map's samples taken several at a time
//! ([`EnvMap::sample_each`]), bit for bit those of [`EnvMap::sample`].
//!
//! A sample of a large map (rs_pbrt's 2048×1024 sky: a 4096×2048-bin
//! distribution of 64 MB and 25 MB of texels) is a chain of three cache
//! misses: the conditional row's guide table entry, its CDF entries, the
//! texels around the point found. Taken one after another, the samples
//! wait for each miss in turn; taken together, each stage asks for the
//! lines of every sample before any is read, so the misses of the batch
//! overlap. `cargo run --release --example env_bench -- MAP` times both.

use super::infinite::{EnvMap, EnvSample, EnvSampling};
use glam::Vec2;

/// The most values [`EnvMap::sample_each`] overlaps at once (more are
/// sampled one at a time).
pub const SAMPLE_EACH_MAX: usize = 8;

impl EnvMap {
    /// Whether `sample` reads the map's sampling tables and texels (a map
    /// of more than one texel sampled by its distribution or alias tables):
    /// what [`EnvMap::sample_each`] overlaps, tables larger than the cache
    /// for a large map.
    pub fn samples_large_tables(&self) -> bool {
        self.constant.is_none() && self.sampling != EnvSampling::Uniform
    }

    /// Speed only: `sample` for several values at once: for each
    /// `(map, u, out)`, `out` becomes `map.sample(u)` bit for bit. The work
    /// runs in stages, each asking for the cache lines the next reads, for
    /// every value before any is read (the guide table entries, the CDF
    /// entries, the texels): the cache misses of a large map's samples
    /// then overlap instead of following one another.
    pub fn sample_each(batch: &mut [(&EnvMap, Vec2, Option<EnvSample>)]) {
        let searched = |m: &EnvMap| m.sampling == EnvSampling::Map && m.constant.is_none();
        for &mut (m, u, _) in batch.iter_mut() {
            if searched(m) {
                m.distribution.prefetch_sample_row(u);
            }
        }
        for &mut (m, u, _) in batch.iter_mut() {
            if searched(m) {
                m.distribution.prefetch_sample_bins(u);
            }
        }
        let mut at = [(Vec2::ZERO, 0.0f32); SAMPLE_EACH_MAX];
        for (&mut (m, u, _), a) in batch.iter_mut().zip(&mut at) {
            if m.sampling != EnvSampling::Uniform {
                *a = m.sample_map_with(u, false);
                if m.constant.is_none() {
                    m.levels[0].prefetch(a.0);
                }
            }
        }
        for (k, (m, u, out)) in batch.iter_mut().enumerate() {
            *out = if m.sampling == EnvSampling::Uniform || k >= SAMPLE_EACH_MAX {
                m.sample(*u)
            } else {
                m.sample_direction(at[k].0, at[k].1)
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lights::infinite::tests::{lumpy, rotated};
    use glam::Vec3;

    /// `sample_each` gives `sample`'s values bit for bit, for batches of 0
    /// to 11 values (past `SAMPLE_EACH_MAX`), maps sampled by the CDF
    /// search, by alias tables and uniformly, a one-texel map, and the
    /// maps mixed in one batch.
    #[test]
    fn sample_each_equals_sample() {
        let img = lumpy(64, 32);
        let maps = [
            EnvMap::new(Some(&img), Vec3::ONE, rotated(), EnvSampling::Map),
            EnvMap::new(Some(&img), Vec3::ONE, rotated(), EnvSampling::Alias),
            EnvMap::new(Some(&img), Vec3::ONE, rotated(), EnvSampling::Uniform),
            EnvMap::new(None, Vec3::splat(0.5), rotated(), EnvSampling::Map),
        ];
        let bits = |s: Option<EnvSample>| {
            s.map(|(a, b, c)| {
                (
                    a.to_array().map(f32::to_bits),
                    b.to_array().map(f32::to_bits),
                    c.to_bits(),
                )
            })
        };
        let mut rng = crate::sampling::Pcg32::with_sequence(11);
        let mut checked = 0;
        for round in 0..400 {
            let n = round % 12;
            let mut batch: Vec<(&EnvMap, Vec2, Option<EnvSample>)> = (0..n)
                .map(|k| {
                    let m = if round % 5 == 4 {
                        &maps[(round + k) % 4]
                    } else {
                        &maps[round % 4]
                    };
                    let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
                    (m, u, None)
                })
                .collect();
            EnvMap::sample_each(&mut batch);
            for &(m, u, out) in &batch {
                assert_eq!(bits(out), bits(m.sample(u)), "u {u}");
                checked += out.is_some() as usize;
            }
        }
        assert!(checked > 1500, "{checked}");
    }
}
