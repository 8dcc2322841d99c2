//! `goniometric`: a point light whose intensity over directions is an
//! image (pbrt-v3's `GonioPhotometricLight`, lights/goniometric.h).
//!
//! | parameter | type | pbrt-v3 default | |
//! |---|---|---|---|
//! | `I` | spectrum | 1 | radiant intensity |
//! | `scale` | spectrum or float | 1 | multiplies `I` (pbrt-v3 reads a spectrum; pbrs also takes a float) |
//! | `mapname` | string (image file) | none: 1 in every direction | the goniometric diagram, a lat-long image |
//!
//! Light-to-world is the CTM; the light sits at its origin. The map's axes
//! are pbrt-v3's: a world direction is taken to light space and its y and z
//! swapped, so the light's +y is the map's pole: the top row (t = 0) is
//! θ = 0 along light-space +y, and φ = atan2(z, x) in light space (from +x
//! towards +z) runs along s from 0 to 2π. The image
//! is read as pbrt-v3's `ReadImage` returns it (8-bit files decoded from
//! sRGB), not flipped, and looked up bilinearly at its finest level of a
//! MIP map made as pbrt-v3 makes one (sides resampled up to powers of two,
//! wrap mode repeat). Power, for light selection: 4π·I times the map's
//! average (its MIP lookup at (½, ½) with width ½, as pbrt-v3).

use super::bvh::LightBounds;
use super::{sample_at_point, EmittedRay, LightKind, LightModel, LightSample};
use crate::accel::Aggregate;
use crate::geometry::{luminance, Bounds3, Ray};
use crate::sampling::{uniform_sample_sphere, uniform_sphere_pdf};
use crate::scene::{Decode, ParamSpec, ParamValues, Report, RgbImage, Support};
use crate::shapes::SurfacePoint;
use crate::textures::{MipMap, Wrap};
use glam::{DMat4, DVec3, Mat3, Vec2, Vec3};
use std::f32::consts::PI;
use std::fmt;
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::spectrum_any("I", [1.0; 3], "radiant intensity"),
    ParamSpec::spectrum_or_float(
        "scale",
        [1.0; 3],
        "multiplies I (a spectrum in pbrt-v3; pbrs also takes a float)",
    ),
    ParamSpec::image(
        "mapname",
        Decode::Raw,
        "goniometric diagram: lat-long image, pole along light-space +y (top row), none: 1 everywhere",
    ),
];

pub const KIND: LightKind = LightKind {
    name: "goniometric",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "a point light at the CTM's origin whose intensity I·scale is scaled over directions by a lat-long image (pbrt-v3's axes: the map's pole along light-space +y)",
    build: |p, ctm, report| GoniometricLight::new(p, ctm, report).map(Into::into),
};

/// An image as a light's directional scale: pbrt-v3's MIP map of the
/// image as `ReadImage` returns it (rows from the top), wrap mode repeat.
#[derive(Clone)]
pub struct LightMap {
    pub mip: Arc<MipMap<Vec3>>,
    pub width: u32,
    pub height: u32,
}

impl fmt::Debug for LightMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "LightMap({}×{})", self.width, self.height)
    }
}

impl LightMap {
    /// The map of `image`; `None` (after a warning at `mapname`) when it
    /// is too large for a MIP map.
    pub fn new(image: &RgbImage, report: &mut dyn Report) -> Option<LightMap> {
        let (w, h) = (image.width(), image.height());
        let mip = MipMap::new(
            w as usize,
            h as usize,
            image.pixels().to_vec(),
            false,
            8.0,
            Wrap::Repeat,
        );
        match mip {
            Some(mip) => Some(LightMap {
                mip: Arc::new(mip),
                width: w,
                height: h,
            }),
            None => {
                report.warn(
                    Some("mapname"),
                    format!(
                        "image ({w}×{h}) is too large for a MIP map: the light is not scaled by it"
                    ),
                    "image too large",
                );
                None
            }
        }
    }

    /// pbrt-v3's `Lookup(st)`: bilinear at the finest level.
    #[inline]
    pub fn at(&self, st: Vec2) -> Vec3 {
        self.mip.lookup_width(st, 0.0)
    }

