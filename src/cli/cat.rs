//! `pbrs --cat` and `pbrs --toply`: the scene as pbrs read it, printed back
//! (pbrt-v3's `--cat` and `--toply`, core/api.cpp and paramset.cpp).
//!
//! - Includes are spliced; one directive per line, indented by block
//!   (AttributeBegin, TransformBegin, ObjectBegin), blank lines around the
//!   world block, as pbrt-v3 prints it.
//! - Parameters are normalised: `"type name" [ values ]`, pbrt-v3's type
//!   spellings (`color` → `rgb`, `point3` → `point`, `vector3` → `vector`),
//!   a name given twice only once (the later, which is the one pbrt-v3
//!   uses), numbers in the shortest form that reads back to the same value
//!   (pbrt-v3 prints `%.9g`, which can lose bits of a double), strings
//!   escaped. Unlike pbrt-v3, which turns every spectrum into RGB, spectra
//!   stay as written, so the printed scene renders byte for byte the same.
//! - File names (meshes, images, spectrum and BSDF files, lens files) are
//!   printed resolved as pbrs resolves them, i.e. relative to the current
//!   directory (absolute if the scene path was): write the output in the
//!   current directory or pipe it into `pbrs -`, and every file is found.
//!   The Film's output "filename" is left as written (pbrt-v3 writes it
//!   relative to the current directory already).
//! - `--toply` writes each `trianglemesh` with 500 indices or more (pbrt-v3's
//!   threshold) to `mesh_NNNNN.ply` in the current directory (`$PLY_PREFIX`
//!   replaces `mesh`, as in pbrt-v3), binary little-endian with the
//!   attributes it has (positions; normals, uv and face indices if given),
//!   and prints a `plymesh` naming it with the other parameters. A mesh that
//!   pbrs would not take as it is (bad counts, out-of-range indices, zero
//!   normals...) is printed inline unchanged, so its diagnostics stay.

use super::render::scenes_label;
use super::Args;
use crate::image::io::write_atomic;
use crate::lang::params::{Param, ParamList, ParamType, Values};
use crate::lang::parser::{resolve, ActiveKind, DiskLoader, Name};
use crate::lang::{DirKind, Directive, Stmt};
use crate::loader::{parse_inputs, print_diagnostics, read_scene_input, Parsed};
use crate::materials::MATERIALS;
use crate::scene::ParamKind;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// pbrt-v3 converts meshes with at least this many indices.
const TOPLY_MIN_INDICES: usize = 500;

pub fn run(args: &Args) -> i32 {
    let mut inputs = Vec::new();
    for p in &args.scenes {
        match read_scene_input(p) {
            Ok(i) => inputs.push(i),
            Err(f) => {
                print_diagnostics(&f.errors);
                return 1;
            }
        }
    }
    let parsed = parse_inputs(inputs, &DiskLoader);
    if !parsed.diags.errors.is_empty() {
        if args.warnings() {
            print_diagnostics(&parsed.diags.warnings);
        }
        print_diagnostics(&parsed.diags.errors);
        eprintln!(
            "{}: the scene was not parsed; nothing was printed",
            scenes_label(args)
        );
        return 1;
    }
    if args.warnings() {
        print_diagnostics(&parsed.diags.warnings);
    }
    let prefix = std::env::var("PLY_PREFIX").unwrap_or_else(|_| "mesh".into());
    let mut printer = Printer::new(&parsed, args.toply.then(|| PlyOut::new(prefix)));
    let text = match printer.print_all() {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return 1;
        }
    };
    if args.warnings() {
        for w in &printer.notes {
            eprintln!("warning: {w}");
        }
    }
    let mut out = std::io::stdout().lock();
    if out
        .write_all(text.as_bytes())
        .and_then(|_| out.flush())
        .is_err()
    {
        return 1;
    }
    0
}

/// Where `--toply` writes meshes: `{prefix}_{n:05}.ply` in the current directory.
pub struct PlyOut {
    prefix: String,
    count: u32,
}

impl PlyOut {
    pub fn new(prefix: String) -> PlyOut {
        PlyOut { prefix, count: 0 }
    }
}

/// Prints statements back as scene text.
pub struct Printer<'a> {
    parsed: &'a Parsed,
    ply: Option<PlyOut>,
    indent: usize,
    out: String,
    /// Warnings found while printing.
    pub notes: Vec<String>,
}

