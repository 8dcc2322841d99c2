//! Scene building: graphics state to a plain scene description.
//!
//! - [`state`]: the walk over statements with pbrt-v3's graphics state
//!   (`state/shape.rs`: a `Shape` statement with the state current at it).
//! - [`kinds`]: any family's statement read through its kind's table and
//!   built by the kind's builder; [`options`]: the camera, film, filter,
//!   sampler and integrator statements; [`lights`], [`material`],
//!   [`texture`], [`medium`], [`shapes`] (with [`camera`]: lens files) the
//!   others; [`lookup`]: parameters by name for everything else.
//! - [`color`]: spectra to linear RGB against the CIE table [`cie1931`];
//!   [`spd`]: spectrum files; [`ply`]: the PLY reader for `plymesh`;
//!   [`fourier`]: the tabulated BSDF reader for the `fourier` material;
//!   [`refine`]: `loopsubdiv`, `nurbs` and `heightfield` as triangle meshes.
//! - [`image`]: image files for textures and lights, read once per scene.
//! - [`summary`]: what `pbrs --check` prints.

pub mod camera;
pub mod cie1931;
pub mod color;
pub mod fourier;
pub mod image;
pub mod kinds;
pub mod lights;
pub mod lookup;
pub mod material;
pub mod medium;
pub mod meshfile;
pub mod options;
pub mod params;
pub mod ply;
pub mod reference;
pub mod refine;
pub mod shapes;
pub mod spd;
pub mod state;
pub mod summary;
pub mod texture;

use crate::lang::params::{Param, ParamList};
use crate::lang::parser::{to_text, DiskLoader, FileLoader, Parser};
use crate::lang::{Diags, Loc, SourceMap};
use crate::scene::{Elem, FourierTable, ParamKind, ParamSpec, SceneDescription};
use glam::Vec3;
use miette::Severity;
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use summary::{DeclaredKind, Summary};

/// A scene that loaded, with its warnings and a summary for `--check`.
pub struct LoadedScene {
    pub scene: SceneDescription,
    pub warnings: Vec<miette::Report>,
    pub summary: Summary,
    /// Whether the Film gave a 4-value "cropwindow" (pbrt-v3 then ignores
    /// the command line's `--cropwindow`).
    pub film_has_cropwindow: bool,
}

/// A scene that did not load: at least one error.
pub struct LoadFailure {
    pub errors: Vec<miette::Report>,
    pub warnings: Vec<miette::Report>,
}

impl std::fmt::Debug for LoadFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for e in &self.errors {
            writeln!(f, "error: {e}")?;
        }
        Ok(())
    }
}

/// What building needs besides the statements: sources for diagnostics, where
/// files are, and the diagnostics gathered so far.
pub struct Ctx {
    pub sources: SourceMap,
    pub diags: Diags,
    /// Per source file id, the directory its file names are relative to
    /// (the directory of the top-level scene file it was reached from).
    pub file_dirs: Vec<PathBuf>,
    pub loader: Box<dyn FileLoader>,
    /// Images read so far (each file is read once).
    pub images: image::ImageCache,
    /// Spectrum files read so far, by resolved path, as RGB (pbrt-v3 reads
    /// each file once: `cachedSpectra`).
    pub spectra: HashMap<PathBuf, Vec3>,
    /// Tabulated BSDFs by resolved path, read once per scene (`None`: the
    /// file could not be read, already reported).
    pub fourier_tables: HashMap<PathBuf, Option<Arc<FourierTable>>>,
}

impl Ctx {
    /// A file name written at `loc`, resolved as pbrt-v3 does: relative to
    /// the directory of the top-level scene file it appears in.
    pub fn resolve(&self, loc: Loc, name: &str) -> PathBuf {
        let dir = self
            .file_dirs
            .get(loc.file as usize)
            .map(PathBuf::as_path)
            .unwrap_or(Path::new(""));
        crate::lang::parser::resolve(dir, name)
    }

