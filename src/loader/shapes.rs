//! `Shape` statements: the kind found in
//! [`SHAPES`](crate::shapes::SHAPES) and built from its parameters
//! (unknown shapes: a warning, and the shape is skipped, as pbrt-v3); the
//! files a kind's builder asks for (PLY, OBJ, glTF meshes) and the refined
//! shapes' meshes come from here, through [`ShapeInput`].

use super::kinds::{self, Family, StatementReport, Unknown};
use super::meshfile::{read_gltf, read_obj};
use super::ply::{read_ply, PlyMesh};
use super::Ctx;
use crate::lang::params::ParamList;
use crate::lang::parser::Name;
use crate::scene::{kind, MeshData, Report, Surface};
use crate::shapes::{MeshFormat, ShapeBuild, ShapeInput, SHAPES};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// The meshes read so far, by resolved path (`None`: the file failed).
pub type MeshCache = HashMap<PathBuf, Option<Arc<MeshData>>>;

const FAMILY: Family<ShapeBuild> = Family {
    directive: "Shape",
    noun: "shape",
    table: SHAPES,
    unknown: Unknown::Warn,
};

/// True for shapes pbrs skips as unknown (an invalid shape of a known type
/// got an error or warning of its own).
pub fn is_unsupported_shape(name: &str) -> bool {
    kind::find(SHAPES, name).is_none()
}

/// The surface of a `Shape`, or `None` (unknown or invalid: a warning, as
/// pbrt-v3 renders on without it; the kind's builder says why). Unused parameters are left to the
/// caller (the material may still read some).
pub fn surface(
    ctx: &mut Ctx,
    name: &Name,
    p: &ParamList,
    meshes: &mut MeshCache,
) -> Option<Surface> {
    let r = kinds::read(ctx, &FAMILY, name, p)?;
    let mut input = Input {
        report: StatementReport {
            ctx,
            at: name.loc,
            params: p,
        },
        name,
        meshes,
    };
    (r.kind.build)(&r.params, &mut input)
}

/// The loader's side of a shape kind's builder.
struct Input<'a> {
    report: StatementReport<'a>,
    name: &'a Name,
    meshes: &'a mut MeshCache,
}

impl Report for Input<'_> {
    fn warn(&mut self, at: Option<&str>, msg: String, label: &str) {
        self.report.warn(at, msg, label);
    }
    /// pbrt-v3 reports an invalid shape with `Error` and renders on
    /// without it: a warning that says the shape is skipped.
    fn error(&mut self, at: Option<&str>, msg: String, label: &str) {
        self.report.warn(at, format!("{msg}: {SKIPPED}"), label);
    }
}

/// What follows every reason a shape is not built.
const SKIPPED: &str =
    "the shape is skipped and the rest renders (as pbrt-v3 reports an invalid shape)";

impl ShapeInput for Input<'_> {
    fn mesh_file(&mut self, format: MeshFormat, file: &str) -> Option<Arc<MeshData>> {
        let floc = self
            .report
            .params
            .get("filename")
            .map_or(self.name.loc, |q| q.values_loc);
        let ctx = &mut *self.report.ctx;
        let path = ctx.resolve(floc, file);
        if let Some(m) = self.meshes.get(&path) {
            return m.clone();
        }
        let kind = format.label();
        let result = match ctx.loader.load(&path) {
            Err(e) => Err(format!(
                "cannot read {kind} file \"{}\": {e}",
                path.display()
            )),
            Ok(bytes) => {
                let read = match format {
                    MeshFormat::Ply => read_ply(&bytes),
                    MeshFormat::Obj => read_obj(&bytes).map(|mesh| PlyMesh {
                        mesh,
                        notes: Vec::new(),
                    }),
                    MeshFormat::Gltf => {
                        let dir = path.parent().unwrap_or(std::path::Path::new("."));
                        let loader = &ctx.loader;
                        read_gltf(&bytes, dir, &|f| loader.load(f)).map(|mesh| PlyMesh {
                            mesh,
                            notes: Vec::new(),
                        })
                    }
                };
                read.map_err(|e| format!("{kind} file \"{}\": {e}", path.display()))
            }
        };
        let mesh = match result {
            Ok(m) => {
                for n in m.notes {
                    ctx.warn(
                        floc,
                        format!("{kind} file \"{}\": {n}", path.display()),
                        "this mesh",
                    );
                }
                if m.mesh.positions.iter().any(|v| !v.is_finite()) {
                    ctx.warn(
                        floc,
                        format!(
                            "{kind} file \"{}\" has a vertex that is not a finite 32-bit number: {SKIPPED}",
                            path.display()
                        ),
                        "this mesh",
                    );
                    None
                } else {
                    Some(Arc::new(m.mesh))
                }
            }
            Err(e) => {
                ctx.warn(floc, format!("{e}: {SKIPPED}"), "this mesh");
                None
            }
        };
        self.meshes.insert(path, mesh.clone());
        mesh
    }

    fn refine(&mut self, _kind: &'static str) -> Option<MeshData> {
        super::refine::shape(self.report.ctx, self.name, self.report.params)
    }
}
