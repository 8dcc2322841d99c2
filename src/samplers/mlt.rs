//! pbrt-v3's `MLTSampler` (src/integrators/mlt.{h,cpp}): the primary
//! sample space of Metropolis light transport. Not a `Sampler` directive
//! kind: the `mlt` integrator makes one per Markov chain (and one per
//! bootstrap path) and hands it to bdpt's subpath and connection code in
//! place of the scene's sampler.
//!
//! A path is a function of an infinite vector of uniform values X. Values
//! are made lazily, when the path asks for them: the i-th value of stream
//! k (camera 0, light 1, connection 2) is `X[k + 3·i]`, so a path whose
//! camera subpath grows does not shift its light subpath's values. Each
//! iteration is either a large step (every value redrawn uniformly) or a
//! small step (every value moved by a normal of standard deviation
//! `sigma`, wrapped into [0, 1)); a value not read for n iterations gets
//! the n small steps it missed at once (standard deviation σ·√n), or a
//! fresh value if a large step came in between. Values changed in an
//! iteration keep a backup, restored if the proposal is rejected.

use super::ArrayStore;
use crate::bxdf::microfacet::erf_inv;
use crate::sampling::rng::Pcg32;
use glam::{IVec2, Vec2};

/// The streams of a path's values (pbrt-v3's constants).
pub const CAMERA_STREAM: usize = 0;
pub const LIGHT_STREAM: usize = 1;
pub const CONNECTION_STREAM: usize = 2;
const STREAMS: usize = 3;

/// One value of X with what rejecting its last change restores.
#[derive(Clone, Copy, Debug, Default)]
struct PrimarySample {
    value: f32,
    last_modified: i64,
    value_backup: f32,
    modified_backup: i64,
}

#[derive(Clone, Debug)]
pub struct MltSampler {
    rng: Pcg32,
    sigma: f32,
    large_step_probability: f32,
    x: Vec<PrimarySample>,
    iteration: i64,
    large_step: bool,
    last_large_step: i64,
    stream: usize,
    index: usize,
    /// Mutations per pixel: pbrt-v3's samples per pixel of this sampler,
    /// which scale the camera rays' differentials.
    mutations_per_pixel: u32,
    /// No arrays are requested of it (bdpt asks for none).
    pub(super) arrays: ArrayStore,
}

impl MltSampler {
    /// pbrt-v3's `MLTSampler(mutationsPerPixel, rngSequenceIndex, sigma,
    /// largeStepProbability, 3)`: its random numbers are PCG32's sequence
    /// `sequence`.
    pub fn new(
        mutations_per_pixel: u32,
        sequence: u64,
        sigma: f32,
        large_step_probability: f32,
    ) -> MltSampler {
        MltSampler {
            rng: Pcg32::with_sequence(sequence),
            sigma,
            large_step_probability,
            x: Vec::new(),
            iteration: 0,
            large_step: true,
            last_large_step: 0,
            stream: 0,
            index: 0,
            mutations_per_pixel,
            arrays: ArrayStore::default(),
        }
    }

    /// This sampler as [`MltSampler::new`] makes it with `sequence`,
    /// keeping its storage (the bootstrap makes a fresh sampler per path).
    pub fn restart(&mut self, sequence: u64) {
        self.rng = Pcg32::with_sequence(sequence);
        self.x.clear();
        self.iteration = 0;
        self.large_step = true;
        self.last_large_step = 0;
        self.stream = 0;
        self.index = 0;
        self.arrays = ArrayStore::default();
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.mutations_per_pixel
    }

    /// Starts the next proposal: a large step with the large-step
    /// probability, else a small one.
    pub fn start_iteration(&mut self) {
        self.iteration += 1;
        self.large_step = self.rng.uniform_f32() < self.large_step_probability;
    }

    /// The proposal was accepted.
    pub fn accept(&mut self) {
        if self.large_step {
            self.last_large_step = self.iteration;
        }
    }

