//! `MakeNamedMedium`: the medium of its `type` from
//! [`MEDIA`](crate::media::MEDIA), built by the type's builder
//! (pbrt-v3's `MakeMedium` with its checks, in the types' files) in the
//! space current at the statement.

use super::kinds::{self, Family, StatementReport, Unknown};
use super::Ctx;
use crate::lang::params::{ParamList, ParamType};
use crate::lang::parser::Name;
use crate::media::{Medium, MediumInput, MEDIA};
use crate::scene::kind::closest_name;
use glam::DMat4;

/// The medium defined by `MakeNamedMedium "name" …`, or `None` after an
/// error or a warning that says it is not defined (as pbrt-v3, which then
/// leaves the name undefined).
pub fn medium(ctx: &mut Ctx, name: &Name, p: &ParamList, ctm: DMat4) -> Option<Medium> {
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
    let ty_name = Name {
        value: ty.strs()[0].clone(),
        loc: ty.values_loc,
    };
    let family = Family {
        directive: "MakeNamedMedium",
        noun: "medium type",
        table: MEDIA,
        unknown: Unknown::Warn,
    };
    if crate::scene::kind::find(MEDIA, &ty_name.value).is_none() {
        p.mark_all_used();
        let names = crate::scene::kind::names(MEDIA);
        let help = closest_name(&ty_name.value, &names)
            .map(|c| format!("did you mean \"{c}\"?"))
            .unwrap_or_else(|| "pbrt-v3 has \"homogeneous\" and \"heterogeneous\"".into());
        ctx.warn(
            ty_name.loc,
            format!("{what}: unknown medium type \"{}\": the medium is not defined (as pbrt-v3); {help}", ty_name.value),
            "not a medium type",
        );
        return None;
    }
    let read = kinds::read(ctx, &family, &ty_name, p)?;
    let input = MediumInput {
        name: &name.value,
        ctm,
    };
    let built = (read.kind.build)(
        &read.params,
        &input,
        &mut StatementReport {
            ctx,
            at: name.loc,
            params: p,
        },
    );
    if built.is_none() {
        p.mark_all_used();
    }
    ctx.report_unused_with_specs(p, &what, &["type"], read.kind.params);
    built
}
