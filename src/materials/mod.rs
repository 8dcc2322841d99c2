//! Materials: one file per pbrt-v3 material type, each with its parameters
//! (names, types, pbrt-v3's defaults) declared at its top, and one table,
//! [`MATERIALS`], that the loader (parsing and "did you mean"), `--check`,
//! `grammar/REFERENCE.md` and the tests all read.
//!
//! A material turns the shading context of a hit into a [`Bsdf`] (pbrt-v3's
//! `ComputeScatteringFunctions`). [`Material`] is the closed set; it only
//! delegates to the files.

mod bump;
mod disney;
mod fourier;
mod glass;
mod hair;
mod kdsubsurface;
mod matte;
mod metal;
mod mirror;
mod mix;
mod plastic;
mod substrate;
mod subsurface;
mod translucent;
mod uber;

use crate::bssrdf::TabulatedBssrdf;
pub use crate::bxdf::{Bsdf, BsdfSample, BxdfFlags};
pub use bump::bump;
pub use disney::Disney;
pub use fourier::Fourier;
pub use glass::Glass;
pub use hair::Hair;
pub use kdsubsurface::KdSubsurface;
pub use matte::Matte;
pub use metal::Metal;
pub use mirror::Mirror;
pub use mix::Mix;
pub use plastic::Plastic;
pub use substrate::Substrate;
pub use subsurface::Subsurface;
pub use translucent::Translucent;
pub use uber::Uber;

use crate::accel::SurfaceHit;
use crate::bxdf::{roughness_to_alpha, MicrofacetDistribution, TrowbridgeReitz};
use crate::geometry::Frame;
use crate::scene::{FloatTex, MaterialDesc, MaterialId, ParamValues, SpectrumTex};
use crate::shapes::DiffGeom;
use std::sync::Arc;

pub use crate::scene::Support;

/// What a material kind builds from its parameters.
pub type MaterialBuild = fn(&ParamValues) -> Material;

/// One material kind: its pbrt-v3 name, its parameters, and its builder.
pub type MaterialKind = crate::scene::Kind<MaterialBuild>;

/// Every material type pbrt-v3 knows, in the order of pbrt-v3's
/// `MakeMaterial`.
pub static MATERIALS: &[MaterialKind] = &[
    matte::KIND,
    plastic::KIND,
    translucent::KIND,
    glass::KIND,
    mirror::KIND,
    mix::KIND,
    metal::KIND,
    substrate::KIND,
    uber::KIND,
    disney::KIND,
    fourier::KIND,
    NONE_KIND,
    subsurface::KIND,
    kdsubsurface::KIND,
    hair::KIND,
];

const NONE_KIND: MaterialKind = MaterialKind {
    name: "none",
    aliases: &[""],
    support: Support::Supported,
    params: &[],
    doc: "no surface: rays pass through (it only delimits media)",
    build: |_| Material::None,
};

/// The table entry of a material type (`""` is `"none"`, as in pbrt-v3).
pub fn kind(name: &str) -> Option<&'static MaterialKind> {
    crate::scene::kind::find(MATERIALS, name)
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
    Plastic(Plastic),
    Translucent(Translucent),
    Glass(Glass),
    Mirror(Mirror),
    Mix(Mix),
    Metal(Metal),
    Substrate(Substrate),
    Uber(Uber),
    Disney(Disney),
    Fourier(Fourier),
    /// `subsurface` and `kdsubsurface`: the boundary's BSDF here; the
    /// BSSRDF from their coefficients and table.
    Subsurface(Arc<Subsurface>),
    KdSubsurface(Arc<KdSubsurface>),
    Hair(Hair),
    /// `Material "none"`: no BSDF.
    None,
    /// A material with a `bumpmap`: its shading frame is bumped before its
    /// lobes are built (one code path for every material).
    Bumped(Arc<Bumped>),
}

/// A material and its bump map.
#[derive(Clone, Debug)]
pub struct Bumped {
    pub material: Material,
    pub bumpmap: FloatTex,
}