    /// pbrt-v3's `Lookup((½, ½), ½)`, the average its `Power()` takes.
    pub fn average(&self) -> Vec3 {
        self.mip.lookup_width(Vec2::splat(0.5), 0.5)
    }
}

/// The light's frame from the CTM: the light's world position and the
/// world-to-light linear map; `None` (after a warning) when the CTM is not
/// invertible or not finite.
pub fn light_frame(ctm: DMat4, what: &str, report: &mut dyn Report) -> Option<(Vec3, Mat3)> {
    let inv = ctm.inverse();
    let p = ctm.transform_point3(DVec3::ZERO).as_vec3();
    let m = Mat3::from_cols(
        inv.x_axis.truncate().as_vec3(),
        inv.y_axis.truncate().as_vec3(),
        inv.z_axis.truncate().as_vec3(),
    );
    if !p.is_finite() || !m.is_finite() || ctm.determinant() == 0.0 {
        report.warn(
            None,
            format!("{what} light with a singular or non-finite transform: skipped"),
            "degenerate light",
        );
        return None;
    }
    Some((p, m))
}

#[derive(Clone, Debug)]
pub struct GoniometricLight {
    /// World-space position.
    pub p: Vec3,
    /// `I`·`scale`.
    pub intensity: Vec3,
    /// World-to-light, for directions.
    pub world_to_light: Mat3,
    pub map: Option<LightMap>,
}

impl GoniometricLight {
    pub fn new(p: &ParamValues, ctm: DMat4, report: &mut dyn Report) -> Option<GoniometricLight> {
        let intensity = p.spectrum("I") * p.spectrum("scale");
        let (pos, world_to_light) = light_frame(ctm, "goniometric", report)?;
        let map = p
            .image("mapname")
            .and_then(|img| LightMap::new(&img, report));
        Some(GoniometricLight {
            p: pos,
            intensity,
            world_to_light,
            map,
        })
    }

    /// pbrt-v3's `Scale(w)` for a world direction `w` leaving the light.
    #[inline]
    pub fn scale(&self, w: Vec3) -> Vec3 {
        let Some(map) = &self.map else {
            return Vec3::ONE;
        };
        let wl = self.world_to_light * w;
        let wp = wl / wl.length();
        let (x, y, z) = (wp.x, wp.z, wp.y);
        let theta = z.clamp(-1.0, 1.0).acos();
        let phi = {
            let p = y.atan2(x);
            if p < 0.0 {
                p + 2.0 * PI
            } else {
                p
            }
        };
        map.at(Vec2::new(phi * (0.5 / PI), theta * (1.0 / PI)))
    }
}

impl LightModel for GoniometricLight {
    #[inline]
    fn is_delta(&self) -> bool {
        true
    }

    fn power(&self) -> Vec3 {
        let average = self.map.as_ref().map_or(Vec3::ONE, LightMap::average);
        4.0 * PI * self.intensity * average
    }

    #[inline]
    fn sample_li(&self, r: &SurfacePoint, _u: Vec2, _geom: &Aggregate) -> Option<LightSample> {
        sample_at_point(self.p, r, |w| self.intensity * self.scale(w))
    }

    /// pbrt-v3's: no density by area (a point), uniform over the sphere.
    fn pdf_le(&self, _d: Vec3, _n: Vec3) -> (f32, f32) {
        (0.0, uniform_sphere_pdf())
    }

    /// pbrt-v3's: a direction uniform over the sphere.
    fn sample_le(&self, u1: Vec2, _u2: Vec2, _geom: &Aggregate) -> Option<EmittedRay> {
        let d = uniform_sample_sphere(u1);
        Some(EmittedRay {
            le: self.intensity * self.scale(d),
            ray: Ray::new(self.p, d),
            n: d,
            pdf_pos: 1.0,
            pdf_dir: uniform_sphere_pdf(),
        })
    }

    /// A point emitting in every direction, φ its power.
    fn bounds(&self, _geom: &Aggregate) -> Option<LightBounds> {
        Some(LightBounds {
            bounds: Bounds3::from_point(self.p),
            w: Vec3::Z,
            phi: luminance(self.power()).max(0.0),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: false,
        })
    }
}
