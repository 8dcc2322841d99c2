//! The grid medium's majorant grid (as pbrt-v4's `MajorantGrid`): the
//! unit cube of the medium's space cut into up to 16 cells per axis, each
//! holding the largest density the trilinear interpolation can take in it,
//! and a 3D DDA that walks a ray through the cells. Delta and ratio
//! tracking then step by each cell's own majorant instead of the whole
//! grid's largest density: fewer null collisions where the medium is thin,
//! none at all in empty cells. A majorant grid of one cell is pbrt-v3's
//! tracking exactly.

/// The cells' largest densities.
#[derive(Clone, Debug)]
pub struct Majorants {
    /// Cells per axis.
    pub res: [i32; 3],
    /// Largest density per cell, x fastest.
    pub max: Vec<f32>,
}

impl Majorants {
    /// The majorants of a density grid of `n` voxels (x fastest) over the
    /// unit cube, with `cells` cells per axis (at most `n` along each).
    pub fn new(n: [i32; 3], density: &[f32], cells: i32) -> Self {
        let res = n.map(|v| v.min(cells).max(1));
        // The voxels whose values the interpolation mixes anywhere in cell
        // `c` along an axis of `n` voxels and `r` cells: the lower corners
        // floor(p·n − 0.5) for p in [c/r, (c+1)/r] and the voxels after
        // them, widened by one voxel each side against rounding.
        let span = |c: i32, n: i32, r: i32| {
            let lo = ((c as f64 * n as f64 / r as f64) - 0.5).floor() as i32 - 1;
            let hi = (((c + 1) as f64 * n as f64 / r as f64) - 0.5).floor() as i32 + 2;
            (lo.max(0), hi.min(n - 1))
        };
        let mut max = Vec::with_capacity((res[0] * res[1] * res[2]) as usize);
        for cz in 0..res[2] {
            let (z0, z1) = span(cz, n[2], res[2]);
            for cy in 0..res[1] {
                let (y0, y1) = span(cy, n[1], res[1]);
                for cx in 0..res[0] {
                    let (x0, x1) = span(cx, n[0], res[0]);
                    let mut m = 0.0f32;
                    for z in z0..=z1 {
                        for y in y0..=y1 {
                            let row = ((z * n[1] + y) * n[0]) as usize;
                            for x in x0..=x1 {
                                m = m.max(density[row + x as usize]);
                            }
                        }
                    }
                    max.push(m);
                }
            }
        }
        Self { res, max }
    }

    /// The cells along the ray `o + t·d` (medium space) for `t` in
    /// `[t_min, t_max]`, the part of the ray inside the unit cube.
    #[inline]
    pub fn walk(&self, o: glam::Vec3, d: glam::Vec3, t_min: f32, t_max: f32) -> Dda<'_> {
        let p = o + d * t_min;
        let mut cell = [0i32; 3];
        let mut step = [0i32; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        for a in 0..3 {
            let r = self.res[a];
            let g = p[a] * r as f32;
            cell[a] = (g.floor() as i32).clamp(0, r - 1);
            if d[a] > 0.0 {
                step[a] = 1;
                next[a] = t_min + ((cell[a] + 1) as f32 / r as f32 - p[a]) / d[a];
                delta[a] = 1.0 / (d[a] * r as f32);
            } else if d[a] < 0.0 {
                step[a] = -1;
                next[a] = t_min + (cell[a] as f32 / r as f32 - p[a]) / d[a];
                delta[a] = -1.0 / (d[a] * r as f32);
            }
        }
        Dda {
            m: self,
            cell,
            step,
            next,
            delta,
            t: t_min,
            t_max,
            done: false,
        }
    }
}

/// A ray's walk through the cells of a [`Majorants`] grid (Amanatides and
/// Woo's DDA): segments `[t0, t1)` in order, each with its cell's largest
/// density, at least one (a ray of zero length has one, empty, as pbrt-v3's
/// tracking takes one step along it).
pub struct Dda<'a> {
    m: &'a Majorants,
    cell: [i32; 3],
    step: [i32; 3],
    next: [f32; 3],
    delta: [f32; 3],
    t: f32,
    t_max: f32,
    /// The ray's end was reached.
    done: bool,
}