impl Material {
    /// Builds the material from its description (the kind must be in
    /// [`MATERIALS`]; the loader guarantees it). A `mix` needs
    /// [`link_materials`] afterwards.
    pub fn new(desc: &MaterialDesc) -> Material {
        let m = match kind(desc.kind) {
            Some(k) => (k.build)(&desc.params),
            None => panic!("material kind \"{}\" is not in the table", desc.kind),
        };
        // Every material's `bumpmap` (ParamSpec::BUMPMAP) is read here. A
        // constant 0 displaces nothing; another constant still moves the
        // shading normal on curved surfaces (d·∂n/∂u), as in pbrt-v3.
        match desc.params.get("bumpmap") {
            Some(crate::scene::ParamValue::FloatTexture(b))
                if b.as_constant() != Some(0.0) && !m.is_none() =>
            {
                Material::Bumped(Arc::new(Bumped {
                    material: m,
                    bumpmap: b.clone(),
                }))
            }
            _ => m,
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
            Material::Plastic(m) => m.needs_geom(),
            Material::Translucent(m) => m.needs_geom(),
            Material::Glass(m) => m.needs_geom(),
            Material::Mirror(m) => m.needs_geom(),
            Material::Mix(m) => m.needs_geom,
            Material::Metal(m) => m.needs_geom(),
            Material::Substrate(m) => m.needs_geom(),
            Material::Uber(m) => m.needs_geom(),
            Material::Disney(m) => m.needs_geom(),
            Material::Fourier(m) => m.needs_geom(),
            Material::Subsurface(m) => m.needs_geom(),
            Material::KdSubsurface(m) => m.needs_geom(),
            Material::Hair(m) => m.needs_geom(),
            Material::None => false,
            Material::Bumped(_) => true,
        }
    }

    /// True if a lobe is anisotropic: then the shading frame's x axis
    /// follows the shading dp/du (else any frame around the normal does).
    pub fn anisotropic(&self) -> bool {
        match self {
            Material::Glass(m) => m.anisotropic(),
            Material::Mix(m) => m.anisotropic,
            Material::Metal(m) => m.anisotropic(),
            Material::Substrate(m) => m.anisotropic(),
            Material::Uber(m) => m.anisotropic(),
            Material::Bumped(b) => b.material.anisotropic(),
            Material::Disney(m) => m.anisotropic(),
            Material::Subsurface(m) => m.boundary.anisotropic(),
            Material::KdSubsurface(m) => m.boundary.anisotropic(),
            // The hair's frame follows the curve.
            Material::Hair(_) => true,
            // pbrt-v3's FourierBSDF is isotropic.
            Material::Matte(_)
            | Material::Plastic(_)
            | Material::Translucent(_)
            | Material::Mirror(_)
            | Material::Fourier(_)
            | Material::None => false,
        }
    }

    /// The most lobes the material can add to a BSDF, given that count for
    /// the materials a `mix` refers to (pbrt-v3 aborts beyond
    /// [`crate::bxdf::MAX_BXDFS`]; the loader warns).
    pub fn max_lobes(&self, lobes_of: &dyn Fn(MaterialId) -> usize) -> usize {
        match self {
            Material::Matte(m) => m.max_lobes(),
            Material::Plastic(m) => m.max_lobes(),
            Material::Translucent(m) => m.max_lobes(),
            Material::Glass(m) => m.max_lobes(),
            Material::Mirror(m) => m.max_lobes(),
            Material::Mix(m) => m.max_lobes(lobes_of),
            Material::Metal(m) => m.max_lobes(),
            Material::Substrate(m) => m.max_lobes(),
            Material::Uber(m) => m.max_lobes(),
            Material::Disney(m) => m.max_lobes(),
            Material::Fourier(m) => m.max_lobes(),
            Material::Subsurface(m) => m.boundary.max_lobes(),
            Material::KdSubsurface(m) => m.boundary.max_lobes(),
            Material::Hair(m) => m.max_lobes(),
            Material::None => 0,
            Material::Bumped(b) => b.material.max_lobes(lobes_of),
        }
    }

