use super::{coordinate_system, DiffGeom, ShapeSample, SurfacePoint};
use crate::accel::SurfaceHit;
use crate::geometry::{face_forward, gamma, Bounds3};
use crate::materials::ShadingContext;
use crate::sampling::uniform_sample_triangle;
use crate::scene::FloatTex;
use glam::{Vec2, Vec3, Vec4};
use std::sync::Arc;

/// A triangle mesh with vertices in world space. Vertex arrays are shared by
/// all triangles (32-bit indices).
#[derive(Clone, Debug)]
pub struct TriangleMesh {
    /// Vertex positions (shared with the scene's mesh data when its
    /// transform is the identity).
    pub p: Arc<Vec<Vec3>>,
    /// Per-vertex normals in world space (unnormalised allowed).
    pub n: Option<Vec<Vec3>>,
    pub uv: Option<Vec<Vec2>>,
    /// Three per triangle (shared with the scene's mesh data).
    pub indices: Arc<Vec<u32>>,
    /// Per-triangle Ptex face ids (pbrt-v3's `faceIndices`).
    pub face_indices: Option<Vec<i32>>,
    /// ReverseOrientation XOR the transform swaps handedness.
    pub flip_normal: bool,
    /// ReverseOrientation alone: pbrt-v3 flips interpolated shading normals
    /// by it (not by the handedness), and the geometric normal follows them.
    pub reverse_orientation: bool,
    pub material: u32,
    /// Index of the area light of this mesh's first triangle; triangle `i`
    /// has light `first_light + i` (one light per triangle, as pbrt-v3).
    pub first_light: Option<u32>,
    /// pbrt-v3's alpha masks, if any (then the BVH hands this mesh's
    /// triangles to [`TriangleMesh::alpha_passes`] instead of testing them
    /// four at a time).
    pub alpha: Option<Arc<AlphaMask>>,
}

/// A mesh's `alpha` and `shadowalpha` textures (at least one is set).
#[derive(Clone, Debug)]
pub struct AlphaMask {
    /// Hits where it is 0 are ignored by every ray.
    pub alpha: Option<FloatTex>,
    /// Hits where it is 0 are ignored by shadow rays.
    pub shadow: Option<FloatTex>,
}

impl TriangleMesh {
    /// Positions and indices alone (no normals, uv, alpha or light;
    /// material 0): the meshes that benchmarks and tests generate.
    pub fn plain(p: Vec<Vec3>, indices: Vec<u32>) -> TriangleMesh {
        TriangleMesh {
            p: p.into(),
            n: None,
            uv: None,
            indices: indices.into(),
            face_indices: None,
            flip_normal: false,
            reverse_orientation: false,
            material: 0,
            first_light: None,
            alpha: None,
        }
    }

    /// pbrt-v3's alpha test of a hit at barycentrics `b`: false if the hit
    /// is to be ignored (`alpha` is 0 there, or for a shadow ray
    /// `shadowalpha` is). The textures see the hit's point, uv and
    /// dp/du, dp/dv, without differentials (pbrt-v3's `isectLocal`).
    pub fn alpha_passes(&self, tri: u32, b: [f32; 3], shadow: bool) -> bool {
        let Some(mask) = &self.alpha else {
            return true;
        };
        let point = self.surface_point(tri, b);
        // pbrt-v3's alpha test sees face 0 whatever the mesh's faceIndices.
        let geom = DiffGeom {
            face_index: 0,
            ..self.diff_geom(tri, b, point.n)
        };
        let hit = SurfaceHit {
            point,
            material: self.material,
            light: None,
            time: 0.0,
        };
        let sc = ShadingContext {
            hit: &hit,
            geom: &geom,
        };
        let cut = |t: &Option<FloatTex>| t.as_ref().is_some_and(|t| t.eval(&sc) == 0.0);
        !(cut(&mask.alpha) || (shadow && cut(&mask.shadow)))
    }

