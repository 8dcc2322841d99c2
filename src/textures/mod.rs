//! Textures: one file per pbrt-v3 texture class, each with its parameters
//! (names, types, pbrt-v3's defaults) declared at its top, and one table,
//! [`TEXTURES`], that the loader (parsing, type rules, "did you mean"),
//! `--check`, `grammar/REFERENCE.md` and the tests read.
//!
//! A texture handle ([`Tex`]) is a constant or an `Arc` of a [`Texture`]:
//! the closed set of classes ([`Class`]), which only delegates to the files.
//! Textures are generic over their value ([`TexValue`]: `f32` or linear RGB
//! `Vec3`), as pbrt-v3's templates are; the arithmetic follows pbrt-v3's
//! operation order in `f32`, so values agree with pbrt-v3's bit for bit
//! where the inputs do (the noise textures and MIP maps are tested so).
//!
//! Evaluation reads the hit through the [`ShadingContext`]: the world-space
//! point `hit.point.p`, and `geom.uv` with the screen-space differentials
//! `geom.{dpdx, dpdy, dudx, dvdx, dudy, dvdy}` (zero when the ray carries
//! none: then filtered textures are point-sampled, as pbrt-v3 does).

mod bilerp;
mod checkerboard;
mod constant;
mod dots;
mod ewa_lanes;
mod fbm;
mod gamma_fast;
mod imagemap;
mod mapping;
mod marble;
mod mipmap;
mod mix;
pub mod noise;
mod noise_lanes;
pub use noise::MAX_OCTAVES;
mod ptex;
pub mod ptex_file;
pub mod ptex_filter;
mod scale;
mod uv;
mod windy;
mod wrinkled;

pub use bilerp::Bilerp;
pub use checkerboard::{AaMode, Checkerboard2D, Checkerboard3D};
pub use dots::Dots;
pub use fbm::Fbm;
pub use imagemap::{ImageMap, ImageSource, MipCache, MipKey};
pub use mapping::{Mapping2D, Mapping3D, MAPPING_KINDS, PLANAR_MAPPING_PARAMS, UV_MAPPING_PARAMS};
pub use marble::Marble;
pub use mipmap::{ewa_weights, lanczos, resample_weights, MipMap, Wrap, MAX_TEXELS};
pub use mix::Mix;
pub use ptex::PtexTexture;
pub use scale::Scale;
pub use uv::UvTexture;
pub use windy::Windy;
pub use wrinkled::Wrinkled;

use crate::materials::ShadingContext;
use crate::scene::{ParamValues, Tex};
use glam::Vec3;
use std::collections::HashMap;
use std::fmt::Debug;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// What a texture's values are: `f32` (float textures) or `Vec3` (linear
/// RGB, pbrt-v3's `Spectrum` in its default RGB build).
pub trait TexValue: Copy + PartialEq + Debug + Send + Sync + 'static {
    const ZERO: Self;
    /// True for float textures.
    const IS_FLOAT: bool;
    fn splat(v: f32) -> Self;
    /// A colour as this type (spectrum textures only are built from
    /// colours; for floats this is the luminance).
    fn from_rgb(c: Vec3) -> Self;
    /// `self * o`, per channel.
    fn mul(self, o: Self) -> Self;
    /// `s * self`.
    fn scale(self, s: f32) -> Self;
    fn add(self, o: Self) -> Self;
    /// `self / s`, per channel (pbrt-v3 divides, it does not multiply by
    /// the reciprocal).
    fn div(self, s: f32) -> Self;
    /// Negative channels set to 0 (the MIP map's resampling clamp).
    fn clamp_non_negative(self) -> Self;
    /// An image texel as stored by an `imagemap` (pbrt-v3's `convertIn`:
    /// float maps keep the luminance, decoded from sRGB after taking it).
    fn from_texel(rgb: Vec3, scale: f32, gamma: bool) -> Self;
    /// The handle of a parameter of this type (`SameTexture`/`SameValue`).
    fn param(p: &ParamValues, name: &str) -> Option<Tex<Self>>;
    /// This type's MIP maps in the shared cache.
    fn mips(c: &mut MipCache) -> &mut HashMap<MipKey, Arc<MipMap<Self>>>;
}

/// pbrt-v3's `InverseGammaCorrect`: sRGB-encoded to linear. The values of
/// 8-bit images (`k/255`, most image textures) come from a table of the
/// formula's results ([`gamma_fast`]), any other value from the formula.
#[inline]
pub fn inverse_gamma(v: f32) -> f32 {
    gamma_fast::of_8bit_code(v).unwrap_or_else(|| inverse_gamma_computed(v))
}

/// [`inverse_gamma`] by its formula.
#[inline]
fn inverse_gamma_computed(v: f32) -> f32 {
    if v <= 0.04045 {
        v * 1.0 / 12.92
    } else {
        ((v + 0.055) * 1.0 / 1.055).powf(2.4)
    }
}