    /// True if the material has a BSSRDF under its boundary (`subsurface`,
    /// `kdsubsurface`, bumped or not): the integrators then sample an exit
    /// point after a transmission through it.
    pub fn has_bssrdf(&self) -> bool {
        match self {
            Material::Subsurface(_) | Material::KdSubsurface(_) => true,
            Material::Bumped(b) => b.material.has_bssrdf(),
            _ => false,
        }
    }

    /// The BSSRDF at a hit (pbrt-v3's `TabulatedBSSRDF` that
    /// `ComputeScatteringFunctions` sets beside the BSDF), `None` for
    /// materials without one. A `mix` of a subsurface material has none in
    /// pbrs (pbrt-v3 keeps its first material's BSSRDF, whose probe rays
    /// then never find a hit of that material, so its paths end there).
    pub fn bssrdf<'a>(&'a self, sc: &ShadingContext) -> Option<TabulatedBssrdf<'a>> {
        match self {
            Material::Subsurface(m) => Some(m.boundary.bssrdf(m.coefficients(sc))),
            Material::KdSubsurface(m) => Some(m.boundary.bssrdf(m.coefficients(sc))),
            Material::Bumped(b) => b.material.bssrdf(sc),
            _ => None,
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
    ///
    /// A bumped material is built at the bumped hit: the shading frame of
    /// `out` (`out.frame.n`) is then the bumped shading normal, which the
    /// integrators use for the cosine terms (pbrt-v3's `isect.shading.n`
    /// after `Bump`).
    #[inline(always)]
    pub fn bsdf_into<'a>(&'a self, sc: &ShadingContext, ctx: &BsdfContext<'a>, out: &mut Bsdf<'a>) {
        match self.leading_bump() {
            Some(b) => self.bumped_bsdf_into(b, sc, ctx, out),
            None => self.unbumped_bsdf_into(sc, ctx, out),
        }
    }

    /// The bump map that sets the BSDF's shading frame: the material's own,
    /// or for a mix, that of its first material (recursively), since
    /// pbrt-v3's `MixMaterial` keeps material 1's bumped interaction.
    #[inline]
    fn leading_bump(&self) -> Option<&FloatTex> {
        match self {
            Material::Bumped(b) => Some(&b.bumpmap),
            Material::Mix(m) => m.leading_bump.as_ref(),
            _ => None,
        }
    }

    /// The BSDF at the hit bumped by `bumpmap` (out of line: the common,
    /// unbumped path stays small).
    #[inline(never)]
    fn bumped_bsdf_into<'a>(
        &'a self,
        bumpmap: &FloatTex,
        sc: &ShadingContext,
        ctx: &BsdfContext<'a>,
        out: &mut Bsdf<'a>,
    ) {
        let (hit, geom) = bump(bumpmap, sc);
        let bumped = ShadingContext {
            hit: &hit,
            geom: &geom,
        };
        self.unbumped_bsdf_into(&bumped, ctx, out);
    }

    /// The BSDF at `sc` as given (no bump step; the caller did it).
    #[inline(always)]
    fn unbumped_bsdf_into<'a>(
        &'a self,
        sc: &ShadingContext,
        ctx: &BsdfContext<'a>,
        out: &mut Bsdf<'a>,
    ) {
        out.reset(shading_frame(sc, self.anisotropic()), sc.hit.point.n);
        match self {
            // The most common material, inline at the hit; `scatter` is
            // recursive (mix, bump) and stays a call with every material's
            // code in it.
            Material::Matte(m) => m.scatter(sc, out),
            _ => self.scatter(sc, ctx, out),
        }
    }

    /// Adds the material's lobes to `bsdf` and sets its η (the frame is
    /// the caller's; a `mix` adds both materials' lobes to one BSDF).
    #[inline]
    pub fn scatter<'a>(&'a self, sc: &ShadingContext, ctx: &BsdfContext<'a>, bsdf: &mut Bsdf<'a>) {
        match self {
            Material::Matte(m) => m.scatter(sc, bsdf),
            Material::Plastic(m) => m.scatter(sc, bsdf),
            Material::Translucent(m) => m.scatter(sc, bsdf),
            Material::Glass(m) => m.scatter(sc, ctx, bsdf),
            Material::Mirror(m) => m.scatter(sc, bsdf),
            Material::Mix(m) => m.scatter(sc, ctx, bsdf),
            Material::Metal(m) => m.scatter(sc, bsdf),
            Material::Substrate(m) => m.scatter(sc, bsdf),
            Material::Uber(m) => m.scatter(sc, bsdf),
            Material::Disney(m) => m.scatter(sc, bsdf),
            Material::Fourier(m) => m.scatter(sc, bsdf),
            Material::Subsurface(m) => m.boundary.scatter(sc, ctx, bsdf),
            Material::KdSubsurface(m) => m.boundary.scatter(sc, ctx, bsdf),
            Material::Hair(m) => m.scatter(sc, bsdf),
            Material::None => {}
            // The caller bumped the hit if this material leads the BSDF
            // (see `leading_bump`); a mix's second material's bump map
            // is ignored, as in pbrt-v3 (its lobes take material 1's frame).
            Material::Bumped(b) => b.material.scatter(sc, ctx, bsdf),
        }
    }
}