impl<'a> Printer<'a> {
    pub fn new(parsed: &'a Parsed, ply: Option<PlyOut>) -> Printer<'a> {
        Printer {
            parsed,
            ply,
            indent: 0,
            out: String::new(),
            notes: Vec::new(),
        }
    }

    pub fn print_all(&mut self) -> Result<String, String> {
        for s in &self.parsed.stmts {
            self.stmt(s)?;
        }
        Ok(std::mem::take(&mut self.out))
    }

    fn line_start(&mut self) {
        for _ in 0..self.indent {
            self.out.push_str("    ");
        }
    }

    fn stmt(&mut self, s: &Stmt) -> Result<(), String> {
        use DirKind as K;
        match s.kind {
            K::AttributeEnd | K::TransformEnd | K::ObjectEnd => {
                self.indent = self.indent.saturating_sub(1)
            }
            K::WorldBegin => self.out.push('\n'),
            _ => {}
        }
        if s.kind == K::Shape && self.ply.is_some() {
            if let Directive::Entity { name, params } = &s.dir {
                if name.value == "trianglemesh" && self.toply(name, params)? {
                    return Ok(());
                }
            }
        }
        self.line_start();
        self.out.push_str(s.kind.name());
        match &s.dir {
            Directive::Plain => {}
            Directive::Numbers(v) => {
                let bracket = matches!(s.kind, K::Transform | K::ConcatTransform);
                if bracket {
                    self.out.push_str(" [");
                }
                for &x in v {
                    self.out.push(' ');
                    push_num(&mut self.out, x);
                }
                if bracket {
                    self.out.push_str(" ]");
                }
            }
            Directive::ActiveTransform(k) => self.out.push_str(match k {
                ActiveKind::All => " All",
                ActiveKind::StartTime => " StartTime",
                ActiveKind::EndTime => " EndTime",
            }),
            Directive::Named(n) => {
                self.out.push(' ');
                push_str(&mut self.out, &n.value);
            }
            Directive::MediumInterface(a, b) => {
                self.out.push(' ');
                push_str(&mut self.out, &a.value);
                if let Some(b) = b {
                    self.out.push(' ');
                    push_str(&mut self.out, &b.value);
                }
            }
            Directive::Texture {
                name,
                kind,
                class,
                params,
            } => {
                for n in [name, kind, class] {
                    self.out.push(' ');
                    push_str(&mut self.out, &n.value);
                }
                self.params(s.kind, &class.value, params, &[]);
            }
            Directive::Entity { name, params } => {
                self.out.push(' ');
                push_str(&mut self.out, &name.value);
                let class = if s.kind == K::MakeNamedMaterial {
                    params
                        .get("type")
                        .and_then(|q| q.strs().first())
                        .map(String::as_str)
                        .unwrap_or("")
                } else {
                    &name.value
                };
                self.params(s.kind, class, params, &[]);
            }
        }
        self.out.push('\n');
        match s.kind {
            K::AttributeBegin | K::TransformBegin | K::ObjectBegin => self.indent += 1,
            K::WorldBegin => self.out.push('\n'),
            _ => {}
        }
        Ok(())
    }

    /// Prints the parameters of a `kind` directive of class `class`, leaving out `skip`.
    fn params(&mut self, kind: DirKind, class: &str, p: &ParamList, skip: &[&str]) {
        for q in &p.items {
            if skip.contains(&q.name.as_str()) {
                continue;
            }
            self.out.push_str(" \"");
            self.out.push_str(type_spelling(q.ty));
            self.out.push(' ');
            self.out.push_str(&q.name);
            self.out.push_str("\" [");
            let file = is_file_param(kind, class, q);
            match &q.values {
                Values::Nums(v) => {
                    for &x in v {
                        self.out.push(' ');
                        push_num(&mut self.out, x);
                    }
                }
                Values::Strs(v) => {
                    for s in v {
                        self.out.push(' ');
                        if file && !s.is_empty() {
                            let path = self.resolve(q, s);
                            push_str(&mut self.out, &path.to_string_lossy());
                        } else {
                            push_str(&mut self.out, s);
                        }
                    }
                }
                Values::Bools(v) => {
                    for &b in v {
                        self.out
                            .push_str(if b { " \"true\"" } else { " \"false\"" });
                    }
                }
            }
            self.out.push_str(" ]");
        }
    }

    fn resolve(&self, q: &Param, name: &str) -> PathBuf {
        let dir = self
            .parsed
            .file_dirs
            .get(q.values_loc.file as usize)
            .map(PathBuf::as_path)
            .unwrap_or(Path::new(""));
        resolve(dir, name)
    }

    /// `--toply` for one trianglemesh: writes the PLY and prints a plymesh,
    /// or returns false (print it inline).
    fn toply(&mut self, name: &Name, p: &ParamList) -> Result<bool, String> {
        let Some(mesh) = PlyMesh::from_params(p) else {
            return Ok(false);
        };
        let Some(ply) = &mut self.ply else {
            return Ok(false);
        };
        ply.count += 1;
        let file = format!("{}_{:05}.ply", ply.prefix, ply.count);
        write_atomic(Path::new(&file), &mesh.encode())
            .map_err(|e| format!("cannot write PLY file \"{file}\": {e}"))?;
        if p.get("S").is_some() {
            self.notes.push(format!(
                "{file}: the PLY mesh has no tangent vectors \"S\" (as pbrt-v3; pbrs does not use them)"
            ));
        }
        let _ = name;
        self.line_start();
        self.out
            .push_str("Shape \"plymesh\" \"string filename\" [ ");
        push_str(&mut self.out, &file);
        self.out.push_str(" ]");
        self.params(
            DirKind::Shape,
            "plymesh",
            p,
            &["indices", "P", "uv", "st", "N", "S", "faceIndices"],
        );
        self.out.push('\n');
        Ok(true)
    }
}

/// pbrt-v3's spelling of a parameter type (what its printer writes).
fn type_spelling(t: ParamType) -> &'static str {
    match t {
        ParamType::Float => "float",
        ParamType::Integer => "integer",
        ParamType::Bool => "bool",
        ParamType::Point2 => "point2",
        ParamType::Vector2 => "vector2",
        ParamType::Point3 => "point",
        ParamType::Vector3 => "vector",
        ParamType::Normal => "normal",
        ParamType::String => "string",
        ParamType::Texture => "texture",
        ParamType::Rgb => "rgb",
        ParamType::Xyz => "xyz",
        ParamType::Blackbody => "blackbody",
        ParamType::Spectrum => "spectrum",
    }
}

