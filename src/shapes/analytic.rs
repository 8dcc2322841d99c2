//! The analytic shapes (pbrt-v3's quadrics, and curve pieces): the shapes
//! the render core intersects by their equations rather than as triangles.
//! Each kind answers [`Analytic`] in its own file; [`AnalyticShape`] is
//! their closed set as one enum that only delegates (a `match`, inlined: no
//! dynamic dispatch per ray). The BVH holds them as non-triangle
//! primitives, traced by callback, and area lights sit on them (not on
//! curves, which pbrt-v3 cannot sample). [`Placement`] is where one sits in
//! world space, written once for every kind.

use super::curve::CurveHit;
use super::{DiffGeom, ShapeSample, SurfacePoint};
use crate::geometry::efloat::EFloat;
use crate::geometry::{gamma, offset_ray_origin, Bounds3};
use glam::{DMat3, DMat4, DVec3, Mat4, Vec2, Vec3};

/// What every analytic shape answers, each in its own file;
/// [`AnalyticShape`] only delegates. The defaults are pbrt-v3's for shapes
/// sampled by area alone.
pub trait Analytic: Sized {
    /// The same shape placed by `to_world` (from its object space), with
    /// the orientation flag and material of its `Shape` statement.
    fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> Self;
    /// False for shapes left out of the scene (singular transforms, no area).
    fn is_valid(&self) -> bool;
    /// World area.
    fn area(&self) -> f32;
    /// World bounds.
    fn bounds(&self) -> Bounds3;
    /// Closest hit with 0 < t < t_max: t and the object-space hit.
    fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)>;
    /// The world point, error bound and oriented normal of a hit.
    fn surface_point(&self, h: AnalyticHit) -> SurfacePoint;
    /// The world differential geometry of a hit.
    fn diff_geom(&self, h: AnalyticHit) -> DiffGeom;
    /// Density by world area of the shape's area sampling at an object
    /// point (NaN for the shapes not sampled by area alone).
    fn area_density(&self, _p_obj: DVec3) -> f32 {
        f32::NAN
    }
    /// A point sampled by area (`None`: never a light).
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample>;
    /// A point sampled as seen from a reference point; density by solid angle.
    #[inline]
    fn sample_from(&self, p: Vec3, _p_error: Vec3, _n: Vec3, u: Vec2) -> Option<ShapeSample> {
        super::to_solid_angle(p, self.sample_area(u)?)
    }
    /// pbrt-v3's `Shape::Pdf(ref, wi)`: the area density at the first hit
    /// of the ray spawned along `wi`, by solid angle.
    #[inline]
    fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        let o = offset_ray_origin(p, p_error, n, wi);
        match self.intersect(o, wi, f32::INFINITY) {
            Some((_, h)) => {
                let density = self.area_density(h.point_and_error().0);
                solid_angle_pdf(p, &self.surface_point(h), wi, density)
            }
            None => 0.0,
        }
    }
}