/// Lets each `mix` learn what its materials need (anisotropy, differential
/// geometry). The loader puts a mix after the materials it refers to.
pub fn link_materials(materials: &mut [Material]) {
    for i in 0..materials.len() {
        let (before, rest) = materials.split_at_mut(i);
        if let Material::Mix(m) = &mut rest[0] {
            m.link(before);
        }
    }
}

/// pbrt-v3's Trowbridge–Reitz distribution of a material: roughness along
/// dp/du and dp/dv, remapped to α by `RoughnessToAlpha` if asked.
#[inline]
pub fn trowbridge_reitz(u: f32, v: f32, remap: bool) -> MicrofacetDistribution {
    let (ax, ay) = if remap {
        (roughness_to_alpha(u), roughness_to_alpha(v))
    } else {
        (u, v)
    };
    TrowbridgeReitz::new(ax, ay).into()
}

/// The `remaproughness` row of every material with a microfacet lobe.
pub const REMAP_ROUGHNESS: crate::scene::ParamSpec = crate::scene::ParamSpec::boolean(
    "remaproughness",
    true,
    "roughness → α as pbrt-v3's RoughnessToAlpha",
);

/// The microfacet roughness of `glass`, `metal`, `substrate`, `uber` and
/// the subsurface boundaries: along dp/du and dp/dv, and whether it is
/// remapped to α by pbrt-v3's `RoughnessToAlpha`.
#[derive(Clone, Debug)]
pub struct Roughness {
    pub u: FloatTex,
    pub v: FloatTex,
    pub remap: bool,
}

impl Roughness {
    /// `uroughness`, `vroughness` and `remaproughness` with the defaults
    /// of the material's table.
    pub fn read(p: &ParamValues) -> Roughness {
        Roughness {
            u: p.float_tex("uroughness").expect("default"),
            v: p.float_tex("vroughness").expect("default"),
            remap: p.boolean("remaproughness"),
        }
    }

    /// True unless both are the same constant.
    pub fn anisotropic(&self) -> bool {
        match (self.u.as_constant(), self.v.as_constant()) {
            (Some(a), Some(b)) => a != b,
            _ => true,
        }
    }

    /// True if either is a texture (or they may differ): the hit's
    /// differential geometry is needed.
    pub fn needs_geom(&self) -> bool {
        self.u.as_constant().is_none() || self.v.as_constant().is_none() || self.anisotropic()
    }

    /// The roughness at a hit, along u and v.
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> (f32, f32) {
        (self.u.eval(sc), self.v.eval(sc))
    }

    /// The Trowbridge–Reitz distribution of roughness `(u, v)`.
    #[inline]
    pub fn distribution(&self, (u, v): (f32, f32)) -> MicrofacetDistribution {
        trowbridge_reitz(u, v, self.remap)
    }
}

/// True unless the weight is a constant that clamps to black.
fn may_scatter(t: &SpectrumTex) -> bool {
    t.as_constant().is_none_or(|c| c.max_element() > 0.0)
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