    /// The proposal was rejected: the values it changed go back.
    pub fn reject(&mut self) {
        for xi in &mut self.x {
            if xi.last_modified == self.iteration {
                xi.value = xi.value_backup;
                xi.last_modified = xi.modified_backup;
            }
        }
        self.iteration -= 1;
    }

    /// Values come from stream `k` from its first on.
    pub fn start_stream(&mut self, k: usize) {
        debug_assert!(k < STREAMS);
        self.stream = k;
        self.index = 0;
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        let i = self.stream + STREAMS * self.index;
        self.index += 1;
        self.ensure_ready(i);
        self.x[i].value
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.get_1d();
        Vec2::new(x, self.get_1d())
    }

    /// Brings X[i] up to the current iteration (pbrt-v3's `EnsureReady`).
    fn ensure_ready(&mut self, i: usize) {
        if i >= self.x.len() {
            self.x.resize(i + 1, PrimarySample::default());
        }
        let (iteration, large, last_large) =
            (self.iteration, self.large_step, self.last_large_step);
        let xi = &mut self.x[i];
        // A large step since its last change: it is a fresh value.
        if xi.last_modified < last_large {
            xi.value = self.rng.uniform_f32();
            xi.last_modified = last_large;
        }
        xi.value_backup = xi.value;
        xi.modified_backup = xi.last_modified;
        if large {
            xi.value = self.rng.uniform_f32();
        } else {
            let n_small = iteration - xi.last_modified;
            let normal = std::f32::consts::SQRT_2 * erf_inv(2.0 * self.rng.uniform_f32() - 1.0);
            let sigma = self.sigma * (n_small as f32).sqrt();
            xi.value += normal * sigma;
            xi.value -= xi.value.floor();
        }
        xi.last_modified = iteration;
    }

    // What the `Sampler` enum asks of every sampler.

    pub fn request_1d_array(&mut self, n: u32) {
        self.arrays.request_1d(n, 1);
    }

    pub fn request_2d_array(&mut self, n: u32) {
        self.arrays.request_2d(n, 1);
    }

    /// Positioning by pixel does not apply: the chain positions itself.
    pub fn start_pixel_sample(&mut self, _pixel: IVec2, _sample_index: u32) {
        self.arrays.reset();
    }

    pub fn get_1d_array(&mut self, n: u32) -> Option<&[f32]> {
        self.arrays.get_1d(n, 0)
    }

    pub fn get_2d_array(&mut self, n: u32) -> Option<&[Vec2]> {
        self.arrays.get_2d(n, 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rejected_proposal_restores_every_value() {
        let mut s = MltSampler::new(4, 7, 0.01, 0.3);
        let first: Vec<f32> = (0..5).map(|_| s.get_1d()).collect();
        for _ in 0..20 {
            s.start_iteration();
            s.start_stream(CAMERA_STREAM);
            let moved: Vec<f32> = (0..5).map(|_| s.get_1d()).collect();
            assert!(moved.iter().all(|v| (0.0..1.0).contains(v)));
            s.reject();
        }
        s.start_stream(CAMERA_STREAM);
        // Reading again at the restored iteration: no step (n_small = 0
        // and no large step since), the same values.
        s.large_step = false;
        let again: Vec<f32> = (0..5).map(|_| s.get_1d()).collect();
        assert_eq!(first, again);
    }

    #[test]
    fn small_steps_move_values_by_about_sigma() {
        let mut s = MltSampler::new(4, 3, 0.01, 0.0);
        let v0 = s.get_1d();
        let mut moved = 0.0f64;
        for _ in 0..1000 {
            s.start_iteration();
            s.start_stream(CAMERA_STREAM);
            let v = s.get_1d();
            let d = (v - v0).abs().min(1.0 - (v - v0).abs());
            moved += d as f64;
            s.reject();
        }
        // E|N(0, σ)| = σ·√(2/π) ≈ 0.008.
        let mean = moved / 1000.0;
        assert!((0.006..0.010).contains(&mean), "{mean}");
    }
}
