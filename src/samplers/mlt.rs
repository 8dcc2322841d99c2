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

/// How many of the sampler's random numbers are drawn ahead.
const AHEAD: usize = 16;

/// The sampler's next random numbers, drawn ahead of their use, and, once
/// a small step asks for one, the normal variate each would give: a small
/// step's values then wait for no erf⁻¹ (a chain of dependent operations
/// behind a logarithm), whose results for the whole batch the processor
/// computes side by side. The numbers are PCG32's in order, each used
/// exactly once, as a uniform value or through its normal variate,
/// whichever the reader asks for, so the values are those of drawing
/// each when it is needed.
#[derive(Clone, Debug)]
struct Ahead {
    rng: Pcg32,
    uniform: [f32; AHEAD],
    normal: [f32; AHEAD],
    /// The next unread slot (`AHEAD`: none drawn).
    next: usize,
    /// Whether `normal` holds the variates of this batch's unread slots.
    normals: bool,
}

impl Ahead {
    fn new(sequence: u64) -> Ahead {
        Ahead {
            rng: Pcg32::with_sequence(sequence),
            uniform: [0.0; AHEAD],
            normal: [0.0; AHEAD],
            next: AHEAD,
            normals: false,
        }
    }

    /// As [`Ahead::new`] makes it (the arrays are written before they are read).
    fn restart(&mut self, sequence: u64) {
        self.rng = Pcg32::with_sequence(sequence);
        self.next = AHEAD;
        self.normals = false;
    }

    #[inline]
    fn slot(&mut self) -> usize {
        if self.next == AHEAD {
            self.draw();
        }
        self.next += 1;
        self.next - 1
    }

    /// Draws the next batch.
    #[inline(never)]
    fn draw(&mut self) {
        for u in &mut self.uniform {
            *u = self.rng.uniform_f32();
        }
        self.next = 0;
        self.normals = false;
    }

    /// The normal variates of the unread slots from `i` on.
    #[inline(never)]
    fn make_normals(&mut self, i: usize) {
        for j in i..AHEAD {
            self.normal[j] = std::f32::consts::SQRT_2 * erf_inv(2.0 * self.uniform[j] - 1.0);
        }
        self.normals = true;
    }

    /// The next number, drawn now: only while no batch is pending (after
    /// a restart, for a sampler that never draws ahead).
    #[inline]
    fn uniform_unbatched(&mut self) -> f32 {
        debug_assert_eq!(self.next, AHEAD, "a batch is pending");
        self.rng.uniform_f32()
    }

    /// The next number, uniform in [0, 1).
    #[inline]
    fn uniform_f32(&mut self) -> f32 {
        let i = self.slot();
        self.uniform[i]
    }

    /// The standard normal variate of the next number u: √2·erf⁻¹(2u − 1).
    #[inline]
    fn normal(&mut self) -> f32 {
        let i = self.slot();
        if !self.normals {
            self.make_normals(i);
        }
        self.normal[i]
    }
}

