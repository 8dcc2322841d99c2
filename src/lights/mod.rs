//! Lights: one file per pbrt-v3 light type, each opening with its
//! parameters (names, types, pbrt-v3's defaults) and its `KIND`, and
//! holding the light's struct, its builder (with pbrt-v3's checks of the
//! parameters) and its sampling code: [`point`], [`spot`], [`distant`],
//! [`infinite`] (`LightSource`), and [`diffuse`] (`AreaLightSource`: one
//! light per triangle, as pbrt-v3, or per analytic shape). Two tables,
//! [`LIGHTS`] and [`AREA_LIGHTS`], are what the loader (parsing and "did
//! you mean"), `--check`, `grammar/REFERENCE.md` and the tests read.
//!
//! [`Light`] is the closed set; it only delegates to the files (a `match`
//! per call, no dynamic dispatch). Also here: the light sample type and the
//! distributions that choose which light to sample.

pub mod bvh;
pub mod diffuse;
pub mod distant;
mod distribution;
pub mod env_batch;
pub mod goniometric;
pub mod infinite;
mod infinite_lanes;
mod pack;
pub mod point;
pub mod projection;
pub mod spot;

pub use diffuse::{AreaShape, DiffuseEmission, DiffuseLight, TriangleCache};
pub use distant::DistantLight;
pub use distribution::{LightSampler, LightSamplerKind, SPATIAL_MAX_LIGHTS};
pub use env_batch::SAMPLE_EACH_MAX;
pub use goniometric::GoniometricLight;
pub use infinite::{EnvMap, EnvSample, EnvSampling, InfiniteLight};
pub use pack::{dot3, lane3, pack_triangle_lights, splat3, TriangleLightPack, Vec3x4};
pub use point::PointLight;
pub use projection::ProjectionLight;
pub use spot::SpotLight;

use crate::accel::Aggregate;
use crate::geometry::{luminance, Ray};
use crate::scene::{Kind, ParamValues, Report};
use crate::shapes::SurfacePoint;
use bvh::LightBounds;
use glam::{DMat4, Vec2, Vec3};
use std::f32::consts::PI;

/// What a `LightSource` kind builds from its parameters and the CTM
/// (light-to-world); `None` when pbrt-v3's checks refuse the light (the
/// builder has said why).
pub type LightBuild = fn(&ParamValues, DMat4, &mut dyn Report) -> Option<Light>;

/// One `LightSource` type: its pbrt-v3 name, its parameters, its builder.
pub type LightKind = Kind<LightBuild>;

/// Every light type pbrt-v3's `MakeLight` knows, in its order.
pub static LIGHTS: &[LightKind] = &[
    point::KIND,
    spot::KIND,
    goniometric::KIND,
    projection::KIND,
    distant::KIND,
    infinite::KIND,
];

/// What an `AreaLightSource` kind builds from its parameters: the emission
/// of the shapes that follow it (each shape's light is made from it when
/// the scene is built, [`DiffuseLight::new`]).
pub type AreaLightBuild = fn(&ParamValues, &mut dyn Report) -> DiffuseEmission;

/// One `AreaLightSource` type.
pub type AreaLightKind = Kind<AreaLightBuild>;

/// Every area light type pbrt-v3's `MakeAreaLight` knows.
pub static AREA_LIGHTS: &[AreaLightKind] = &[diffuse::KIND];

/// A light sample as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    pub li: Vec3,
    pub wi: Vec3,
    /// Solid-angle density (1 for delta lights).
    pub pdf: f32,
    /// The shadow ray to test; unoccluded means the light is seen.
    pub shadow: Ray,
}

/// A ray leaving a light, as pbrt-v3's `Sample_Le` samples it (photon
/// emission for `sppm`, light subpaths for bidirectional methods).
#[derive(Clone, Copy, Debug)]
pub struct EmittedRay {
    /// Emitted radiance along the ray (area and infinite lights; the
    /// distant light's radiance) or intensity (point-like lights).
    pub le: Vec3,
    pub ray: Ray,
    /// The normal at the ray's origin (the ray's direction where the light
    /// has no surface).
    pub n: Vec3,
    /// Density of the origin by area (1 for a point).
    pub pdf_pos: f32,
    /// Density of the direction by solid angle (1 for a distant light).
    pub pdf_dir: f32,
}

/// What every light type does (pbrt-v3's `Light` interface). The defaults
/// are those of a light that rays cannot hit and that is not at infinity.
pub trait LightModel {
    /// A delta light (a point or a direction) cannot be hit by rays: no
    /// BSDF sample for it in MIS.
    fn is_delta(&self) -> bool;

    /// Seen by rays that escape the scene ([`LightModel::le`]).
    fn is_infinite(&self) -> bool {
        false
    }

    /// At infinity (distant and infinite lights): no bounds in the light
    /// BVH, chosen apart from it.
    fn at_infinity(&self) -> bool {
        false
    }

