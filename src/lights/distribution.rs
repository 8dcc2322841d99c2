//! Which light to sample at a point (pbrt-v3's LightDistribution): uniform,
//! by power, or spatial (a voxel grid over the scene bounds whose per-voxel
//! distributions are built lazily, on first use, safely across threads).
//!
//! Lights with zero power are never chosen: they could not contribute.
//!
//! `Bvh` (a pbrs extension) chooses by a light BVH ([`super::bvh`]); the
//! spatial distribution uses it too past `SPATIAL_MAX_LIGHTS` lights, where
//! pbrt-v3's per-voxel estimates (128 points × every light) would cost more
//! than the render.

use super::bvh::LightBvh;
use super::Light;
use crate::accel::Aggregate;
use crate::geometry::Bounds3;
use crate::sampling::distribution::{find_interval_by, sanitise_u};
use crate::sampling::Distribution1D;
use glam::{Vec2, Vec3};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::OnceLock;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSamplerKind {
    Uniform,
    Power,
    Spatial,
    /// A light BVH (pbrt-v4's BVHLightSampler).
    Bvh,
}

/// Most lights for pbrt-v3's spatial distribution: each voxel it builds
/// costs 128 × this many contribution estimates (about 1 ms at 1024 lights
/// on this machine's cores), and a scene's surfaces touch up to a few
/// thousand of the 32³ voxels, so set-up stays within seconds. Past it,
/// `spatial` chooses by the light BVH instead (noted in `--stats`): the
/// same kind of position-aware choice at O(log n) a lookup and O(n log n)
/// set-up. The Cornell scenes and every golden scene have far fewer lights.
pub const SPATIAL_MAX_LIGHTS: usize = 1024;

pub struct LightSampler {
    kind: LightSamplerKind,
    /// Indices of lights that can emit, in scene order.
    active: Vec<u32>,
    /// Position of each scene light in `active` (`u32::MAX` if it cannot emit).
    active_pos: Vec<u32>,
    power: Option<Distribution1D>,
    spatial: Option<SpatialGrid>,
    bvh: Option<LightBvh>,
    /// `spatial` was asked for but the BVH chosen (too many lights).
    spatial_fallback: bool,
}

struct SpatialGrid {
    bounds: Bounds3,
    n: [i32; 3],
    /// Bricks along x and y (see `slot`).
    bricks: [usize; 2],
    voxels: VoxelStore,
}

/// The voxels' light-selection CDFs (`active + 1` values each), built on
/// first use by whichever thread gets there first. Their contents are a
/// function of the voxel alone, so who builds them never shows in the image.
enum VoxelStore {
    /// All voxels in one table: the CDF's inner values (`active - 1` words of
    /// f32 bits; the first is 0 and the last 1 anyway), the first word
    /// doubling as the state (`EMPTY` or `BUILDING`, NaN patterns no CDF
    /// value has). One memory access per lookup, used while the table stays
    /// small (few lights). Voxels are stored in bricks of 4×2×2, so that the
    /// voxels along any wall share cache lines: shading points lie on
    /// surfaces, and with x-rows a wall facing x would touch a cache line
    /// per voxel (for two lights, a brick is one 64-byte line).
    Flat {
        words: Vec<AtomicU32>,
        stride: usize,
    },
    /// One allocation per built voxel, for many lights.
    Boxed(Vec<OnceLock<Box<[f32]>>>),
}

/// Largest flat voxel table, in bytes.
const FLAT_BUDGET: usize = 16 << 20;
const EMPTY: u32 = u32::MAX;
const BUILDING: u32 = u32::MAX - 1;
/// Voxels per brick (4×2×2) of the flat table.
const BRICK: usize = 16;

/// A voxel's light choice: the CDF over the active lights.
#[derive(Clone, Copy)]
pub struct VoxelCdf<'a> {
    cdf: CdfRef<'a>,
}

