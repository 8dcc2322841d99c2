//! The parts of `grammar/REFERENCE.md` written from the tables, so that the
//! reference cannot drift from what the loader reads: the material section
//! comes from [`MATERIALS`] (every kind, its parameters, their types and
//! pbrt-v3's defaults). `tests/lang_grammar.rs` checks that the committed file
//! holds exactly what [`materials_section`] writes, and rewrites it when
//! `PBRS_WRITE_REFERENCE=1` is set.

use super::color::sampled_to_rgb;
use crate::materials::{MaterialKind, Support, MATERIALS};
use crate::scene::{ParamKind, ParamSpec, Range, SpectrumDefault};
use std::fmt::Write;

/// The line that opens the generated material section.
pub const MATERIALS_BEGIN: &str = "<!-- BEGIN generated from materials::MATERIALS: edit the tables, then run `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` -->";
/// The line that closes it.
pub const MATERIALS_END: &str = "<!-- END generated materials -->";

/// Every material type pbrt-v3's `MakeMaterial` knows (`""` aside), for
/// naming the ones the table does not have yet.
pub const PBRT_V3_MATERIALS: &[&str] = &[
    "matte",
    "plastic",
    "translucent",
    "glass",
    "mirror",
    "hair",
    "disney",
    "mix",
    "metal",
    "substrate",
    "uber",
    "subsurface",
    "kdsubsurface",
    "fourier",
    "none",
];

/// The material section, between its markers (both included), from the table.
pub fn materials_section() -> String {
    let mut out = String::new();
    out.push_str(MATERIALS_BEGIN);
    out.push('\n');
    let (supported, unsupported): (Vec<&MaterialKind>, Vec<&MaterialKind>) = MATERIALS
        .iter()
        .partition(|k| k.support == Support::Supported);
    for k in &supported {
        write_kind(&mut out, k);
    }
    if !unsupported.is_empty() {
        out.push_str("\n### Known to pbrt-v3, not rendered by pbrs\n\n");
        out.push_str("A warning names the reason; the material is replaced by a `matte` with the material's `Kd` (else 0.5), and its other parameters are not reported as unused.\n\n");
        out.push_str("| type | why |\n|---|---|\n");
        for k in &unsupported {
            if let Support::Unsupported(why) = k.support {
                let _ = writeln!(out, "| `{}` | {} |", k.name, cell(why));
            }
        }
    }
    let missing: Vec<String> = PBRT_V3_MATERIALS
        .iter()
        .filter(|n| !MATERIALS.iter().any(|k| k.name == **n))
        .map(|n| format!("`{n}`"))
        .collect();
    out.push_str("\n### Other types\n\n");
    if !missing.is_empty() {
        let _ = writeln!(
            out,
            "pbrt-v3 types pbrs does not know yet: {}. These and any other unknown type give a warning (with a \"did you mean\" when a known type is close) and are read as a `matte` with the material's parameters, as pbrt-v3 does for an unknown type.",
            missing.join(", ")
        );
    } else {
        out.push_str("An unknown type gives a warning (with a \"did you mean\" when a known type is close) and is read as a `matte` with the material's parameters, as pbrt-v3 does.\n");
    }
    out.push('\n');
    out.push_str(MATERIALS_END);
    out.push('\n');
    out
}

fn write_kind(out: &mut String, k: &MaterialKind) {
    let title = if k.name == "none" {
        "`none` (or `\"\"`)".to_string()
    } else {
        format!("`{}`", k.name)
    };
    let _ = write!(out, "\n### {title}\n\n{}\n", sentence(k.doc));
    if k.params.is_empty() {
        out.push_str("\nNo parameters.\n");
        return;
    }
    out.push_str("\n| parameter | type | default | meaning |\n|---|---|---|---|\n");
    for p in k.params {
        let (ty, default) = describe(p);
        let meaning = match p.kind {
            ParamKind::Unsupported(why) => format!("warning: {why}"),
            _ => p.doc.to_string(),
        };
        let _ = writeln!(
            out,
            "| `{}` | {ty} | {default} | {} |",
            p.name,
            cell(&meaning)
        );
    }
}

