//! `grammar/pbrt.ebnf` and `grammar/REFERENCE.md` are kept in step with the parser:
//! the directive names, their operands and the parameter types must match
//! the tables in `src/lang`.

use pbrs::lang::params::TYPE_NAMES;
use pbrs::lang::parse_text;
use pbrs::lang::parser::{DirKind, DiskLoader, DIRECTIVES};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn grammar() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/pbrt.ebnf"))
        .unwrap()
}

/// The rules of the grammar: name -> body (comments removed).
fn rules() -> BTreeMap<String, String> {
    let mut g = grammar();
    while let Some(s) = g.find("(*") {
        let e = g[s..].find("*)").map(|e| s + e + 2).unwrap_or(g.len());
        g.replace_range(s..e, " ");
    }
    let mut out = BTreeMap::new();
    for rule in g.split(';') {
        if let Some((name, body)) = rule.split_once('=') {
            out.insert(name.trim().to_string(), body.to_string());
        }
    }
    out
}

/// Double-quoted literals of a rule body.
fn literals(body: &str) -> Vec<String> {
    body.split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

const STATEMENT_RULES: &[&str] = &[
    "plain",
    "numeric",
    "bracketed",
    "named",
    "include",
    "active",
    "medium",
    "texture",
    "entity",
];
const ACTIVE_WORDS: &[&str] = &["All", "StartTime", "EndTime"];

fn grammar_directives() -> BTreeSet<String> {
    let r = rules();
    STATEMENT_RULES
        .iter()
        .flat_map(|n| literals(r.get(*n).unwrap_or_else(|| panic!("rule {n} missing"))))
        .filter(|l| {
            l.starts_with(|c: char| c.is_ascii_uppercase()) && !ACTIVE_WORDS.contains(&l.as_str())
        })
        .collect()
}

#[test]
fn directives_match_the_parser_table() {
    let parser: BTreeSet<String> = DIRECTIVES.iter().map(|(n, _)| n.to_string()).collect();
    let grammar = grammar_directives();
    assert_eq!(grammar, parser, "grammar/pbrt.ebnf and DIRECTIVES differ");
    assert_eq!(parser.len(), 37, "pbrt-v3 has 37 directives");
}

#[test]
fn parameter_types_match() {
    let r = rules();
    let grammar: BTreeSet<String> = literals(&r["type"]).into_iter().collect();
    let parser: BTreeSet<String> = TYPE_NAMES.iter().map(|(n, _)| n.to_string()).collect();
    assert_eq!(grammar, parser);
}

fn parses(text: &str) -> bool {
    let (_, _, d) = parse_text(text, Path::new("g.pbrt"), &DiskLoader);
    d.errors.is_empty()
}

/// Every directive's operands as the grammar states them are what the parser takes.
#[test]
fn operands_match() {
    let r = rules();
    let mut checked = 0;
    // numeric: `"Name" , N * number`
    for part in r["numeric"].split('|') {
        let name = literals(part)[0].clone();
        let n: usize = part
            .split(',')
            .nth(1)
            .unwrap()
            .split('*')
            .next()
            .unwrap()
            .trim()
            .parse()
            .unwrap();
        let nums = |k: usize| vec!["1"; k].join(" ");
        assert!(
            parses(&format!("{name} {}", nums(n))),
            "{name} with {n} numbers"
        );
        assert!(
            !parses(&format!("{name} {}", nums(n - 1))),
            "{name} with {} numbers",
            n - 1
        );
        assert!(
            !parses(&format!("{name} [ {} ]", nums(n))),
            "{name} with brackets"
        );
        checked += 1;
    }
    for name in literals(&r["bracketed"]) {
        if name == "[" || name == "]" {
            continue;
        }
        let nums = |k: usize| vec!["1"; k].join(" ");
        assert!(parses(&format!("{name} [ {} ]", nums(16))), "{name}");
        assert!(!parses(&format!("{name} [ {} ]", nums(15))), "{name} 15");
        assert!(
            !parses(&format!("{name} {}", nums(16))),
            "{name} without brackets"
        );
        checked += 1;
    }
    for name in literals(&r["plain"]) {
        assert!(parses(&name), "{name}");
        checked += 1;
    }
    for name in literals(&r["named"]) {
        assert!(parses(&format!("{name} \"x\"")), "{name}");
        assert!(!parses(&name), "{name} without operand");
        checked += 1;
    }
    for w in ACTIVE_WORDS {
        assert!(parses(&format!("ActiveTransform {w}")));
    }
    assert!(!parses("ActiveTransform \"All\""));
    assert!(parses("MediumInterface \"a\"") && parses("MediumInterface \"a\" \"b\""));
    assert!(parses(
        "Texture \"t\" \"float\" \"constant\" \"float value\" 1"
    ));
    for name in literals(&r["entity"]) {
        assert!(
            parses(&format!("{name} \"x\" \"float a\" 1 \"string b\" [\"c\"]")),
            "{name}"
        );
        checked += 1;
    }
    assert_eq!(
        checked + 4,
        DIRECTIVES.len(),
        "Include, ActiveTransform, MediumInterface, Texture are checked apart"
    );
    let _ = DirKind::Include;
}

#[test]
fn reference_documents_every_directive_and_type() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let reference =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md"))
            .unwrap();
    for (n, _) in DIRECTIVES {
        assert!(
            reference.contains(&format!("`{n}`")),
            "REFERENCE.md lacks `{n}`"
        );
    }
    for (n, _) in TYPE_NAMES {
        assert!(
            reference.contains(&format!("`{n}`")),
            "REFERENCE.md lacks type `{n}`"
        );
    }
}

