//! Texture mappings (pbrt-v3's `TextureMapping2D` and `IdentityMapping3D`,
//! core/texture.cpp): from a hit to texture coordinates and their
//! screen-space differentials.
//!
//! | `mapping` | parameters (default) | st |
//! |---|---|---|
//! | `uv` (default) | `uscale` 1, `vscale` 1, `udelta` 0, `vdelta` 0 | (su·u + du, sv·v + dv) |
//! | `spherical` | | (θ/π, φ/2π) of the hit in texture space |
//! | `cylindrical` | | ((π + atan2(y, x))/2π, z) of the normalised texture-space direction |
//! | `planar` | `v1` (1,0,0), `v2` (0,1,0), `udelta` 0, `vdelta` 0 | (du + p·v1, dv + p·v2), world-space p |
//!
//! Texture space is the `Texture` statement's CTM read as texture-to-world
//! (spherical and cylindrical use its inverse). The 3D mapping of the solid
//! textures applies the CTM itself to the world-space point: pbrt-v3 passes
//! its texture-to-world transform where `IdentityMapping3D` expects
//! world-to-texture, and pbrs keeps that (scenes were tuned with it). The
//! planar mapping ignores the transform, as pbrt-v3's does.

use crate::materials::ShadingContext;
use crate::scene::ParamSpec;
use glam::{DMat4, Mat4, Vec2, Vec3};
use std::f32::consts::PI;

const INV_PI: f32 = 0.318_309_87;
const INV_2PI: f32 = 0.159_154_94;

/// The values of `mapping`.
pub const MAPPING_KINDS: &[&str] = &["uv", "spherical", "cylindrical", "planar"];

/// The parameters of `mapping` "uv".
pub const UV_MAPPING_PARAMS: &[ParamSpec] = &[
    ParamSpec::float("uscale", 1.0, "scale of u"),
    ParamSpec::float("vscale", 1.0, "scale of v"),
    ParamSpec::float("udelta", 0.0, "offset of s"),
    ParamSpec::float("vdelta", 0.0, "offset of t"),
];

/// The parameters of `mapping` "planar".
pub const PLANAR_MAPPING_PARAMS: &[ParamSpec] = &[
    ParamSpec::vector3("v1", [1.0, 0.0, 0.0], "world direction of s"),
    ParamSpec::vector3("v2", [0.0, 1.0, 0.0], "world direction of t"),
    ParamSpec::float("udelta", 0.0, "offset of s"),
    ParamSpec::float("vdelta", 0.0, "offset of t"),
];

/// A 2D texture mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping2D {
    Uv {
        su: f32,
        sv: f32,
        du: f32,
        dv: f32,
    },
    Spherical {
        world_to_texture: Mat4,
    },
    Cylindrical {
        world_to_texture: Mat4,
    },
    Planar {
        vs: Vec3,
        vt: Vec3,
        ds: f32,
        dt: f32,
    },
}

impl Default for Mapping2D {
    fn default() -> Self {
        Mapping2D::Uv {
            su: 1.0,
            sv: 1.0,
            du: 0.0,
            dv: 0.0,
        }
    }
}

/// pbrt-v3's `Transform` applied to a point (divides by w unless it is 1;
/// pbrt-v3's vectors divide by multiplying with the reciprocal).
#[inline]
fn transform_point(m: &Mat4, p: Vec3) -> Vec3 {
    let h = *m * p.extend(1.0);
    if h.w == 1.0 {
        h.truncate()
    } else {
        h.truncate() * (1.0 / h.w)
    }
}

impl Mapping2D {
    /// The spherical and cylindrical mappings from the statement's
    /// texture-to-world transform.
    pub fn spherical(tex_to_world: DMat4) -> Mapping2D {
        Mapping2D::Spherical {
            world_to_texture: tex_to_world.inverse().as_mat4(),
        }
    }
    pub fn cylindrical(tex_to_world: DMat4) -> Mapping2D {
        Mapping2D::Cylindrical {
            world_to_texture: tex_to_world.inverse().as_mat4(),
        }
    }

    /// Texture coordinates of the hit and their x and y differentials.
    #[inline]
    pub fn map(&self, sc: &ShadingContext) -> (Vec2, Vec2, Vec2) {
        let g = sc.geom;
        let p = sc.hit.point.p;
        match *self {
            Mapping2D::Uv { su, sv, du, dv } => (
                Vec2::new(su * g.uv.x + du, sv * g.uv.y + dv),
                Vec2::new(su * g.dudx, sv * g.dvdx),
                Vec2::new(su * g.dudy, sv * g.dvdy),
            ),
            Mapping2D::Spherical { world_to_texture } => {
                let sphere = |q: Vec3| {
                    let v = transform_point(&world_to_texture, q).normalize();
                    let theta = v.z.clamp(-1.0, 1.0).acos();
                    let phi = v.y.atan2(v.x);
                    let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
                    Vec2::new(theta * INV_PI, phi * INV_2PI)
                };
                let st = sphere(p);
                let delta = 0.1;
                let dx = (sphere(p + delta * g.dpdx) - st) * (1.0 / delta);
                let dy = (sphere(p + delta * g.dpdy) - st) * (1.0 / delta);
                (st, seam(dx), seam(dy))
            }
            Mapping2D::Cylindrical { world_to_texture } => {
                let cylinder = |q: Vec3| {
                    let v = transform_point(&world_to_texture, q).normalize();
                    Vec2::new((PI + v.y.atan2(v.x)) * INV_2PI, v.z)
                };
                let st = cylinder(p);
                let delta = 0.01;
                let dx = (cylinder(p + delta * g.dpdx) - st) * (1.0 / delta);
                let dy = (cylinder(p + delta * g.dpdy) - st) * (1.0 / delta);
                (st, seam(dx), seam(dy))
            }
            Mapping2D::Planar { vs, vt, ds, dt } => (
                Vec2::new(ds + p.dot(vs), dt + p.dot(vt)),
                Vec2::new(g.dpdx.dot(vs), g.dpdx.dot(vt)),
                Vec2::new(g.dpdy.dot(vs), g.dpdy.dot(vt)),
            ),
        }
    }
}

/// pbrt-v3's correction of a differential's t across the mapping's seam
/// (it applies it to t, the second coordinate, in both mappings).
#[inline]
fn seam(mut d: Vec2) -> Vec2 {
    if d.y > 0.5 {
        d.y = 1.0 - d.y;
    } else if d.y < -0.5 {
        d.y = -(d.y + 1.0);
    }
    d
}

/// The 3D mapping of the solid textures: the statement's CTM applied to
/// the world-space hit (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mapping3D {
    pub transform: Mat4,
}

impl Default for Mapping3D {
    fn default() -> Self {
        Mapping3D {
            transform: Mat4::IDENTITY,
        }
    }
}

impl Mapping3D {
    pub fn new(ctm: DMat4) -> Mapping3D {
        Mapping3D {
            transform: ctm.as_mat4(),
        }
    }

    /// The texture-space point and its x and y differentials.
    #[inline]
    pub fn map(&self, sc: &ShadingContext) -> (Vec3, Vec3, Vec3) {
        let m = &self.transform;
        (
            transform_point(m, sc.hit.point.p),
            m.transform_vector3(sc.geom.dpdx),
            m.transform_vector3(sc.geom.dpdy),
        )
    }
}