    pub fn warn(&mut self, loc: Loc, msg: impl Into<String>, label: impl Into<String>) {
        let r = self
            .sources
            .report(Severity::Warning, loc, msg, label, None);
        self.diags.warnings.push(r);
    }

    pub fn error(
        &mut self,
        loc: Loc,
        msg: impl Into<String>,
        label: impl Into<String>,
        help: Option<String>,
    ) {
        let r = self.sources.report(Severity::Error, loc, msg, label, help);
        self.diags.errors.push(r);
    }

    /// pbrt-v3's `ReportUnused`: a warning for each parameter never looked up.
    pub fn report_unused(&mut self, p: &ParamList, what: &str) {
        self.report_unused_except(p, what, &[]);
    }

    pub fn report_unused_except(&mut self, p: &ParamList, what: &str, except: &[&str]) {
        self.report_unused_with_specs(p, what, except, &[]);
    }

    /// [`Ctx::report_unused_except`] for an entity kind with a `ParamSpec`
    /// list: the warning's help says which type a known name takes, or
    /// which known name is close ("did you mean").
    pub fn report_unused_with_specs(
        &mut self,
        p: &ParamList,
        what: &str,
        except: &[&str],
        specs: &[ParamSpec],
    ) {
        for q in p.unused() {
            if except.contains(&q.name.as_str()) {
                continue;
            }
            q.used.set(true);
            let r = self.sources.report(
                Severity::Warning,
                q.loc,
                format!(
                    "parameter \"{} {}\" not used by {what}",
                    q.type_name, q.name
                ),
                "unused parameter",
                unused_hint(q, specs),
            );
            self.diags.warnings.push(r);
        }
    }
}

/// The parameter types a spec accepts, the one to suggest first.
fn accepted_types(kind: ParamKind) -> &'static [&'static str] {
    match kind {
        ParamKind::FloatTexture(_) => &["float", "texture"],
        ParamKind::SpectrumTexture(_) => {
            &["rgb", "color", "xyz", "blackbody", "spectrum", "texture"]
        }
        ParamKind::Float(_) => &["float"],
        ParamKind::FloatOpt => &["float"],
        ParamKind::Bool(_) => &["bool"],
        ParamKind::String(_)
        | ParamKind::NamedMaterial
        | ParamKind::FourierFile
        | ParamKind::Choice { .. }
        | ParamKind::Filename => &["string"],
        ParamKind::BoolOpt => &["bool"],
        ParamKind::Int(_) => &["integer"],
        ParamKind::Vector3(_) => &["vector3", "vector"],
        // The texture's own type decides which of these applies.
        ParamKind::SameTexture(_) => &[
            "float",
            "rgb",
            "color",
            "xyz",
            "blackbody",
            "spectrum",
            "texture",
        ],
        ParamKind::SameValue(_) => &["float", "rgb", "color", "xyz", "blackbody", "spectrum"],
        ParamKind::Unsupported(_) => &[],
        ParamKind::Spectrum(_) => &["rgb", "color", "xyz", "blackbody", "spectrum"],
        ParamKind::Point3(_) => &["point3", "point"],
        ParamKind::Floats => &["float"],
        ParamKind::SpectrumOrFloat(_) => &["rgb", "color", "xyz", "blackbody", "spectrum", "float"],
        ParamKind::IntOpt => &["integer"],
        ParamKind::Image(_) => &["string"],
        ParamKind::List(Elem::Number) => &["float", "integer"],
        ParamKind::List(Elem::Int) => &["integer"],
        ParamKind::List(Elem::Point2) => &["point2", "float"],
        ParamKind::List(Elem::Point3) => &["point3", "point"],
        ParamKind::List(Elem::Normal) => &["normal"],
    }
}

