//! Every `.pbrt` file under `scenes/` passes `pbrs --check` (exit 0) with the
//! expected summary, through the binary and through the library.

use pbrs::loader::load_scene;
use pbrs::scene::*;
use std::path::Path;
use std::process::Command;

struct Expect {
    file: &'static str,
    shapes: usize,
    triangles: usize,
    area_lights: usize,
    materials: &'static [(&'static str, usize)],
    lines: &'static [&'static str],
    /// Substrings of the expected warnings, one per warning.
    warnings: &'static [&'static str],
}

const EXPECT: &[Expect] = &[
    Expect {
        file: "cornell-box.pbrt",
        warnings: &[],
        shapes: 8,
        triangles: 36,
        area_lights: 1,
        materials: &[("matte", 4)],
        lines: &[
            "film:       1024×1024",
            "sampler:    sobol, 64 samples per pixel",
            "filter:     triangle, radius 1 1",
            "integrator: path, maxdepth 65",
        ],
    },
    Expect {
        file: "cornell-direct.pbrt",
        warnings: &[],
        shapes: 8,
        triangles: 36,
        area_lights: 1,
        materials: &[("matte", 4)],
        lines: &[
            "integrator: directlighting, maxdepth 5, strategy all",
            "film:       512×512",
        ],
    },
    Expect {
        file: "cornell-dragon-glass.pbrt",
        warnings: &[],
        shapes: 7,
        triangles: 43_546,
        area_lights: 1,
        materials: &[("glass", 1), ("matte", 3)],
        lines: &["materials:  4 (1 glass, 3 matte)"],
    },
    Expect {
        file: "cornell-dragon.pbrt",
        warnings: &[],
        shapes: 7,
        triangles: 43_546,
        area_lights: 1,
        materials: &[("matte", 4)],
        lines: &[
            "camera:     perspective, fov 90°, lens radius 0.02",
            "light samples uniform",
        ],
    },
    Expect {
        file: "cornell-glass.pbrt",
        warnings: &[],
        shapes: 8,
        triangles: 12,
        area_lights: 1,
        materials: &[("glass", 1), ("matte", 4)],
        lines: &[
            "shapes:     8 (2 sphere, 6 trianglemesh)",
            "integrator: path, maxdepth 16",
        ],
    },
    Expect {
        file: "cornell-path.pbrt",
        warnings: &[],
        shapes: 8,
        triangles: 36,
        area_lights: 1,
        materials: &[("matte", 4)],
        lines: &[
            "integrator: path, maxdepth 8",
            "sampler:    halton, 64 samples per pixel",
        ],
    },
    Expect {
        file: "instancing-dragons.pbrt",
        warnings: &[],
        shapes: 1,
        triangles: 2,
        area_lights: 0,
        materials: &[("matte", 2)],
        lines: &["objects:    1 (1 shapes, 43534 triangles), 100 instances"],
    },
    Expect {
        file: "materials-a.pbrt",
        warnings: &[],
        shapes: 9,
        triangles: 12,
        area_lights: 1,
        materials: &[("matte", 4), ("metal", 1), ("plastic", 1), ("substrate", 1)],
        lines: &[
            "shapes:     9 (3 sphere, 6 trianglemesh)",
            "materials:  7 (4 matte, 1 metal, 1 plastic, 1 substrate)",
            "integrator: path, maxdepth 8, rrthreshold 1, light samples spatial",
        ],
    },
    Expect {
        file: "materials-direct.pbrt",
        warnings: &[],
        shapes: 9,
        triangles: 12,
        area_lights: 1,
        materials: &[("matte", 4), ("metal", 1), ("plastic", 1), ("substrate", 1)],
        lines: &[
            "shapes:     9 (3 sphere, 6 trianglemesh)",
            "materials:  7 (4 matte, 1 metal, 1 plastic, 1 substrate)",
            "integrator: directlighting, maxdepth 5, strategy all",
        ],
    },
    Expect {
        file: "materials-whitted.pbrt",
        warnings: &[],
        shapes: 9,
        triangles: 12,
        area_lights: 1,
        materials: &[("matte", 4), ("metal", 1), ("plastic", 1), ("substrate", 1)],
        lines: &[
            "shapes:     9 (3 sphere, 6 trianglemesh)",
            "materials:  7 (4 matte, 1 metal, 1 plastic, 1 substrate)",
            "integrator: whitted, maxdepth 5",
        ],
    },
    Expect {
        // heightfield 11·9·2, Loop grid 32·16, Loop octahedron 8·64, two
        // NURBS 2·29·29 each, ground 2.
        file: "refined-shapes.pbrt",
        warnings: &[],
        shapes: 6,
        triangles: 198 + 512 + 512 + 2 * 1682 + 2,
        area_lights: 0,
        materials: &[("matte", 2), ("plastic", 4)],
        lines: &[
            "shapes:     6 (6 trianglemesh)",
            "lights:     2 (0 area-light shapes; 1 distant, 1 infinite)",
        ],
    },
];