#[derive(Clone, Debug)]
pub struct MltSampler {
    rng: Ahead,
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
    /// Whether X is kept: false for a bootstrap path ([`MltSampler::restart_unkept`]).
    keep: bool,
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
            rng: Ahead::new(sequence),
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
            keep: true,
        }
    }

    /// This sampler as [`MltSampler::new`] makes it with `sequence`,
    /// keeping its storage (the bootstrap makes a fresh sampler per path).
    pub fn restart(&mut self, sequence: u64) {
        self.rng.restart(sequence);
        self.x.clear();
        self.iteration = 0;
        self.large_step = true;
        self.last_large_step = 0;
        self.stream = 0;
        self.index = 0;
        self.arrays = ArrayStore::default();
        self.keep = true;
    }

    /// [`MltSampler::restart`] for a path that is made once and never
    /// mutated (a bootstrap path): its values are not kept. At the first
    /// iteration every value read is a large step's fresh one, one random
    /// number per read in the order of the reads (`ensure_ready` with
    /// `large_step` and no large step after the value's last change), so
    /// the values are those of a kept X bit for bit.
    pub fn restart_unkept(&mut self, sequence: u64) {
        self.restart(sequence);
        self.keep = false;
    }

    pub fn samples_per_pixel(&self) -> u32 {
        self.mutations_per_pixel
    }

    /// Starts the next proposal: a large step with the large-step
    /// probability, else a small one.
    pub fn start_iteration(&mut self) {
        debug_assert!(self.keep, "an unkept path is never mutated");
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
        if !self.keep {
            // Drawn one at a time (a bootstrap path reads few values and
            // asks for no normal variates): `restart` emptied the batch.
            return self.rng.uniform_unbatched();
        }
        let i = self.stream + STREAMS * self.index;
        self.index += 1;
        // The common case without a call: a value that exists and needs no
        // fresh draw for a large step missed, stepped by the next random
        // number of the batch (its normal variate already made for a small
        // step). As `ensure_ready`, in the same order.
        let next = self.rng.next;
        if let Some(xi) = self.x.get_mut(i) {
            if xi.last_modified >= self.last_large_step
                && next < AHEAD
                && (self.large_step || self.rng.normals)
            {
                xi.value_backup = xi.value;
                xi.modified_backup = xi.last_modified;
                self.rng.next = next + 1;
                if self.large_step {
                    xi.value = self.rng.uniform[next];
                } else {
                    let n_small = self.iteration - xi.last_modified;
                    let sigma = if n_small == 1 {
                        self.sigma
                    } else {
                        self.sigma * (n_small as f32).sqrt()
                    };
                    xi.value += self.rng.normal[next] * sigma;
                    xi.value -= xi.value.floor();
                }
                xi.last_modified = self.iteration;
                return xi.value;
            }
        }
        self.get_1d_general(i)
    }

    /// [`MltSampler::get_1d`]'s other cases: a new value, a fresh draw
    /// for a large step missed, a batch to draw or its normal variates to
    /// make.
    #[inline(never)]
    fn get_1d_general(&mut self, i: usize) -> f32 {
        self.ensure_ready(i);
        self.x[i].value
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.get_1d();
        Vec2::new(x, self.get_1d())
    }

    /// Brings X[i] up to the current iteration (pbrt-v3's `EnsureReady`).
    #[inline]
    fn ensure_ready(&mut self, i: usize) {
        if i >= self.x.len() {
            self.grow(i);
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
            let normal = self.rng.normal();
            // Most values are read at every iteration: one step, σ·√1 = σ.
            let sigma = if n_small == 1 {
                self.sigma
            } else {
                self.sigma * (n_small as f32).sqrt()
            };
            xi.value += normal * sigma;
            xi.value -= xi.value.floor();
        }
        xi.last_modified = iteration;
    }

    /// X up to X[i], the new values never changed.
    #[cold]
    #[inline(never)]
    fn grow(&mut self, i: usize) {
        self.x.resize(i + 1, PrimarySample::default());
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
    fn an_unkept_path_reads_the_values_a_kept_one_does() {
        for sequence in [0, 11, 1 << 40] {
            let mut kept = MltSampler::new(4, sequence, 0.01, 0.3);
            let mut unkept = MltSampler::new(4, sequence ^ 5, 0.01, 0.3);
            unkept.restart_unkept(sequence);
            // Streams read in turn, one of them twice (its values drawn
            // afresh the second time, as the first iteration's large step
            // draws them).
            for (k, n) in [
                (CAMERA_STREAM, 7),
                (LIGHT_STREAM, 5),
                (CONNECTION_STREAM, 3),
                (CAMERA_STREAM, 9),
                (LIGHT_STREAM, 2),
            ] {
                kept.start_stream(k);
                unkept.start_stream(k);
                for _ in 0..n {
                    assert_eq!(kept.get_1d().to_bits(), unkept.get_1d().to_bits());
                }
            }
        }
    }

    #[test]
    fn numbers_drawn_ahead_are_those_drawn_when_needed() {
        let mut ahead = Ahead::new(9);
        let mut rng = Pcg32::with_sequence(9);
        let mut pick = Pcg32::with_sequence(1);
        // Uniforms and normals in a random order over many batches, and
        // runs of each longer than a batch.
        for k in 0..2000 {
            let normal = match k / 500 {
                1 => true,
                2 => false,
                _ => pick.uniform_f32() < 0.7,
            };
            let u = rng.uniform_f32();
            if normal {
                let n = std::f32::consts::SQRT_2 * erf_inv(2.0 * u - 1.0);
                assert_eq!(ahead.normal().to_bits(), n.to_bits());
            } else {
                assert_eq!(ahead.uniform_f32().to_bits(), u.to_bits());
            }
        }
        ahead.restart(4);
        let mut rng = Pcg32::with_sequence(4);
        for _ in 0..40 {
            assert_eq!(ahead.uniform_f32().to_bits(), rng.uniform_f32().to_bits());
        }
    }

    #[test]
    fn reads_without_a_call_are_the_general_reads() {
        // Two samplers of one sequence, one read through `get_1d`, the
        // other always through the general path, over iterations of small
        // and large steps (accepted and rejected), streams of varying
        // lengths (values missed for several iterations, new values), and
        // batches drawn part uniform, part normal.
        let mut fast = MltSampler::new(4, 21, 0.05, 0.3);
        let mut general = MltSampler::new(4, 21, 0.05, 0.3);
        let mut pick = Pcg32::with_sequence(77);
        let read = |fast: &mut MltSampler, general: &mut MltSampler, k: usize, n: u32| {
            fast.start_stream(k);
            general.start_stream(k);
            for _ in 0..n {
                let i = general.stream + STREAMS * general.index;
                general.index += 1;
                assert_eq!(fast.get_1d().to_bits(), general.get_1d_general(i).to_bits());
            }
        };
        read(&mut fast, &mut general, CAMERA_STREAM, 9);
        for _ in 0..3000 {
            fast.start_iteration();
            general.start_iteration();
            assert_eq!(fast.large_step, general.large_step);
            for k in [CAMERA_STREAM, LIGHT_STREAM, CONNECTION_STREAM] {
                let n = (pick.uniform_f32() * 14.0) as u32;
                read(&mut fast, &mut general, k, n);
            }
            if pick.uniform_f32() < 0.4 {
                fast.accept();
                general.accept();
            } else {
                fast.reject();
                general.reject();
            }
        }
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