macro_rules! analytic_shapes {
    (
        $d:tt
        // The quadrics: boxed, each with a [`Placed`] header.
        boxed { $($(#[$bdoc:meta])* $bvariant:ident = $bkind:ident,)* }
        $($(#[$doc:meta])* $variant:ident = $kind:ident,)*
    ) => {
        /// The quadrics are boxed (each holds its transforms, several
        /// hundred bytes), so that the array of primitives stays small: a
        /// scene of 10,000 curves has 80,000 pieces of a few words each,
        /// which would otherwise each take a quadric's size (672 bytes) and
        /// spread the BVH's leaf tests over 54 MB.
        #[derive(Clone, Debug)]
        pub enum AnalyticShape {
            $($(#[$bdoc])* $bvariant(Box<super::$bkind::$bvariant>),)*
            $($(#[$doc])* $variant(super::$kind::$variant),)*
        }

        $(impl From<super::$bkind::$bvariant> for AnalyticShape {
            fn from(s: super::$bkind::$bvariant) -> AnalyticShape {
                AnalyticShape::$bvariant(Box::new(s))
            }
        })*
        $(impl From<super::$kind::$variant> for AnalyticShape {
            fn from(s: super::$kind::$variant) -> AnalyticShape {
                AnalyticShape::$variant(s)
            }
        })*

        /// Every method of [`Analytic`], delegated by `match`.
        /// `$e` for the shape `$s` of any variant of `$self`.
        macro_rules! each {
            ($d self:ident, $d s:ident => $d e:expr) => {
                match $d self {
                    $(AnalyticShape::$bvariant($d s) => $d e,)*
                    $(AnalyticShape::$variant($d s) => $d e,)*
                }
            };
        }

        impl AnalyticShape {
            /// Its `Shape` statement's material (the quadrics hold it in
            /// their [`Placed`], the curve pieces in the piece).
            #[inline]
            pub fn material(&self) -> u32 {
                match self {
                    $(AnalyticShape::$bvariant(s) => s.at.material,)*
                    $(AnalyticShape::$variant(s) => s.material,)*
                }
            }
            /// Its area light, if it emits.
            #[inline]
            pub fn light(&self) -> Option<u32> {
                match self {
                    $(AnalyticShape::$bvariant(s) => s.at.light,)*
                    $(AnalyticShape::$variant(s) => s.light,)*
                }
            }
            pub fn set_light(&mut self, light: Option<u32>) {
                match self {
                    $(AnalyticShape::$bvariant(s) => s.at.light = light,)*
                    $(AnalyticShape::$variant(s) => s.light = light,)*
                }
            }
            /// The name of its kind in [`SHAPES`](super::SHAPES).
            pub fn kind_name(&self) -> &'static str {
                match self {
                    $(AnalyticShape::$bvariant(_) => super::$bkind::KIND.name,)*
                    $(AnalyticShape::$variant(_) => super::$kind::KIND.name,)*
                }
            }
        }
    };
}

analytic_shapes! {
    $
    boxed {
        Sphere = sphere,
        Disk = disk,
        Cylinder = cylinder,
        Cone = cone,
        Paraboloid = paraboloid,
        Hyperboloid = hyperboloid,
    }
    /// A piece of a curve segment (never a light: pbrt-v3 cannot sample
    /// curves, and the scene leaves their emission out).
    Curve = curve,
}

impl AnalyticShape {
    /// The same shape placed by `to_world`, with the orientation flag and
    /// material of its `Shape` statement.
    pub fn placed(&self, to_world: DMat4, reverse: bool, material: u32) -> AnalyticShape {
        each!(self, s => AnalyticShape::from(s.placed(to_world, reverse, material)))
    }
    pub fn area(&self) -> f32 {
        each!(self, s => s.area())
    }
    pub fn bounds(&self) -> Bounds3 {
        each!(self, s => s.bounds())
    }
    /// False for shapes left out of the scene (singular transforms, no area).
    pub fn is_valid(&self) -> bool {
        each!(self, s => s.is_valid())
    }
    /// Closest hit with 0 < t < t_max: t and the object-space point.
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, AnalyticHit)> {
        each!(self, s => s.intersect(o, d, t_max))
    }
    #[inline]
    pub fn surface_point(&self, h: AnalyticHit) -> SurfacePoint {
        each!(self, s => s.surface_point(h))
    }
    #[inline]
    pub fn diff_geom(&self, h: AnalyticHit) -> DiffGeom {
        each!(self, s => s.diff_geom(h))
    }
    /// Density by world area of the shape's area sampling at an object
    /// point (the shapes sampled by area alone; not spheres or disks).
    pub fn area_density(&self, p_obj: DVec3) -> f32 {
        each!(self, s => s.area_density(p_obj))
    }
    /// A point sampled uniformly by area (density by area; `None` for
    /// shapes that cannot be sampled, curves).
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        each!(self, s => s.sample_area(u))
    }
    /// A point sampled as seen from a reference point; density by solid
    /// angle.
    #[inline]
    pub fn sample_from(&self, p: Vec3, p_error: Vec3, n: Vec3, u: Vec2) -> Option<ShapeSample> {
        each!(self, s => s.sample_from(p, p_error, n, u))
    }
    /// Density by solid angle of `sample_from` producing direction `wi`:
    /// pbrt-v3's `Shape::Pdf(ref, wi)`.
    #[inline]
    pub fn pdf_from(&self, p: Vec3, p_error: Vec3, n: Vec3, wi: Vec3) -> f32 {
        each!(self, s => s.pdf_from(p, p_error, n, wi))
    }
}

/// A hit on an analytic shape in its object space: a point computed in f64 (its
/// error is the shape's to bound), or pbrt-v3's f32 point with its running
/// error bound.
#[derive(Clone, Copy, Debug)]
pub enum AnalyticHit {
    Exact(DVec3),
    Bounded {
        p: Vec3,
        err: Vec3,
    },
    /// A curve piece's hit (its dp/dv depends on the ray).
    Curve(CurveHit),
}

impl AnalyticHit {
    #[inline]
    pub fn point_and_error(self) -> (DVec3, DVec3) {
        match self {
            AnalyticHit::Exact(p) => (p, DVec3::ZERO),
            AnalyticHit::Bounded { p, err } => (p.as_dvec3(), err.as_dvec3()),
            AnalyticHit::Curve(h) => (h.p.as_dvec3(), DVec3::splat(h.err as f64)),
        }
    }
}

/// What every quadric holds besides its own surface: the parameters its
/// kind built it from (so that it can be placed again), where it sits, and
/// its `Shape` statement's material and area light.
#[derive(Clone, Debug)]
pub struct Placed<A> {
    pub args: A,
    pub place: Placement,
    pub material: u32,
    pub light: Option<u32>,
}

impl<A: Copy> Placed<A> {
    /// `args` placed by `object_to_world`, with the orientation flag and
    /// material of a `Shape` statement.
    pub fn new(args: A, object_to_world: DMat4, reverse: bool, material: u32) -> Placed<A> {
        Placed {
            args,
            place: Placement::new(object_to_world, reverse),
            material,
            light: None,
        }
    }

    /// `args` in their object space: what a kind's builder makes.
    pub fn origin(args: A) -> Placed<A> {
        Placed::new(args, DMat4::IDENTITY, false, 0)
    }

    /// The same parameters placed again (see [`Placed::new`]).
    pub fn again(&self, to_world: DMat4, reverse: bool, material: u32) -> Placed<A> {
        Placed::new(self.args, to_world, reverse, material)
    }
}

/// Where an analytic shape sits: its object-to-world transform and what the
/// ray tests, normals, bounds and densities derive from it (the inverse,
/// the normal matrix, the Jacobian, pbrt-v3's normal flip), computed once
/// for every kind.
#[derive(Clone, Debug)]
pub struct Placement {
    pub object_to_world: DMat4,
    pub world_to_object: DMat4,
    /// Both rounded to f32, for pbrt-v3's f32 transforms.
    pub world_to_object_f32: Mat4,
    object_to_world_f32: Mat4,
    /// The linear part, and its inverse transpose (for normals).
    pub lin: DMat3,
    pub normal_matrix: DMat3,
    /// |det| of the linear part.
    pub det_abs: f64,
    /// ReverseOrientation xor a handedness-swapping transform (pbrt-v3's
    /// normal flip).
    pub flip_normal: bool,
}

impl Placement {
    pub fn new(object_to_world: DMat4, reverse: bool) -> Placement {
        let lin = DMat3::from_mat4(object_to_world);
        let det = lin.determinant();
        Placement {
            object_to_world,
            world_to_object: object_to_world.inverse(),
            world_to_object_f32: object_to_world.inverse().as_mat4(),
            object_to_world_f32: object_to_world.as_mat4(),
            lin,
            normal_matrix: lin.inverse().transpose(),
            det_abs: det.abs(),
            flip_normal: reverse ^ (det < 0.0),
        }
    }

    pub fn is_valid(&self) -> bool {
        self.world_to_object.is_finite() && self.det_abs > 0.0 && self.det_abs.is_finite()
    }

    /// An invertible placement (finite inverse) of a shape of world area
    /// `area` > 0 and finite: what a shape needs to be in the scene.
    pub fn holds(&self, area: f32) -> bool {
        self.world_to_object.is_finite() && area > 0.0 && area.is_finite()
    }

    /// World bounds of the surface of revolution of `radius` about z over
    /// `z_min`..`z_max` (its object-space box).
    pub fn zone_bounds(&self, radius: f64, z_min: f64, z_max: f64) -> Bounds3 {
        let r = radius;
        self.bounds(DVec3::new(-r, -r, z_min), DVec3::new(r, r, z_max))
    }

    /// The ray in object space, in f64.
    #[inline]
    pub fn ray_to_object(&self, o: Vec3, d: Vec3) -> (DVec3, DVec3) {
        (
            self.world_to_object.transform_point3(o.as_dvec3()),
            self.world_to_object.transform_vector3(d.as_dvec3()),
        )
    }

    /// World bounds of an object-space box, padded by a few f32 ulps so the
    /// rounded corners stay conservative.
    pub fn bounds(&self, lo: DVec3, hi: DVec3) -> Bounds3 {
        let mut b = Bounds3::EMPTY;
        for i in 0..8 {
            let c = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            b = b.union_point(self.object_to_world.transform_point3(c).as_vec3());
        }
        let pad = (b.max.abs().max(b.min.abs())) * 4.0 * f32::EPSILON;
        Bounds3 {
            min: b.min - pad,
            max: b.max + pad,
        }
    }

    /// The world point with its error bound and the oriented unit normal of
    /// `n_obj`, as pbrt-v3 transforms a `SurfaceInteraction`: the point in f32
    /// in its operation order, the error (γ₃ + 1)·|M|·`obj_err` +
    /// γ₃·(|M||p| + |t|).
    pub fn surface_point(&self, p_obj: DVec3, n_obj: DVec3, obj_err: DVec3) -> SurfacePoint {
        let c = self.object_to_world_f32.to_cols_array_2d();
        let (p, e) = (p_obj.as_vec3(), obj_err.as_vec3());
        let g3 = gamma(3);
        let mut pw = [0.0f32; 3];
        let mut ew = [0.0f32; 3];
        for i in 0..3 {
            let (m0, m1, m2, m3) = (c[0][i], c[1][i], c[2][i], c[3][i]);
            pw[i] = (m0 * p.x + m1 * p.y) + (m2 * p.z + m3);
            ew[i] = (g3 + 1.0) * (m0.abs() * e.x + m1.abs() * e.y + m2.abs() * e.z)
                + g3 * ((m0 * p.x).abs() + (m1 * p.y).abs() + (m2 * p.z).abs() + m3.abs());
        }
        let w = (c[0][3] * p.x + c[1][3] * p.y) + (c[2][3] * p.z + c[3][3]);
        let mut pw = Vec3::from(pw);
        if w != 1.0 {
            pw /= w;
        }
        let n = self.normal(n_obj);
        SurfacePoint {
            p: pw,
            p_error: Vec3::from(ew),
            n,
            ns: n,
        }
    }

    /// The oriented world unit normal of the object normal `n_obj` (any
    /// length).
    #[inline]
    pub fn normal(&self, n_obj: DVec3) -> Vec3 {
        let mut n = (self.normal_matrix * n_obj).normalize().as_vec3();
        if self.flip_normal {
            n = -n;
        }
        n
    }

    /// The world point of an object point computed in f64 (the shapes that
    /// intersect in f64), with its error bound: the object-space error
    /// `obj_err` (none: the point is exact) carried through the transform,
    /// plus the transform's rounding γ₃·(|M||p| + |t|) and the final
    /// rounding to f32; `n` is the oriented world normal.
    #[inline(always)]
    pub fn exact_point(&self, p_obj: DVec3, obj_err: Option<DVec3>, n: Vec3) -> SurfacePoint {
        let p = self.object_to_world.transform_point3(p_obj).as_vec3();
        let lin = self.lin;
        let abs_lin = DMat3::from_cols(lin.x_axis.abs(), lin.y_axis.abs(), lin.z_axis.abs());
        let rounding = (abs_lin * p_obj.abs() + self.object_to_world.w_axis.truncate().abs())
            * gamma(3) as f64;
        let err = match obj_err {
            Some(e) => abs_lin * e + rounding,
            None => rounding,
        };
        SurfacePoint {
            p,
            p_error: err.as_vec3() + p.abs() * f32::EPSILON,
            n,
            ns: n,
        }
    }

    /// The world differential geometry of an object-space parametrisation
    /// at a hit: dp/du, dp/dv and the second derivatives (dn/du, dn/dv by
    /// pbrt-v3's Weingarten equations); the shading frame is the same.
    pub fn diff_geom(&self, uv: (f64, f64), dpdu: DVec3, dpdv: DVec3, d2: [DVec3; 3]) -> DiffGeom {
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2[0], d2[1], d2[2]);
        let (dpdu, dpdv) = (self.vector(dpdu), self.vector(dpdv));
        let (dndu, dndv) = (self.normal_derivative(dndu), self.normal_derivative(dndv));
        DiffGeom {
            uv: Vec2::new(uv.0 as f32, uv.1 as f32),
            dpdu,
            dpdv,
            dndu,
            dndv,
            shading_dpdu: dpdu,
            shading_dpdv: dpdv,
            shading_dndu: dndu,
            shading_dndv: dndv,
            ..DiffGeom::ZERO
        }
    }

    /// A tangent vector in world space.
    #[inline]
    pub fn vector(&self, v: DVec3) -> Vec3 {
        (self.lin * v).as_vec3()
    }

    /// A normal derivative in world space (pbrt-v3 transforms dn/du and
    /// dn/dv as normals); zero if not finite.
    #[inline]
    pub fn normal_derivative(&self, n: DVec3) -> Vec3 {
        let v = (self.normal_matrix * n).as_vec3();
        if v.is_finite() {
            v
        } else {
            Vec3::ZERO
        }
    }

    /// dA_world / dA_obj at a point whose object normal is `n_obj` (any
    /// length): |det M| · |M^-T n̂|.
    #[inline]
    pub fn area_scale(&self, n_obj: DVec3) -> f64 {
        if n_obj.length_squared() > 0.0 {
            self.det_abs * (self.normal_matrix * n_obj.normalize()).length()
        } else {
            // An apex, where the normal is undefined (measure zero).
            self.det_abs.powf(2.0 / 3.0)
        }
    }

    /// The world area of an object area: exact for similarities, a
    /// volume-based estimate otherwise (only the power light distribution
    /// reads it then; every density is exact).
    pub fn world_area(&self, obj_area: f64) -> f32 {
        (obj_area * self.det_abs.powf(2.0 / 3.0)) as f32
    }
}

/// pbrt-v3's choice of root for its f32 quadrics: t0 unless its interval
/// reaches 0, then t1; the first candidate `clipped` rejects is replaced by
/// t1 once. Returns t, the f32 point o + t·d and its running error bound.
#[inline]
pub fn pbrt_closest(
    roots: (EFloat, EFloat),
    o: [EFloat; 3],
    d: [EFloat; 3],
    t_max: f32,
    clipped: impl Fn(Vec3) -> bool,
) -> Option<(f32, Vec3, Vec3)> {
    let (t0, t1) = roots;
    if t0.high > t_max || t1.low <= 0.0 {
        return None;
    }
    let mut t = t0;
    if t.low <= 0.0 {
        t = t1;
        if t.high > t_max {
            return None;
        }
    }
    let at = |t: EFloat| {
        Vec3::new(
            o[0].v + d[0].v * t.v,
            o[1].v + d[1].v * t.v,
            o[2].v + d[2].v * t.v,
        )
    };
    let mut p = at(t);
    if clipped(p) {
        if t.v == t1.v {
            return None;
        }
        t = t1;
        if t1.high > t_max {
            return None;
        }
        p = at(t);
        if clipped(p) {
            return None;
        }
    }
    let err = Vec3::new(
        (o[0] + t * d[0]).abs_error(),
        (o[1] + t * d[1]).abs_error(),
        (o[2] + t * d[2]).abs_error(),
    );
    Some((t.v, p, err))
}

/// φ of an f32 object point in [0, 2π), as pbrt-v3 computes it.
#[inline]
pub fn phi_f32(p: Vec3) -> f32 {
    let phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi + std::f32::consts::TAU
    } else {
        phi
    }
}

/// φ of an object point in [0, 2π).
#[inline]
pub fn phi_of(p: DVec3) -> f64 {
    let phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi + std::f64::consts::TAU
    } else {
        phi
    }
}

/// pbrt-v3's Weingarten equations: dn/du and dn/dv from the first and
/// second fundamental forms (object space).
fn weingarten(dpdu: DVec3, dpdv: DVec3, d2uu: DVec3, d2uv: DVec3, d2vv: DVec3) -> (DVec3, DVec3) {
    let (e1, f1, g1) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let n = dpdu.cross(dpdv).normalize();
    let (e2, f2, g2) = (n.dot(d2uu), n.dot(d2uv), n.dot(d2vv));
    let inv = 1.0 / (e1 * g1 - f1 * f1);
    let dndu = (f2 * f1 - e2 * g1) * inv * dpdu + (e2 * f1 - f2 * e1) * inv * dpdv;
    let dndv = (g2 * f1 - f2 * g1) * inv * dpdu + (f2 * f1 - g2 * e1) * inv * dpdv;
    (dndu, dndv)
}

/// pbrt-v3's `Shape::Pdf(ref, wi)` for an area density at the surface point
/// `h` the ray from `p` along `wi` hits: the solid-angle density.
#[inline]
fn solid_angle_pdf(p: Vec3, h: &SurfacePoint, wi: Vec3, area_density: f32) -> f32 {
    let pdf = area_density * h.p.distance_squared(p) / h.n.dot(wi).abs();
    if pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}
