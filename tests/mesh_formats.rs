//! The seed's dragon from every mesh format gives the same image: the binary
//! PLY of `scenes/cornell-dragon.pbrt` is converted at test time (in a temp
//! directory) to ASCII PLY, big-endian PLY, OBJ, binary glTF (`.glb`) and
//! glTF with an external `.bin`; each version of the scene renders at 64×64,
//! 4 spp to the same bytes as the original.

mod common;
use common::*;
use pbrs::image::Image;
use pbrs::loader::load_scene_str;
use pbrs::loader::ply::read_ply;
use pbrs::scene::MeshData;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

fn dragon() -> MeshData {
    let bytes = std::fs::read(repo().join("scenes/meshes/dragon_43k.ply")).unwrap();
    read_ply(&bytes).unwrap().mesh
}

fn temp_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("pbrs-mesh-formats-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ascii_ply(m: &MeshData) -> Vec<u8> {
    let mut s = format!(
        "ply\nformat ascii 1.0\ncomment converted by tests/mesh_formats.rs\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        m.positions.len(),
        m.triangle_count()
    );
    // `{}` prints the shortest decimal that reads back as the same f32.
    for p in m.positions.iter() {
        writeln!(s, "{} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in m.indices.chunks_exact(3) {
        writeln!(s, "3 {} {} {}", t[0], t[1], t[2]).unwrap();
    }
    s.into_bytes()
}

fn big_endian_ply(m: &MeshData) -> Vec<u8> {
    let mut d = format!(
        "ply\nformat binary_big_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar ushort vertex_index\nend_header\n",
        m.positions.len(),
        m.triangle_count()
    )
    .into_bytes();
    for p in m.positions.iter() {
        for c in p.to_array() {
            d.extend_from_slice(&c.to_be_bytes());
        }
    }
    for t in m.indices.chunks_exact(3) {
        d.push(3);
        for &i in t {
            d.extend_from_slice(&u16::try_from(i).unwrap().to_be_bytes());
        }
    }
    d
}

fn obj(m: &MeshData) -> Vec<u8> {
    let mut s = String::from("# converted by tests/mesh_formats.rs\no dragon\n");
    for p in m.positions.iter() {
        writeln!(s, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in m.indices.chunks_exact(3) {
        writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).unwrap();
    }
    s.into_bytes()
}

/// (JSON, binary buffer) of a one-mesh glTF; `uri` names an external buffer.
fn gltf_parts(m: &MeshData, uri: Option<&str>) -> (String, Vec<u8>) {
    let mut bin = Vec::new();
    for p in m.positions.iter() {
        for c in p.to_array() {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let pos_len = bin.len();
    for &i in m.indices.iter() {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in m.positions.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let uri = uri.map(|u| format!(",\"uri\":\"{u}\"")).unwrap_or_default();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],"buffers":[{{"byteLength":{}{uri}}}],"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{pos_len}}},{{"buffer":0,"byteOffset":{pos_len},"byteLength":{}}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":{},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}},{{"bufferView":1,"componentType":5125,"count":{},"type":"SCALAR"}}]}}"#,
        bin.len(),
        bin.len() - pos_len,
        m.positions.len(),
        lo[0],
        lo[1],
        lo[2],
        hi[0],
        hi[1],
        hi[2],
        m.indices.len()
    );
    (json, bin)
}

fn glb(m: &MeshData) -> Vec<u8> {
    let (json, mut bin) = gltf_parts(m, None);
    let mut json = json.into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut d = Vec::with_capacity(total);
    d.extend_from_slice(b"glTF");
    d.extend_from_slice(&2u32.to_le_bytes());
    d.extend_from_slice(&(total as u32).to_le_bytes());
    d.extend_from_slice(&(json.len() as u32).to_le_bytes());
    d.extend_from_slice(b"JSON");
    d.extend_from_slice(&json);
    d.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    d.extend_from_slice(b"BIN\0");
    d.extend_from_slice(&bin);
    d
}

/// cornell-dragon.pbrt with its dragon `Shape` replaced.
fn scene_with(shape: &str, file: &Path) -> String {
    let text = std::fs::read_to_string(repo().join("scenes/cornell-dragon.pbrt")).unwrap();
    let old = r#"Shape "plymesh" "string filename" [ "meshes/dragon_43k.ply" ]"#;
    assert!(text.contains(old));
    text.replace(
        old,
        &format!(
            r#"Shape "{shape}" "string filename" [ "{}" ]"#,
            file.display()
        ),
    )
}

fn render_text(text: &str, dir: &Path) -> Image {
    let loaded = load_scene_str(text, &dir.join("scene.pbrt"))
        .unwrap_or_else(|f| panic!("scene failed to load: {f:?}"));
    assert_eq!(
        loaded
            .scene
            .shapes
            .iter()
            .map(|s| match &s.surface {
                pbrs::scene::Surface::TriangleMesh(m) => m.triangle_count(),
                _ => 0,
            })
            .max(),
        Some(43534)
    );
    render_at(loaded.scene, 64, 4, None).0
}

fn bits(img: &Image) -> Vec<u32> {
    img.data.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn every_format_renders_the_same_bytes() {
    let m = dragon();
    let dir = temp_dir();
    let original = render_text(
        &scene_with("plymesh", &repo().join("scenes/meshes/dragon_43k.ply")),
        &dir,
    );
    let (gltf_json, gltf_bin) = gltf_parts(&m, Some("dragon%20data.bin"));
    let files: Vec<(&str, &str, Vec<u8>)> = vec![
        ("plymesh", "dragon_ascii.ply", ascii_ply(&m)),
        ("plymesh", "dragon_be.ply", big_endian_ply(&m)),
        ("objmesh", "dragon.obj", obj(&m)),
        ("gltfmesh", "dragon.glb", glb(&m)),
        ("gltfmesh", "dragon.gltf", gltf_json.into_bytes()),
    ];
    std::fs::write(dir.join("dragon data.bin"), gltf_bin).unwrap();
    let mut mismatches = Vec::new();
    for (shape, name, bytes) in files {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let img = render_text(&scene_with(shape, &path), &dir);
        if bits(&img) != bits(&original) {
            mismatches.push(name);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        mismatches.is_empty(),
        "different images from {mismatches:?}"
    );
}
