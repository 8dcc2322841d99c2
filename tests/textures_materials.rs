//! Every material reads its textured parameters through the texture
//! evaluation at the hit, asks for differential geometry when one of them is
//! not constant, and takes a `bumpmap` (pbrt-v3's `Material::Bump`); a `mix`
//! takes its first material's bumped frame, as pbrt-v3's `MixMaterial`.
//! Driven by `MATERIALS`: a material added to the table is tested here.

mod tex_common;

use glam::{Vec2, Vec3};
use pbrs::materials::BxdfFlags;
use pbrs::materials::{link_materials, Bsdf, BsdfContext, Material, Support, MATERIALS};
use pbrs::scene::{ParamKind, ParamSpec};
use tex_common::*;

/// The materials of `world` (statements ending with the `Material` the
/// sphere uses), built and linked for rendering, and the sphere's index.
fn materials(world: &str) -> (Vec<Material>, usize, String) {
    let s = load(
        &format!("WorldBegin\n{world}\nShape \"sphere\"\nWorldEnd\n"),
        &MemFiles::default(),
    );
    let mut m: Vec<Material> = s.scene.materials.iter().map(Material::new).collect();
    link_materials(&mut m);
    let i = s.scene.shapes[0].material.0 as usize;
    (m, i, warnings(&s))
}

fn bsdf_at<'a>(m: &'a [Material], i: usize, at: &At) -> Bsdf<'a> {
    let ctx = BsdfContext {
        materials: m,
        multiple_lobes: true,
    };
    m[i].bsdf(&at.sc(), &ctx)
}

/// The kinds pbrs renders, but `none` and `mix` (no parameters of their
/// own to texture or bump).
fn surface_kinds() -> impl Iterator<Item = &'static pbrs::materials::MaterialKind> {
    MATERIALS
        .iter()
        .filter(|k| k.support == Support::Supported && !matches!(k.name, "none" | "mix"))
}

/// d(u, v) = k·u.
fn ramp(name: &str, k: f32) -> String {
    format!("Texture \"{name}\" \"float\" \"bilerp\" \"float v00\" 0 \"float v01\" 0 \"float v10\" {k} \"float v11\" {k}")
}

#[track_caller]
fn assert_dir(got: Vec3, want: Vec3, what: &str) {
    let want = want.normalize();
    assert!(
        (got - want).length() < 2e-4,
        "{what}: {got} vs expected {want}"
    );
}

#[test]
fn every_material_but_mix_and_hair_takes_a_bump_map() {
    let mut n = 0;
    // pbrt-v3's hair material has no bump map.
    for k in surface_kinds().filter(|k| k.name != "hair") {
        assert!(
            k.params.iter().any(|p| p.name == "bumpmap"),
            "{} has no bumpmap parameter",
            k.name
        );
        let (m, i, w) = materials(&format!(
            "{}\nMaterial \"{}\" \"texture bumpmap\" \"d\"",
            ramp("d", 0.5),
            k.name
        ));
        assert!(!w.contains("bumpmap"), "{}: {w}", k.name);
        assert!(matches!(m[i], Material::Bumped(_)), "{}", k.name);
        assert!(m[i].needs_geom(), "{}", k.name);
        // dp'/du = x + ½z on the z-up plane: the normal tilts to (−½, 0, 1).
        for at in [At::uv(0.3, 0.6), At::uv(0.7, 0.2).duv(0.05, 0.0, 0.1, 0.02)] {
            assert_dir(
                bsdf_at(&m, i, &at).frame.n,
                Vec3::new(-0.5, 0.0, 1.0),
                k.name,
            );
        }
        n += 1;
    }
    assert!(n >= 9, "{n} material kinds");
    // pbrt-v3's mix has no bump map of its own.
    let mix = MATERIALS.iter().find(|k| k.name == "mix").unwrap();
    assert!(mix.params.iter().all(|p| p.name != "bumpmap"));
}

#[test]
fn an_anisotropic_frame_follows_the_bumped_tangent() {
    // pbrt-v3's BSDF takes its x axis from the bumped shading dp/du:
    // (1, 0, ½) for d = ½u, already perpendicular to the bumped normal.
    let (m, i, w) = materials(&format!(
        "{}\nMaterial \"metal\" \"float uroughness\" 0.1 \"float vroughness\" 0.4 \"texture bumpmap\" \"d\"",
        ramp("d", 0.5)
    ));
    assert!(w.is_empty(), "{w}");
    assert!(m[i].anisotropic());
    let b = bsdf_at(&m, i, &At::uv(0.5, 0.5));
    assert_dir(b.frame.s, Vec3::new(1.0, 0.0, 0.5), "tangent");
    assert_dir(b.frame.n, Vec3::new(-0.5, 0.0, 1.0), "normal");
}

