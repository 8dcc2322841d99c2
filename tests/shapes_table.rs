//! Every kind of `shapes::SHAPES`, loaded from a `Shape` statement
//! (mesh files written next to the scene): it builds the geometry it should,
//! without warnings, and its checks fire on a bad parameter, located at the
//! parameter. A kind of the table without a case here fails.

use pbrs::loader::load_scene_str;
use pbrs::scene::Surface;
use pbrs::shapes::{kind_name, SHAPES};
use std::path::{Path, PathBuf};

/// One kind's case: a good statement, what it builds (kind name, triangle
/// count), a bad statement and a piece of its message.
struct Case {
    good: &'static str,
    builds: &'static str,
    triangles: usize,
    bad: &'static str,
    says: &'static str,
}

fn case(name: &str) -> Option<Case> {
    let c = |good, builds, triangles, bad, says| Case {
        good,
        builds,
        triangles,
        bad,
        says,
    };
    Some(match name {
        "sphere" => c(
            r#""float radius" 2 "float zmin" -1"#,
            "sphere",
            0,
            r#""float radius" -1"#,
            "sphere radius -1 is not positive",
        ),
        "disk" => c(
            r#""float innerradius" 0.5"#,
            "disk",
            0,
            r#""float innerradius" 2"#,
            "disk with an empty extent",
        ),
        "cylinder" => c(
            r#""float zmin" 0"#,
            "cylinder",
            0,
            r#""float radius" 0"#,
            "cylinder radius 0",
        ),
        "cone" => c(
            r#""float height" 2"#,
            "cone",
            0,
            r#""float height" -1"#,
            "cone height -1 is not a positive 32-bit float",
        ),
        "paraboloid" => c(
            r#""float zmin" 0.5"#,
            "paraboloid",
            0,
            r#""float zmax" -1"#,
            "paraboloid zmax",
        ),
        "hyperboloid" => c(
            r#""point p1" [1 0 -1] "point p2" [0 1 1]"#,
            "hyperboloid",
            0,
            r#""point p1" [1 0 0] "point p2" [0 1 0]"#,
            "same height",
        ),
        "curve" => c(
            r#""point P" [0 0 0 1 0 0 2 1 0 3 1 0] "float width" 0.1"#,
            "curve",
            0,
            r#""point P" [0 0 0 1 0 0 2 1 0] "float width" 0.1"#,
            "3 control points",
        ),
        "trianglemesh" => c(
            r#""point P" [0 0 0 1 0 0 1 1 0 0 1 0] "integer indices" [0 1 2 0 2 3] "float uv" [0 0 1 0 1 1 0 1]"#,
            "trianglemesh",
            2,
            r#""point P" [0 0 0 1 0 0 1 1 0] "integer indices" [0 1 3]"#,
            "out of range",
        ),
        "plymesh" => c(
            r#""string filename" "quad.ply""#,
            "trianglemesh",
            2,
            r#""string filename" "missing.ply""#,
            "cannot read PLY file",
        ),
        "objmesh" => c(
            r#""string filename" "quad.obj""#,
            "trianglemesh",
            2,
            r#""string filename" "missing.obj""#,
            "cannot read OBJ file",
        ),
        "gltfmesh" => c(
            r#""string filename" "tri.gltf""#,
            "trianglemesh",
            1,
            r#""string filename" "missing.gltf""#,
            "cannot read glTF file",
        ),
        "loopsubdiv" => c(
            r#""integer levels" 1 "point P" [0 0 0 1 0 0 0 1 0 0 0 1] "integer indices" [0 2 1 0 1 3 0 3 2 1 2 3]"#,
            "trianglemesh",
            16,
            r#""point P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 5]"#,
            "loopsubdiv",
        ),
        "nurbs" => c(
            r#""integer nu" 2 "integer nv" 2 "integer uorder" 2 "integer vorder" 2 "float uknots" [0 0 1 1] "float vknots" [0 0 1 1] "point P" [0 0 0 1 0 0 0 1 0 1 1 0]"#,
            "trianglemesh",
            2 * 29 * 29,
            r#""integer nu" 2"#,
            "nurbs",
        ),
        "heightfield" => c(
            r#""integer nu" 2 "integer nv" 3 "float Pz" [0 0 1 1 0 0]"#,
            "trianglemesh",
            4,
            r#""integer nu" 2 "integer nv" 2 "float Pz" [0 0 1]"#,
            "\"Pz\" has 3 heights",
        ),
        _ => return None,
    })
}

fn temp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-shapes-table-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A unit quad as ASCII PLY and OBJ, a triangle as glTF with its buffer.
fn write_files(dir: &Path) {
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    std::fs::write(dir.join("quad.ply"), ply).unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    std::fs::write(dir.join("quad.obj"), obj).unwrap();
    let bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    let gltf = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
"buffers":[{"uri":"tri.bin","byteLength":36}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]}"#;
    std::fs::write(dir.join("tri.gltf"), gltf).unwrap();
}

fn scene(kind: &str, params: &str) -> String {
    format!("WorldBegin\nShape \"{kind}\" {params}\nWorldEnd\n")
}

#[test]
fn every_shape_kind_has_a_case_and_builds() {
    let dir = temp_dir();
    write_files(&dir);
    let path = dir.join("scene.pbrt");
    let mut missing = Vec::new();
    for k in SHAPES {
        let Some(c) = case(k.name) else {
            missing.push(k.name);
            continue;
        };
        let loaded = load_scene_str(&scene(k.name, c.good), &path)
            .unwrap_or_else(|f| panic!("{}: {:?}", k.name, f.errors));
        let warnings: Vec<String> = loaded.warnings.iter().map(|w| w.to_string()).collect();
        assert!(warnings.is_empty(), "{}: {warnings:?}", k.name);
        let shapes = &loaded.scene.shapes;
        assert_eq!(shapes.len(), 1, "{}", k.name);
        let g = &shapes[0].surface;
        assert_eq!(kind_name(g), c.builds, "{}", k.name);
        let tris = match g {
            Surface::TriangleMesh(m) => m.triangle_count(),
            _ => 0,
        };
        assert_eq!(tris, c.triangles, "{}", k.name);
        // The bad statement: an error (no scene), or a warning and no shape.
        let text = scene(k.name, c.bad);
        let said = match load_scene_str(&text, &path) {
            Err(f) => f.errors.iter().map(|e| e.to_string()).collect::<Vec<_>>(),
            Ok(l) => {
                assert!(l.scene.shapes.is_empty(), "{}: bad case built", k.name);
                l.warnings.iter().map(|w| w.to_string()).collect()
            }
        };
        assert!(
            said.iter().any(|m| m.contains(c.says)),
            "{}: expected {:?} in {said:?}",
            k.name,
            c.says
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        missing.is_empty(),
        "shape kinds without a case: {missing:?}"
    );
}

#[test]
fn unknown_shapes_are_skipped_with_a_hint() {
    let dir = temp_dir();
    let l = load_scene_str(&scene("sphre", ""), &dir.join("scene.pbrt")).unwrap();
    assert!(l.scene.shapes.is_empty());
    let w: Vec<String> = l.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        w.iter()
            .any(|m| m.contains("unknown shape \"sphre\" (did you mean \"sphere\"?)")),
        "{w:?}"
    );
}