/// Why an unused parameter was not read, when its kind's specs tell.
fn unused_hint(q: &Param, specs: &[ParamSpec]) -> Option<String> {
    let accepts = |s: &ParamSpec| accepted_types(s.kind).contains(&q.type_name);
    if let Some(s) = specs.iter().find(|s| s.name == q.name) {
        let types = accepted_types(s.kind);
        if accepts(s) {
            let n = q.count();
            return (n != 1).then(|| format!("\"{}\" takes one value; {n} were given", q.name));
        }
        let forms: Vec<String> = types
            .iter()
            .filter(|t| **t != "color")
            .map(|t| format!("\"{t} {}\"", q.name))
            .collect();
        let list = match forms.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => return None,
        };
        return Some(format!(
            "\"{}\" is a {} parameter, not \"{}\": write {list}",
            q.name,
            kind_name(s.kind),
            q.type_name
        ));
    }
    let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
    let close = state::closest_name(&q.name, &names)?;
    let s = specs.iter().find(|s| s.name == close)?;
    let ty = if accepts(s) {
        q.type_name
    } else {
        accepted_types(s.kind).first()?
    };
    Some(format!("did you mean \"{ty} {close}\"?"))
}

fn kind_name(kind: ParamKind) -> &'static str {
    match kind {
        ParamKind::FloatTexture(_) => "float texture",
        ParamKind::SpectrumTexture(_) => "spectrum texture",
        ParamKind::Float(_) => "float",
        ParamKind::FloatOpt => "float",
        ParamKind::Bool(_) => "bool",
        ParamKind::String(_) => "string",
        ParamKind::NamedMaterial => "named-material",
        ParamKind::FourierFile | ParamKind::Filename => "file-name",
        ParamKind::Choice { .. } => "string",
        ParamKind::BoolOpt => "bool",
        ParamKind::Int(_) => "integer",
        ParamKind::Vector3(_) => "vector3",
        ParamKind::SameTexture(_) => "texture",
        ParamKind::SameValue(_) => "value",
        ParamKind::Unsupported(_) => "ignored",
        ParamKind::Spectrum(_) => "spectrum",
        ParamKind::Point3(_) => "point3",
        ParamKind::Floats => "float list",
        ParamKind::SpectrumOrFloat(_) => "spectrum",
        ParamKind::IntOpt => "integer",
        ParamKind::Image(_) => "file-name",
        ParamKind::List(e) => e.name(),
    }
}

/// Reads, parses and builds a scene file.
pub fn load_scene(path: &Path) -> Result<LoadedScene, LoadFailure> {
    load_scene_files(std::slice::from_ref(&path.to_path_buf()))
}

/// The name standard input has in diagnostics; its file names are relative
/// to the current directory.
pub const STDIN_NAME: &str = "<stdin>";

/// The largest scene file pbrs reads (1 GiB): the text is held in memory
/// while it is parsed, so an endless input (standard input that never
/// ends, `/dev/zero`) stops here with an error instead of growing without
/// bound. Bigger geometry belongs in PLY files, which are read by count.
pub const MAX_SCENE_BYTES: u64 = 1 << 30;

/// Reads at most [`MAX_SCENE_BYTES`] of scene text from `r`: `Err` says why
/// it is not scene text (too large, a NUL byte) or why it could not be read.
fn read_scene_bytes(mut r: impl std::io::Read) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = match r.read(&mut buf) {
            Ok(0) => return Ok(out),
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.to_string()),
        };
        if let Some(i) = buf[..n].iter().position(|&b| b == 0) {
            return Err(format!(
                "it holds a NUL byte at offset {}: it is not scene text",
                out.len() + i
            ));
        }
        if out.len() as u64 + n as u64 > MAX_SCENE_BYTES {
            return Err(format!(
                "it is larger than {} MiB, the most pbrs reads as scene text (put big meshes in PLY files)",
                MAX_SCENE_BYTES >> 20
            ));
        }
        out.extend_from_slice(&buf[..n]);
    }
}