fn scenes_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

#[test]
fn every_scene_is_covered() {
    let mut files: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".pbrt"))
        .collect();
    files.sort();
    let expected: Vec<&str> = EXPECT.iter().map(|e| e.file).collect();
    assert_eq!(files, expected);
}

#[test]
fn check_passes_with_expected_summary() {
    for e in EXPECT {
        let out = Command::new(env!("CARGO_BIN_EXE_pbrs"))
            .arg("--check")
            .arg(Path::new("scenes").join(e.file))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{}: {stderr}", e.file);
        for w in e.warnings {
            assert!(
                stderr.contains(w),
                "{}: expected warning {w:?} in {stderr}",
                e.file
            );
        }
        assert_eq!(
            stderr.matches('⚠').count(),
            e.warnings.len(),
            "{}: unexpected warnings: {stderr}",
            e.file
        );
        assert!(
            stdout.contains(&format!("shapes:     {} (", e.shapes)),
            "{}: {stdout}",
            e.file
        );
        assert!(
            stdout.contains(&format!("triangles:  {}\n", e.triangles)),
            "{}: {stdout}",
            e.file
        );
        assert!(
            stdout.contains(&format!("({} area-light shapes", e.area_lights)),
            "{}: {stdout}",
            e.file
        );
        for l in e.lines {
            assert!(stdout.contains(l), "{}: {l:?} not in\n{stdout}", e.file);
        }
    }
}

#[test]
fn library_loads_with_expected_counts() {
    for e in EXPECT {
        let loaded =
            load_scene(&scenes_dir().join(e.file)).unwrap_or_else(|f| panic!("{}: {f:?}", e.file));
        let s = &loaded.summary;
        assert_eq!(loaded.warnings.len(), e.warnings.len(), "{}", e.file);
        assert_eq!(s.shapes, e.shapes, "{}", e.file);
        assert_eq!(s.triangles, e.triangles, "{}", e.file);
        assert_eq!(s.area_lights, e.area_lights, "{}", e.file);
        let mats: Vec<(&str, usize)> = s.materials_by_type.iter().map(|(k, v)| (*k, *v)).collect();
        assert_eq!(mats, e.materials, "{}", e.file);
        assert_eq!(
            loaded.scene.materials.len(),
            e.materials.iter().map(|m| m.1).sum::<usize>()
        );
        for sh in &loaded.scene.shapes {
            assert!((sh.material.0 as usize) < loaded.scene.materials.len());
            if let Surface::TriangleMesh(m) = &sh.surface {
                assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
            }
        }
    }
}

#[test]
fn cornell_path_details() {
    let s = load_scene(&scenes_dir().join("cornell-path.pbrt"))
        .unwrap()
        .scene;
    // Scale -1 1 1, LookAt 0 1 6.8 -> 0 1 0: the camera sits at (0, 1, 6.8).
    let eye = s.camera.camera_to_world.transform_point3(glam::DVec3::ZERO);
    assert!(
        (eye - glam::DVec3::new(0.0, 1.0, 6.8)).length() < 1e-9,
        "{eye}"
    );
    let fwd = s.camera.camera_to_world.transform_vector3(glam::DVec3::Z);
    assert!((fwd - glam::DVec3::new(0.0, 0.0, -1.0)).length() < 1e-9);
    // The light: first shape, emits 17 12 4, one-sided, normals given.
    let light = s.shapes.iter().find(|sh| sh.area_light.is_some()).unwrap();
    let a = light.area_light.unwrap();
    assert_eq!(a.l, glam::Vec3::new(17.0, 12.0, 4.0));
    assert!(!a.two_sided);
    let m = &s.materials[light.material.0 as usize];
    assert_eq!(m.kind, "matte");
    assert_eq!(m.constant_spectrum("Kd"), Some(glam::Vec3::ZERO));
    assert_eq!(m.constant_float("sigma"), Some(0.0));
    // The boxes: unitcube.inc under Translate·Rotate·Scale.
    let boxes: Vec<_> = s
        .shapes
        .iter()
        .filter(|sh| matches!(&sh.surface, Surface::TriangleMesh(m) if m.triangle_count() == 12))
        .collect();
    assert_eq!(boxes.len(), 2);
    let c = boxes[0].object_to_world.transform_point3(glam::DVec3::ZERO);
    assert!((c - glam::DVec3::new(0.33, 0.3, 0.37)).length() < 1e-9);
}

#[test]
fn dragon_mesh_is_loaded_once_and_shared() {
    let s = load_scene(&scenes_dir().join("cornell-dragon.pbrt"))
        .unwrap()
        .scene;
    let dragon = s
        .shapes
        .iter()
        .find_map(|sh| match &sh.surface {
            Surface::TriangleMesh(m) if m.triangle_count() > 1000 => Some(m.clone()),
            _ => None,
        })
        .unwrap();
    assert_eq!(dragon.triangle_count(), 43_534);
    assert_eq!(dragon.positions.len(), 21_790);
    assert!(dragon.normals.is_none());
}
