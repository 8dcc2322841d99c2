//! The whole load path from bytes: tokenize, parse, build a scene from an
//! in-memory text whose Includes and PLY meshes are served from the same input,
//! and the PLY reader on arbitrary bytes. Nothing may panic or allocate without
//! bound.
//!
//! Input layout: `scene text [0xFF files]`: every file name the scene asks for
//! (Include, plymesh) is served the bytes after the first 0xFF.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pbrs::build::{load_scene_with, ply::read_ply};
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
    if let Ok(text) = std::str::from_utf8(scene) {
        let _ = load_scene_with(text, Path::new("fuzz.pbrt"), Box::new(Served(files.to_vec())));
    }
});