#[derive(Clone, Copy)]
enum CdfRef<'a> {
    Words(&'a [AtomicU32]),
    Floats(&'a [f32]),
}

impl VoxelCdf<'_> {
    #[inline(always)]
    fn at(&self, i: usize) -> f32 {
        match self.cdf {
            // Inner values only: cdf[0] = 0 and cdf[n] = 1 always.
            CdfRef::Words(w) => {
                if i == 0 {
                    0.0
                } else if i > w.len() {
                    1.0
                } else {
                    f32::from_bits(w[i - 1].load(Ordering::Relaxed))
                }
            }
            CdfRef::Floats(f) => f[i],
        }
    }

    #[inline(always)]
    fn len(&self) -> usize {
        match self.cdf {
            CdfRef::Words(w) => w.len() + 2,
            CdfRef::Floats(f) => f.len(),
        }
    }

    /// Bin `i` with `cdf[i] <= u < cdf[i + 1]` and its probability.
    #[inline]
    fn sample(&self, u: f32) -> (usize, f32) {
        let i = find_interval_by(self.len(), sanitise_u(u), |i| self.at(i));
        (i, self.pmf(i))
    }

    #[inline]
    fn pmf(&self, i: usize) -> f32 {
        (self.at(i + 1) - self.at(i)).max(0.0)
    }
}

/// Voxels along the longest axis of the scene bounds. pbrt-v3 uses 64; 32
/// keeps the voxel table (one entry per voxel, most never built) within L2
/// cache and builds 8× fewer distributions. Light selection probabilities
/// stay a valid distribution either way, so the expected image is unchanged;
/// measured: cornell-path 8 spp on one thread 16.6 s -> 15.0 s.
const MAX_VOXELS: f32 = 32.0;

fn radical_inverse(base: u32, mut a: u64) -> f32 {
    let inv = 1.0 / base as f64;
    let (mut rev, mut f) = (0u64, 1.0f64);
    while a > 0 {
        rev = rev * base as u64 + a % base as u64;
        f *= inv;
        a /= base as u64;
    }
    ((rev as f64 * f) as f32).min(crate::sampling::ONE_MINUS_EPSILON)
}

/// Points per voxel when estimating light contributions (pbrt-v3: 128).
const VOXEL_SAMPLES: usize = 128;

/// The first 128 points of the 5D Halton sequence (bases 2, 3, 5, 7, 11):
/// three for the position in the voxel, two for the light sample.
fn halton_points() -> &'static [[f32; 5]; VOXEL_SAMPLES] {
    static POINTS: OnceLock<[[f32; 5]; VOXEL_SAMPLES]> = OnceLock::new();
    POINTS.get_or_init(|| {
        let mut pts = [[0.0; 5]; VOXEL_SAMPLES];
        for (i, p) in pts.iter_mut().enumerate() {
            for (d, base) in [2, 3, 5, 7, 11].into_iter().enumerate() {
                p[d] = radical_inverse(base, i as u64);
            }
        }
        pts
    })
}

impl LightSampler {
    /// Builds only what the strategy needs: nothing for one light or uniform,
    /// a power table, or an (initially empty) voxel grid.
    pub fn new(kind: LightSamplerKind, lights: &[Light], geom: &Aggregate) -> LightSampler {
        let active: Vec<u32> = (0..lights.len() as u32)
            .filter(|&i| lights[i as usize].power() > 0.0)
            .collect();
        let mut active_pos = vec![u32::MAX; lights.len()];
        for (k, &i) in active.iter().enumerate() {
            active_pos[i as usize] = k as u32;
        }
        let asked = kind;
        let kind = if active.len() <= 1 {
            LightSamplerKind::Uniform
        } else if kind == LightSamplerKind::Spatial && active.len() > SPATIAL_MAX_LIGHTS {
            LightSamplerKind::Bvh
        } else {
            kind
        };
        let spatial_fallback = asked == LightSamplerKind::Spatial && kind == LightSamplerKind::Bvh;
        let bvh = (kind == LightSamplerKind::Bvh).then(|| LightBvh::new(&active, lights, geom));
        let power = (kind == LightSamplerKind::Power).then(|| {
            let p: Vec<f32> = active.iter().map(|&i| lights[i as usize].power()).collect();
            Distribution1D::new(&p)
        });
        let spatial = (kind == LightSamplerKind::Spatial).then(|| {
            let bounds = if geom.bounds.is_empty() {
                Bounds3::from_point(Vec3::ZERO)
            } else {
                geom.bounds
            };
            let diag = bounds.diagonal();
            let max_extent = diag.max_element();
            let mut n = [1i32; 3];
            for (i, ni) in n.iter_mut().enumerate() {
                if max_extent > 0.0 {
                    *ni = ((diag[i] / max_extent * MAX_VOXELS).round() as i32).max(1);
                }
            }
            let bricks = [
                (n[0] as usize).div_ceil(4),
                (n[1] as usize).div_ceil(2),
                (n[2] as usize).div_ceil(2),
            ];
            let count = bricks[0] * bricks[1] * bricks[2] * BRICK;
            // Spatial sampling has at least two lights (one is uniform).
            let stride = active.len() - 1;
            let voxels = if count.saturating_mul(stride).saturating_mul(4) <= FLAT_BUDGET {
                VoxelStore::Flat {
                    words: (0..count * stride).map(|_| AtomicU32::new(EMPTY)).collect(),
                    stride,
                }
            } else {
                VoxelStore::Boxed((0..count).map(|_| OnceLock::new()).collect())
            };
            SpatialGrid {
                bounds,
                n,
                bricks: [bricks[0], bricks[1]],
                voxels,
            }
        });
        LightSampler {
            kind,
            active,
            active_pos,
            power,
            spatial,
            bvh,
            spatial_fallback,
        }
    }

