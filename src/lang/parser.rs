//! Directives: tokens to a list of typed statements, each with its location.
//! `Include` splices the included file's tokens into the stream (parser.cpp:798-829),
//! so a parameter list may continue after the Include line in the parent.
//! A directive's parameter list is read in `parser/param_list.rs`.

use super::lexer::{dequote, parse_number, Lexer, NumError, TokKind, Token};
use super::params::{split_declaration, Param, ParamList, ParamType, Values, TYPE_NAMES};
use super::source::{Loc, SourceMap};
use super::Diags;
use miette::Severity;
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod param_list;

/// Every directive of pbrt-v3 (parser.cpp:857-1091).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DirKind {
    Accelerator,
    ActiveTransform,
    AreaLightSource,
    AttributeBegin,
    AttributeEnd,
    Camera,
    ConcatTransform,
    CoordinateSystem,
    CoordSysTransform,
    Film,
    Identity,
    Include,
    Integrator,
    LightSource,
    LookAt,
    MakeNamedMaterial,
    MakeNamedMedium,
    Material,
    MediumInterface,
    NamedMaterial,
    ObjectBegin,
    ObjectEnd,
    ObjectInstance,
    PixelFilter,
    ReverseOrientation,
    Rotate,
    Sampler,
    Scale,
    Shape,
    Texture,
    Transform,
    TransformBegin,
    TransformEnd,
    TransformTimes,
    Translate,
    WorldBegin,
    WorldEnd,
}

/// The directive table: the parser's only source of directive names.
pub const DIRECTIVES: &[(&str, DirKind)] = &[
    ("Accelerator", DirKind::Accelerator),
    ("ActiveTransform", DirKind::ActiveTransform),
    ("AreaLightSource", DirKind::AreaLightSource),
    ("AttributeBegin", DirKind::AttributeBegin),
    ("AttributeEnd", DirKind::AttributeEnd),
    ("Camera", DirKind::Camera),
    ("ConcatTransform", DirKind::ConcatTransform),
    ("CoordinateSystem", DirKind::CoordinateSystem),
    ("CoordSysTransform", DirKind::CoordSysTransform),
    ("Film", DirKind::Film),
    ("Identity", DirKind::Identity),
    ("Include", DirKind::Include),
    ("Integrator", DirKind::Integrator),
    ("LightSource", DirKind::LightSource),
    ("LookAt", DirKind::LookAt),
    ("MakeNamedMaterial", DirKind::MakeNamedMaterial),
    ("MakeNamedMedium", DirKind::MakeNamedMedium),
    ("Material", DirKind::Material),
    ("MediumInterface", DirKind::MediumInterface),
    ("NamedMaterial", DirKind::NamedMaterial),
    ("ObjectBegin", DirKind::ObjectBegin),
    ("ObjectEnd", DirKind::ObjectEnd),
    ("ObjectInstance", DirKind::ObjectInstance),
    ("PixelFilter", DirKind::PixelFilter),
    ("ReverseOrientation", DirKind::ReverseOrientation),
    ("Rotate", DirKind::Rotate),
    ("Sampler", DirKind::Sampler),
    ("Scale", DirKind::Scale),
    ("Shape", DirKind::Shape),
    ("Texture", DirKind::Texture),
    ("Transform", DirKind::Transform),
    ("TransformBegin", DirKind::TransformBegin),
    ("TransformEnd", DirKind::TransformEnd),
    ("TransformTimes", DirKind::TransformTimes),
    ("Translate", DirKind::Translate),
    ("WorldBegin", DirKind::WorldBegin),
    ("WorldEnd", DirKind::WorldEnd),
];

pub fn directive_kind(name: &str) -> Option<DirKind> {
    DIRECTIVES.iter().find(|(n, _)| *n == name).map(|&(_, k)| k)
}

impl DirKind {
    pub fn name(self) -> &'static str {
        DIRECTIVES
            .iter()
            .find(|(_, k)| *k == self)
            .map(|(n, _)| *n)
            .unwrap_or("?")
    }
}

/// A quoted operand and where it was.
#[derive(Clone, Debug, PartialEq)]
pub struct Name {
    pub value: String,
    pub loc: Loc,
}