/// Reads one scene file named on the command line; `-` is standard input.
pub fn read_scene_input(path: &Path) -> Result<(PathBuf, Arc<str>), LoadFailure> {
    let stdin = path.as_os_str() == "-";
    let shown = if stdin {
        PathBuf::from(STDIN_NAME)
    } else {
        path.to_path_buf()
    };
    // The user named this file, so a pipe or a device is read (unlike
    // Include targets), up to the size limit.
    let read = if stdin {
        read_scene_bytes(std::io::stdin().lock())
    } else {
        std::fs::File::open(path)
            .map_err(|e| e.to_string())
            .and_then(read_scene_bytes)
    };
    let text = match read {
        Ok(b) => b,
        Err(e) => {
            return Err(plain_failure(
                &shown,
                format!("cannot read scene file \"{}\": {e}", shown.display()),
            ))
        }
    };
    match to_text(text) {
        Ok(t) => Ok((shown, t)),
        Err(at) => Err(plain_failure(
            &shown,
            format!(
                "scene file \"{}\" is not UTF-8 text (invalid byte at offset {at})",
                shown.display()
            ),
        )),
    }
}

/// Reads, parses and builds the scene files named on the command line as one
/// scene, in order (pbrt-v3 parses each in turn into the same state); `-`
/// reads standard input. Each file's names resolve against its own directory.
pub fn load_scene_files(paths: &[PathBuf]) -> Result<LoadedScene, LoadFailure> {
    let mut inputs = Vec::with_capacity(paths.len());
    for p in paths {
        inputs.push(read_scene_input(p)?);
    }
    load(inputs, Box::new(DiskLoader))
}

/// Same, from text in memory; `path` names it in diagnostics and its parent dir
/// resolves Includes and meshes.
pub fn load_scene_str(text: &str, path: &Path) -> Result<LoadedScene, LoadFailure> {
    load(
        vec![(path.to_path_buf(), Arc::from(text))],
        Box::new(DiskLoader),
    )
}

/// Same, with files (Includes, PLY meshes) read through `loader`.
pub fn load_scene_with(
    text: &str,
    path: &Path,
    loader: Box<dyn FileLoader>,
) -> Result<LoadedScene, LoadFailure> {
    load(vec![(path.to_path_buf(), Arc::from(text))], loader)
}

fn plain_failure(path: &Path, msg: String) -> LoadFailure {
    LoadFailure {
        errors: vec![miette::miette!("{}:1:1: {msg}", path.display())],
        warnings: Vec::new(),
    }
}

/// Statements of one or more top-level files, Includes spliced, with what
/// diagnostics and file-name resolution need.
pub struct Parsed {
    pub stmts: Vec<crate::lang::Stmt>,
    pub sources: SourceMap,
    pub diags: Diags,
    /// Per source file id, the directory its file names are relative to.
    pub file_dirs: Vec<PathBuf>,
}

/// Parses `inputs` (path, text) in order as one statement list.
pub fn parse_inputs(inputs: Vec<(PathBuf, Arc<str>)>, loader: &dyn FileLoader) -> Parsed {
    let mut it = inputs.into_iter();
    let (path, text) = it
        .next()
        .unwrap_or_else(|| (PathBuf::from(STDIN_NAME), Arc::from("")));
    let mut parser = Parser::new(&path, text, loader);
    let mut stmts = parser.parse();
    for (path, text) in it {
        parser.add_top_level(&path, text);
        stmts.extend(parser.parse());
    }
    let Parser {
        sources,
        diags,
        file_dirs,
        ..
    } = parser;
    Parsed {
        stmts,
        sources,
        diags,
        file_dirs,
    }
}

/// What one build of a statement list gives.
struct Built {
    scene: SceneDescription,
    kinds: Vec<DeclaredKind>,
    textures: TexturesByClass,
    film_has_cropwindow: bool,
}

type TexturesByClass = std::collections::BTreeMap<&'static str, usize>;