    pub fn kind(&self) -> LightSamplerKind {
        self.kind
    }

    pub fn active_count(&self) -> usize {
        self.active.len()
    }

    /// True when `spatial` was asked for and the light BVH used instead.
    pub fn spatial_fallback(&self) -> bool {
        self.spatial_fallback
    }

    /// (lights in the tree, lights at infinity, tree depth) of the light
    /// BVH, if one was built.
    pub fn bvh_shape(&self) -> Option<(usize, usize, usize)> {
        self.bvh
            .as_ref()
            .map(|b| (b.tree_lights(), b.infinite_count(), b.max_depth))
    }

    /// Number of voxel distributions built so far (spatial only).
    pub fn voxels_built(&self) -> usize {
        self.spatial.as_ref().map_or(0, |s| match &s.voxels {
            VoxelStore::Flat { words, stride } => words
                .chunks(*stride)
                .filter(|v| v[0].load(Ordering::Acquire) < BUILDING)
                .count(),
            VoxelStore::Boxed(v) => v.iter().filter(|v| v.get().is_some()).count(),
        })
    }

    /// Choose a light for shading point `p` with geometric normal `normal`
    /// (zero in a medium; only the BVH looks at it): (light index,
    /// probability).
    #[inline]
    pub fn sample(
        &self,
        p: Vec3,
        normal: Vec3,
        u: f32,
        lights: &[Light],
        geom: &Aggregate,
    ) -> Option<(u32, f32)> {
        let n = self.active.len();
        if n == 0 {
            return None;
        }
        let (i, pmf) = match self.kind {
            LightSamplerKind::Bvh => return self.bvh.as_ref()?.sample(p, normal, u),
            LightSamplerKind::Uniform => (((u * n as f32) as usize).min(n - 1), 1.0 / n as f32),
            LightSamplerKind::Power => {
                let (i, pmf, _) = self.power.as_ref()?.sample_discrete(u);
                (i, pmf)
            }
            LightSamplerKind::Spatial => {
                let spatial = self.spatial.as_ref()?;
                let mut local = Vec::new();
                spatial
                    .lookup(p, &self.active, lights, geom, &mut local)
                    .sample(u)
            }
        };
        (pmf > 0.0).then(|| (self.active[i], pmf))
    }

    /// Probability that `sample` at `p` (normal `normal`) chooses scene
    /// light `light`.
    #[inline]
    pub fn pmf(
        &self,
        p: Vec3,
        normal: Vec3,
        light: u32,
        lights: &[Light],
        geom: &Aggregate,
    ) -> f32 {
        let n = self.active.len();
        let Some(&k) = self.active_pos.get(light as usize) else {
            return 0.0;
        };
        if k == u32::MAX {
            return 0.0;
        }
        match self.kind {
            LightSamplerKind::Bvh => self.bvh.as_ref().map_or(0.0, |b| b.pmf(p, normal, light)),
            LightSamplerKind::Uniform => 1.0 / n as f32,
            LightSamplerKind::Power => self
                .power
                .as_ref()
                .map_or(0.0, |d| d.discrete_pdf(k as usize)),
            LightSamplerKind::Spatial => self.spatial.as_ref().map_or(0.0, |s| {
                let mut local = Vec::new();
                s.lookup(p, &self.active, lights, geom, &mut local)
                    .pmf(k as usize)
            }),
        }
    }
}