    #[inline(always)]
    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        let i = 3 * tri as usize;
        [
            self.p[self.indices[i] as usize],
            self.p[self.indices[i + 1] as usize],
            self.p[self.indices[i + 2] as usize],
        ]
    }

    pub fn triangle_count(&self) -> u32 {
        (self.indices.len() / 3) as u32
    }

    pub fn area(&self, tri: u32) -> f32 {
        let [p0, p1, p2] = self.vertices(tri);
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    pub fn bounds(&self, tri: u32) -> Bounds3 {
        let [p0, p1, p2] = self.vertices(tri);
        Bounds3::from_point(p0).union_point(p1).union_point(p2)
    }

    /// True if the triangle has zero area or non-finite vertices: such
    /// triangles are left out of the scene (they can never be seen).
    pub fn is_degenerate(&self, tri: u32) -> bool {
        let [p0, p1, p2] = self.vertices(tri);
        let l2 = (p0 - p2).cross(p1 - p2).length_squared();
        let finite = p0.is_finite() && p1.is_finite() && p2.is_finite() && l2.is_finite();
        !finite || l2 <= 0.0
    }

    /// Oriented normals at barycentrics (b0, b1, b2), as pbrt-v3's triangle.cpp.
    #[inline(always)]
    fn normals_at(&self, tri: u32, b: [f32; 3], geometric: Vec3) -> (Vec3, Vec3) {
        let mut n = geometric;
        if self.flip_normal {
            n = -n;
        }
        if let Some(normals) = &self.n {
            let i = 3 * tri as usize;
            let ns = b[0] * normals[self.indices[i] as usize]
                + b[1] * normals[self.indices[i + 1] as usize]
                + b[2] * normals[self.indices[i + 2] as usize];
            let l2 = ns.length_squared();
            if l2 > 0.0 && l2.is_finite() {
                let ns = ns / l2.sqrt();
                let ns = if self.reverse_orientation { -ns } else { ns };
                // Per-vertex normals are authoritative for orientation.
                return (face_forward(geometric, ns), ns);
            }
        }
        (n, n)
    }

    /// The oriented geometric normal at barycentrics `b` (no position, no
    /// error bound: for estimates).
    #[inline]
    pub fn oriented_normal(&self, tri: u32, b: [f32; 3]) -> Vec3 {
        let [p0, p1, p2] = self.vertices(tri);
        let geometric = (p0 - p2).cross(p1 - p2).normalize();
        self.normals_at(tri, b, geometric).0
    }

    /// The surface point at barycentrics `b` (b0 + b1 + b2 = 1).
    #[inline]
    pub fn surface_point(&self, tri: u32, b: [f32; 3]) -> SurfacePoint {
        let [p0, p1, p2] = self.vertices(tri);
        let p = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let p_error = gamma(7) * ((b[0] * p0).abs() + (b[1] * p1).abs() + (b[2] * p2).abs());
        let geometric = (p0 - p2).cross(p1 - p2).normalize();
        let (n, ns) = self.normals_at(tri, b, geometric);
        SurfacePoint { p, p_error, n, ns }
    }

    /// The differential geometry at barycentrics `b` (pbrt-v3's
    /// `Triangle::Intersect`): uv (default (0,0), (1,0), (1,1)), dp/du and
    /// dp/dv from the uv parameterisation (any frame of the plane if it is
    /// degenerate), and with per-vertex normals the shading tangents (dp/du
    /// made perpendicular to the shading normal `ns`) and dn/du, dn/dv.
    #[inline]
    pub fn diff_geom(&self, tri: u32, b: [f32; 3], ns: Vec3) -> DiffGeom {
        let [p0, p1, p2] = self.vertices(tri);
        let i = 3 * tri as usize;
        let v = [
            self.indices[i] as usize,
            self.indices[i + 1] as usize,
            self.indices[i + 2] as usize,
        ];
        let uv = match &self.uv {
            Some(uv) => [uv[v[0]], uv[v[1]], uv[v[2]]],
            None => [Vec2::ZERO, Vec2::X, Vec2::ONE],
        };
        let duv02 = uv[0] - uv[2];
        let duv12 = uv[1] - uv[2];
        let dp02 = p0 - p2;
        let dp12 = p1 - p2;
        let det = duv02.x * duv12.y - duv02.y * duv12.x;
        let degenerate_uv = det.abs() < 1e-8;
        let (mut dpdu, mut dpdv) = (Vec3::ZERO, Vec3::ZERO);
        if !degenerate_uv {
            let inv = 1.0 / det;
            dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
            dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
        }
        if degenerate_uv || dpdu.cross(dpdv).length_squared() == 0.0 {
            let ng = (p2 - p0).cross(p1 - p0);
            (dpdu, dpdv) = coordinate_system(ng.normalize());
        }
        let uv_hit = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
        let mut g = DiffGeom {
            uv: uv_hit,
            dpdu,
            dpdv,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            face_index: self.face_indices.as_ref().map_or(0, |f| f[tri as usize]),
            ..DiffGeom::default()
        };
        if let Some(normals) = &self.n {
            let mut ss = dpdu.normalize();
            let mut ts = ss.cross(ns);
            if ts.length_squared() > 0.0 {
                ts = ts.normalize();
                ss = ts.cross(ns);
            } else {
                (ss, ts) = coordinate_system(ns);
            }
            let [n0, n1, n2] = [normals[v[0]], normals[v[1]], normals[v[2]]];
            let (dndu, dndv) = if degenerate_uv {
                let dn = (n2 - n0).cross(n1 - n0);
                if dn.length_squared() == 0.0 {
                    (Vec3::ZERO, Vec3::ZERO)
                } else {
                    coordinate_system(dn.normalize())
                }
            } else {
                let inv = 1.0 / det;
                let dn1 = n0 - n2;
                let dn2 = n1 - n2;
                (
                    (duv12.y * dn1 - duv02.y * dn2) * inv,
                    (duv02.x * dn2 - duv12.x * dn1) * inv,
                )
            };
            g.shading_dpdu = ss;
            g.shading_dpdv = ts;
            g.shading_dndu = dndu;
            g.shading_dndv = dndv;
        }
        g
    }

    /// Uniform sample by area (pbrt-v3 Triangle::Sample).
    pub fn sample_area(&self, tri: u32, u: Vec2) -> ShapeSample {
        let (b, p, p_error) = sample_triangle_point(self.vertices(tri), u);
        let mut point = self.surface_point(tri, b);
        point.p = p;
        point.p_error = p_error;
        ShapeSample {
            point,
            pdf: 1.0 / self.area(tri),
        }
    }
}