/// The material section of REFERENCE.md is what the generator writes from
/// `materials::MATERIALS`; with `PBRS_WRITE_REFERENCE=1` the test
/// rewrites it instead (then review and commit the diff).
#[test]
fn reference_material_section_is_generated_from_the_table() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use pbrs::loader::reference::{materials_section, splice, MATERIALS_BEGIN, MATERIALS_END};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let section = materials_section();
    let Some(expected) = splice(&doc, &section) else {
        panic!("REFERENCE.md lacks the lines {MATERIALS_BEGIN:?} and, after it, {MATERIALS_END:?}");
    };
    if std::env::var_os("PBRS_WRITE_REFERENCE").is_some_and(|v| v == "1") {
        if expected != doc {
            std::fs::write(&path, &expected).unwrap();
        }
        return;
    }
    if expected != doc {
        let first = doc
            .lines()
            .zip(expected.lines())
            .position(|(a, b)| a != b)
            .map_or_else(|| "(line count)".to_string(), |i| format!("line {}", i + 1));
        panic!(
            "grammar/REFERENCE.md's material section differs from the material table at {first}; \
             regenerate it with `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` \
             and commit the diff"
        );
    }
    // What the section must say, read from the table itself (so that a
    // generator that dropped rows would fail here too).
    for k in pbrs::materials::MATERIALS {
        assert!(section.contains(&format!("`{}`", k.name)), "{}", k.name);
        for p in k.params {
            let (ty, default) = pbrs::loader::reference::describe(p);
            let row = format!("| `{}` | {ty} | {default} |", p.name);
            assert!(section.contains(&row), "{}: no row {row:?}", k.name);
        }
    }
}

/// The integrators section of REFERENCE.md is what the generator writes
/// from `integrators::INTEGRATORS` (`PBRS_WRITE_REFERENCE=1`
/// rewrites it).
#[test]
fn reference_integrators_section_is_generated_from_the_table() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use pbrs::loader::reference::{
        integrators_section, splice_between, INTEGRATORS_BEGIN, INTEGRATORS_END,
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let section = integrators_section();
    let Some(expected) = splice_between(&doc, &section, INTEGRATORS_BEGIN, INTEGRATORS_END) else {
        panic!(
            "REFERENCE.md lacks the lines {INTEGRATORS_BEGIN:?} and, after it, {INTEGRATORS_END:?}"
        );
    };
    if std::env::var_os("PBRS_WRITE_REFERENCE").is_some_and(|v| v == "1") {
        if expected != doc {
            std::fs::write(&path, &expected).unwrap();
        }
        return;
    }
    assert!(
        expected == doc,
        "grammar/REFERENCE.md's integrators section differs from the integrator table; regenerate it with \
         `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` and commit the diff"
    );
    for k in pbrs::integrators::INTEGRATORS {
        assert!(section.contains(&format!("`{}`", k.name)), "{}", k.name);
        for p in k.params.iter().filter(|_| k.is_supported()) {
            assert!(section.contains(&format!("| `{}` |", p.name)), "{}", p.name);
        }
    }
}

/// The media section of REFERENCE.md is what the generator writes from
/// `media::MEDIA` (`PBRS_WRITE_REFERENCE=1` rewrites it).
#[test]
fn reference_media_section_is_generated_from_the_table() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use pbrs::loader::reference::{media_section, splice_between, MEDIA_BEGIN, MEDIA_END};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let section = media_section();
    let Some(expected) = splice_between(&doc, &section, MEDIA_BEGIN, MEDIA_END) else {
        panic!("REFERENCE.md lacks the lines {MEDIA_BEGIN:?} and, after it, {MEDIA_END:?}");
    };
    if std::env::var_os("PBRS_WRITE_REFERENCE").is_some_and(|v| v == "1") {
        if expected != doc {
            std::fs::write(&path, &expected).unwrap();
        }
        return;
    }
    assert!(
        expected == doc,
        "grammar/REFERENCE.md's media section differs from the media table; regenerate it with \
         `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` and commit the diff"
    );
    for k in pbrs::media::MEDIA {
        assert!(section.contains(&format!("### `{}`", k.name)), "{}", k.name);
        for p in k.params {
            assert!(
                section.contains(&format!("| `{}` |", p.name)),
                "{}: {}",
                k.name,
                p.name
            );
        }
    }
}

