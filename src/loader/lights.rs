//! `LightSource` and `AreaLightSource`: read through the tables of
//! `lights` (`LIGHTS`, `AREA_LIGHTS`), with the CTM as light-to-world.

use super::kinds::{self, Family, StatementReport, Unknown};
use super::Ctx;
use crate::lang::params::ParamList;
use crate::lang::parser::Name;
use crate::lights::{AreaLightBuild, LightBuild, AREA_LIGHTS, LIGHTS};
use crate::scene::kind;
use crate::scene::*;
use glam::DMat4;

const LIGHT_FAMILY: Family<LightBuild> = Family {
    directive: "LightSource",
    noun: "light type",
    table: LIGHTS,
    unknown: Unknown::Warn,
};

const AREA_LIGHT_FAMILY: Family<AreaLightBuild> = Family {
    directive: "AreaLightSource",
    noun: "area light",
    table: AREA_LIGHTS,
    unknown: Unknown::Warn,
};

/// `LightSource`: a type of `lights::LIGHTS`, its parameters read
/// through its table and the light built by its builder with the CTM as
/// light-to-world; types pbrs does not render, unknown types and lights
/// the builder refuses are warned about and skipped.
pub fn light(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<Light> {
    let r = kinds::read(ctx, &LIGHT_FAMILY, name, p)?;
    if r.kind.unsupported().is_some() {
        p.mark_all_used();
        ctx.warn(
            name.loc,
            format!("light \"{}\" is not supported by pbrs: ignored", name.value),
            "light ignored",
        );
        return None;
    }
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let light = (r.kind.build)(&r.params, ctm, &mut report);
    kinds::report_unused(ctx, &LIGHT_FAMILY, &r, name, p);
    light
}

/// Whether `AreaLightSource` names a type of `lights::AREA_LIGHTS`
/// (else a warning: later shapes do not emit). Its parameters are read by
/// [`area_light`] when a shape first uses it.
pub fn area_light_known(ctx: &mut Ctx, name: &Name, p: &ParamList) -> bool {
    if kind::find(AREA_LIGHTS, &name.value).is_some() {
        return true;
    }
    p.mark_all_used();
    let known = AREA_LIGHTS
        .iter()
        .map(|k| {
            let aliases: String = k
                .aliases
                .iter()
                .map(|a| format!(", alias \"{a}\""))
                .collect();
            format!("\"{}\"{aliases}", k.name)
        })
        .collect::<Vec<_>>()
        .join("; ");
    ctx.warn(
        name.loc,
        format!(
            "unknown area light \"{}\" (pbrt-v3 has {known}): ignored, later shapes are not emissive",
            name.value
        ),
        "not an area light type",
    );
    false
}

/// `AreaLightSource`'s emission, read through its type's table (`None`
/// for an unknown type, which [`area_light_known`] reported).
pub fn area_light(ctx: &mut Ctx, name: &Name, p: &ParamList) -> Option<DiffuseEmission> {
    let r = kinds::read(ctx, &AREA_LIGHT_FAMILY, name, p)?;
    let mut report = StatementReport {
        ctx,
        at: name.loc,
        params: p,
    };
    let emission = (r.kind.build)(&r.params, &mut report);
    kinds::report_unused(ctx, &AREA_LIGHT_FAMILY, &r, name, p);
    Some(emission)
}