/// Whether `q`'s strings are file names pbrt-v3 looks up relative to the
/// scene file (`FindOneFilename`, spectrum files).
fn is_file_param(kind: DirKind, class: &str, q: &Param) -> bool {
    use DirKind as K;
    if q.ty == ParamType::Spectrum {
        return true;
    }
    if q.ty != ParamType::String {
        return false;
    }
    let n = q.name.as_str();
    match kind {
        K::Shape => n == "filename" && matches!(class, "plymesh" | "objmesh" | "gltfmesh"),
        K::Texture => n == "filename" && matches!(class, "imagemap" | "ptex"),
        K::LightSource => {
            n == "mapname" && matches!(class, "infinite" | "goniometric" | "projection")
        }
        K::Camera => n == "lensfile" && class == "realistic",
        K::Material | K::MakeNamedMaterial => MATERIALS
            .iter()
            .find(|m| m.name == class)
            .and_then(|m| m.params.iter().find(|s| s.name == n))
            .is_some_and(|s| matches!(s.kind, ParamKind::Filename | ParamKind::FourierFile)),
        _ => false,
    }
}

/// Appends `v` in the shortest form that parses back to the same `f64`.
pub fn push_num(out: &mut String, v: f64) {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) {
        let _ = write!(out, "{v}");
    } else {
        let _ = write!(out, "{v:e}");
    }
}

/// Appends `s` quoted, with the escapes the lexer reads.
pub fn push_str(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            '\u{8}' => out.push_str("\\b"),
            '\u{c}' => out.push_str("\\f"),
            c => out.push(c),
        }
    }
    out.push('"');
}

/// A trianglemesh's data as the loader would take it, for a PLY file.
struct PlyMesh {
    positions: Vec<[f32; 3]>,
    indices: Vec<i32>,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    face_indices: Option<Vec<i32>>,
}

fn typed<'p>(p: &'p ParamList, name: &str, ok: impl Fn(ParamType) -> bool) -> Option<&'p Param> {
    p.items.iter().find(|q| q.name == name && ok(q.ty))
}

