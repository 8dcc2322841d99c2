//! The whole load path from bytes: tokenize, parse, build a scene from an
//! in-memory text whose Includes and mesh files are served from the same input,
//! and the PLY, OBJ and glTF readers on arbitrary bytes. Nothing may panic or allocate without
//! bound.
//!
//! Input layout: `scene text [0xFF files]`: every file name the scene asks for
//! (Include, plymesh, objmesh, gltfmesh) is served the bytes after the first 0xFF.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pbrs::loader::meshfile::{read_gltf, read_obj};
use pbrs::loader::{load_scene_with, ply::read_ply};
use pbrs::lang::FileLoader;
use std::path::Path;

struct Served(Vec<u8>);

impl FileLoader for Served {
    fn load(&self, path: &Path) -> Result<Vec<u8>, String> {
        if path.to_string_lossy().contains("missing") {
            return Err("not found".into());
        }
        Ok(self.0.clone())
    }
}

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0xFF).unwrap_or(data.len());
    let (scene, files) = (&data[..split], data.get(split + 1..).unwrap_or(&[]));
    let _ = read_ply(data);
    let _ = read_ply(files);
    let _ = read_obj(files);
    let _ = read_gltf(files, Path::new("."), &|_| Err("not served".into()));
    if let Ok(text) = std::str::from_utf8(scene) {
        let _ = load_scene_with(text, Path::new("fuzz.pbrt"), Box::new(Served(files.to_vec())));
    }
});