/// A uniformly sampled point of a triangle (pbrt-v3 Triangle::Sample):
/// barycentrics, position, and the position's error bound.
#[inline]
pub fn sample_triangle_point(p: [Vec3; 3], u: Vec2) -> ([f32; 3], Vec3, Vec3) {
    let b = uniform_sample_triangle(u);
    let b = [b.x, b.y, 1.0 - b.x - b.y];
    let q = b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
    let err = gamma(6) * ((b[0] * p[0]).abs() + (b[1] * p[1]).abs() + (b[2] * p[2]).abs());
    (b, q, err)
}

/// pbrt-v3's watertight ray–triangle test with its conservative check that
/// t is positive. Returns (t, [b0, b1, b2]).
#[inline]
pub fn intersect_triangle(
    o: Vec3,
    d: Vec3,
    t_max: f32,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
) -> Option<(f32, [f32; 3])> {
    TriangleRay::new(o, d).intersect(t_max, p0, p1, p2)
}

/// The per-ray part of pbrt-v3's watertight triangle test (the axis
/// permutation and the shear), computed once per ray instead of once per
/// triangle. The permutation is applied with static swizzles: `kz` is the
/// same for every triangle a ray meets, so the branch on it is predicted.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    o: Vec3,
    kz: u8,
    /// (Sx, Sy, Sz) of pbrt-v3.
    shear: Vec3,
}

impl TriangleRay {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> TriangleRay {
        let ad = d.abs();
        let kz = if ad.x > ad.y {
            if ad.x > ad.z {
                0
            } else {
                2
            }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let dp = permute(kz, d);
        let sz = 1.0 / dp.z;
        TriangleRay {
            o,
            kz,
            shear: Vec3::new(-dp.x * sz, -dp.y * sz, sz),
        }
    }

