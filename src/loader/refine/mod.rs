//! pbrt-v3's refined shapes: `loopsubdiv`, `nurbs` and `heightfield` become a
//! triangle mesh when the `Shape` directive is read (once per directive; a
//! shape inside `ObjectBegin` is refined once however often it is
//! instanced), and that mesh then takes the triangle-mesh path.
//!
//! Each shape is a pair of plain functions: `read` takes the parameters
//! (marking what pbrt-v3 looks up as used) and `refine` builds the mesh from
//! plain numbers, so the geometry can be tested without a scene file.
//! Problems name the parameter they concern; [`shape`] turns them into
//! located diagnostics. pbrt-v3 gives these meshes no `alpha`/`shadowalpha`
//! (it passes no alpha textures for them), so the loader leaves those
//! parameters unread and they are reported unused, as pbrt-v3 does.

pub mod heightfield;
pub mod loopsubdiv;
pub mod nurbs;

use super::Ctx;
use crate::lang::params::{Param, ParamList, ParamType};
use crate::lang::parser::Name;
use crate::scene::MeshData;

/// The most vertices a refinement may produce (the work and memory are
/// proportional to it; a request above it is refused before allocating).
pub const MAX_REFINED_VERTICES: u64 = 1 << 22;
/// The most triangles a refinement may produce.
pub const MAX_REFINED_TRIANGLES: u64 = 1 << 23;

/// Something wrong with a refined shape's input, about parameter `param`
/// (`None`: the shape as a whole).
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub param: Option<&'static str>,
    pub message: String,
}

impl Problem {
    pub fn at(param: &'static str, message: impl Into<String>) -> Problem {
        Problem {
            param: Some(param),
            message: message.into(),
        }
    }

    pub fn shape(message: impl Into<String>) -> Problem {
        Problem {
            param: None,
            message: message.into(),
        }
    }
}

/// Warnings gathered while reading and refining.
pub type Notes = Vec<Problem>;

/// The names this module refines.
pub const REFINED_SHAPES: &[&str] = &["loopsubdiv", "nurbs", "heightfield"];

/// The mesh of a refined shape, or `None` after a located error.
pub fn shape(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<MeshData> {
    let mut notes = Notes::new();
    let result = match name.value.as_str() {
        "loopsubdiv" => loopsubdiv::read(p, &mut notes).and_then(|i| i.refine(&mut notes)),
        "nurbs" => nurbs::read(p, &mut notes).and_then(|i| i.refine(&mut notes)),
        "heightfield" => heightfield::read(p, &mut notes).and_then(|i| i.refine(&mut notes)),
        other => Err(Problem::shape(format!(
            "\"{other}\" is not a refined shape"
        ))),
    };
    let loc_of = |q: &Problem| {
        q.param
            .and_then(|n| p.get(n))
            .map(|q| q.values_loc)
            .unwrap_or(name.loc)
    };
    for n in &notes {
        ctx.warn(loc_of(n), format!("{}: {}", name.value, n.message), "here");
    }
    match result {
        Ok(mesh) => Some(mesh),
        Err(e) => {
            ctx.warn(
                loc_of(&e),
                format!(
                    "{}: {}: the shape is skipped and the rest renders (as pbrt-v3 reports an invalid shape)",
                    name.value, e.message
                ),
                "this shape",
            );
            None
        }
    }
}

/// The parameter `name` of type `ty`, marked used (pbrt-v3's `Find*`).
pub(crate) fn array<'a>(p: &'a ParamList, name: &str, ty: ParamType) -> Option<&'a Param> {
    p.find(name, |t| t == ty)
}

/// pbrt-v3's `FindOneInt`: the value of a one-value integer parameter.
pub(crate) fn one_int(p: &ParamList, name: &str) -> Option<i64> {
    super::lookup::one(p, name, |t| t == ParamType::Integer).map(|q| q.nums()[0] as i64)
}

/// pbrt-v3's `FindOneFloat`.
pub(crate) fn one_float(p: &ParamList, name: &str) -> Option<f64> {
    super::lookup::one(p, name, |t| t == ParamType::Float).map(|q| q.nums()[0])
}

/// The first value of `v` that is not finite as a 32-bit float, with its index.
pub(crate) fn first_non_finite(v: &[f64]) -> Option<(usize, f64)> {
    v.iter()
        .enumerate()
        .find(|(_, x)| !(**x as f32).is_finite())
        .map(|(i, x)| (i, *x))
}

/// Refuses a refinement of `vertices` vertices and `triangles` triangles
/// beyond the budget (checked before anything of that size is allocated).
pub(crate) fn within_budget(vertices: u64, triangles: u64, what: &str) -> Result<(), Problem> {
    if vertices > MAX_REFINED_VERTICES || triangles > MAX_REFINED_TRIANGLES {
        return Err(Problem::shape(format!(
            "{what} would make {vertices} vertices and {triangles} triangles, more than pbrs refines ({MAX_REFINED_VERTICES} vertices, {MAX_REFINED_TRIANGLES} triangles)"
        )));
    }
    Ok(())
}

/// A mesh ready for the triangle path (every position finite as f32).
pub(crate) fn finished(mesh: MeshData) -> Result<MeshData, Problem> {
    if mesh.positions.iter().any(|v| !v.is_finite()) {
        return Err(Problem::shape(
            "a refined vertex does not fit a 32-bit float (the input is too large)",
        ));
    }
    Ok(mesh)
}