/// The type column and the default column of one parameter.
pub fn describe(p: &ParamSpec) -> (String, String) {
    let nonneg = if p.range == Range::NonNegative {
        ", ≥ 0 (else warning, 0)"
    } else {
        ""
    };
    let (ty, default) = match p.kind {
        ParamKind::FloatTexture(d) => ("float texture".to_string(), d.map(num)),
        ParamKind::SpectrumTexture(d) => ("spectrum texture".to_string(), d.map(spectrum)),
        ParamKind::Float(d) => ("float".to_string(), Some(num(d))),
        ParamKind::FloatOpt => ("float".to_string(), None),
        ParamKind::Bool(d) => ("bool".to_string(), Some(format!("`{d}`"))),
        ParamKind::String(d) => ("string".to_string(), Some(format!("`\"{d}\"`"))),
        ParamKind::NamedMaterial => ("string: a named material".to_string(), None),
        ParamKind::FourierFile => ("string: a `.bsdf` file".to_string(), None),
        ParamKind::Unsupported(_) => ("any".to_string(), None),
        ParamKind::BoolOpt => ("bool".to_string(), None),
        ParamKind::Int(d) => ("integer".to_string(), Some(format!("{d}"))),
        ParamKind::Vector3([x, y, z]) => (
            "vector3".to_string(),
            Some(format!("{} {} {}", num(x), num(y), num(z))),
        ),
        ParamKind::Choice { default, options } => {
            let list: Vec<String> = options.iter().map(|o| format!("`\"{o}\"`")).collect();
            (
                format!("string: one of {}", list.join(", ")),
                Some(format!("`\"{default}\"`")),
            )
        }
        ParamKind::Filename => ("string: a file name".to_string(), None),
        ParamKind::SameTexture(d) => ("texture of the texture's type".to_string(), Some(num(d))),
        ParamKind::SameValue(d) => ("value of the texture's type".to_string(), Some(num(d))),
        ParamKind::Spectrum(d) => (
            "spectrum".to_string(),
            Some(spectrum(SpectrumDefault::Rgb(d))),
        ),
        ParamKind::Point3([x, y, z]) => (
            "point3".to_string(),
            Some(format!("{} {} {}", num(x), num(y), num(z))),
        ),
        ParamKind::Floats => ("float list".to_string(), None),
        ParamKind::SpectrumOrFloat(d) => (
            "spectrum or float".to_string(),
            Some(spectrum(SpectrumDefault::Rgb(d))),
        ),
        ParamKind::IntOpt => ("integer".to_string(), None),
        ParamKind::Image(_) => ("string: an image file".to_string(), None),
        ParamKind::List(e) => (format!("{} values", e.name()), None),
    };
    (
        format!("{ty}{nonneg}"),
        default.unwrap_or_else(|| "—".into()),
    )
}

fn num(v: f32) -> String {
    format!("{v}")
}

fn spectrum(d: SpectrumDefault) -> String {
    match d {
        SpectrumDefault::Rgb([r, g, b]) if r == g && g == b => num(r),
        SpectrumDefault::Rgb([r, g, b]) => format!("rgb {} {} {}", num(r), num(g), num(b)),
        SpectrumDefault::Sampled { lambda, values } => {
            let pairs: Vec<f64> = lambda
                .iter()
                .zip(values)
                .flat_map(|(&l, &v)| [l as f64, v as f64])
                .collect();
            let c = sampled_to_rgb(&pairs);
            format!(
                "measured spectrum, {} samples (rgb {:.4} {:.4} {:.4})",
                lambda.len(),
                c.x,
                c.y,
                c.z
            )
        }
    }
}

/// A doc string as a sentence: capitalised, with a full stop.
fn sentence(s: &str) -> String {
    let mut c = s.chars();
    let mut out = match c.next() {
        Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
        None => String::new(),
    };
    if !out.ends_with('.') {
        out.push('.');
    }
    out
}

/// Text safe inside a Markdown table cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// `doc` with its generated material section replaced by `section`, or
/// `None` when the markers are missing or out of order.
pub fn splice(doc: &str, section: &str) -> Option<String> {
    splice_between(doc, section, MATERIALS_BEGIN, MATERIALS_END)
}

/// The line that opens the generated media section.
pub const MEDIA_BEGIN: &str = "<!-- BEGIN generated from media::MEDIA: edit the tables, then run `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` -->";
/// The line that closes it.
pub const MEDIA_END: &str = "<!-- END generated media -->";

/// The media section, between its markers (both included), from
/// [`MEDIA`](crate::media::MEDIA).
pub fn media_section() -> String {
    let mut out = String::new();
    out.push_str(MEDIA_BEGIN);
    out.push('\n');
    for k in crate::media::MEDIA {
        let _ = write!(out, "\n### `{}`\n\n{}\n", k.name, sentence(k.doc));
        out.push_str("\n| parameter | type | default | meaning |\n|---|---|---|---|\n");
        for p in k.params {
            let (ty, default) = describe(p);
            let _ = writeln!(out, "| `{}` | {ty} | {default} | {} |", p.name, cell(p.doc));
        }
    }
    out.push('\n');
    out.push_str(MEDIA_END);
    out.push('\n');
    out
}