    /// Hit distance and barycentrics for `0 < t < t_max`.
    #[inline(always)]
    pub fn intersect(&self, t_max: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<(f32, [f32; 3])> {
        match self.kz {
            0 => self.intersect_k::<0>(t_max, p0, p1, p2),
            1 => self.intersect_k::<1>(t_max, p0, p1, p2),
            _ => self.intersect_k::<2>(t_max, p0, p1, p2),
        }
    }

    #[inline(always)]
    fn intersect_k<const KZ: u8>(
        &self,
        t_max: f32,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
    ) -> Option<(f32, [f32; 3])> {
        // Translate to the ray origin, permute so z is the largest direction axis.
        let mut p0t = permute(KZ, p0 - self.o);
        let mut p1t = permute(KZ, p1 - self.o);
        let mut p2t = permute(KZ, p2 - self.o);
        // Shear so the ray runs along +z.
        let (sx, sy, sz) = (self.shear.x, self.shear.y, self.shear.z);
        p0t.x += sx * p0t.z;
        p0t.y += sy * p0t.z;
        p1t.x += sx * p1t.z;
        p1t.y += sy * p1t.z;
        p2t.x += sx * p2t.z;
        p2t.y += sy * p2t.z;
        let mut e0 = p1t.x * p2t.y - p1t.y * p2t.x;
        let mut e1 = p2t.x * p0t.y - p2t.y * p0t.x;
        let mut e2 = p0t.x * p1t.y - p0t.y * p1t.x;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            // Exactly on an edge in f32: decide in f64 (watertightness).
            e0 = (p1t.x as f64 * p2t.y as f64 - p1t.y as f64 * p2t.x as f64) as f32;
            e1 = (p2t.x as f64 * p0t.y as f64 - p2t.y as f64 * p0t.x as f64) as f32;
            e2 = (p0t.x as f64 * p1t.y as f64 - p0t.y as f64 * p1t.x as f64) as f32;
        }
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        // The largest |z| before z is scaled to ray-parameter units: the
        // shear's x and y errors are in length units (see `delta_x`).
        let max_z = p0t.z.abs().max(p1t.z.abs()).max(p2t.z.abs());
        p0t.z *= sz;
        p1t.z *= sz;
        p2t.z *= sz;
        let t_scaled = e0 * p0t.z + e1 * p1t.z + e2 * p2t.z;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        // Conservatively reject hits whose t cannot be told apart from zero.
        let max_zt = p0t.z.abs().max(p1t.z.abs()).max(p2t.z.abs());
        let delta_z = gamma(3) * max_zt;
        let max_xt = p0t.x.abs().max(p1t.x.abs()).max(p2t.x.abs());
        let max_yt = p0t.y.abs().max(p1t.y.abs()).max(p2t.y.abs());
        // pbrt-v3's bound on the sheared x and y, γ₅(max|x| + max|z|) (its
        // book, 3.9.6), with z in length units as the shear used it. (pbrt-v3's
        // code takes the z scaled by 1/d_z, which agrees within √3 for unit
        // directions but is not scale-invariant: an instance's object-space
        // ray at scale 1e5 has |d| ~ 1e-5, and the scaled z then rejected
        // most real hits as indistinguishable from t = 0.)
        let delta_x = gamma(5) * (max_xt + max_z);
        let delta_y = gamma(5) * (max_yt + max_z);
        let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs();
        if t <= delta_t {
            return None;
        }
        Some((t, [e0 * inv_det, e1 * inv_det, e2 * inv_det]))
    }
}

/// Four triangles in SIMD lanes: `v[3 * k + axis]` holds coordinate `axis`
/// of vertex `k` of the four triangles.
pub type TrianglePack = [Vec4; 9];

/// Puts up to four triangles in lanes (missing lanes are zero; callers mask
/// them out).
pub fn pack_triangles(tris: &[[Vec3; 3]]) -> TrianglePack {
    assert!(tris.len() <= 4);
    let mut a = [[0.0f32; 4]; 9];
    for (lane, t) in tris.iter().enumerate() {
        for (k, p) in t.iter().enumerate() {
            a[3 * k][lane] = p.x;
            a[3 * k + 1][lane] = p.y;
            a[3 * k + 2][lane] = p.z;
        }
    }
    a.map(Vec4::from_array)
}

/// [`TriangleRay`] for four-lane tests: the permuted origin and the shear
/// splatted into lanes once per ray.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay4 {
    /// Origin coordinates (kx, ky, kz).
    o: [Vec4; 3],
    /// (Sx, Sy, Sz).
    s: [Vec4; 3],
    scalar: TriangleRay,
}

