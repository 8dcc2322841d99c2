//! Errors pbrt-v3 renders through (README: "Errors pbrt-v3 renders
//! through"): each case loads with a located warning that names the file or
//! name and the substitute, and renders the image of the scene written with
//! the substitute; `--strict` makes the warning an error (exit 1, no image).

mod common;

use common::{load_text, render_at, warning_text};
use std::process::Command;

// (A missing `.png` texture is pbrt-v3's grey 0.5 sRGB-decoded, as every
// 8-bit texel: 0.214; an `.exr` one is 0.5.)

/// The scene around one statement block: a sphere in front of the camera
/// lit by a point light, with `body` in the world block.
fn scene(body: &str) -> String {
    format!(
        "LookAt 0 0 -4  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
         Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16\n\
         Sampler \"halton\" \"integer pixelsamples\" 4\n\
         WorldBegin\nLightSource \"point\" \"point from\" [0 2 -3] \"rgb I\" [8 8 8]\n{body}\nWorldEnd\n"
    )
}

struct Case {
    /// The statements pbrt-v3 renders through.
    broken: &'static str,
    /// What pbrs warns (part of the message).
    warning: &'static str,
    /// The same scene written with the substitute.
    substitute: &'static str,
}

const CASES: &[Case] = &[
    Case {
        broken: "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"no-such-image.exr\"\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\"",
        warning: "no-such-image.exr\": ",
        substitute: "Material \"matte\" \"rgb Kd\" [0.5 0.5 0.5]\nShape \"sphere\"",
    },
    Case {
        broken: "Texture \"t\" \"spectrum\" \"ptex\" \"string filename\" \"no-such.ptx\"\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\"",
        warning: "cannot read Ptex file",
        substitute: "Material \"matte\" \"rgb Kd\" [0 0 0]\nShape \"sphere\"",
    },
    Case {
        broken: "LightSource \"infinite\" \"rgb L\" [0.2 0.3 0.4] \"string mapname\" \"no-such-sky.exr\"\nShape \"sphere\"",
        warning: "rendered as without \"mapname\"",
        substitute: "LightSource \"infinite\" \"rgb L\" [0.2 0.3 0.4]\nShape \"sphere\"",
    },
    Case {
        broken: "Material \"matte\" \"rgb Kd\" [0.2 0.6 0.3]\nMakeNamedMaterial \"red\" \"string type\" \"matte\" \"rgb Kd\" [1 0 0]\nNamedMaterial \"rde\"\nShape \"sphere\"",
        warning: "unknown named material \"rde\" (did you mean \"red\"?): the current material is kept",
        substitute: "Material \"matte\" \"rgb Kd\" [0.2 0.6 0.3]\nShape \"sphere\"",
    },
    Case {
        broken: "Material \"matte\" \"rgb Kd\" [0.25, 0.5, 0.75]\nShape \"sphere\" \"float radius\" 0.8,",
        warning: "number `0.25,` is followed by a comma: read as 0.25",
        substitute: "Material \"matte\" \"rgb Kd\" [0.25 0.5 0.75]\nShape \"sphere\" \"float radius\" 0.8",
    },
    Case {
        broken: "Material \"matte\" \"spectrum Kd\" [400 0.5 700 0.5 800]\nShape \"sphere\"",
        warning: "has 5 numbers, an odd count: the last is ignored",
        substitute: "Material \"matte\" \"spectrum Kd\" [400 0.5 700 0.5]\nShape \"sphere\"",
    },
    Case {
        broken: "Shape \"trianglemesh\" \"integer indices\" [0 1 2]\nShape \"sphere\"",
        warning: "trianglemesh needs vertex positions \"point P\": the shape is skipped",
        substitute: "Shape \"sphere\"",
    },
    Case {
        broken: "Shape \"plymesh\" \"string filename\" \"no-such-mesh.ply\"\nShape \"sphere\"",
        warning: "cannot read PLY file",
        substitute: "Shape \"sphere\"",
    },
];

#[test]
fn pbrt_v3_renders_through_and_so_does_pbrs() {
    for c in CASES {
        let broken = load_text(&scene(c.broken));
        let w = warning_text(&broken);
        assert!(w.contains(c.warning), "{}: {w}", c.broken);
        assert!(w.contains("mem.pbrt:"), "not located: {w}");
        let fixed = load_text(&scene(c.substitute));
        assert_eq!(warning_text(&fixed), "", "{}", c.substitute);
        let (a, _) = render_at(broken.scene, 16, 4, Some(1));
        let (b, _) = render_at(fixed.scene, 16, 4, Some(1));
        assert!(a.data == b.data, "{}: not the substitute's image", c.broken);
        // --strict: the warning is an error.
        assert!(pbrs::loader::strictly(vec![load_text(&scene(c.broken))]).is_err());
    }
}

/// The binary: the default renders and writes the image; `--strict` exits 1
/// with the warning as a located error and writes nothing.
#[test]
fn strict_fails_early_and_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("pbrs-render-on-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("scene.pbrt");
    std::fs::write(&file, scene(CASES[0].broken)).unwrap();
    let run = |strict: bool, out: &str| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_pbrs"));
        if strict {
            cmd.arg("--strict");
        }
        let o = cmd
            .arg(&file)
            .arg("--outfile")
            .arg(dir.join(out))
            .env("NO_COLOR", "1")
            .output()
            .unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = run(false, "default.pfm");
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("cannot read image"), "{err}");
    assert!(dir.join("default.pfm").exists());
    let (code, err) = run(true, "strict.pfm");
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("× ")
            && err.contains("scene.pbrt:7:")
            && err.contains("an error with --strict"),
        "{err}"
    );
    assert!(!dir.join("strict.pfm").exists());
    std::fs::remove_dir_all(&dir).ok();
}