/// The markers around a family's generated section: `<!-- BEGIN generated
/// from TABLE … -->` and `<!-- END generated NOUN -->`.
pub fn markers(table: &str, noun: &str) -> (String, String) {
    (
        format!("<!-- BEGIN generated from {table}: edit the tables, then run `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` -->"),
        format!("<!-- END generated {noun} -->"),
    )
}

/// A family's section from its table: each kind (with its aliases) and
/// its parameters, then the kinds known to pbrt-v3 that pbrs does not
/// render, with the reason.
pub fn kinds_section<B>(
    (begin, end): (&str, &str),
    table: &'static [crate::scene::Kind<B>],
) -> String {
    let mut out = format!("{begin}\n");
    for k in table.iter().filter(|k| k.is_supported()) {
        let mut names = vec![format!("`{}`", k.name)];
        names.extend(k.aliases.iter().map(|a| format!("`{a}`")));
        let _ = write!(out, "\n### {}\n\n{}\n", names.join(" = "), sentence(k.doc));
        if k.params.is_empty() {
            out.push_str("\nNo parameters.\n");
            continue;
        }
        out.push_str("\n| parameter | type | default | meaning |\n|---|---|---|---|\n");
        for p in k.params {
            let (ty, default) = describe(p);
            let _ = writeln!(out, "| `{}` | {ty} | {default} | {} |", p.name, cell(p.doc));
        }
    }
    let unsupported: Vec<_> = table.iter().filter(|k| !k.is_supported()).collect();
    if !unsupported.is_empty() {
        out.push_str("\n### Known to pbrt-v3, not rendered by pbrs\n\n| type | what pbrs does |\n|---|---|\n");
        for k in unsupported {
            let mut names = vec![format!("`{}`", k.name)];
            names.extend(k.aliases.iter().map(|a| format!("`{a}`")));
            let _ = writeln!(
                out,
                "| {} | {} |",
                names.join(", "),
                cell(k.unsupported().unwrap_or(""))
            );
        }
    }
    out.push('\n');
    out.push_str(end);
    out.push('\n');
    out
}

/// The filter section, from [`FILTERS`](crate::filters::FILTERS).
pub fn filters_section() -> String {
    let (b, e) = markers("filters::FILTERS", "filters");
    kinds_section((&b, &e), crate::filters::FILTERS)
}

/// The sampler section, from [`SAMPLERS`](crate::samplers::SAMPLERS).
pub fn samplers_section() -> String {
    let (b, e) = markers("samplers::SAMPLERS", "samplers");
    kinds_section((&b, &e), crate::samplers::SAMPLERS)
}

/// The camera section, from [`CAMERAS`](crate::cameras::CAMERAS).
pub fn cameras_section() -> String {
    let (b, e) = markers("cameras::CAMERAS", "cameras");
    kinds_section((&b, &e), crate::cameras::CAMERAS)
}

/// The line that opens the generated lights section.
pub const LIGHTS_BEGIN: &str = "<!-- BEGIN generated from lights::LIGHTS and AREA_LIGHTS: edit the tables, then run `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` -->";
/// The line that closes it.
pub const LIGHTS_END: &str = "<!-- END generated lights -->";

/// The lights section, between its markers (both included), from
/// [`LIGHTS`](crate::lights::LIGHTS) (`LightSource`) and
/// [`AREA_LIGHTS`](crate::lights::AREA_LIGHTS) (`AreaLightSource`).
pub fn lights_section() -> String {
    use crate::lights::{AREA_LIGHTS, LIGHTS};
    use crate::scene::Kind;
    fn title<B>(k: &Kind<B>) -> String {
        let mut t = format!("`{}`", k.name);
        for a in k.aliases {
            let _ = write!(t, " (alias `{a}`)");
        }
        t
    }
    fn kind<B>(out: &mut String, what: &str, k: &Kind<B>) {
        let _ = write!(out, "\n### {what} {}\n\n{}\n", title(k), sentence(k.doc));
        out.push_str("\n| parameter | type | default | meaning |\n|---|---|---|---|\n");
        for p in k.params {
            let (ty, default) = describe(p);
            let _ = writeln!(out, "| `{}` | {ty} | {default} | {} |", p.name, cell(p.doc));
        }
    }
    let mut out = String::new();
    out.push_str(LIGHTS_BEGIN);
    out.push('\n');
    for k in LIGHTS.iter().filter(|k| k.is_supported()) {
        kind(&mut out, "LightSource", k);
    }
    for k in AREA_LIGHTS.iter().filter(|k| k.is_supported()) {
        kind(&mut out, "AreaLightSource", k);
    }
    out.push_str("\n### Known to pbrt-v3, not rendered by pbrs\n\n");
    out.push_str("A warning (`light \"…\" is not supported by pbrs: ignored`), and the light is skipped; its parameters are not reported as unused.\n\n");
    out.push_str("| type | what it is |\n|---|---|\n");
    let unsupported = LIGHTS
        .iter()
        .filter_map(|k| Some((k.name, k.unsupported()?)))
        .chain(
            AREA_LIGHTS
                .iter()
                .filter_map(|k| Some((k.name, k.unsupported()?))),
        );
    for (name, why) in unsupported {
        let _ = writeln!(out, "| `{name}` | {} |", cell(why));
    }
    out.push_str("\nAn unknown `LightSource` type gives a warning (with a \"did you mean\" when a known type is close) and is ignored; an unknown `AreaLightSource` type gives a warning, and the shapes after it in its scope do not emit.\n");
    out.push('\n');
    out.push_str(LIGHTS_END);
    out.push('\n');
    out
}