impl TriangleRay4 {
    /// The axis the ray's direction is largest along: the `KZ` to call the
    /// four-lane tests with (callers branch on it once per ray; a branch per
    /// test is mispredicted whenever ray directions are random).
    #[inline(always)]
    pub fn kz(&self) -> u8 {
        self.scalar.kz
    }

    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> TriangleRay4 {
        let scalar = TriangleRay::new(o, d);
        let po = permute(scalar.kz, o);
        TriangleRay4 {
            o: [Vec4::splat(po.x), Vec4::splat(po.y), Vec4::splat(po.z)],
            s: [
                Vec4::splat(scalar.shear.x),
                Vec4::splat(scalar.shear.y),
                Vec4::splat(scalar.shear.z),
            ],
            scalar,
        }
    }

    /// The closest of the pack's triangles in `lanes` (a bit mask) with
    /// `0 < t <= t_max`: (lane, t, barycentrics). The same arithmetic as
    /// [`TriangleRay::intersect`] in four lanes, so hits, distances and
    /// barycentrics are bit-identical to testing the triangles one by one;
    /// ties go to the lower lane.
    #[inline(always)]
    pub fn intersect4<const KZ: u8>(
        &self,
        v: &TrianglePack,
        t_max: f32,
        lanes: u32,
    ) -> Option<(u32, f32, [f32; 3])> {
        debug_assert_eq!(KZ, self.scalar.kz);
        self.intersect4_kz(KZ as usize, v, t_max, lanes)
    }

    /// [`TriangleRay4::intersect4`] with the ray's own axis read at run
    /// time (the vertices' coordinates loaded from offsets it computes, so
    /// no branch on it): for rays traced side by side, whose axes differ.
    #[inline(always)]
    pub fn intersect4_any_axis(
        &self,
        v: &TrianglePack,
        t_max: f32,
        lanes: u32,
    ) -> Option<(u32, f32, [f32; 3])> {
        self.intersect4_kz(self.scalar.kz as usize, v, t_max, lanes)
    }

    #[inline(always)]
    fn intersect4_kz(
        &self,
        kz: usize,
        v: &TrianglePack,
        t_max: f32,
        lanes: u32,
    ) -> Option<(u32, f32, [f32; 3])> {
        let Some(r) = self.lanes_kz(kz, v, t_max, lanes) else {
            return self.scalar.intersect4_scalar(v, t_max, lanes);
        };
        if r.mask == 0 {
            return None;
        }
        let t = r.t.to_array();
        let mut lane = r.mask.trailing_zeros();
        let mut rest = r.mask & (r.mask - 1);
        while rest != 0 {
            let l = rest.trailing_zeros();
            if t[l as usize] < t[lane as usize] {
                lane = l;
            }
            rest &= rest - 1;
        }
        let i = lane as usize;
        let inv = r.inv_det.to_array()[i];
        Some((
            lane,
            t[i],
            [
                r.e0.to_array()[i] * inv,
                r.e1.to_array()[i] * inv,
                r.e2.to_array()[i] * inv,
            ],
        ))
    }

    /// True if any of the pack's triangles in `lanes` is hit with
    /// `0 < t <= t_max`.
    #[inline(always)]
    pub fn any4<const KZ: u8>(&self, v: &TrianglePack, t_max: f32, lanes: u32) -> bool {
        debug_assert_eq!(KZ, self.scalar.kz);
        match self.lanes_kz(KZ as usize, v, t_max, lanes) {
            Some(r) => r.mask != 0,
            None => self.scalar.intersect4_scalar(v, t_max, lanes).is_some(),
        }
    }

    /// [`TriangleRay4::any4`] with the ray's own axis read at run time (as
    /// [`TriangleRay4::intersect4_any_axis`]): for shadow rays traced side
    /// by side.
    #[inline(always)]
    pub fn any4_any_axis(&self, v: &TrianglePack, t_max: f32, lanes: u32) -> bool {
        match self.lanes_kz(self.scalar.kz as usize, v, t_max, lanes) {
            Some(r) => r.mask != 0,
            None => self.scalar.intersect4_scalar(v, t_max, lanes).is_some(),
        }
    }