    /// Shadow samples a `directlighting` "all" estimate takes.
    fn n_samples(&self) -> u32 {
        1
    }

    /// The sample count `--quick` divides, for lights that have one.
    fn n_samples_mut(&mut self) -> Option<&mut u32> {
        None
    }

    /// Emitted power (pbrt-v3's `Power()`), as RGB.
    fn power(&self) -> Vec3;

    /// Emitted radiance of an area light at a point with normal `n`,
    /// towards `w`.
    #[inline]
    fn emitted(&self, _n: Vec3, _w: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    /// Radiance arriving along an escaping ray of direction `d` (pbrt-v3's
    /// `Le`).
    #[inline]
    fn le(&self, _d: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    /// luminance(Li)/pdf at `p` for one sample (not yet made finite and
    /// non-negative): the spatial light distribution's estimate.
    fn contribution(&self, p: Vec3, u: Vec2, geom: &Aggregate) -> f32 {
        contribution_by_sampling(self, p, u, geom)
    }

    /// Sample incident light at `r` (pbrt-v3's `Sample_Li`). Visibility is
    /// not tested here: the caller traces `shadow`.
    fn sample_li(&self, r: &SurfacePoint, u: Vec2, geom: &Aggregate) -> Option<LightSample>;

    /// A ray leaving the light from `u1` (its origin) and `u2` (its
    /// direction), pbrt-v3's `Sample_Le`; `None` when nothing is emitted or
    /// a density is 0. Every light kind has its own.
    fn sample_le(&self, u1: Vec2, u2: Vec2, geom: &Aggregate) -> Option<EmittedRay>;

    /// Densities of `sample_le` producing a ray leaving the light in
    /// direction `d` from a point with normal `n` (pbrt-v3's `Pdf_Le`):
    /// (by area of the origin, by solid angle of the direction). Every
    /// light kind has its own.
    fn pdf_le(&self, d: Vec3, n: Vec3) -> (f32, f32);

    /// Solid-angle density of `sample_li` producing direction `wi` from `r`
    /// (pbrt-v3's `Pdf_Li`); 0 when `wi` cannot come from this light.
    #[inline]
    fn pdf_li(&self, _r: &SurfacePoint, _wi: Vec3, _geom: &Aggregate) -> f32 {
        0.0
    }

    /// `pdf_li` for the direction of `ray`, the ray spawned from `r` in
    /// that direction.
    #[inline]
    fn pdf_li_ray(&self, _r: &SurfacePoint, _ray: &Ray, _geom: &Aggregate) -> f32 {
        0.0
    }

    /// Bounds for the light BVH (pbrt-v4's `Bounds()`); `None` for lights
    /// at infinity.
    fn bounds(&self, _geom: &Aggregate) -> Option<LightBounds> {
        None
    }

    /// What the light needs of the built scene (pbrt-v3's `Preprocess`:
    /// the scene's bounding radius for distant and infinite lights).
    fn preprocess(&mut self, _geom: &Aggregate) {}
}

/// A ray coming from direction `w` (unit, towards the light) into the
/// scene: its origin uniform (from `u`) on the disk of radius `radius`
/// (the scene's bounding radius) around the scene's centre, perpendicular
/// to `w`, moved out by `radius` along `w`, and its density by area
/// (pbrt-v3's distant and infinite `Sample_Le`). `None` for an empty scene.
pub(crate) fn disk_ray(geom: &Aggregate, radius: f32, w: Vec3, u: Vec2) -> Option<(Ray, f32)> {
    if radius <= 0.0 || radius.is_nan() {
        return None;
    }
    let center = geom.bounds.bounding_sphere().0;
    let f = crate::geometry::Frame::from_normal(w);
    let cd = crate::sampling::concentric_sample_disk(u);
    let p_disk = center + radius * (cd.x * f.s + cd.y * f.t);
    Some((
        Ray::new(p_disk + radius * w, -w),
        1.0 / (PI * radius * radius),
    ))
}

/// pbrt-v3's `Sample_Li` of a light at the point `p` (point, spot,
/// goniometric and projection lights): the direction to it with density
/// 1, and `towards(w)`, the light's intensity in the direction `w` leaving
/// it, over the squared distance.
#[inline]
pub(super) fn sample_at_point(
    p: Vec3,
    r: &SurfacePoint,
    towards: impl FnOnce(Vec3) -> Vec3,
) -> Option<LightSample> {
    let d = p - r.p;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let wi = d / d2.sqrt();
    Some(LightSample {
        li: towards(-wi) / d2,
        wi,
        pdf: 1.0,
        shadow: crate::geometry::spawn_ray_to_point(r.p, r.p_error, r.n, p),
    })
}

/// [`LightModel::contribution`] by one `sample_li` from a point with no
/// normal and no error bounds (pbrt-v3 also ignores visibility here).
#[inline(never)]
pub fn contribution_by_sampling<L: LightModel + ?Sized>(
    light: &L,
    p: Vec3,
    u: Vec2,
    geom: &Aggregate,
) -> f32 {
    let r = SurfacePoint {
        p,
        p_error: Vec3::ZERO,
        n: Vec3::ZERO,
        ns: Vec3::ZERO,
    };
    match light.sample_li(&r, u, geom) {
        Some(s) if s.pdf > 0.0 => luminance(s.li) / s.pdf,
        _ => 0.0,
    }
}

/// The closed set of lights: each variant is one file's struct, and every
/// method matches and delegates.
macro_rules! lights {
    ($($(#[$doc:meta])* $variant:ident($ty:ty) = $kind:expr,)*) => {
        #[derive(Clone, Debug)]
        pub enum Light {
            $($(#[$doc])* $variant($ty),)*
        }
        $(impl From<$ty> for Light {
            fn from(l: $ty) -> Light {
                Light::$variant(l)
            }
        })*
        impl Light {
            /// The name of its kind in the table.
            pub fn name(&self) -> &'static str {
                match self { $(Light::$variant(_) => $kind.name,)* }
            }
            #[inline]
            pub fn is_delta(&self) -> bool {
                match self { $(Light::$variant(l) => l.is_delta(),)* }
            }
            pub fn is_infinite(&self) -> bool {
                match self { $(Light::$variant(l) => l.is_infinite(),)* }
            }
            pub fn at_infinity(&self) -> bool {
                match self { $(Light::$variant(l) => l.at_infinity(),)* }
            }
            pub fn n_samples(&self) -> u32 {
                match self { $(Light::$variant(l) => l.n_samples(),)* }
            }
            pub fn n_samples_mut(&mut self) -> Option<&mut u32> {
                match self { $(Light::$variant(l) => l.n_samples_mut(),)* }
            }
            /// Luminance of the emitted power (pbrt-v3's `Power().y()`), ≥ 0.
            pub fn power(&self) -> f32 {
                luminance(match self { $(Light::$variant(l) => l.power(),)* }).max(0.0)
            }
            #[inline]
            pub fn emitted(&self, n: Vec3, w: Vec3) -> Vec3 {
                match self { $(Light::$variant(l) => l.emitted(n, w),)* }
            }
            #[inline]
            pub fn le(&self, d: Vec3) -> Vec3 {
                match self { $(Light::$variant(l) => l.le(d),)* }
            }
            /// A cheap estimate of luminance(Li)/pdf at a point in space,
            /// for the spatial light distribution: finite and ≥ 0.
            pub fn contribution_estimate(&self, p: Vec3, u: Vec2, geom: &Aggregate) -> f32 {
                let c = match self { $(Light::$variant(l) => l.contribution(p, u, geom),)* };
                if c.is_finite() {
                    c.max(0.0)
                } else {
                    0.0
                }
            }
            #[inline]
            pub fn sample_li(&self, r: &SurfacePoint, u: Vec2, geom: &Aggregate) -> Option<LightSample> {
                match self { $(Light::$variant(l) => l.sample_li(r, u, geom),)* }
            }
            /// See [`LightModel::sample_le`].
            #[inline]
            pub fn sample_le(&self, u1: Vec2, u2: Vec2, geom: &Aggregate) -> Option<EmittedRay> {
                match self { $(Light::$variant(l) => l.sample_le(u1, u2, geom),)* }
            }
            /// See [`LightModel::pdf_le`].
            #[inline]
            pub fn pdf_le(&self, d: Vec3, n: Vec3) -> (f32, f32) {
                match self { $(Light::$variant(l) => l.pdf_le(d, n),)* }
            }
            #[inline]
            pub fn pdf_li(&self, r: &SurfacePoint, wi: Vec3, geom: &Aggregate) -> f32 {
                match self { $(Light::$variant(l) => l.pdf_li(r, wi, geom),)* }
            }
            #[inline]
            pub fn pdf_li_ray(&self, r: &SurfacePoint, ray: &Ray, geom: &Aggregate) -> f32 {
                match self { $(Light::$variant(l) => l.pdf_li_ray(r, ray, geom),)* }
            }
            pub fn bounds(&self, geom: &Aggregate) -> Option<LightBounds> {
                match self { $(Light::$variant(l) => l.bounds(geom),)* }
            }
            pub fn preprocess(&mut self, geom: &Aggregate) {
                match self { $(Light::$variant(l) => l.preprocess(geom),)* }
            }
        }
    };
}

lights! {
    /// An area light on one triangle or analytic shape.
    Diffuse(DiffuseLight) = diffuse::KIND,
    Point(PointLight) = point::KIND,
    Spot(SpotLight) = spot::KIND,
    Goniometric(GoniometricLight) = goniometric::KIND,
    Projection(ProjectionLight) = projection::KIND,
    Distant(DistantLight) = distant::KIND,
    Infinite(InfiniteLight) = infinite::KIND,
}