/// pbrt-v3's `RGBSpectrum::y()`.
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

impl TexValue for f32 {
    const ZERO: f32 = 0.0;
    const IS_FLOAT: bool = true;
    #[inline]
    fn splat(v: f32) -> f32 {
        v
    }
    #[inline]
    fn from_rgb(c: Vec3) -> f32 {
        luminance(c)
    }
    #[inline]
    fn mul(self, o: f32) -> f32 {
        self * o
    }
    #[inline]
    fn scale(self, s: f32) -> f32 {
        s * self
    }
    #[inline]
    fn add(self, o: f32) -> f32 {
        self + o
    }
    #[inline]
    fn div(self, s: f32) -> f32 {
        self / s
    }
    #[inline]
    fn clamp_non_negative(self) -> f32 {
        // pbrt-v3's Clamp(v, 0, ∞): NaN passes through.
        if self < 0.0 {
            0.0
        } else {
            self
        }
    }
    fn from_texel(rgb: Vec3, scale: f32, gamma: bool) -> f32 {
        let y = luminance(rgb);
        scale * if gamma { inverse_gamma(y) } else { y }
    }
    fn param(p: &ParamValues, name: &str) -> Option<Tex<f32>> {
        p.float_tex(name)
    }
    fn mips(c: &mut MipCache) -> &mut HashMap<MipKey, Arc<MipMap<f32>>> {
        &mut c.float
    }
}

impl TexValue for Vec3 {
    const ZERO: Vec3 = Vec3::ZERO;
    const IS_FLOAT: bool = false;
    #[inline]
    fn splat(v: f32) -> Vec3 {
        Vec3::splat(v)
    }
    #[inline]
    fn from_rgb(c: Vec3) -> Vec3 {
        c
    }
    #[inline]
    fn mul(self, o: Vec3) -> Vec3 {
        self * o
    }
    #[inline]
    fn scale(self, s: f32) -> Vec3 {
        s * self
    }
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        self + o
    }
    #[inline]
    fn div(self, s: f32) -> Vec3 {
        self / s
    }
    #[inline]
    fn clamp_non_negative(self) -> Vec3 {
        Vec3::new(
            self.x.clamp_non_negative(),
            self.y.clamp_non_negative(),
            self.z.clamp_non_negative(),
        )
    }
    fn from_texel(rgb: Vec3, scale: f32, gamma: bool) -> Vec3 {
        let f = |c: f32| scale * if gamma { inverse_gamma(c) } else { c };
        Vec3::new(f(rgb.x), f(rgb.y), f(rgb.z))
    }
    fn param(p: &ParamValues, name: &str) -> Option<Tex<Vec3>> {
        p.spectrum_tex(name)
    }
    fn mips(c: &mut MipCache) -> &mut HashMap<MipKey, Arc<MipMap<Vec3>>> {
        &mut c.rgb
    }
}

/// pbrt-v3's `Lerp(t, a, b)`: `(1 - t)·a + t·b`.
#[inline]
pub fn lerp<T: TexValue>(t: f32, a: T, b: T) -> T {
    a.scale(1.0 - t).add(b.scale(t))
}

/// A texture that varies over surfaces.
pub struct Texture<T> {
    /// Unique within the process (names can be redefined).
    pub id: u32,
    /// The name of its `Texture` statement.
    pub name: String,
    pub class: Class<T>,
}

/// The texture classes (`constant` is [`Tex::Constant`]).
pub enum Class<T> {
    Scale(Scale<T>),
    Mix(Mix<T>),
    Bilerp(Bilerp<T>),
    ImageMap(ImageMap<T>),
    /// Spectrum only (pbrt-v3 has no float `uv`).
    Uv(UvTexture),
    Checkerboard2D(Checkerboard2D<T>),
    Checkerboard3D(Checkerboard3D<T>),
    Dots(Dots<T>),
    Fbm(Fbm),
    Wrinkled(Wrinkled),
    Windy(Windy),
    /// Spectrum only (pbrt-v3 has no float `marble`).
    Marble(Marble),
    Ptex(PtexTexture<T>),
}

static NEXT_ID: AtomicU32 = AtomicU32::new(1);

impl<T> Texture<T> {
    /// A new texture handle.
    pub fn new_handle(name: &str, class: Class<T>) -> Tex<T> {
        Tex::Texture(Arc::new(Texture {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            name: name.to_string(),
            class,
        }))
    }

