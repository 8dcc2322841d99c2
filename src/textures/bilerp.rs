//! `bilerp`: bilinear interpolation of four values over the 2D mapping's
//! (s, t) (not wrapped: outside [0, 1]² it extrapolates, as pbrt-v3).
//!
//! | parameter | type | default | |
//! |---|---|---|---|
//! | `v00` | value of the texture's type | 0 | at (0, 0) |
//! | `v01` | value of the texture's type | 1 | at (0, 1) |
//! | `v10` | value of the texture's type | 0 | at (1, 0) |
//! | `v11` | value of the texture's type | 1 | at (1, 1) |
//! | mapping | see `mapping.rs` | uv | |

use super::{
    Class, Mapping2D, MappingUse, Support, TexBuild, TexBuilder, TexValue, Texture, TextureClass,
};
use crate::materials::ShadingContext;
use crate::scene::{ParamSpec, Tex};

pub const PARAMS: &[ParamSpec] = &[
    ParamSpec::same_value("v00", 0.0, "value at (0, 0)"),
    ParamSpec::same_value("v01", 1.0, "value at (0, 1)"),
    ParamSpec::same_value("v10", 0.0, "value at (1, 0)"),
    ParamSpec::same_value("v11", 1.0, "value at (1, 1)"),
];

pub const CLASS: TextureClass = TextureClass {
    name: "bilerp",
    aliases: &[],
    support: Support::Supported,
    params: PARAMS,
    doc: "bilinear interpolation of v00, v01, v10, v11 over (s, t)",
    build: TexBuild {
        mapping: MappingUse::TwoD,
        float: Some(build::<f32>),
        spectrum: Some(build::<glam::Vec3>),
    },
};

pub struct Bilerp<T> {
    pub mapping: Mapping2D,
    pub v: [T; 4],
}

fn build<T: TexValue>(b: &mut TexBuilder) -> Result<Tex<T>, String> {
    let v = [
        b.value::<T>("v00"),
        b.value::<T>("v01"),
        b.value::<T>("v10"),
        b.value::<T>("v11"),
    ];
    Ok(Texture::new_handle(
        b.name,
        Class::Bilerp(Bilerp {
            mapping: b.mapping2d,
            v,
        }),
    ))
}

impl<T: TexValue> Bilerp<T> {
    #[inline]
    pub fn eval(&self, sc: &ShadingContext) -> T {
        let (st, _, _) = self.mapping.map(sc);
        let (s, t) = (st.x, st.y);
        let [v00, v01, v10, v11] = self.v;
        v00.scale((1.0 - s) * (1.0 - t))
            .add(v01.scale((1.0 - s) * t))
            .add(v10.scale(s * (1.0 - t)))
            .add(v11.scale(s * t))
    }
}
