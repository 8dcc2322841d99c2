//! `MakeNamedMedium`: a medium from its parameters, read through its type's
//! table in `render::media::MEDIA`, with pbrt-v3's `MakeMedium` defaults
//! and rules (src/core/api.cpp): a `preset` from the measured table first,
//! then `sigma_a`/`sigma_s`, both times `scale`; a heterogeneous grid needs
//! `density` with `nx·ny·nz` values and spans `p0`…`p1` in the space
//! current at the statement.

use super::entities::{int, point3, spectrum};
use super::state::closest_name;
use super::Ctx;
use crate::lang::params::{ParamList, ParamType};
use crate::lang::parser::Name;
use crate::render::media::{self, presets, MEDIA};
use crate::scene::{MediumDesc, MediumKind};
use glam::{DMat4, DVec3, Vec3};
use std::sync::Arc;

/// The most voxels a density grid may have (1 GiB of f32).
pub const MAX_GRID_VOXELS: i64 = 1 << 28;

/// The medium defined by `MakeNamedMedium "name" …`, or `None` after an
/// error or a warning that says it is not defined (as pbrt-v3, which then
/// leaves the name undefined).
pub fn medium(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<MediumDesc> {
    let what = format!("MakeNamedMedium \"{}\"", name.value);
    let Some(ty) = p.find("type", |t| t == ParamType::String) else {
        p.mark_all_used();
        ctx.error(
            name.loc,
            format!("{what} has no \"string type\" parameter"),
            "needs \"string type\" [ \"homogeneous\" ] or [ \"heterogeneous\" ]",
            None,
        );
        return None;
    };
    let (ty_name, ty_loc) = (ty.strs()[0].clone(), ty.values_loc);
    let Some(kind) = media::kind(&ty_name) else {
        p.mark_all_used();
        let names: Vec<&str> = MEDIA.iter().map(|k| k.name).collect();
        let help = closest_name(&ty_name, &names)
            .map(|c| format!("did you mean \"{c}\"?"))
            .unwrap_or_else(|| "pbrt-v3 has \"homogeneous\" and \"heterogeneous\"".into());
        ctx.warn(
            ty_loc,
            format!("{what}: unknown medium type \"{ty_name}\": the medium is not defined (as pbrt-v3); {help}"),
            "not a medium type",
        );
        return None;
    };
    let spec = |n: &str| kind.params.iter().find(|s| s.name == n).map(|s| s.kind);
    let default = |n: &str| match spec(n) {
        Some(crate::scene::ParamKind::Spectrum(d)) => Vec3::from_array(d),
        _ => Vec3::ZERO,
    };
    let (mut sigma_a, mut sigma_s) = (default("sigma_a"), default("sigma_s"));
    if let Some(q) = p.find("preset", |t| t == ParamType::String) {
        let preset = q.strs()[0].as_str();
        match presets::measured(preset) {
            Some(m) => {
                sigma_a = Vec3::from_array(m.sigma_a);
                sigma_s = Vec3::from_array(m.sigma_prime_s);
            }
            None if preset.is_empty() => {}
            None => {
                let names: Vec<&str> = presets::MEASURED.iter().map(|m| m.name).collect();
                let help = closest_name(preset, &names)
                    .map(|c| format!("; did you mean \"{c}\"?"))
                    .unwrap_or_default();
                ctx.warn(
                    q.values_loc,
                    format!("{what}: unknown preset \"{preset}\": pbrt-v3's default coefficients are used (as pbrt-v3){help}"),
                    "not a measured medium",
                );
            }
        }
    }
    let scale = float_param(p, "scale", 1.0);
    let mut g = float_param(p, "g", 0.0);
    let sigma_a = spectrum(ctx, p, "sigma_a", sigma_a) * scale;
    let sigma_a = nonneg(ctx, p, &what, "sigma_a", sigma_a);
    let sigma_s = spectrum(ctx, p, "sigma_s", sigma_s) * scale;
    let sigma_s = nonneg(ctx, p, &what, "sigma_s", sigma_s);
    if g.is_nan() || g.abs() >= 1.0 {
        let loc = p.get("g").map(|q| q.values_loc).unwrap_or(name.loc);
        let clamped = if g.is_nan() {
            0.0
        } else {
            g.clamp(-0.999, 0.999)
        };
        ctx.warn(
            loc,
            format!("{what}: \"g\" is {g}: the Henyey–Greenstein asymmetry must be in (-1, 1); {clamped} is used"),
            "out of range",
        );
        g = clamped;
    }
    let kind = match kind.name {
        "homogeneous" => MediumKind::Homogeneous,
        _ => grid(ctx, name, p, &what, ctm, sigma_a, sigma_s)?,
    };
    ctx.report_unused_with_specs(
        p,
        &what,
        &["type"],
        media::kind(&ty_name).map_or(&[], |k| k.params),
    );
    Some(MediumDesc {
        name: name.value.clone(),
        sigma_a,
        sigma_s,
        g,
        kind,
    })
}

fn float_param(p: &ParamList, n: &str, def: f32) -> f32 {
    super::entities::float(p, n, def as f64) as f32
}

/// A coefficient with negative channels set to 0 (and a warning there).
fn nonneg(ctx: &mut Ctx, p: &ParamList, what: &str, n: &str, v: Vec3) -> Vec3 {
    if v.cmpge(Vec3::ZERO).all() && v.is_finite() {
        return v;
    }
    let loc = p.get(n).or_else(|| p.get("scale")).map(|q| q.values_loc);
    let fixed = Vec3::new(fix(v.x), fix(v.y), fix(v.z));
    if let Some(loc) = loc {
        ctx.warn(
            loc,
            format!("{what}: \"{n}\" is {} {} {}: coefficients must be finite and ≥ 0; {} {} {} is used", v.x, v.y, v.z, fixed.x, fixed.y, fixed.z),
            "negative or non-finite coefficient",
        );
    }
    fixed
}

fn fix(c: f32) -> f32 {
    if c.is_finite() {
        c.max(0.0)
    } else {
        0.0
    }
}

#[allow(clippy::too_many_arguments)]
fn grid(
    ctx: &mut Ctx,
    name: &Name,
    p: &ParamList,
    what: &str,
    ctm: DMat4,
    sigma_a: Vec3,
    sigma_s: Vec3,
) -> Option<MediumKind> {
    let Some(dq) = p.find("density", |t| t == ParamType::Float) else {
        p.mark_all_used();
        ctx.error(
            name.loc,
            format!("{what}: a heterogeneous medium needs \"float density\" values (pbrt-v3: \"No density values provided\")"),
            "no \"float density\"",
            None,
        );
        return None;
    };
    let mut n = [0i64; 3];
    for (i, axis) in ["nx", "ny", "nz"].iter().enumerate() {
        let (v, loc) = int(p, axis, 1);
        if v < 1 {
            p.mark_all_used();
            ctx.error(
                loc.unwrap_or(name.loc),
                format!(
                    "{what}: \"{axis}\" is {v}: the grid needs at least one voxel along each axis"
                ),
                "must be ≥ 1",
                None,
            );
            return None;
        }
        n[i] = v;
    }
    let voxels = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
    let values = dq.nums();
    if voxels > MAX_GRID_VOXELS || values.len() as i64 != voxels {
        p.mark_all_used();
        let why = if voxels > MAX_GRID_VOXELS {
            format!(
                "{} × {} × {} voxels is more than pbrs takes ({MAX_GRID_VOXELS})",
                n[0], n[1], n[2]
            )
        } else {
            format!(
                "\"density\" has {} values; nx·ny·nz = {} × {} × {} = {voxels} expected (pbrt-v3 reports the same error)",
                values.len(),
                n[0],
                n[1],
                n[2]
            )
        };
        ctx.error(
            dq.values_loc,
            format!("{what}: {why}"),
            "wrong number of densities",
            None,
        );
        return None;
    }
    if let Err(why) = crate::scene::memory::check_budget(
        &format!("{what}: the {} × {} × {} density grid", n[0], n[1], n[2]),
        (voxels as u64).saturating_mul(4),
    ) {
        p.mark_all_used();
        ctx.error(dq.values_loc, why, "too large for this machine", None);
        return None;
    }
    let mut density: Vec<f32> = values.iter().map(|&v| v as f32).collect();
    if density.iter().any(|d| !(d.is_finite() && *d >= 0.0)) {
        ctx.warn(
            dq.values_loc,
            format!("{what}: negative or non-finite densities are set to 0"),
            "densities must be finite and ≥ 0",
        );
        for d in &mut density {
            *d = fix(*d);
        }
    }
    let sigma_t = sigma_a + sigma_s;
    if sigma_t.x != sigma_t.y || sigma_t.x != sigma_t.z {
        let loc = p
            .get("sigma_a")
            .or_else(|| p.get("sigma_s"))
            .or_else(|| p.get("preset"))
            .map_or(name.loc, |q| q.values_loc);
        ctx.warn(
            loc,
            format!("{what}: sigma_a + sigma_s = {} {} {} differs by channel: a heterogeneous medium needs one attenuation coefficient (pbrt-v3 reports an error and uses the first channel's, as pbrs does)", sigma_t.x, sigma_t.y, sigma_t.z),
            "spectrally varying attenuation",
        );
    }
    let p0 = point3(p, "p0", DVec3::ZERO);
    let p1 = point3(p, "p1", DVec3::ONE);
    let data_to_medium = DMat4::from_translation(p0) * DMat4::from_scale(p1 - p0);
    let medium_to_world = ctm * data_to_medium;
    if !medium_to_world.is_finite() || medium_to_world.determinant() == 0.0 {
        ctx.error(
            name.loc,
            format!("{what}: the grid's box p0…p1 in the current transform is degenerate (zero extent along an axis, or a singular transform)"),
            "degenerate grid box",
            None,
        );
        return None;
    }
    Some(MediumKind::Grid {
        nx: n[0] as u32,
        ny: n[1] as u32,
        nz: n[2] as u32,
        density: Arc::new(density),
        medium_to_world,
    })
}
