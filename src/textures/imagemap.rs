//! `imagemap`: an image file, MIP-mapped, looked up over the 2D mapping's
//! (s, t) with (0, 0) at the image's lower left corner.
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `filename` | string | | the image (PNG, TGA, EXR, PFM, HDR), relative to the scene file |
//! | `trilinear` | bool | false | trilinear filtering instead of EWA |
//! | `maxanisotropy` | float | 8 | EWA's largest ratio of the ellipse's axes |
//! | `wrap` | string | `repeat` | `repeat`, `black` or `clamp` |
//! | `scale` | float | 1 | factor on every texel |
//! | `gamma` | bool | true for `.png` and `.tga` files | decode texels from sRGB |
//! | mapping | see `mapping.rs` | uv | |
//!
//! As pbrt-v3's `ImageTexture`: a float texture keeps the luminance of the
//! RGB texels (sRGB decoding, when `gamma`, applies to the luminance), a
//! spectrum texture the RGB; `scale` and the decoding are applied before
//! the MIP map is built. Textures with the same file and settings share one
//! MIP map ([`MipCache`]). An image that cannot be read is replaced by a
//! constant 0.5 grey (decoded and scaled like the image), after a warning
//! naming the file. pbrt-v4's `filter` and `invert` are not pbrt-v3
//! parameters: a warning, ignored.

use super::mipmap::{MipMap, Wrap};
use super::{
    Class, Mapping2D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass,
};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, RgbImage, Tex};
use glam::Vec3;
use std::collections::HashMap;
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::filename("filename", "the image file"),
    ParamSpec::boolean("trilinear", false, "trilinear filtering instead of EWA"),
    ParamSpec::float("maxanisotropy", 8.0, "EWA's largest axis ratio"),
    ParamSpec::choice(
        "wrap",
        "repeat",
        &["repeat", "black", "clamp"],
        "lookups outside [0, 1]²",
    ),
    ParamSpec::float("scale", 1.0, "factor on every texel"),
    ParamSpec::bool_opt("gamma", "decode from sRGB (default: for .png and .tga files)"),
    ParamSpec::unsupported(
        "filter",
        "\"filter\" is a pbrt-v4 parameter; pbrt-v3 filters with EWA, or trilinearly with \"bool trilinear\" true: ignored",
    ),
    ParamSpec::unsupported(
        "invert",
        "\"invert\" is a pbrt-v4 parameter, not read by pbrt-v3: ignored",
    ),
];

pub const CLASS: TextureClass = TextureClass {
    name: "imagemap",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "an image file, MIP-mapped (EWA or trilinear filtering)",
    build: TexBuild {
        mapping: MappingUse::TwoD,
        float: Some(build::<f32>),
        spectrum: Some(build::<Vec3>),
    },
};

/// Where image textures get their images (the loader: files read once,
/// failures reported with the statement's location).
pub trait ImageSource {
    /// The image of a file name as written in the scene (raw values, as
    /// pbrt-v3's `ReadImage`), or `None` after a located warning (the
    /// texture is then constant grey, as pbrt-v3's).
    fn image(&mut self, path: &str) -> Option<Arc<RgbImage>>;
    /// The Ptex file of a file name as written in the scene, with 1 or 3
    /// channels, or `None` after a located warning naming the file and
    /// `substitute`.
    fn ptex(&mut self, path: &str, substitute: &str) -> Option<Arc<super::ptex_file::PtexFile>>;
}

/// What makes two image textures share a MIP map (pbrt-v3's `TexInfo`).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct MipKey {
    pub path: String,
    pub trilinear: bool,
    pub max_anisotropy: u32,
    pub wrap: Wrap,
    pub scale: u32,
    pub gamma: bool,
}

/// MIP maps shared by the image textures of a scene, by type.
#[derive(Default)]
pub struct MipCache {
    pub float: HashMap<MipKey, Arc<MipMap<f32>>>,
    pub rgb: HashMap<MipKey, Arc<MipMap<Vec3>>>,
}

pub struct ImageMap<T> {
    pub mapping: Mapping2D,
    pub mip: Arc<MipMap<T>>,
}

/// pbrt-v3's `HasExtension` (case-insensitive).
fn has_extension(name: &str, ext: &str) -> bool {
    name.len() >= ext.len()
        && name.as_bytes()[name.len() - ext.len()..].eq_ignore_ascii_case(ext.as_bytes())
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let p = b.params;
    let path = p.string("filename").to_string();
    let gamma = p
        .bool_opt("gamma")
        .unwrap_or(has_extension(&path, ".tga") || has_extension(&path, ".png"));
    let key = MipKey {
        path,
        trilinear: p.boolean("trilinear"),
        max_anisotropy: p.float("maxanisotropy").to_bits(),
        wrap: match p.string("wrap") {
            "black" => Wrap::Black,
            "clamp" => Wrap::Clamp,
            _ => Wrap::Repeat,
        },
        scale: p.float("scale").to_bits(),
        gamma,
    };
    let mip = match T::mips(b.mips).get(&key) {
        Some(m) => m.clone(),
        None => {
            let mip = Arc::new(mip_map::<T>(&key, b)?);
            T::mips(b.mips).insert(key, mip.clone());
            mip
        }
    };
    Ok(Texture::new_handle(
        b.name,
        Class::ImageMap(ImageMap {
            mapping: b.mapping2d,
            mip,
        }),
    ))
}

/// The MIP map of an image texture (pbrt-v3's `GetTexture`).
fn mip_map<T: TexValue>(key: &MipKey, b: &mut TexBuilder) -> Result<MipMap<T>, String> {
    let scale = f32::from_bits(key.scale);
    let image = b.images.image(&key.path);
    let (w, h, texels) = match image.as_deref() {
        Some(img) => {
            let (w, h) = (img.width() as usize, img.height() as usize);
            // Texture space has t = 0 at the bottom row.
            let mut texels = Vec::with_capacity(w * h);
            for row in img.pixels().chunks_exact(w).rev() {
                texels.extend(row.iter().map(|&c| T::from_texel(c, scale, key.gamma)));
            }
            (w, h, texels)
        }
        None => (
            1,
            1,
            vec![T::from_texel(Vec3::splat(0.5), scale, key.gamma)],
        ),
    };
    MipMap::new(
        w,
        h,
        texels,
        key.trilinear,
        f32::from_bits(key.max_anisotropy),
        key.wrap,
    )
    .ok_or_else(|| {
        format!(
            "image \"{}\" ({w}×{h}) is too large for a MIP map: after rounding up to powers of two it would exceed {} texels",
            key.path,
            super::MAX_TEXELS
        )
    })
}

impl<T: TexValue> ImageMap<T> {
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (st, dstdx, dstdy) = self.mapping.map(sc);
        self.mip.lookup(st, dstdx, dstdy)
    }
}