/// Every family's generated section of REFERENCE.md is what the generator
/// writes from its table (`PBRS_WRITE_REFERENCE=1` rewrites them), and
/// lists every kind and parameter of the table.
#[test]
fn reference_family_sections_are_generated_from_the_tables() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use pbrs::loader::reference::{markers, splice_between};
    type Section = (
        &'static str,
        &'static str,
        fn() -> String,
        Vec<(&'static str, Vec<&'static str>)>,
    );
    fn rows<B>(t: &'static [pbrs::scene::Kind<B>]) -> Vec<(&'static str, Vec<&'static str>)> {
        t.iter()
            .map(|k| (k.name, k.params.iter().map(|p| p.name).collect()))
            .collect()
    }
    let sections: Vec<Section> = vec![
        (
            "filters::FILTERS",
            "filters",
            pbrs::loader::reference::filters_section,
            rows(pbrs::filters::FILTERS),
        ),
        (
            "samplers::SAMPLERS",
            "samplers",
            pbrs::loader::reference::samplers_section,
            rows(pbrs::samplers::SAMPLERS),
        ),
        (
            "cameras::CAMERAS",
            "cameras",
            pbrs::loader::reference::cameras_section,
            rows(pbrs::cameras::CAMERAS),
        ),
        (
            "shapes::SHAPES",
            "shapes",
            pbrs::loader::reference::shapes_section,
            rows(pbrs::shapes::SHAPES),
        ),
    ];
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md");
    let write = std::env::var_os("PBRS_WRITE_REFERENCE").is_some_and(|v| v == "1");
    for (table, noun, make, kinds) in sections {
        let doc = std::fs::read_to_string(&path).unwrap();
        let (begin, end) = markers(table, noun);
        let section = make();
        let Some(expected) = splice_between(&doc, &section, &begin, &end) else {
            panic!("REFERENCE.md lacks the lines {begin:?} and, after it, {end:?}");
        };
        if write {
            if expected != doc {
                std::fs::write(&path, &expected).unwrap();
            }
            continue;
        }
        assert!(
            expected == doc,
            "grammar/REFERENCE.md's {noun} section differs from {table}; regenerate it with \
             `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` and commit the diff"
        );
        for (name, params) in kinds {
            assert!(section.contains(&format!("`{name}`")), "{noun}: {name}");
            for p in params {
                assert!(
                    section.contains(&format!("| `{p}` |")),
                    "{noun} {name}: {p}"
                );
            }
        }
    }
}

/// The lights section of REFERENCE.md is what the generator writes from
/// `lights::LIGHTS` and `AREA_LIGHTS` (`PBRS_WRITE_REFERENCE=1`
/// rewrites it).
#[test]
fn reference_lights_section_is_generated_from_the_tables() {
    let _one_writer = REFERENCE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    use pbrs::lights::{AREA_LIGHTS, LIGHTS};
    use pbrs::loader::reference::{lights_section, splice_between, LIGHTS_BEGIN, LIGHTS_END};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("grammar/REFERENCE.md");
    let doc = std::fs::read_to_string(&path).unwrap();
    let section = lights_section();
    let Some(expected) = splice_between(&doc, &section, LIGHTS_BEGIN, LIGHTS_END) else {
        panic!("REFERENCE.md lacks the lines {LIGHTS_BEGIN:?} and, after it, {LIGHTS_END:?}");
    };
    if std::env::var_os("PBRS_WRITE_REFERENCE").is_some_and(|v| v == "1") {
        if expected != doc {
            std::fs::write(&path, &expected).unwrap();
        }
        return;
    }
    assert!(
        expected == doc,
        "grammar/REFERENCE.md's lights section differs from the light tables; regenerate it with \
         `PBRS_WRITE_REFERENCE=1 cargo test --release --test lang_grammar` and commit the diff"
    );
    let kinds = LIGHTS
        .iter()
        .map(|k| (k.name, k.params, k.is_supported()))
        .chain(
            AREA_LIGHTS
                .iter()
                .map(|k| (k.name, k.params, k.is_supported())),
        );
    for (name, params, supported) in kinds {
        assert!(section.contains(&format!("`{name}`")), "{name}");
        if supported {
            for p in params {
                assert!(
                    section.contains(&format!("| `{}` |", p.name)),
                    "{name}: {}",
                    p.name
                );
            }
        }
    }
}

/// The reference tests read, and with `PBRS_WRITE_REFERENCE=1` rewrite,
/// one file: one at a time.
static REFERENCE_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