/// `ActiveTransform` operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActiveKind {
    All,
    StartTime,
    EndTime,
}

/// A directive with its operands.
#[derive(Debug)]
pub enum Directive {
    /// Directives without operands: WorldBegin, WorldEnd, AttributeBegin/End,
    /// TransformBegin/End, ObjectEnd, ReverseOrientation, Identity.
    Plain,
    /// Translate (3), Scale (3), Rotate (4), LookAt (9), Transform (16),
    /// ConcatTransform (16), TransformTimes (2).
    Numbers(Vec<f64>),
    ActiveTransform(ActiveKind),
    /// CoordinateSystem, CoordSysTransform, NamedMaterial, ObjectBegin, ObjectInstance.
    Named(Name),
    MediumInterface(Name, Option<Name>),
    Texture {
        name: Name,
        kind: Name,
        class: Name,
        params: ParamList,
    },
    /// Camera, Sampler, Film, PixelFilter, Integrator, Accelerator, Shape, Material,
    /// MakeNamedMaterial, LightSource, AreaLightSource, MakeNamedMedium.
    Entity {
        name: Name,
        params: ParamList,
    },
}

/// One statement: the directive keyword's location, its kind and operands.
#[derive(Debug)]
pub struct Stmt {
    pub kind: DirKind,
    pub loc: Loc,
    pub dir: Directive,
}

impl Stmt {
    pub fn params(&self) -> Option<&ParamList> {
        match &self.dir {
            Directive::Texture { params, .. } | Directive::Entity { params, .. } => Some(params),
            _ => None,
        }
    }
}

/// Where files come from: the disk, or (for tests and fuzzing) nowhere but memory.
pub trait FileLoader {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String>;
}

/// Reads files from the disk.
pub struct DiskLoader;

impl FileLoader for DiskLoader {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        // Only regular files: a device or a FIFO could be endless.
        match std::fs::metadata(path) {
            Ok(m) if !m.is_file() => return Err("not a regular file".into()),
            Err(e) => return Err(e.to_string()),
            Ok(_) => {}
        }
        std::fs::read(path).map_err(|e| e.to_string())
    }
}

/// Resolves a file name as pbrt-v3 does: relative to the top-level file's directory.
pub fn resolve(base_dir: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() || base_dir.as_os_str().is_empty() {
        p.to_path_buf()
    } else {
        base_dir.join(p)
    }
}

/// Turns bytes into text, or says where the first invalid UTF-8 byte is.
pub fn to_text(bytes: Vec<u8>) -> Result<Arc<str>, usize> {
    match String::from_utf8(bytes) {
        Ok(s) => Ok(Arc::from(s)),
        Err(e) => Err(e.utf8_error().valid_up_to()),
    }
}

const MAX_INCLUDE_DEPTH: usize = 64;
const MAX_ERRORS: usize = 50;

/// Parses a whole scene (following Includes).
pub struct Parser<'l> {
    pub sources: SourceMap,
    pub diags: Diags,
    stack: Vec<Lexer>,
    peeked: Option<Token>,
    base_dir: PathBuf,
    /// The directory file names are resolved against, per source file id:
    /// that of the top-level file the file was reached from (pbrt-v3 sets its
    /// search directory per file named on the command line).
    pub file_dirs: Vec<PathBuf>,
    canon: Vec<PathBuf>,
    loader: &'l dyn FileLoader,
    /// Location of the end of the last token read (for EOF errors).
    last: Loc,
    /// Source files already warned about numbers followed by commas.
    comma_warned: Vec<u32>,
}

/// Result of one step: `Err(())` means an error was reported.
type PResult<T> = Result<T, ()>;