impl Iterator for Dda<'_> {
    type Item = (f32, f32, f32);

    #[inline]
    fn next(&mut self) -> Option<(f32, f32, f32)> {
        if self.done {
            return None;
        }
        let [cx, cy, cz] = self.cell;
        let [rx, ry, rz] = self.m.res;
        if cx < 0 || cy < 0 || cz < 0 || cx >= rx || cy >= ry || cz >= rz {
            return None;
        }
        let maj = self.m.max[((cz * ry + cy) * rx + cx) as usize];
        let a = if self.next[0] < self.next[1] {
            if self.next[0] < self.next[2] {
                0
            } else {
                2
            }
        } else if self.next[1] < self.next[2] {
            1
        } else {
            2
        };
        let t0 = self.t;
        let to = self.cell[a] + self.step[a];
        // The ray's last cell (no crossing ahead, or the next is outside
        // the grid) takes it to its end, whatever rounding says.
        let last = self.step[a] == 0 || to < 0 || to >= self.m.res[a];
        let t1 = if last {
            self.t_max
        } else {
            self.next[a].min(self.t_max).max(t0)
        };
        self.t = t1;
        self.cell[a] = to;
        self.next[a] += self.delta[a];
        // (A NaN end ends the walk too.)
        self.done = last || t1.partial_cmp(&self.t_max) != Some(std::cmp::Ordering::Less);
        Some((t0, t1, maj))
    }
}

#[cfg(test)]
mod tests {
    use crate::media::Grid;
    use crate::sampling::rng::Pcg32;
    use glam::Vec3;
    use std::sync::Arc;

    fn grid(n: [u32; 3], seed: u64) -> (Grid, Vec<f32>) {
        let mut rng = Pcg32::with_sequence(seed);
        let count = (n[0] * n[1] * n[2]) as usize;
        // Sparse blobs: most voxels empty, a few dense.
        let d: Vec<f32> = (0..count)
            .map(|_| {
                let u = rng.uniform_f32();
                if u < 0.7 {
                    0.0
                } else {
                    rng.uniform_f32() * 10.0 * u
                }
            })
            .collect();
        let g = Grid::new(
            Vec3::splat(0.5),
            Vec3::splat(1.5),
            n,
            Arc::new(d.clone()),
            glam::Mat4::IDENTITY,
            16,
        );
        (g, d)
    }

    /// Every interpolated density is at most its cell's majorant.
    #[test]
    fn majorants_bound_the_density() {
        for (k, n) in [
            [37u32, 20, 9],
            [16, 16, 16],
            [5, 40, 3],
            [1, 1, 1],
            [64, 2, 33],
        ]
        .into_iter()
        .enumerate()
        {
            let (g, _) = grid(n, k as u64);
            let m = g.majorants();
            let mut rng = Pcg32::with_sequence(100 + k as u64);
            for _ in 0..20000 {
                let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
                let c = [0, 1, 2].map(|a| ((p[a] * m.res[a] as f32) as i32).min(m.res[a] - 1));
                let maj = m.max[((c[2] * m.res[1] + c[1]) * m.res[0] + c[0]) as usize];
                let d = g.density_at(p);
                assert!(
                    d <= maj * (1.0 + 1e-6),
                    "{n:?} at {p}: density {d} > majorant {maj}"
                );
            }
        }
    }

    /// The walk covers `[t_min, t_max]` with consecutive segments through
    /// neighbouring cells, each holding the points of its part of the ray.
    #[test]
    fn walk_covers_the_ray_cell_by_cell() {
        let (g, _) = grid([37, 20, 9], 1);
        let m = g.majorants();
        let mut rng = Pcg32::with_sequence(9);
        for _ in 0..5000 {
            let o = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32());
            let mut d = Vec3::new(
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
                rng.uniform_f32() - 0.5,
            );
            if rng.uniform_f32() < 0.2 {
                d[rng.uniform_u32_below(3) as usize] = 0.0;
            }
            // To the cube's far side.
            let t_max = (0..3)
                .map(|a| {
                    if d[a] > 0.0 {
                        (1.0 - o[a]) / d[a]
                    } else if d[a] < 0.0 {
                        -o[a] / d[a]
                    } else {
                        f32::INFINITY
                    }
                })
                .fold(f32::INFINITY, f32::min);
            let mut t = 0.0f32;
            let mut n = 0;
            for (t0, t1, maj) in m.walk(o, d, 0.0, t_max) {
                assert_eq!(t0, t, "segments are consecutive");
                assert!(t1 >= t0);
                let mid = o + d * (0.5 * (t0 + t1));
                if t1 - t0 > 1e-4 {
                    assert!(g.density_at(mid) <= maj * (1.0 + 1e-6));
                }
                t = t1;
                n += 1;
                assert!(n <= 37 + 20 + 9 + 3);
            }
            assert_eq!(t, t_max, "the walk ends at the ray's end");
        }
    }
}
