//! A statement of a table-driven family (`PixelFilter "gaussian" …`,
//! `LightSource "spot" …`): its kind found in the family's table (with
//! "did you mean" for an unknown name), its parameters read through the
//! kind's `ParamSpec` list with pbrt-v3's defaults, the unused ones
//! reported, and a [`Report`] that locates what the kind's builder says.

use super::params::Textures;
use super::params::{read_params, Lookup};
use super::Ctx;
use crate::lang::params::ParamList;
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::scene::kind::closest_name;
use crate::scene::kind::{self, Kind, Report};
use crate::scene::ParamValues;

/// What pbrt-v3 does with a type name it does not know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unknown {
    /// A fatal error (filters, samplers, integrators, cameras).
    Error,
    /// A warning, and the statement is ignored (lights, shapes).
    Warn,
}

/// One family's statement word and pbrt-v3's behaviour, for messages.
pub struct Family<B: 'static> {
    /// The directive, e.g. `PixelFilter`.
    pub directive: &'static str,
    /// What one kind is called in messages, e.g. `filter`.
    pub noun: &'static str,
    pub table: &'static [Kind<B>],
    pub unknown: Unknown,
}

/// A statement read through its kind's table.
pub struct Read<B: 'static> {
    pub kind: &'static Kind<B>,
    pub params: ParamValues,
}

/// Finds the kind of `name` in the family's table and reads the
/// statement's parameters through its `ParamSpec` list. An unknown name is
/// reported as pbrt-v3 does (error or warning, with "did you mean"), its
/// parameters marked used, and `None` returned. An unsupported kind is
/// returned like any other: its builder decides what pbrs does instead,
/// and says so.
pub fn read<B>(ctx: &mut Ctx, family: &Family<B>, name: &Name, p: &ParamList) -> Option<Read<B>> {
    let Some(kind) = kind::find(family.table, &name.value) else {
        p.mark_all_used();
        let names = kind::names(family.table);
        let known = family
            .table
            .iter()
            .map(|k| k.name)
            .collect::<Vec<_>>()
            .join(", ");
        let hint = closest_name(&name.value, &names)
            .map(|c| format!("did you mean \"{c}\"?"))
            .unwrap_or_else(|| format!("pbrt-v3 has {known}"));
        let msg = format!("unknown {} \"{}\" ({hint})", family.noun, name.value);
        let label = format!("unknown {}", family.noun);
        match family.unknown {
            Unknown::Error => ctx.error(name.loc, msg, label, None),
            Unknown::Warn => ctx.warn(name.loc, format!("{msg}: ignored"), label),
        }
        return None;
    };
    let textures = Textures::default();
    let lookup = Lookup {
        first: None,
        second: p,
        textures: &textures,
    };
    let (params, _) = read_params(ctx, kind.params, &lookup);
    Some(Read { kind, params })
}

/// Reports pbrt-v3's unused-parameter warnings for a statement read with
/// [`read`] (after its builder ran: a builder may read more).
pub fn report_unused<B>(
    ctx: &mut Ctx,
    family: &Family<B>,
    r: &Read<B>,
    name: &Name,
    p: &ParamList,
) {
    ctx.report_unused_with_specs(
        p,
        &format!("{} \"{}\"", family.directive, name.value),
        &[],
        r.kind.params,
    );
}

/// The [`Report`] of one statement: a parameter's message at its values,
/// the others at the statement's type name.
pub struct StatementReport<'a> {
    pub ctx: &'a mut Ctx,
    pub at: Loc,
    pub params: &'a ParamList,
}

impl StatementReport<'_> {
    fn loc(&self, param: Option<&str>) -> Loc {
        param
            .and_then(|n| self.params.get(n))
            .map_or(self.at, |q| q.values_loc)
    }
}

impl Report for StatementReport<'_> {
    fn warn(&mut self, at: Option<&str>, msg: String, label: &str) {
        let loc = self.loc(at);
        self.ctx.warn(loc, msg, label);
    }
    fn error(&mut self, at: Option<&str>, msg: String, label: &str) {
        let loc = self.loc(at);
        self.ctx.error(loc, msg, label, None);
    }
}

/// The builder shape of the families whose kinds need nothing but their
/// parameters (filters, samplers, integrators).
pub type PlainBuild<T> = fn(&ParamValues, &mut dyn Report) -> T;

/// Reads a statement of such a family and builds it; `None` for an unknown
/// kind (already reported).
pub fn build<T>(
    ctx: &mut Ctx,
    family: &Family<PlainBuild<T>>,
    name: &Name,
    p: &ParamList,
) -> Option<T> {
    let r = read(ctx, family, name, p)?;
    let built = (r.kind.build)(
        &r.params,
        &mut StatementReport {
            ctx,
            at: name.loc,
            params: p,
        },
    );
    report_unused(ctx, family, &r, name, p);
    Some(built)
}

/// A [`Report`] that keeps messages in order, to be replayed into a
/// statement's report once the context is free (a builder that also reads
/// files through the context).
#[derive(Default)]
pub struct Buffered {
    messages: Vec<(bool, Option<String>, String, String)>,
}

impl Report for Buffered {
    fn warn(&mut self, at: Option<&str>, msg: String, label: &str) {
        self.messages
            .push((false, at.map(str::to_string), msg, label.to_string()));
    }
    fn error(&mut self, at: Option<&str>, msg: String, label: &str) {
        self.messages
            .push((true, at.map(str::to_string), msg, label.to_string()));
    }
}

impl Buffered {
    pub fn replay(self, to: &mut dyn Report) {
        for (error, at, msg, label) in self.messages {
            if error {
                to.error(at.as_deref(), msg, &label);
            } else {
                to.warn(at.as_deref(), msg, &label);
            }
        }
    }
}