    /// The four-lane body of `intersect_k` for the ray's axis `kz`. `None` if a lane in `lanes` has
    /// an edge value of exactly zero (the caller then decides lane by lane).
    #[inline(always)]
    fn lanes_kz(&self, kz: usize, v: &TrianglePack, t_max: f32, lanes: u32) -> Option<Lanes> {
        let (kx, ky) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        let [ox, oy, oz] = self.o;
        // Translate and permute.
        let mut p0x = v[kx] - ox;
        let mut p0y = v[ky] - oy;
        let mut p0z = v[kz] - oz;
        let mut p1x = v[3 + kx] - ox;
        let mut p1y = v[3 + ky] - oy;
        let mut p1z = v[3 + kz] - oz;
        let mut p2x = v[6 + kx] - ox;
        let mut p2y = v[6 + ky] - oy;
        let mut p2z = v[6 + kz] - oz;
        // Shear.
        let [sx, sy, sz] = self.s;
        p0x += sx * p0z;
        p0y += sy * p0z;
        p1x += sx * p1z;
        p1y += sy * p1z;
        p2x += sx * p2z;
        p2y += sy * p2z;
        let e0 = p1x * p2y - p1y * p2x;
        let e1 = p2x * p0y - p2y * p0x;
        let e2 = p0x * p1y - p0y * p1x;
        let zero = Vec4::ZERO;
        let neg = e0.cmplt(zero) | e1.cmplt(zero) | e2.cmplt(zero);
        let pos = e0.cmpgt(zero) | e1.cmpgt(zero) | e2.cmpgt(zero);
        let inside = !(neg & pos);
        let inside_lanes = inside.bitmask() & lanes;
        if inside_lanes == 0 {
            // Most packs a ray reaches miss in every lane. An edge value of
            // exactly zero does not matter here: a nonzero f32 edge value
            // has the sign of the exact one (rounding is monotonic, so the
            // two products keep their order), so a lane with edge values of
            // both signs is outside whatever f64 makes of its zeros.
            return Some(Lanes {
                mask: 0,
                t: zero,
                e0,
                e1,
                e2,
                inv_det: zero,
            });
        }
        if (e0.cmpeq(zero) | e1.cmpeq(zero) | e2.cmpeq(zero)).bitmask() & inside_lanes != 0 {
            return None;
        }
        let det = e0 + e1 + e2;
        let finite = det.abs().cmplt(Vec4::INFINITY);
        let mut ok = inside & det.cmpne(zero) & finite;
        // Unscaled |z| for the x and y error bounds (see the scalar test).
        let max_z = p0z.abs().max(p1z.abs()).max(p2z.abs());
        p0z *= sz;
        p1z *= sz;
        p2z *= sz;
        let t_scaled = e0 * p0z + e1 * p1z + e2 * p2z;
        let tmd = Vec4::splat(t_max) * det;
        let reject_neg = det.cmplt(zero) & (t_scaled.cmpge(zero) | t_scaled.cmplt(tmd));
        let reject_pos = det.cmpgt(zero) & (t_scaled.cmple(zero) | t_scaled.cmpgt(tmd));
        ok &= !(reject_neg | reject_pos);
        let inv_det = Vec4::ONE / det;
        let t = t_scaled * inv_det;
        let max_zt = p0z.abs().max(p1z.abs()).max(p2z.abs());
        let delta_z = Vec4::splat(gamma(3)) * max_zt;
        let max_xt = p0x.abs().max(p1x.abs()).max(p2x.abs());
        let max_yt = p0y.abs().max(p1y.abs()).max(p2y.abs());
        let g5 = Vec4::splat(gamma(5));
        let delta_x = g5 * (max_xt + max_z);
        let delta_y = g5 * (max_yt + max_z);
        let delta_e = Vec4::splat(2.0)
            * (Vec4::splat(gamma(2)) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = Vec4::splat(3.0)
            * (Vec4::splat(gamma(3)) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        ok &= t.cmpgt(delta_t);
        Some(Lanes {
            mask: ok.bitmask() & lanes,
            t,
            e0,
            e1,
            e2,
            inv_det,
        })
    }
}

impl TriangleRay {
    /// Lane by lane with the scalar test (which decides edge values that are
    /// exactly zero in f64).
    #[cold]
    fn intersect4_scalar(
        &self,
        v: &TrianglePack,
        t_max: f32,
        lanes: u32,
    ) -> Option<(u32, f32, [f32; 3])> {
        let a = v.map(|x| x.to_array());
        let vertex = |k: usize, l: usize| Vec3::new(a[3 * k][l], a[3 * k + 1][l], a[3 * k + 2][l]);
        let mut best: Option<(u32, f32, [f32; 3])> = None;
        for l in 0..4 {
            if lanes & (1 << l) == 0 {
                continue;
            }
            if let Some((t, b)) = self.intersect(t_max, vertex(0, l), vertex(1, l), vertex(2, l)) {
                if best.is_none_or(|(_, bt, _)| t < bt) {
                    best = Some((l as u32, t, b));
                }
            }
        }
        best
    }
}

/// Per-lane results of the four-lane triangle test.
struct Lanes {
    mask: u32,
    t: Vec4,
    e0: Vec4,
    e1: Vec4,
    e2: Vec4,
    inv_det: Vec4,
}

/// pbrt-v3's permutation (kx, ky, kz) = (kz+1, kz+2, kz) mod 3, as a swizzle.
#[inline(always)]
fn permute(kz: u8, v: Vec3) -> Vec3 {
    match kz {
        0 => Vec3::new(v.y, v.z, v.x),
        1 => Vec3::new(v.z, v.x, v.y),
        _ => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_inside_misses_outside() {
        let (p0, p1, p2) = (
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        );
        let h = intersect_triangle(
            Vec3::new(0.2, 0.2, 1.0),
            -Vec3::Z,
            f32::INFINITY,
            p0,
            p1,
            p2,
        )
        .unwrap();
        assert!((h.0 - 1.0).abs() < 1e-6);
        let p = h.1[0] * p0 + h.1[1] * p1 + h.1[2] * p2;
        assert!((p - Vec3::new(0.2, 0.2, 0.0)).length() < 1e-6);
        assert!(intersect_triangle(
            Vec3::new(0.8, 0.8, 1.0),
            -Vec3::Z,
            f32::INFINITY,
            p0,
            p1,
            p2
        )
        .is_none());
        assert!(
            intersect_triangle(Vec3::new(0.2, 0.2, 1.0), Vec3::Z, f32::INFINITY, p0, p1, p2)
                .is_none()
        );
        assert!(intersect_triangle(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.5, p0, p1, p2).is_none());
    }

    #[test]
    fn degenerate_triangle_never_hits() {
        let (p0, p1, p2) = (Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        for d in [-Vec3::Z, Vec3::new(0.1, 0.0, -1.0), Vec3::Y] {
            assert!(
                intersect_triangle(Vec3::new(0.5, 0.0, 1.0), d, f32::INFINITY, p0, p1, p2)
                    .is_none()
            );
        }
    }

    /// The four-lane test against the scalar one, lane by lane, with rays
    /// through vertices and along edges (edge values exactly zero, decided
    /// in f64) as well as ordinary ones, for every largest-axis case.
    #[test]
    fn four_lanes_match_the_scalar_test() {
        let tris = [
            [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            [
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            [
                Vec3::new(0.0, 0.0, 1.0),
                Vec3::new(0.0, 1.0, 2.0),
                Vec3::new(1.0, 0.0, 0.5),
            ],
            [
                Vec3::new(-1.0, 0.5, 0.0),
                Vec3::new(0.5, -1.0, 1.0),
                Vec3::new(0.25, 0.25, -1.0),
            ],
        ];
        let pack = pack_triangles(&tris);
        let mut checked = 0;
        let mut hits = 0;
        for axis in 0..3 {
            for i in 0..=8 {
                for j in 0..=8 {
                    // Lattice points on the triangles' edges and corners.
                    let (a, b) = (i as f32 / 4.0 - 0.5, j as f32 / 4.0 - 0.5);
                    let (o, d) = match axis {
                        0 => (Vec3::new(a, b, 5.0), Vec3::new(0.01, -0.02, -1.0)),
                        1 => (Vec3::new(-5.0, a, b), Vec3::new(1.0, 0.0, 0.0)),
                        _ => (Vec3::new(a, 5.0, b), Vec3::new(-0.0, -1.0, 0.0)),
                    };
                    let d = if i % 3 == 0 {
                        Vec3::new(0.0, 0.0, -1.0)
                    } else {
                        d
                    };
                    let r4 = TriangleRay4::new(o, d);
                    for lanes in [0b1111u32, 0b0101, 0b0010] {
                        for t_max in [f32::INFINITY, 5.0] {
                            let got = match r4.kz() {
                                0 => r4.intersect4::<0>(&pack, t_max, lanes),
                                1 => r4.intersect4::<1>(&pack, t_max, lanes),
                                _ => r4.intersect4::<2>(&pack, t_max, lanes),
                            };
                            let mut want: Option<(u32, f32, [f32; 3])> = None;
                            for (l, t) in tris.iter().enumerate() {
                                if lanes & (1 << l) == 0 {
                                    continue;
                                }
                                if let Some((th, b)) =
                                    intersect_triangle(o, d, t_max, t[0], t[1], t[2])
                                {
                                    if want.is_none_or(|(_, bt, _)| th < bt) {
                                        want = Some((l as u32, th, b));
                                    }
                                }
                            }
                            assert_eq!(got, want, "o {o:?} d {d:?} lanes {lanes:b} t_max {t_max}");
                            let any = match r4.kz() {
                                0 => r4.any4::<0>(&pack, t_max, lanes),
                                1 => r4.any4::<1>(&pack, t_max, lanes),
                                _ => r4.any4::<2>(&pack, t_max, lanes),
                            };
                            assert_eq!(any, want.is_some());
                            checked += 1;
                            hits += want.is_some() as u32;
                        }
                    }
                }
            }
        }
        assert!(checked > 1000 && hits > 100, "{checked} cases, {hits} hits");
    }

    /// Rays aimed at random points of shared edges: some edge values round
    /// to exactly zero in f32 and are decided in f64; the four-lane test must
    /// decide them as the scalar test does.
    #[test]
    fn four_lanes_match_the_scalar_test_on_shared_edges() {
        use crate::sampling::rng::Pcg32;
        let (a, b) = (Vec3::new(0.1, 0.2, 0.05), Vec3::new(0.7, 0.9, 0.3));
        let tris = [
            [a, b, Vec3::new(0.9, 0.1, 0.2)],
            [b, a, Vec3::new(0.0, 0.8, 0.1)],
            [a, Vec3::new(0.3, -0.4, 0.0), Vec3::new(0.9, 0.1, 0.2)],
            [Vec3::new(0.0, 0.8, 0.1), Vec3::new(-0.5, 0.5, 0.2), a],
        ];
        let pack = pack_triangles(&tris);
        let mut rng = Pcg32::with_sequence(5);
        for _ in 0..200_000 {
            let s = rng.uniform_f32();
            let p = a + s * (b - a);
            let d = Vec3::new(
                (rng.uniform_f32() - 0.5) * 0.2,
                (rng.uniform_f32() - 0.5) * 0.2,
                -1.0,
            );
            let o = p - 2.0 * d;
            let r4 = TriangleRay4::new(o, d);
            let got = match r4.kz() {
                0 => r4.intersect4::<0>(&pack, f32::INFINITY, 0b1111),
                1 => r4.intersect4::<1>(&pack, f32::INFINITY, 0b1111),
                _ => r4.intersect4::<2>(&pack, f32::INFINITY, 0b1111),
            };
            let mut want: Option<(u32, f32, [f32; 3])> = None;
            for (l, t) in tris.iter().enumerate() {
                if let Some((th, bc)) = intersect_triangle(o, d, f32::INFINITY, t[0], t[1], t[2]) {
                    if want.is_none_or(|(_, bt, _)| th < bt) {
                        want = Some((l as u32, th, bc));
                    }
                }
            }
            assert_eq!(got, want, "o {o:?} d {d:?}");
        }
    }
}
