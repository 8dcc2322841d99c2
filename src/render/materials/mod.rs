//! Materials: one file per pbrt-v3 material type, each with its parameters
//! (names, types, pbrt-v3's defaults) declared at its top, and one table,
//! [`MATERIALS`], that the loader (parsing and "did you mean"), `--check`,
//! `grammar/REFERENCE.md` and the tests all read.
//!
//! A material turns the shading context of a hit into a [`Bsdf`] (pbrt-v3's
//! `ComputeScatteringFunctions`). [`Material`] is the closed set; it only
//! delegates to the files.

mod fourier;
mod glass;
mod matte;
mod mirror;

pub use crate::render::bxdf::{Bsdf, BsdfSample, BxdfFlags};
pub use fourier::Fourier;
pub use glass::Glass;
pub use matte::Matte;
pub use mirror::Mirror;

use crate::render::accel::SurfaceHit;
use crate::render::geometry::Frame;
use crate::render::shapes::DiffGeom;
use crate::scene::{MaterialDesc, ParamSpec, ParamValues};

/// Whether pbrs renders a material kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    Supported,
    /// Known to pbrt-v3, not rendered by pbrs: the loader substitutes a
    /// matte with the material's `Kd` and warns, giving the reason.
    Unsupported(&'static str),
}

/// One material kind: its pbrt-v3 name, its parameters, and its builder.
pub struct MaterialKind {
    pub name: &'static str,
    pub support: Support,
    pub params: &'static [ParamSpec],
    /// What it is, for `grammar/REFERENCE.md`.
    pub doc: &'static str,
    pub build: fn(&ParamValues) -> Material,
}

/// Every material type pbrt-v3 knows, in the order of pbrt-v3's
/// `MakeMaterial`.
pub static MATERIALS: &[MaterialKind] = &[
    matte::KIND,
    mirror::KIND,
    glass::KIND,
    NONE_KIND,
    unsupported(
        "subsurface",
        "subsurface scattering comes with participating media",
    ),
    unsupported(
        "kdsubsurface",
        "subsurface scattering comes with participating media",
    ),
    fourier::KIND,
    unsupported("hair", "the hair BSDF comes after curves"),
];

const NONE_KIND: MaterialKind = MaterialKind {
    name: "none",
    support: Support::Supported,
    params: &[],
    doc: "no surface: rays pass through (it only delimits media)",
    build: |_| Material::None,
};

const fn unsupported(name: &'static str, why: &'static str) -> MaterialKind {
    MaterialKind {
        name,
        support: Support::Unsupported(why),
        params: &[],
        doc: why,
        build: |_| Material::None,
    }
}

/// The table entry of a material type (`""` is `"none"`, as in pbrt-v3).
pub fn kind(name: &str) -> Option<&'static MaterialKind> {
    let name = if name.is_empty() { "none" } else { name };
    MATERIALS.iter().find(|k| k.name == name)
}

/// What materials and textures see of a hit: the point with its normals,
/// and its differential geometry (uv, dp/du, …) when the material asked for
/// it ([`Material::needs_geom`]; otherwise all zero).
#[derive(Clone, Copy)]
pub struct ShadingContext<'a> {
    pub hit: &'a SurfaceHit,
    pub geom: &'a DiffGeom,
}

/// What a material needs besides the hit: the other materials (for `mix`),
/// and whether glass may be one FresnelSpecular lobe (pbrt-v3's
/// `allowMultipleLobes`, which the path tracer sets).
#[derive(Clone, Copy)]
pub struct BsdfContext<'a> {
    pub materials: &'a [Material],
    pub multiple_lobes: bool,
}

/// A material ready to build BSDFs at hit points.
#[derive(Clone, Debug)]
pub enum Material {
    Matte(Matte),
    Mirror(Mirror),
    Glass(Glass),
    Fourier(Fourier),
    /// `Material "none"`: no BSDF.
    None,
}

impl Material {
    /// Builds the material from its description (the kind must be in
    /// [`MATERIALS`]; the loader guarantees it).
    pub fn new(desc: &MaterialDesc) -> Material {
        match kind(desc.kind) {
            Some(k) => (k.build)(&desc.params),
            None => panic!("material kind \"{}\" is not in the table", desc.kind),
        }
    }

    /// True for `Material "none"`: rays pass through without a bounce.
    pub fn is_none(&self) -> bool {
        matches!(self, Material::None)
    }

    /// True if the BSDF depends on more than the normals (textures read
    /// uv, anisotropic lobes align with dp/du): then the integrator computes
    /// the hit's differential geometry for it.
    pub fn needs_geom(&self) -> bool {
        match self {
            Material::Matte(m) => m.needs_geom(),
            Material::Mirror(m) => m.needs_geom(),
            Material::Glass(m) => m.needs_geom(),
            Material::Fourier(m) => m.needs_geom(),
            Material::None => false,
        }
    }

    /// True if a lobe is anisotropic: then the shading frame's x axis
    /// follows the shading dp/du (else any frame around the normal does).
    pub fn anisotropic(&self) -> bool {
        match self {
            Material::Matte(_)
            | Material::Mirror(_)
            | Material::Glass(_)
            | Material::Fourier(_)
            | Material::None => false,
        }
    }

    /// The BSDF at a hit (pbrt-v3's `ComputeScatteringFunctions`).
    pub fn bsdf<'a>(&'a self, sc: &ShadingContext, ctx: &BsdfContext<'a>) -> Bsdf<'a> {
        let mut b = Bsdf::new(shading_frame(sc, false), sc.hit.point.n, 1.0);
        self.bsdf_into(sc, ctx, &mut b);
        b
    }

    /// [`Material::bsdf`] written into `out` (reset first), so that the
    /// integrators build BSDFs in place.
    #[inline]
    pub fn bsdf_into<'a>(&'a self, sc: &ShadingContext, ctx: &BsdfContext<'a>, out: &mut Bsdf<'a>) {
        out.reset(shading_frame(sc, self.anisotropic()), sc.hit.point.n);
        match self {
            Material::Matte(m) => m.scatter(sc, out),
            Material::Mirror(m) => m.scatter(sc, out),
            Material::Glass(m) => m.scatter(sc, ctx, out),
            Material::Fourier(m) => m.scatter(sc, out),
            Material::None => {}
        }
    }
}

/// The shading frame of a hit: z is the shading normal; x is the shading
/// dp/du (made perpendicular to the normal) when `anisotropic`, as pbrt-v3's
/// BSDF. Isotropic lobes do not depend on the rotation about the normal, so
/// they take any frame around it (no differential geometry needed).
#[inline]
pub fn shading_frame(sc: &ShadingContext, anisotropic: bool) -> Frame {
    let ns = sc.hit.point.ns;
    if anisotropic {
        let d = sc.geom.shading_dpdu;
        let s = d - ns * ns.dot(d);
        let l2 = s.length_squared();
        if l2 > 0.0 && l2.is_finite() {
            let s = s / l2.sqrt();
            return Frame {
                s,
                t: ns.cross(s),
                n: ns,
            };
        }
    }
    Frame::from_normal(ns)
}
