//! The `Camera` directive: the kind's builder from
//! [`CAMERAS`](crate::cameras::CAMERAS) (pbrt-v3's `Create*Camera`
//! with its checks, in the kinds' files), the camera transform and the
//! shutter, which every kind has. The realistic camera's lens file is read
//! here (file names resolve as pbrt-v3's, relative to the top-level file).

use super::kinds::{self, Buffered, Family, StatementReport, Unknown};
use super::Ctx;
use crate::cameras::{CameraInput, FileSource, CAMERAS};
use crate::lang::params::ParamList;
use crate::lang::parser::Name;
use crate::lang::Loc;
use crate::scene::{CameraDesc, FilmDesc};
use glam::DMat4;
use std::path::PathBuf;

/// Files a camera's parameters name, read through the scene's file loader.
struct Files<'a> {
    ctx: &'a mut Ctx,
    params: &'a ParamList,
    at: Loc,
}

impl FileSource for Files<'_> {
    fn read(&mut self, param: &str, name: &str) -> (PathBuf, Result<Vec<u8>, String>) {
        let loc = self.params.get(param).map_or(self.at, |q| q.values_loc);
        let path = self.ctx.resolve(loc, name);
        let bytes = self.ctx.loader.load(&path).map_err(|e| e.to_string());
        (path, bytes)
    }
}

/// The camera of the `Camera` statement made under `ctm` (pbrt-v3's
/// default perspective camera without one); `film` gives the realistic
/// camera its sensor size.
pub fn camera(
    ctx: &mut Ctx,
    c: Option<((&Name, &ParamList), DMat4)>,
    film: &FilmDesc,
) -> CameraDesc {
    let Some(((name, p), ctm)) = c else {
        return CameraDesc::default();
    };
    let mut camera_to_world = ctm.inverse();
    if !camera_to_world.is_finite() || ctm.determinant().abs() < 1e-300 {
        ctx.error(
            name.loc,
            "the camera transform (the CTM at Camera) is singular: it cannot be inverted",
            "this Camera",
            None,
        );
        camera_to_world = DMat4::IDENTITY;
    }
    let family = Family {
        directive: "Camera",
        noun: "camera",
        table: CAMERAS,
        unknown: Unknown::Error,
    };
    let Some(read) = kinds::read(ctx, &family, name, p) else {
        return CameraDesc::default();
    };
    let mut files = Files {
        ctx,
        params: p,
        at: name.loc,
    };
    // The file reader borrows the context: the builder's messages are kept
    // and reported after it.
    let built = {
        let mut buffered = Buffered::default();
        let projection = (read.kind.build)(
            &read.params,
            &mut CameraInput {
                film,
                files: &mut files,
            },
            &mut buffered,
        );
        buffered.replay(&mut StatementReport {
            ctx,
            at: name.loc,
            params: p,
        });
        projection
    };
    let projection = match built {
        Some(projection) => projection,
        None => {
            p.mark_all_used();
            Default::default()
        }
    };
    let mut open = read.params.float("shutteropen");
    let mut close = read.params.float("shutterclose");
    if close < open {
        ctx.warn(
            name.loc,
            "shutterclose < shutteropen: swapped (as pbrt-v3)",
            "shutter",
        );
        std::mem::swap(&mut open, &mut close);
    }
    kinds::report_unused(ctx, &family, &read, name, p);
    CameraDesc {
        camera_to_world,
        motion: None,
        projection,
        shutter_open: open,
        shutter_close: close,
    }
}