impl<'l> Parser<'l> {
    pub fn new(path: &Path, text: Arc<str>, loader: &'l dyn FileLoader) -> Parser<'l> {
        let mut sources = SourceMap::new();
        let file = sources.add_file(path, text);
        let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let canon = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        Parser {
            sources,
            diags: Diags::default(),
            stack: vec![Lexer::new(file, 0)],
            peeked: None,
            comma_warned: Vec::new(),
            file_dirs: vec![base_dir.clone()],
            base_dir,
            canon: vec![canon],
            loader,
            last: Loc {
                file,
                chain: 0,
                start: 0,
                end: 0,
            },
        }
    }

    pub fn base_dir(&self) -> &Path {
        &self.base_dir
    }

    /// Queues another top-level file (a further scene file named on the
    /// command line): the next [`Parser::parse`] reads it, with its own
    /// directory for Includes and file names, after everything before it.
    pub fn add_top_level(&mut self, path: &Path, text: Arc<str>) {
        let file = self.sources.add_file(path, text);
        self.base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        self.file_dirs.push(self.base_dir.clone());
        self.canon = vec![path.canonicalize().unwrap_or_else(|_| path.to_path_buf())];
        self.peeked = None;
        self.stack = vec![Lexer::new(file, 0)];
        self.last = Loc {
            file,
            chain: 0,
            start: 0,
            end: 0,
        };
    }

    fn error(
        &mut self,
        loc: Loc,
        msg: impl Into<String>,
        label: impl Into<String>,
        help: Option<String>,
    ) {
        let r = self.sources.report(Severity::Error, loc, msg, label, help);
        self.diags.errors.push(r);
    }

    fn warn(&mut self, loc: Loc, msg: impl Into<String>, label: impl Into<String>) {
        let r = self
            .sources
            .report(Severity::Warning, loc, msg, label, None);
        self.diags.warnings.push(r);
    }

    /// The next token across Include levels; lexer errors are reported and skipped.
    fn next(&mut self) -> Option<Token> {
        if let Some(t) = self.peeked.take() {
            return Some(t);
        }
        loop {
            let lx = self.stack.last_mut()?;
            let text = self.sources.files[lx.file as usize].text.as_bytes();
            match lx.next(text) {
                Some(Ok(t)) => {
                    self.last = Loc {
                        start: t.loc.end,
                        ..t.loc
                    };
                    return Some(t);
                }
                Some(Err(e)) => {
                    let loc = Loc {
                        file: lx.file,
                        chain: lx.chain,
                        start: e.start,
                        end: e.end,
                    };
                    self.error(loc, e.message, e.label, None);
                    if self.diags.errors.len() >= MAX_ERRORS {
                        self.stack.clear();
                        return None;
                    }
                }
                None => {
                    let lx = self.stack.pop().expect("non-empty");
                    self.last = Loc {
                        file: lx.file,
                        chain: lx.chain,
                        start: self.last.end,
                        end: self.last.end,
                    };
                    if !self.stack.is_empty() {
                        self.canon.pop();
                    }
                }
            }
        }
    }

    /// The hot path of big meshes: reads consecutive numbers of the current file
    /// straight from its bytes into `out`. Stops, without consuming it, at the
    /// first token that is not a well-formed number (`]`, a string, an error, the
    /// end of the file), which the general path then handles.
    fn number_run(&mut self, out: &mut Vec<f64>) {
        if self.peeked.is_some() {
            return;
        }
        let Some(lx) = self.stack.last_mut() else {
            return;
        };
        let text = self.sources.files[lx.file as usize].text.as_bytes();
        loop {
            let save = lx.clone();
            match lx.next(text) {
                Some(Ok(t)) if t.kind == TokKind::Bare => {
                    match parse_number(&text[t.loc.start as usize..t.loc.end as usize]) {
                        Ok(v) => {
                            out.push(v);
                            self.last = Loc {
                                start: t.loc.end,
                                ..t.loc
                            };
                        }
                        Err(_) => {
                            *lx = save;
                            return;
                        }
                    }
                }
                _ => {
                    *lx = save;
                    return;
                }
            }
        }
    }

    fn peek(&mut self) -> Option<Token> {
        if self.peeked.is_none() {
            self.peeked = self.next();
        }
        self.peeked
    }

    fn text(&self, t: Token) -> &str {
        self.sources.text(t.loc)
    }

    fn eof_loc(&self) -> Loc {
        self.last
    }

    /// Parses everything; returns the statements (Include already spliced).
    pub fn parse(&mut self) -> Vec<Stmt> {
        let mut out = Vec::new();
        while let Some(tok) = self.next() {
            if self.diags.errors.len() >= MAX_ERRORS {
                break;
            }
            match self.statement(tok) {
                Ok(Some(s)) => out.push(s),
                Ok(None) => {}
                Err(()) => self.recover(),
            }
        }
        out
    }

    /// Skips to the next token that names a directive.
    fn recover(&mut self) {
        while let Some(t) = self.peek() {
            // Stop at a directive, or at a word that may be a misspelt one.
            if t.kind == TokKind::Bare
                && self.text(t).starts_with(|c: char| c.is_ascii_alphabetic())
            {
                return;
            }
            self.next();
        }
    }

    fn statement(&mut self, tok: Token) -> PResult<Option<Stmt>> {
        let word = self.text(tok);
        let kind = match (tok.kind, directive_kind(word)) {
            (TokKind::Bare, Some(k)) => k,
            (TokKind::Bare, None) => {
                let word = word.to_string();
                if parse_number(word.as_bytes()).is_ok() {
                    self.error(tok.loc, format!("unexpected number `{word}`: expected a directive"), "a directive name was expected here", Some("values of a parameter list must follow its \"type name\" string, inside [ ] if there are several".into()));
                } else {
                    let help = if matches!(
                        word.as_str(),
                        "Import" | "ColorSpace" | "Option" | "Attribute"
                    ) {
                        Some(format!(
                            "`{word}` is a pbrt-v4 directive; pbrs reads the pbrt-v3 format"
                        ))
                    } else {
                        did_you_mean(&word).map(|s| format!("did you mean `{s}`?"))
                    };
                    self.error(
                        tok.loc,
                        format!("unknown directive `{word}`"),
                        "not a pbrt-v3 directive",
                        help,
                    );
                }
                return Err(());
            }
            (TokKind::Str { .. }, _) => {
                let w = word.to_string();
                self.error(
                    tok.loc,
                    format!("unexpected string {w}: expected a directive"),
                    "a parameter list must follow a directive",
                    None,
                );
                return Err(());
            }
            (TokKind::LBracket, _) | (TokKind::RBracket, _) => {
                let w = word.to_string();
                self.error(
                    tok.loc,
                    format!("unexpected `{w}`: expected a directive"),
                    "unbalanced bracket",
                    None,
                );
                return Err(());
            }
        };
        use DirKind as K;
        let dir = match kind {
            K::WorldBegin
            | K::WorldEnd
            | K::AttributeBegin
            | K::AttributeEnd
            | K::TransformBegin
            | K::TransformEnd
            | K::ObjectEnd
            | K::ReverseOrientation
            | K::Identity => Directive::Plain,
            K::Translate | K::Scale => Directive::Numbers(self.bare_numbers(tok, kind, 3)?),
            K::Rotate => Directive::Numbers(self.bare_numbers(tok, kind, 4)?),
            K::LookAt => Directive::Numbers(self.bare_numbers(tok, kind, 9)?),
            K::TransformTimes => Directive::Numbers(self.bare_numbers(tok, kind, 2)?),
            K::Transform | K::ConcatTransform => {
                Directive::Numbers(self.bracketed_numbers(tok, kind, 16)?)
            }
            K::ActiveTransform => {
                let t = self.expect_token(tok, "`All`, `StartTime` or `EndTime`")?;
                let k = match (t.kind, self.text(t)) {
                    (TokKind::Bare, "All") => ActiveKind::All,
                    (TokKind::Bare, "StartTime") => ActiveKind::StartTime,
                    (TokKind::Bare, "EndTime") => ActiveKind::EndTime,
                    _ => {
                        self.error(
                            t.loc,
                            "ActiveTransform takes `All`, `StartTime` or `EndTime`",
                            "expected one of these words",
                            None,
                        );
                        return Err(());
                    }
                };
                Directive::ActiveTransform(k)
            }
            K::CoordinateSystem
            | K::CoordSysTransform
            | K::NamedMaterial
            | K::ObjectBegin
            | K::ObjectInstance => Directive::Named(self.string(tok, kind, "a name")?),
            K::Include => {
                let name = self.string(tok, kind, "a file name")?;
                self.include(tok, name)?;
                return Ok(None);
            }
            K::MediumInterface => {
                let inside = self.string(tok, kind, "a medium name")?;
                let outside = match self.peek() {
                    Some(t) if matches!(t.kind, TokKind::Str { .. }) => {
                        Some(self.string(tok, kind, "a medium name")?)
                    }
                    _ => None,
                };
                Directive::MediumInterface(inside, outside)
            }
            K::Texture => {
                let name = self.string(tok, kind, "a texture name")?;
                let tkind = self.string(
                    tok,
                    kind,
                    "the texture type (\"float\", \"color\" or \"spectrum\")",
                )?;
                let class = self.string(tok, kind, "a texture class")?;
                let params = self.param_list()?;
                Directive::Texture {
                    name,
                    kind: tkind,
                    class,
                    params,
                }
            }
            K::Camera
            | K::Sampler
            | K::Film
            | K::PixelFilter
            | K::Integrator
            | K::Accelerator
            | K::Shape
            | K::Material
            | K::MakeNamedMaterial
            | K::LightSource
            | K::AreaLightSource
            | K::MakeNamedMedium => {
                let name = self.string(tok, kind, "a quoted type or name")?;
                let params = self.param_list()?;
                Directive::Entity { name, params }
            }
        };
        Ok(Some(Stmt {
            kind,
            loc: tok.loc,
            dir,
        }))
    }

    fn expect_token(&mut self, after: Token, what: &str) -> PResult<Token> {
        match self.next() {
            Some(t) => Ok(t),
            None => {
                let loc = self.eof_loc();
                let name = self.text(after).to_string();
                self.error(
                    loc,
                    format!("premature end of file: `{name}` needs {what}"),
                    "the file ends here",
                    None,
                );
                Err(())
            }
        }
    }

    fn string(&mut self, dir: Token, kind: DirKind, what: &str) -> PResult<Name> {
        let t = self.expect_token(dir, what)?;
        match t.kind {
            TokKind::Str { escaped } => Ok(Name {
                value: dequote(self.text(t), escaped),
                loc: t.loc,
            }),
            _ => {
                let found = self.text(t).to_string();
                self.peeked = Some(t);
                self.error(
                    dir.loc.to(t.loc),
                    format!(
                        "{} needs {what} in double quotes, found `{found}`",
                        kind.name()
                    ),
                    "expected a quoted string",
                    None,
                );
                Err(())
            }
        }
    }

    fn number(&mut self, t: Token) -> PResult<f64> {
        if t.kind != TokKind::Bare {
            let found = self.text(t).to_string();
            self.error(
                t.loc,
                format!("expected a number, found `{found}`"),
                "not a number",
                None,
            );
            return Err(());
        }
        match self.number_text(t) {
            Ok(v) => Ok(v),
            Err(e) => {
                self.bad_number(t, e);
                Err(())
            }
        }
    }

    /// A bare token as a number; pbrt-v3 reads the number at the start of
    /// a token (`strtod`), so a number followed by commas (`0.43,`, from
    /// exporters that separate values with commas) is read without them,
    /// with one warning per file. Anything else after a number stays an
    /// error.
    pub(super) fn number_text(&mut self, t: Token) -> Result<f64, NumError> {
        let text = self.text(t).as_bytes();
        match parse_number(text) {
            Err(NumError::Malformed) if text.ends_with(b",") => {
                let stem = text
                    .iter()
                    .rposition(|&c| c != b',')
                    .map_or(&text[..0], |i| &text[..=i]);
                let v = parse_number(stem)?;
                if !self.comma_warned.contains(&t.loc.file) {
                    self.comma_warned.push(t.loc.file);
                    let found = self.text(t).to_string();
                    self.warn(
                        t.loc,
                        format!("number `{found}` is followed by a comma: read as {v} (as pbrt-v3); commas are not separators in the pbrt format (further ones in this file are read the same way)"),
                        "a comma after the number",
                    );
                }
                Ok(v)
            }
            r => r,
        }
    }

    fn bad_number(&mut self, t: Token, e: NumError) {
        let found = self.text(t).to_string();
        match e {
            NumError::NotFinite => self.error(
                t.loc,
                format!("number `{found}` is out of range (not finite)"),
                "not a finite number",
                None,
            ),
            NumError::Malformed => {
                let lower = found.to_ascii_lowercase();
                if lower.contains("nan") || lower.contains("inf") {
                    self.error(
                        t.loc,
                        format!("`{found}` is not allowed: numbers must be finite"),
                        "NaN or infinity",
                        None,
                    )
                } else {
                    self.error(t.loc, format!("bad number `{found}`"), "not a number", None)
                }
            }
        }
    }

    fn bare_numbers(&mut self, dir: Token, kind: DirKind, n: usize) -> PResult<Vec<f64>> {
        let mut v = Vec::with_capacity(n);
        for i in 0..n {
            let t = self.expect_token(dir, &format!("{n} numbers"))?;
            if t.kind == TokKind::LBracket {
                self.error(
                    t.loc,
                    format!("{} takes {n} numbers without brackets", kind.name()),
                    "pbrt-v3 does not accept `[` here",
                    None,
                );
                return Err(());
            }
            if t.kind != TokKind::Bare
                || parse_number(self.text(t).as_bytes()).is_err()
                    && directive_kind(self.text(t)).is_some()
            {
                self.peeked = Some(t);
                self.error(
                    dir.loc.to(t.loc),
                    format!("{} takes {n} numbers, found {i}", kind.name()),
                    format!("expected {n} numbers"),
                    None,
                );
                return Err(());
            }
            v.push(self.number(t)?);
        }
        Ok(v)
    }

    fn bracketed_numbers(&mut self, dir: Token, kind: DirKind, n: usize) -> PResult<Vec<f64>> {
        let open = self.expect_token(dir, "`[`")?;
        if open.kind != TokKind::LBracket {
            self.peeked = Some(open);
            self.error(
                open.loc,
                format!("{} needs `[` and {n} numbers", kind.name()),
                "expected `[`",
                None,
            );
            return Err(());
        }
        let mut v = Vec::with_capacity(n);
        loop {
            let t = match self.next() {
                Some(t) => t,
                None => {
                    self.error(
                        open.loc,
                        "unbalanced brackets: `[` is never closed",
                        "this `[`",
                        None,
                    );
                    return Err(());
                }
            };
            match t.kind {
                TokKind::RBracket => break,
                TokKind::Bare if directive_kind(self.text(t)).is_some() => {
                    self.peeked = Some(t);
                    self.error(
                        open.loc,
                        "unbalanced brackets: `[` is never closed",
                        "this `[`",
                        None,
                    );
                    return Err(());
                }
                _ => v.push(self.number(t)?),
            }
        }
        if v.len() != n {
            self.error(
                dir.loc,
                format!("{} takes {n} numbers, found {}", kind.name(), v.len()),
                format!("expected {n} numbers"),
                None,
            );
            return Err(());
        }
        Ok(v)
    }

    fn include(&mut self, tok: Token, name: Name) -> PResult<()> {
        let loc = tok.loc.to(name.loc);
        let path = resolve(&self.base_dir, &name.value);
        if self.stack.len() > MAX_INCLUDE_DEPTH {
            self.error(
                loc,
                format!("Includes nested deeper than {MAX_INCLUDE_DEPTH} levels"),
                "this Include",
                None,
            );
            return Err(());
        }
        let canon = path.canonicalize().unwrap_or_else(|_| path.clone());
        if let Some(i) = self.canon.iter().position(|c| *c == canon) {
            let mut cycle: Vec<String> = self.canon[i..]
                .iter()
                .map(|p| p.display().to_string())
                .collect();
            cycle.push(canon.display().to_string());
            self.error(
                loc,
                format!("Include cycle: \"{}\" is already being read", name.value),
                "this Include closes the cycle",
                Some(format!("cycle: {}", cycle.join(" → "))),
            );
            return Err(());
        }
        let bytes = match self.loader.load(&path) {
            Ok(b) => b,
            Err(e) => {
                self.error(loc, format!("cannot read Include file \"{}\": {e}", path.display()), "this Include", Some("Include paths are relative to the directory of the top-level scene file (as in pbrt-v3)".into()));
                return Err(());
            }
        };
        if bytes.len() >= u32::MAX as usize {
            self.error(
                loc,
                format!("Include file \"{}\" is too large", path.display()),
                "this Include",
                None,
            );
            return Err(());
        }
        let text = match to_text(bytes) {
            Ok(t) => t,
            Err(at) => {
                self.error(
                    loc,
                    format!(
                        "Include file \"{}\" is not UTF-8 text (invalid byte at offset {at})",
                        path.display()
                    ),
                    "this Include",
                    None,
                );
                return Err(());
            }
        };
        let chain = self.sources.push_chain(loc);
        let file = self.sources.add_file(&path, text);
        self.file_dirs.push(self.base_dir.clone());
        // A token peeked before the Include belongs after the included file.
        debug_assert!(self.peeked.is_none());
        self.stack.push(Lexer::new(file, chain));
        self.canon.push(canon);
        Ok(())
    }
}

/// Edit distance (case-insensitive) for "did you mean".
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.to_lowercase().chars().collect();
    let b: Vec<char> = b.to_lowercase().chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

fn closest<'a>(word: &str, names: &[&'a str]) -> Option<&'a str> {
    if word.chars().count() > 64 {
        return None;
    }
    let (best, d) = names
        .iter()
        .map(|n| (*n, distance(word, n)))
        .min_by_key(|&(_, d)| d)?;
    (d <= (word.chars().count() / 3).max(2)).then_some(best)
}