fn build(ctx: &mut Ctx, stmts: &[crate::lang::Stmt]) -> Built {
    let mut b = state::Builder::new(stmts, ctx);
    b.run();
    let film_has_cropwindow = b
        .film
        .and_then(|i| stmts[i].params())
        .and_then(|p| {
            p.items
                .iter()
                .find(|q| q.name == "cropwindow" && q.ty == crate::lang::params::ParamType::Float)
        })
        .is_some_and(|q| q.nums().len() == 4);
    let (camera, film, filter, sampler, integrator) = b.finish();
    let scene = SceneDescription {
        camera,
        film,
        filter,
        sampler,
        integrator,
        materials: std::mem::take(&mut b.scene_materials),
        shapes: std::mem::take(&mut b.shapes),
        lights: std::mem::take(&mut b.lights),
        light_media: std::mem::take(&mut b.light_media),
        objects: std::mem::take(&mut b.scene_objects),
        instances: std::mem::take(&mut b.instances),
        skipped: std::mem::take(&mut b.skipped),
        media: std::mem::take(&mut b.scene_media),
        camera_medium: b.camera_medium,
    };
    let kinds = std::mem::take(&mut b.material_kinds);
    let textures = std::mem::take(&mut b.texture_state.by_class);
    Built {
        scene,
        kinds,
        textures,
        film_has_cropwindow,
    }
}

fn new_ctx(parsed: Parsed, loader: Box<dyn FileLoader>) -> (Vec<crate::lang::Stmt>, Ctx) {
    let Parsed {
        stmts,
        sources,
        diags,
        file_dirs,
    } = parsed;
    let ctx = Ctx {
        sources,
        diags,
        file_dirs,
        loader,
        images: Default::default(),
        spectra: HashMap::new(),
        fourier_tables: HashMap::new(),
    };
    (stmts, ctx)
}

fn failure(ctx: Ctx) -> LoadFailure {
    LoadFailure {
        errors: ctx.diags.errors,
        warnings: ctx.diags.warnings,
    }
}

fn loaded(b: Built, warnings: Vec<miette::Report>, n_warnings: usize) -> LoadedScene {
    let mut summary = Summary::of(&b.scene, &b.kinds, n_warnings);
    summary.textures_by_class = b.textures;
    LoadedScene {
        scene: b.scene,
        warnings,
        summary,
        film_has_cropwindow: b.film_has_cropwindow,
    }
}

fn load(
    inputs: Vec<(PathBuf, Arc<str>)>,
    loader: Box<dyn FileLoader>,
) -> Result<LoadedScene, LoadFailure> {
    let parsed = parse_inputs(inputs, loader.as_ref());
    let (stmts, mut ctx) = new_ctx(parsed, loader);
    if !ctx.diags.errors.is_empty() {
        return Err(failure(ctx));
    }
    let b = build(&mut ctx, &stmts);
    if !ctx.diags.errors.is_empty() {
        return Err(failure(ctx));
    }
    let n = ctx.diags.warnings.len();
    Ok(loaded(b, ctx.diags.warnings, n))
}

/// The statement ranges of the scenes pbrt-v3 renders one after the other:
/// each `WorldEnd` that closes a world block renders, and pbrt-v3 then starts
/// from a fresh state (api.cpp `pbrtWorldEnd` resets the options and the
/// graphics state). Statements after the last `WorldEnd` with no
/// `WorldBegin` among them render nothing (returned second); a list
/// without any WorldEnd is one scene.
pub fn world_blocks(
    stmts: &[crate::lang::Stmt],
) -> (Vec<std::ops::Range<usize>>, Option<std::ops::Range<usize>>) {
    use crate::lang::DirKind;
    let mut out = Vec::new();
    let (mut start, mut in_world) = (0, false);
    for (i, s) in stmts.iter().enumerate() {
        match s.kind {
            DirKind::WorldBegin => in_world = true,
            DirKind::WorldEnd if in_world => {
                out.push(start..i + 1);
                start = i + 1;
                in_world = false;
            }
            _ => {}
        }
    }
    let rest = start..stmts.len();
    if out.is_empty() {
        (vec![rest], None)
    } else if in_world {
        out.push(rest);
        (out, None)
    } else {
        (out, (!rest.is_empty()).then_some(rest))
    }
}