#[test]
fn a_mix_is_bumped_by_its_first_material() {
    let defs = format!(
        "{}\n{}\nMakeNamedMaterial \"flat\" \"string type\" \"plastic\"\n\
         MakeNamedMaterial \"b1\" \"string type\" \"matte\" \"texture bumpmap\" \"d1\"\n\
         MakeNamedMaterial \"b2\" \"string type\" \"substrate\" \"texture bumpmap\" \"d2\"",
        ramp("d1", 0.5),
        ramp("d2", -2.0)
    );
    let mix = |a: &str, b: &str| {
        format!("\"mix\" \"string namedmaterial1\" \"{a}\" \"string namedmaterial2\" \"{b}\"")
    };
    let at = At::uv(0.4, 0.4);
    let cases = [
        (mix("b1", "b2"), Vec3::new(-0.5, 0.0, 1.0)),
        (mix("b2", "b1"), Vec3::new(2.0, 0.0, 1.0)),
        // Material 2's bump map does not move material 1's frame.
        (mix("flat", "b1"), Vec3::Z),
    ];
    for (decl, want) in cases {
        let (m, i, w) = materials(&format!("{defs}\nMaterial {decl}"));
        assert!(w.is_empty(), "{w}");
        assert!(m[i].needs_geom(), "{decl}");
        let b = bsdf_at(&m, i, &at);
        assert_dir(b.frame.n, want, &decl);
        // Both materials' lobes are there (matte 1, plastic 2, substrate 1).
        assert!(b.lobes().len() >= 2, "{decl}: {} lobes", b.lobes().len());
    }
    // Through a nested mix: the leading material's bump.
    let (m, i, w) = materials(&format!(
        "{defs}\nMakeNamedMaterial \"inner\" \"string type\" \"mix\" \"string namedmaterial1\" \"b2\" \"string namedmaterial2\" \"flat\"\nMaterial {}",
        mix("inner", "b1")
    ));
    assert!(w.is_empty(), "{w}");
    assert_dir(
        bsdf_at(&m, i, &at).frame.n,
        Vec3::new(2.0, 0.0, 1.0),
        "nested",
    );
    // A mix of unbumped constant materials needs no differential geometry.
    let (m, i, _) = materials(&format!("{defs}\nMaterial {}", mix("flat", "flat")));
    assert!(!m[i].needs_geom());
    assert_dir(bsdf_at(&m, i, &at).frame.n, Vec3::Z, "unbumped");
}

/// A value for a parameter that differs from its default, and a second one
/// 0.3 above it.
fn test_value(p: &ParamSpec) -> f32 {
    match p.kind {
        _ if p.name == "eta" || p.name == "index" => 1.3,
        ParamKind::FloatTexture(Some(d)) if d > 1.0 => 0.9 * d,
        _ => 0.2,
    }
}

/// The parameters a texture can drive (not `bumpmap`, tested above).
fn textured_params(k: &pbrs::materials::MaterialKind) -> Vec<&'static ParamSpec> {
    k.params
        .iter()
        .filter(|p| {
            p.name != "bumpmap"
                && matches!(
                    p.kind,
                    ParamKind::FloatTexture(_) | ParamKind::SpectrumTexture(_)
                )
        })
        .collect()
}

/// The BSDF's values at a few direction pairs and samples at fixed `u`.
fn signature(b: &Bsdf) -> Vec<f32> {
    let dirs = [
        Vec3::new(0.3, 0.2, 0.9),
        Vec3::new(-0.5, 0.1, 0.6),
        Vec3::new(0.2, -0.7, -0.4),
        Vec3::new(0.0, 0.1, 1.0),
    ]
    .map(Vec3::normalize);
    let mut out = Vec::new();
    for wo in dirs {
        for wi in dirs {
            let (f, pdf) = b.f_pdf(wo, wi, BxdfFlags::ALL);
            out.extend([f.x, f.y, f.z, pdf]);
        }
        for u in [
            Vec2::new(0.13, 0.71),
            Vec2::new(0.62, 0.29),
            Vec2::new(0.91, 0.55),
        ] {
            match b.sample(wo, u, BxdfFlags::ALL) {
                Some(s) => out.extend([s.f.x, s.f.y, s.f.z, s.pdf, s.wi.x, s.wi.y, s.wi.z]),
                None => out.push(-1.0),
            }
        }
    }
    out.push(b.eta);
    out.push(b.lobes().len() as f32);
    out
}