    pub fn class_name(&self) -> &'static str {
        match &self.class {
            Class::Scale(_) => "scale",
            Class::Mix(_) => "mix",
            Class::Bilerp(_) => "bilerp",
            Class::ImageMap(_) => "imagemap",
            Class::Uv(_) => "uv",
            Class::Checkerboard2D(_) | Class::Checkerboard3D(_) => "checkerboard",
            Class::Dots(_) => "dots",
            Class::Fbm(_) => "fbm",
            Class::Wrinkled(_) => "wrinkled",
            Class::Windy(_) => "windy",
            Class::Marble(_) => "marble",
            Class::Ptex(_) => "ptex",
        }
    }
}

impl<T: TexValue> Texture<T> {
    /// The texture's value at the hit (pbrt-v3's `Evaluate`).
    #[inline(never)]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        match &self.class {
            Class::Scale(t) => t.eval(sc),
            Class::Mix(t) => t.eval(sc),
            Class::Bilerp(t) => t.eval(sc),
            Class::ImageMap(t) => t.eval(sc),
            Class::Uv(t) => T::from_rgb(t.eval(sc)),
            Class::Checkerboard2D(t) => t.eval(sc),
            Class::Checkerboard3D(t) => t.eval(sc),
            Class::Dots(t) => t.eval(sc),
            Class::Fbm(t) => T::splat(t.eval(sc)),
            Class::Wrinkled(t) => T::splat(t.eval(sc)),
            Class::Windy(t) => T::splat(t.eval(sc)),
            Class::Marble(t) => T::from_rgb(t.eval(sc)),
            Class::Ptex(t) => t.eval(sc),
        }
    }
}

impl<T: TexValue> Tex<T> {
    /// The value at the hit: a constant is read in place; other textures
    /// are evaluated out of line.
    #[inline(always)]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        match self {
            Tex::Constant(v) => *v,
            Tex::Texture(t) => t.eval(sc),
        }
    }
}

/// Which texture mapping a class reads (from the `mapping` parameters or
/// the `Texture` statement's transform).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MappingUse {
    None,
    /// A 2D mapping: `mapping` "uv" (`uscale`, `vscale`, `udelta`,
    /// `vdelta`), "spherical", "cylindrical" or "planar" (`v1`, `v2`,
    /// `udelta`, `vdelta`).
    TwoD,
    /// pbrt-v3's `IdentityMapping3D` of the statement's transform.
    ThreeD,
    /// 2D or 3D by the `dimension` parameter (`checkerboard`).
    ByDimension,
}

/// What a class builder gets: the statement's parameters (read through
/// the class's `ParamSpec` list, defaults applied), its mappings, and the
/// loader's images.
pub struct TexBuilder<'a> {
    /// The texture's name.
    pub name: &'a str,
    pub params: &'a ParamValues,
    pub mapping2d: Mapping2D,
    pub mapping3d: Mapping3D,
    pub images: &'a mut dyn ImageSource,
    pub mips: &'a mut MipCache,
}

impl TexBuilder<'_> {
    /// A texture parameter of the texture's own type (declared with
    /// `SameTexture` or `SameValue`).
    pub fn tex<T: TexValue>(&self, name: &str) -> Tex<T> {
        T::param(self.params, name)
            .unwrap_or_else(|| panic!("texture parameter \"{name}\" has no default"))
    }
    /// A plain value of the texture's own type (`SameValue`).
    pub fn value<T: TexValue>(&self, name: &str) -> T {
        match self.tex::<T>(name) {
            Tex::Constant(v) => v,
            Tex::Texture(_) => panic!("\"{name}\" is a value, not a texture"),
        }
    }
}

/// A class builder: the texture, or why it is not defined (a located
/// warning at the statement; pbrt-v3 then leaves the name undefined).
pub type Build<T> = fn(&mut TexBuilder) -> Result<Tex<T>, String>;

/// How a texture class is built: the mapping it reads and its builders
/// (`None`: pbrt-v3 has no texture of that type for the class).
pub struct TexBuild {
    pub mapping: MappingUse,
    pub float: Option<Build<f32>>,
    pub spectrum: Option<Build<Vec3>>,
}

/// One texture class: its pbrt-v3 name, its parameters, and its builders.
/// An unsupported class's builders make the stand-in its reason names.
pub type TextureClass = crate::scene::Kind<TexBuild>;

pub use crate::scene::Support;

/// Every texture class pbrt-v3 knows, in the order of its
/// `MakeFloatTexture`.
pub static TEXTURES: &[TextureClass] = &[
    constant::CLASS,
    scale::CLASS,
    mix::CLASS,
    bilerp::CLASS,
    imagemap::CLASS,
    uv::CLASS,
    checkerboard::CLASS,
    dots::CLASS,
    fbm::CLASS,
    wrinkled::CLASS,
    marble::CLASS,
    windy::CLASS,
    ptex::CLASS,
];

/// The table entry of a texture class.
pub fn class(name: &str) -> Option<&'static TextureClass> {
    crate::scene::kind::find(TEXTURES, name)
}