/// The shape section, from [`SHAPES`](crate::shapes::SHAPES).
pub fn shapes_section() -> String {
    let (b, e) = markers("shapes::SHAPES", "shapes");
    kinds_section((&b, &e), crate::shapes::SHAPES)
}

/// The line that opens the generated integrators section.
pub const INTEGRATORS_BEGIN: &str = "<!-- BEGIN generated from integrators::INTEGRATORS: edit the tables, then run `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` -->";
/// The line that closes it.
pub const INTEGRATORS_END: &str = "<!-- END generated integrators -->";

/// The integrators section, between its markers (both included), from
/// [`INTEGRATORS`](crate::integrators::INTEGRATORS).
pub fn integrators_section() -> String {
    use crate::integrators::INTEGRATORS;
    let mut out = String::new();
    out.push_str(INTEGRATORS_BEGIN);
    out.push('\n');
    for k in INTEGRATORS.iter().filter(|k| k.is_supported()) {
        let _ = write!(out, "\n### `{}`\n\n{}\n", k.name, sentence(k.doc));
        out.push_str("\n| parameter | type | default | meaning |\n|---|---|---|---|\n");
        for p in k.params {
            let (ty, default) = describe(p);
            let _ = writeln!(out, "| `{}` | {ty} | {default} | {} |", p.name, cell(p.doc));
        }
    }
    out.push_str("\n### Known to pbrt-v3, not rendered by pbrs\n\n");
    out.push_str("A warning says so; `path` renders the scene instead, with the statement's `maxdepth` (its other parameters are not reported as unused).\n\n");
    out.push_str("| type | why |\n|---|---|\n");
    for k in INTEGRATORS {
        if let Some(why) = k.unsupported() {
            let _ = writeln!(out, "| `{}` | {} |", k.name, cell(why));
        }
    }
    out.push_str("\n### Other types\n\nAn unknown type is an error (with a \"did you mean\" when a known type is close), as in pbrt-v3. A negative `maxdepth` is an error.\n");
    out.push('\n');
    out.push_str(INTEGRATORS_END);
    out.push('\n');
    out
}

/// `doc` with the part from the line `begin_marker` to the line
/// `end_marker` (both included) replaced by `section`.
pub fn splice_between(
    doc: &str,
    section: &str,
    begin_marker: &str,
    end_marker: &str,
) -> Option<String> {
    let begin = doc.find(begin_marker)?;
    let end = doc[begin..].find(end_marker)? + begin + end_marker.len();
    let end = if doc[end..].starts_with('\n') {
        end + 1
    } else {
        end
    };
    Some(format!("{}{section}{}", &doc[..begin], &doc[end..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_and_parameter_is_listed() {
        let s = materials_section();
        for k in MATERIALS {
            assert!(s.contains(&format!("`{}`", k.name)), "{}", k.name);
            for p in k.params {
                assert!(s.contains(&format!("| `{}` |", p.name)), "{}", p.name);
            }
        }
        assert!(s.contains("| `Kd` | spectrum texture | 0.5 |"), "{s}");
        assert!(s.contains("| `sigma` | float texture, ≥ 0"), "{s}");
    }

    #[test]
    fn splice_replaces_only_the_section() {
        let doc = format!("a\n{MATERIALS_BEGIN}\nold\n{MATERIALS_END}\nb\n");
        assert_eq!(splice(&doc, "NEW\n").as_deref(), Some("a\nNEW\nb\n"));
        assert_eq!(splice("no markers", "x"), None);
        assert_eq!(
            splice(&format!("{MATERIALS_END}\n{MATERIALS_BEGIN}"), "x"),
            None
        );
    }
}