#[track_caller]
fn assert_same(a: &[f32], b: &[f32], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x - y).abs() <= 2e-4 * (1.0 + x.abs().max(y.abs())),
            "{what}: {x} vs {y}"
        );
    }
}

#[test]
fn every_textured_parameter_is_read_at_the_hit() {
    let mut tested = 0;
    for k in surface_kinds() {
        let (m, i, _) = materials(&format!("Material \"{}\"", k.name));
        // (hair always reads the curve's v and dp/du.)
        assert!(
            k.name == "hair" || !m[i].needs_geom(),
            "{} with its defaults",
            k.name
        );
        for p in textured_params(k) {
            let a = test_value(p);
            let b = a + 0.3;
            // A ramp in u from a to b (spectra: from (a, a+0.1, a+0.2)).
            let spectrum = matches!(p.kind, ParamKind::SpectrumTexture(_));
            let rgb = |v: f32| format!("[{v} {} {}]", v + 0.1, v + 0.2);
            let tex = if spectrum {
                format!(
                    "Texture \"t\" \"color\" \"bilerp\" \"rgb v00\" {} \"rgb v01\" {} \"rgb v10\" {} \"rgb v11\" {}",
                    rgb(a), rgb(a), rgb(b), rgb(b)
                )
            } else {
                format!("Texture \"t\" \"float\" \"bilerp\" \"float v00\" {a} \"float v01\" {a} \"float v10\" {b} \"float v11\" {b}")
            };
            let constant = |v: f32| {
                if spectrum {
                    format!("\"rgb {}\" {}", p.name, rgb(v))
                } else {
                    format!("\"float {}\" {v}", p.name)
                }
            };
            let what = format!("{} {}", k.name, p.name);
            let (mt, it, _) = materials(&format!(
                "{tex}\nMaterial \"{}\" \"texture {}\" \"t\"",
                k.name, p.name
            ));
            assert!(mt[it].needs_geom(), "{what}: a texture needs uv");
            for (u, v) in [(0.0, a), (1.0, b)] {
                let (mc, ic, _) = materials(&format!("Material \"{}\" {}", k.name, constant(v)));
                // The shading point with dp/du = +x, as the constant
                // material's frame (anisotropic lobes align with it).
                let at = At::uv(u, 0.5);
                assert_same(
                    &signature(&bsdf_at(&mt, it, &at)),
                    &signature(&bsdf_at(&mc, ic, &at)),
                    &format!("{what} at u = {u}"),
                );
            }
            tested += 1;
        }
    }
    // matte 2, plastic 3, translucent 5, glass 5, mirror 1, metal 4,
    // substrate 4, uber 9, disney 13 (at least).
    assert!(tested >= 46, "{tested} parameters");
}

#[test]
fn a_mix_amount_texture_is_read_at_the_hit() {
    let defs = "MakeNamedMaterial \"a\" \"string type\" \"matte\" \"rgb Kd\" [0.8 0.8 0.8]\n\
                MakeNamedMaterial \"b\" \"string type\" \"plastic\"";
    let tex = "Texture \"t\" \"color\" \"bilerp\" \"rgb v00\" [0.2 0.3 0.4] \"rgb v01\" [0.2 0.3 0.4] \"rgb v10\" [0.5 0.6 0.7] \"rgb v11\" [0.5 0.6 0.7]";
    let names = "\"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"b\"";
    let (mt, it, w) = materials(&format!(
        "{defs}\n{tex}\nMaterial \"mix\" {names} \"texture amount\" \"t\""
    ));
    assert!(w.is_empty(), "{w}");
    assert!(mt[it].needs_geom());
    for (u, v) in [(0.0, [0.2, 0.3, 0.4]), (1.0, [0.5, 0.6, 0.7])] {
        let (mc, ic, _) = materials(&format!(
            "{defs}\nMaterial \"mix\" {names} \"rgb amount\" [{} {} {}]",
            v[0], v[1], v[2]
        ));
        let at = At::uv(u, 0.5);
        assert_same(
            &signature(&bsdf_at(&mt, it, &at)),
            &signature(&bsdf_at(&mc, ic, &at)),
            &format!("mix amount at u = {u}"),
        );
    }
}
