//! The mesh readers on damaged input: every truncation and thousands of byte
//! flips of small valid PLY (ascii, both binary orders), OBJ and glTF files
//! give a mesh or an error, never a panic and never a huge allocation (a
//! count that does not fit the file is an error before anything is reserved).

use pbrs::loader::meshfile::{read_gltf, read_obj};
use pbrs::loader::ply::read_ply;
use std::path::Path;

fn ply(format: &str, be: bool) -> Vec<u8> {
    let mut d = format!(
        "ply\nformat {format} 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    let v = [
        [0.0f32, 0.0, 0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0, 0.0, 1.0],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[0, 2, 1]];
    if format == "ascii" {
        for p in v {
            d.extend_from_slice(
                format!("{} {} {} {} {}\n", p[0], p[1], p[2], p[3], p[4]).as_bytes(),
            );
        }
        for f in faces {
            let s: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            d.extend_from_slice(format!("{} {}\n", f.len(), s.join(" ")).as_bytes());
        }
        return d;
    }
    for p in v {
        for c in p {
            d.extend_from_slice(&if be { c.to_be_bytes() } else { c.to_le_bytes() });
        }
    }
    for f in faces {
        d.push(f.len() as u8);
        for &i in f {
            d.extend_from_slice(&if be { i.to_be_bytes() } else { i.to_le_bytes() });
        }
    }
    d
}

const OBJ: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf 1 3 2\n";

/// A one-triangle glTF with its buffer as a base64 data URI.
const GLTF: &str = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"children":[1],"translation":[1,2,3]},{"mesh":0,"scale":[2,2,2]}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],"buffers":[{"byteLength":42,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIA"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;

fn gltf(b: &[u8]) -> Result<pbrs::scene::MeshData, String> {
    read_gltf(b, Path::new("."), &|_| Err("no files".into()))
}

fn damage(valid: &[u8], read: &dyn Fn(&[u8]) -> bool) {
    assert!(read(valid), "the undamaged file must load");
    for n in 0..valid.len() {
        read(&valid[..n]);
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..3000 {
        let mut d = valid.to_vec();
        for _ in 0..1 + (state % 3) {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state % d.len() as u64) as usize;
            d[at] = (state >> 32) as u8;
        }
        read(&d);
    }
}

#[test]
fn ply_survives_damage() {
    for (format, be) in [
        ("ascii", false),
        ("binary_little_endian", false),
        ("binary_big_endian", true),
    ] {
        let valid = ply(format, be);
        let m = read_ply(&valid).unwrap().mesh;
        assert_eq!(*m.indices, vec![0, 1, 2, 0, 2, 3, 0, 2, 1], "{format}");
        assert_eq!(m.uvs.as_ref().map(Vec::len), Some(4));
        damage(&valid, &|b| read_ply(b).is_ok());
    }
}

#[test]
fn obj_survives_damage() {
    let m = read_obj(OBJ.as_bytes()).unwrap();
    assert_eq!(m.triangle_count(), 3);
    damage(OBJ.as_bytes(), &|b| read_obj(b).is_ok());
}

#[test]
fn gltf_node_transforms_and_damage() {
    let m = gltf(GLTF.as_bytes()).unwrap();
    assert_eq!(*m.indices, vec![0, 1, 2]);
    // Node (translate 1 2 3) → child (scale 2): (1,0,0) ↦ (3,2,3).
    assert_eq!(m.positions[1], glam::Vec3::new(3.0, 2.0, 3.0));
    damage(GLTF.as_bytes(), &|b| gltf(b).is_ok());
}
