//! Speed only: the values of the s = 1 strategies of t ≥ 2 drawn before
//! the strategies of t = 2 run, so that their samples of a large
//! environment map are taken together (`EnvMap::sample_each`: their cache
//! misses overlap). Each strategy then gets the values it would have drawn
//! itself (`tests/integrators_bdpt.rs` compares the images with the scalar
//! loop's, which draws in place).

use super::connect::{draw_light, LightDraw};
use super::vertex::{Kind, Vertex};
use super::Ctx;
use crate::integrators::RenderScene;
use crate::lights::{EnvMap, EnvSample, Light, SAMPLE_EACH_MAX};
use crate::samplers::Sampler;
use arrayvec::ArrayVec;
use glam::Vec2;

/// Whether the s = 1 strategies of t ≥ 2 may draw their values before the
/// strategies of t = 2 run ([`draw_ahead`]): nothing in between draws (the
/// strategies of t ≥ 2 with s ≠ 1 draw only for transmittance through a
/// grid medium), and there is an image-mapped infinite light sampled by
/// its tables (`EnvMap::samples_large_tables`).
pub(crate) fn draws_ahead(scene: &RenderScene) -> bool {
    let large = |&i: &u32| match &scene.lights[i as usize] {
        Light::Infinite(l) => l.map.samples_large_tables(),
        _ => false,
    };
    scene.infinite_lights.iter().any(large) && scene.media.iter().all(|m| !m.tr_draws())
}

/// Speed only: the values of the s = 1 strategies of t = 2 ..= the
/// camera subpath's length, drawn in the order `connect` draws them
/// (`out[t - 2]` is t's, `None` where t's strategy draws nothing), with
/// the infinite lights' samples taken together (`EnvMap::sample_each`, so
/// that their cache misses overlap). Called after the strategies of t = 1
/// when [`draws_ahead`]: the strategies then get the same values as when
/// they draw them.
pub(crate) fn draw_ahead(
    c: &Ctx,
    camera: &[Vertex],
    max_depth: u32,
    sampler: &mut Sampler,
    out: &mut Vec<Option<LightDraw>>,
) {
    out.clear();
    for t in 2..=camera.len() {
        let pt = &camera[t - 1];
        // The conditions under which `connect(s = 1, t)` runs and draws.
        let draws = t - 1 <= max_depth as usize && pt.kind != Kind::Light && pt.is_connectible(c);
        out.push(draws.then(|| draw_light(c, sampler)));
    }
    // The infinite lights' samples, up to SAMPLE_EACH_MAX at a time.
    type Batch<'m> = ArrayVec<(&'m EnvMap, Vec2, Option<EnvSample>), SAMPLE_EACH_MAX>;
    fn run(batch: &mut Batch, slots: &mut ArrayVec<usize, SAMPLE_EACH_MAX>, out: &mut [Option<LightDraw>]) {
        EnvMap::sample_each(batch);
        for (b, &k) in batch.iter().zip(slots.iter()) {
            if let Some(d) = &mut out[k] {
                d.env = Some(b.2);
            }
        }
        batch.clear();
        slots.clear();
    }
    let mut batch = Batch::new();
    let mut slots = ArrayVec::new();
    for k in 0..out.len() {
        let Some(LightDraw {
            chosen: Some((i, _)),
            u,
            ..
        }) = out[k]
        else {
            continue;
        };
        if let Light::Infinite(l) = &c.scene.lights[i as usize] {
            batch.push((&*l.map, u, None));
            slots.push(k);
            if batch.is_full() {
                run(&mut batch, &mut slots, out);
            }
        }
    }
    run(&mut batch, &mut slots, out);
}
