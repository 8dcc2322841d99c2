//! `ptex`: a per-face texture from a Ptex file, looked up as pbrt-v3's
//! `PtexTexture` does: the face is the hit's (a triangle mesh's
//! `faceIndices`, face 0 without them), (u, v) the hit's uv, the footprint
//! its screen-space derivatives (du/dx, dv/dx) and (du/dy, dv/dy), through
//! the Ptex library's B-spline filter ([`super::ptex_filter`]) on
//! premultiplied data. Values in [0, 1] are raised to `gamma` (other values
//! are kept); a one-channel file gives grey, a three-channel file RGB (a
//! float texture the channels' mean).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `filename` | string | | the `.ptx` file, relative to the scene file |
//! | `gamma` | float | 2.2 | exponent on values in [0, 1] (1: none) |
//!
//! The file is read when the `Texture` statement is ([`super::ptex_file`]);
//! files are shared by the textures that name them. As in pbrt-v3, a file
//! that cannot be read, is malformed, or has other than 1 or 3 channels
//! gives a texture that is 0 everywhere, after a warning naming the file
//! (an error under `--strict`). Files of triangle meshes are looked up with
//! the Ptex library's point filter for triangles, with a warning: pbrt-v3
//! filters them with the library's triangle filter, which pbrs does not
//! have.

use super::ptex_file::{FaceDataRef, PtexFile};
use super::ptex_filter::{BicubicFilter, MAX_CHANNELS};
use super::{Class, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};
use glam::Vec3;
use std::sync::Arc;

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::filename("filename", "the .ptx file"),
    ParamSpec::float("gamma", 2.2, "exponent on values in [0, 1]"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "ptex",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc:
        "Ptex per-face textures (B-spline filtered; quad meshes; triangle-mesh files point-sampled)",
    build: TexBuild {
        mapping: MappingUse::None,
        float: Some(build::<f32>),
        spectrum: Some(build::<Vec3>),
    },
};

/// What a texture of an unreadable Ptex file is (pbrt-v3's `T{}`).
pub const SUBSTITUTE: &str = "a constant 0 (black) texture is used instead";

/// A Ptex texture.
pub struct PtexTexture<T> {
    pub file: Arc<PtexFile>,
    pub gamma: f32,
    filter: BicubicFilter,
    _value: std::marker::PhantomData<T>,
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let p = b.params;
    let gamma = p.float("gamma");
    let Some(file) = b.images.ptex(p.string("filename"), SUBSTITUTE) else {
        return Ok(Tex::Constant(T::ZERO));
    };
    Ok(Texture::new_handle(
        b.name,
        Class::Ptex(PtexTexture {
            file,
            gamma,
            filter: BicubicFilter::new(0.0),
            _value: std::marker::PhantomData,
        }),
    ))
}

impl<T: TexValue> PtexTexture<T> {
    /// The filtered channels at the hit, before `gamma`.
    pub fn lookup(&self, face: i32, u: f32, v: f32, d: [f32; 4]) -> [f32; MAX_CHANNELS] {
        if self.file.triangles {
            return point_tri(&self.file, face, u, v);
        }
        self.filter
            .eval(&self.file, face, u, v, d[0], d[1], d[2], d[3])
    }

    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let g = sc.geom;
        let mut r = self.lookup(
            g.face_index,
            g.uv.x,
            g.uv.y,
            [g.dudx, g.dvdx, g.dudy, g.dvdy],
        );
        let nc = self.file.nchannels;
        if self.gamma != 1.0 {
            for x in &mut r[..nc] {
                if (0.0..=1.0).contains(x) {
                    *x = x.powf(self.gamma);
                }
            }
        }
        if nc == 1 {
            T::splat(r[0])
        } else if T::IS_FLOAT {
            T::splat((r[0] + r[1] + r[2]) / 3.0)
        } else {
            T::from_rgb(Vec3::new(r[0], r[1], r[2]))
        }
    }
}

/// The Ptex library's point lookup on a triangle face: the texel of the
/// half-square ("even" lower-left or "odd" upper-right) holding (u, v).
fn point_tri(tx: &PtexFile, face: i32, u: f32, v: f32) -> [f32; MAX_CHANNELS] {
    let mut out = [0.0; MAX_CHANNELS];
    let info = tx.face_info(face);
    let Some(data) = tx.data(face, info.res) else {
        return out;
    };
    let res = info.res.u();
    let (ut, vt) = (u * res as f32, v * res as f32);
    let ui = (ut as i32).clamp(0, res - 1);
    let vi = (vt as i32).clamp(0, res - 1);
    let (x, y) = if (ut - ui as f32) + (vt - vi as f32) <= 1.0 {
        (ui, vi)
    } else {
        (res - 1 - vi, res - 1 - ui)
    };
    let n = tx.nchannels.min(MAX_CHANNELS);
    let one = 1.0 / tx.data_type.one();
    let px = match data {
        FaceDataRef::Constant(p) => p,
        FaceDataRef::Packed(r, t) => {
            let i = (y.clamp(0, r.v() - 1) * r.u() + x.clamp(0, r.u() - 1)) as usize * tx.nchannels;
            &t[i..i + tx.nchannels]
        }
    };
    for c in 0..n {
        out[c] = px[c] * one;
    }
    out
}