/// [`load_scene_files`] as pbrt-v3's command line renders: one scene per
/// world block, in order (several complete scene files render one after the
/// other). All warnings go with the first scene; any error fails them all.
/// No statement at all gives no scene.
pub fn load_scene_files_each(paths: &[PathBuf]) -> Result<Vec<LoadedScene>, LoadFailure> {
    let mut inputs = Vec::with_capacity(paths.len());
    for p in paths {
        inputs.push(read_scene_input(p)?);
    }
    let loader: Box<dyn FileLoader> = Box::new(DiskLoader);
    let parsed = parse_inputs(inputs, loader.as_ref());
    let (stmts, mut ctx) = new_ctx(parsed, loader);
    if !ctx.diags.errors.is_empty() {
        return Err(failure(ctx));
    }
    if stmts.is_empty() {
        // pbrt-v3 renders at WorldEnd only: an empty input renders nothing.
        return Ok(Vec::new());
    }
    let (blocks, trailing) = world_blocks(&stmts);
    let mut built: Vec<Built> = blocks
        .into_iter()
        .map(|r| build(&mut ctx, &stmts[r]))
        .collect();
    if let Some(r) = trailing {
        ctx.warn(
            stmts[r.start].loc,
            format!(
                "`{}` after the last WorldEnd: no WorldBegin follows, so nothing renders with it (as pbrt-v3)",
                stmts[r.start].kind.name()
            ),
            "ignored from here on",
        );
    }
    if !ctx.diags.errors.is_empty() {
        return Err(failure(ctx));
    }
    let n = ctx.diags.warnings.len();
    let mut warnings = Some(ctx.diags.warnings);
    Ok(built
        .drain(..)
        .map(|b| loaded(b, warnings.take().unwrap_or_default(), n))
        .collect())
}

/// Prints diagnostics to stderr with miette's graphical handler (no colour when
/// stderr is not a terminal or `NO_COLOR` is set). Each message starts with
/// `FILE:LINE:COL`, and the help lists the Include chain.
/// `--strict`: scenes loaded with warnings fail, each warning (a
/// substitution, something ignored, a file that could not be read) made an
/// error at its place.
pub fn strictly(scenes: Vec<LoadedScene>) -> Result<Vec<LoadedScene>, LoadFailure> {
    if scenes.iter().all(|s| s.warnings.is_empty()) {
        return Ok(scenes);
    }
    let errors = scenes
        .into_iter()
        .flat_map(|s| s.warnings)
        .map(
            |w| match w.downcast_ref::<crate::lang::source::LocatedDiagnostic>() {
                Some(d) => miette::Report::new(d.as_error("an error with --strict")),
                None => miette::miette!("{w} (an error with --strict)"),
            },
        )
        .collect();
    Err(LoadFailure {
        errors,
        warnings: Vec::new(),
    })
}

pub fn print_diagnostics(reports: &[miette::Report]) {
    let color = std::io::stderr().is_terminal()
        && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty());
    let theme = if color {
        miette::GraphicalTheme::unicode()
    } else {
        miette::GraphicalTheme::unicode_nocolor()
    };
    let handler = miette::GraphicalReportHandler::new_themed(theme)
        .with_wrap_lines(false)
        .with_links(false);
    let mut out = String::new();
    for r in reports {
        let mut s = String::new();
        if handler.render_report(&mut s, r.as_ref()).is_err() {
            s = format!("{r}\n");
        }
        out.push_str(&s);
    }
    eprint!("{out}");
}