/// The directive closest to a misspelt word, if any is close.
pub fn did_you_mean(word: &str) -> Option<&'static str> {
    let names: Vec<&'static str> = DIRECTIVES.iter().map(|(n, _)| *n).collect();
    closest(word, &names)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Mem(Vec<(&'static str, &'static str)>);
    impl FileLoader for Mem {
        fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
            self.0
                .iter()
                .find(|(p, _)| Path::new(p) == path)
                .map(|(_, t)| t.as_bytes().to_vec())
                .ok_or_else(|| "not found".into())
        }
    }

    fn parse(text: &str, files: Vec<(&'static str, &'static str)>) -> (Vec<Stmt>, Diags) {
        let mem = Mem(files);
        let mut p = Parser::new(Path::new("dir/main.pbrt"), Arc::from(text), &mem);
        let s = p.parse();
        (s, p.diags)
    }

    #[test]
    fn statements_and_params() {
        let (s, d) = parse("Shape \"sphere\" \"float radius\" 2 \"rgb Kd\" [1 2 3] \"bool b\" \"true\" \"float radius\" [3]\nTranslate 1 2 3", vec![]);
        assert!(d.errors.is_empty(), "{:?}", d.errors);
        assert_eq!(s.len(), 2);
        let p = s[0].params().unwrap();
        assert_eq!(p.items.len(), 3);
        assert_eq!(p.get("radius").unwrap().nums(), &[3.0]);
        assert_eq!(p.get("b").unwrap().bools(), &[true]);
        assert!(matches!(&s[1].dir, Directive::Numbers(v) if v == &[1.0, 2.0, 3.0]));
    }

    #[test]
    fn include_splices_tokens() {
        let (s, d) = parse(
            "Include \"a.inc\" \"float radius\" 2\nWorldEnd",
            vec![("dir/a.inc", "Shape \"sphere\"")],
        );
        assert!(d.errors.is_empty(), "{:?}", d.errors);
        assert_eq!(s[0].params().unwrap().get("radius").unwrap().nums(), &[2.0]);
        assert_eq!(s[1].kind, DirKind::WorldEnd);
    }

    #[test]
    fn errors() {
        for bad in [
            "Shap \"sphere\"",
            "Translate [1 2 3]",
            "Shape \"sphere\" \"float radius\" [1",
            "Shape \"sphere\" \"flot radius\" 1",
            "Shape \"trianglemesh\" \"point P\" [1 2]",
            "Shape \"sphere\" \"float radius\" \"one\"",
            "Shape \"sphere\" \"string x\" 1",
            "Shape \"sphere\" \"float radius\" nan",
            "Shape \"sphere\" \"integer n\" 1.5",
            "Shape \"sphere\" \"float radius\" [1 \"a\"]",
            "Include \"missing.inc\"",
            "Include \"main.pbrt\"",
            "Transform [1 2 3]",
            "]",
            "\"abc",
        ] {
            let (_, d) = parse(bad, vec![]);
            assert!(!d.errors.is_empty(), "{bad}");
        }
        assert_eq!(did_you_mean("Shap"), Some("Shape"));
        assert_eq!(did_you_mean("attributebegin"), Some("AttributeBegin"));
        assert_eq!(did_you_mean("Xyzzyplugh"), None);
    }
}