impl SpatialGrid {
    /// The CDF of the voxel holding `p`, built now if no thread has built it
    /// yet (`local` receives it when another thread is still publishing it).
    #[inline]
    fn lookup<'a>(
        &'a self,
        p: Vec3,
        active: &[u32],
        lights: &[Light],
        geom: &Aggregate,
        local: &'a mut Vec<f32>,
    ) -> VoxelCdf<'a> {
        let o = self.bounds.offset(p);
        let mut v = [0i32; 3];
        for i in 0..3 {
            let x = (o[i] * self.n[i] as f32) as i32; // NaN → 0
            v[i] = x.clamp(0, self.n[i] - 1);
        }
        match &self.voxels {
            VoxelStore::Flat { words, stride } => {
                let idx = self.slot(v);
                let slot = &words[idx * stride..(idx + 1) * stride];
                if slot[0].load(Ordering::Acquire) >= BUILDING {
                    *local = self.compute(v, active, lights, geom);
                    if slot[0]
                        .compare_exchange(EMPTY, BUILDING, Ordering::Acquire, Ordering::Relaxed)
                        .is_ok()
                    {
                        // The inner values; the first one last, publishing.
                        let inner = &local[1..local.len() - 1];
                        for (w, c) in slot[1..].iter().zip(&inner[1..]) {
                            w.store(c.to_bits(), Ordering::Relaxed);
                        }
                        slot[0].store(inner[0].to_bits(), Ordering::Release);
                    }
                    return VoxelCdf {
                        cdf: CdfRef::Floats(local),
                    };
                }
                VoxelCdf {
                    cdf: CdfRef::Words(slot),
                }
            }
            VoxelStore::Boxed(voxels) => VoxelCdf {
                cdf: CdfRef::Floats(
                    voxels[((v[2] * self.n[1] + v[1]) * self.n[0] + v[0]) as usize]
                        .get_or_init(|| self.compute(v, active, lights, geom).into_boxed_slice()),
                ),
            },
        }
    }

    /// Position of voxel `v` in the flat table: its 4×2×2 brick, then its
    /// place in the brick.
    #[inline(always)]
    fn slot(&self, v: [i32; 3]) -> usize {
        let [x, y, z] = v.map(|c| c as usize);
        let brick = ((z >> 1) * self.bricks[1] + (y >> 1)) * self.bricks[0] + (x >> 2);
        brick * BRICK + ((z & 1) << 3 | (y & 1) << 2 | (x & 3))
    }

    /// pbrt-v3's SpatialLightDistribution::ComputeDistribution: estimate each
    /// light's contribution (Li/pdf, visibility ignored) at 128 Halton points
    /// of the voxel, and floor every light at 0.1% of the average.
    fn compute(&self, v: [i32; 3], active: &[u32], lights: &[Light], geom: &Aggregate) -> Vec<f32> {
        let d = self.bounds.diagonal();
        let vmin = self.bounds.min
            + d * Vec3::new(
                v[0] as f32 / self.n[0] as f32,
                v[1] as f32 / self.n[1] as f32,
                v[2] as f32 / self.n[2] as f32,
            );
        let vmax = self.bounds.min
            + d * Vec3::new(
                (v[0] + 1) as f32 / self.n[0] as f32,
                (v[1] + 1) as f32 / self.n[1] as f32,
                (v[2] + 1) as f32 / self.n[2] as f32,
            );
        let voxel = Bounds3 {
            min: vmin,
            max: vmax,
        };
        let mut contrib = vec![0.0f32; active.len()];
        for h in halton_points() {
            let po = voxel.lerp(Vec3::new(h[0], h[1], h[2]));
            let u = Vec2::new(h[3], h[4]);
            for (j, &l) in active.iter().enumerate() {
                contrib[j] += lights[l as usize].contribution_estimate(po, u, geom);
            }
        }
        let sum: f32 = contrib.iter().sum();
        let avg = sum / (VOXEL_SAMPLES as f32 * contrib.len() as f32);
        let min = if avg > 0.0 { 0.001 * avg } else { 1.0 };
        for c in &mut contrib {
            *c = c.max(min);
        }
        cdf_of(&contrib)
    }
}

/// The CDF (`f.len() + 1` values from 0 to 1) of positive weights `f`,
/// accumulated in f64.
fn cdf_of(f: &[f32]) -> Vec<f32> {
    let total: f64 = f.iter().map(|&v| v as f64).sum();
    let n = f.len();
    let mut cdf = Vec::with_capacity(n + 1);
    cdf.push(0.0);
    if total > 0.0 && total.is_finite() {
        let mut acc = 0.0f64;
        for &v in f {
            acc += v as f64;
            cdf.push((acc / total) as f32);
        }
    } else {
        cdf.extend((1..=n).map(|i| i as f32 / n as f32));
    }
    cdf[n] = 1.0;
    cdf
}