impl PlyMesh {
    /// The mesh if it has 500 indices or more and pbrs's trianglemesh would
    /// take every attribute as given (so the PLY renders identically).
    fn from_params(p: &ParamList) -> Option<PlyMesh> {
        let idx = typed(p, "indices", |t| t == ParamType::Integer)?.nums();
        if idx.len() < TOPLY_MIN_INDICES || idx.len() % 3 != 0 {
            return None;
        }
        let pv = typed(p, "P", |t| t == ParamType::Point3)?.nums();
        let positions: Vec<[f32; 3]> = pv
            .chunks_exact(3)
            .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
            .collect();
        let nv = positions.len();
        if nv == 0 || nv > i32::MAX as usize || positions.iter().flatten().any(|x| !x.is_finite()) {
            return None;
        }
        if idx.iter().any(|&i| i < 0.0 || i >= nv as f64) {
            return None;
        }
        let indices = idx.iter().map(|&i| i as i32).collect();
        // Any other "N", "uv" or "st" the loader would warn about and drop:
        // keep such a mesh inline.
        let normals = match p.get("N") {
            None => None,
            Some(q) if q.ty != ParamType::Normal => return None,
            Some(q) => {
                let n: Vec<[f32; 3]> = q
                    .nums()
                    .chunks_exact(3)
                    .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32])
                    .collect();
                let bad = |v: &[f32; 3]| v.iter().any(|x| !x.is_finite()) || *v == [0.0; 3];
                if n.len() != nv || n.iter().any(bad) {
                    return None;
                }
                Some(n)
            }
        };
        let uv_ok = |t| matches!(t, ParamType::Point2 | ParamType::Float);
        let uvq = typed(p, "uv", uv_ok).or_else(|| typed(p, "st", uv_ok));
        if uvq.is_none() && (p.get("uv").is_some() || p.get("st").is_some()) {
            return None;
        }
        let uvs = match uvq {
            None => None,
            Some(q) => {
                let v = q.nums();
                if v.len() != 2 * nv {
                    return None;
                }
                Some(
                    v.chunks_exact(2)
                        .map(|c| [c[0] as f32, c[1] as f32])
                        .collect(),
                )
            }
        };
        let face_indices = match p.get("faceIndices") {
            None => None,
            Some(q) if q.ty == ParamType::Integer && q.nums().len() == idx.len() / 3 => {
                if q.nums()
                    .iter()
                    .any(|&f| f < i32::MIN as f64 || f > i32::MAX as f64)
                {
                    return None;
                }
                Some(q.nums().iter().map(|&f| f as i32).collect())
            }
            Some(_) => return None,
        };
        Some(PlyMesh {
            positions,
            indices,
            normals,
            uvs,
            face_indices,
        })
    }

    /// Binary little-endian PLY, the properties pbrt-v3's `WritePlyFile` writes.
    fn encode(&self) -> Vec<u8> {
        let nt = self.indices.len() / 3;
        let mut h =
            String::from("ply\nformat binary_little_endian 1.0\ncomment written by pbrs --toply\n");
        let _ = writeln!(h, "element vertex {}", self.positions.len());
        h.push_str("property float x\nproperty float y\nproperty float z\n");
        if self.normals.is_some() {
            h.push_str("property float nx\nproperty float ny\nproperty float nz\n");
        }
        if self.uvs.is_some() {
            h.push_str("property float u\nproperty float v\n");
        }
        let _ = writeln!(h, "element face {nt}");
        h.push_str("property list uchar int vertex_indices\n");
        if self.face_indices.is_some() {
            h.push_str("property int face_indices\n");
        }
        h.push_str("end_header\n");
        let per_vertex =
            12 + self.normals.as_ref().map_or(0, |_| 12) + self.uvs.as_ref().map_or(0, |_| 8);
        let mut out = Vec::with_capacity(h.len() + self.positions.len() * per_vertex + nt * 17);
        out.extend_from_slice(h.as_bytes());
        for (i, p) in self.positions.iter().enumerate() {
            let mut put = |v: f32| out.extend_from_slice(&v.to_le_bytes());
            p.iter().for_each(|&v| put(v));
            if let Some(n) = &self.normals {
                n[i].iter().for_each(|&v| put(v));
            }
            if let Some(uv) = &self.uvs {
                uv[i].iter().for_each(|&v| put(v));
            }
        }
        for (t, tri) in self.indices.chunks_exact(3).enumerate() {
            out.push(3);
            for &i in tri {
                out.extend_from_slice(&i.to_le_bytes());
            }
            if let Some(f) = &self.face_indices {
                out.extend_from_slice(&f[t].to_le_bytes());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lang::lexer::parse_number;

    #[test]
    fn numbers_print_back_to_the_same_value() {
        // A simple LCG over bit patterns and decimal-looking values.
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut vals = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            1e-5,
            9.99e15,
            1e16,
            1e-300,
            1e300,
            123456789.125,
        ];
        for _ in 0..20000 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let v = f64::from_bits(x);
            if v.is_finite() {
                vals.push(v);
            }
            vals.push((x >> 40) as f64 / 1000.0);
            vals.push((x >> 11) as f32 as f64 * 1e-7);
        }
        for v in vals {
            let mut s = String::new();
            push_num(&mut s, v);
            let back = parse_number(s.as_bytes()).unwrap_or_else(|e| panic!("{s}: {e:?}"));
            assert_eq!(back.to_bits(), v.to_bits(), "{v:?} printed as {s}");
        }
    }

    #[test]
    fn strings_are_escaped() {
        let mut s = String::new();
        push_str(&mut s, "a\"b\\c\td");
        assert_eq!(s, r#""a\"b\\c\td""#);
    }
}
