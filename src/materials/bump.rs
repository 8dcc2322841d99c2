//! Bump mapping, for every material (pbrt-v3's `Material::Bump`,
//! core/material.cpp): a float texture d displaces the surface along the
//! shading normal; the shading frame becomes that of the displaced surface.
//!
//! With steps du = ½(|∂u/∂x| + |∂u/∂y|) and dv likewise (0.0005 where the
//! ray has no differentials, as pbrt-v3), d is evaluated at the hit and at
//! the hit shifted by du·∂p/∂u (uv + (du, 0)) and dv·∂p/∂v (uv + (0, dv)),
//! all with the shading tangents; then
//!
//! ∂p'/∂u = ∂p/∂u + (d(u+du) − d)/du · n + d · ∂n/∂u (and likewise for v),
//!
//! and the bumped shading normal is normalize(∂p'/∂u × ∂p'/∂v), turned to
//! the geometric normal's side (pbrt-v3's `SetShadingGeometry` with
//! orientation not authoritative). A displacement that makes the tangents
//! degenerate (a zero or non-finite cross product) leaves the hit as it is
//! (pbrt-v3 would shade with a NaN normal).

use super::ShadingContext;
use crate::accel::SurfaceHit;
use crate::geometry::face_forward;
use crate::scene::FloatTex;
use crate::shapes::DiffGeom;
use glam::Vec2;

/// The hit and differential geometry with the shading frame bumped by `d`.
pub fn bump(d: &FloatTex, sc: &ShadingContext) -> (SurfaceHit, DiffGeom) {
    let (hit, g) = (*sc.hit, *sc.geom);
    let mut eval_hit = hit;
    let mut eval_geom = g;
    let normal = g.shading_dpdu.cross(g.shading_dpdv);

    let mut du = 0.5 * (g.dudx.abs() + g.dudy.abs());
    if du == 0.0 {
        du = 0.0005;
    }
    eval_hit.point.p = hit.point.p + du * g.shading_dpdu;
    eval_geom.uv = g.uv + Vec2::new(du, 0.0);
    eval_hit.point.n = (normal + du * g.dndu).normalize();
    let u_displace = d.eval(&ShadingContext {
        hit: &eval_hit,
        geom: &eval_geom,
    });

    let mut dv = 0.5 * (g.dvdx.abs() + g.dvdy.abs());
    if dv == 0.0 {
        dv = 0.0005;
    }
    eval_hit.point.p = hit.point.p + dv * g.shading_dpdv;
    eval_geom.uv = g.uv + Vec2::new(0.0, dv);
    eval_hit.point.n = (normal + dv * g.dndv).normalize();
    let v_displace = d.eval(&ShadingContext {
        hit: &eval_hit,
        geom: &eval_geom,
    });
    let displace = d.eval(sc);

    let ns = hit.point.ns;
    let dpdu = g.shading_dpdu + (u_displace - displace) / du * ns + displace * g.shading_dndu;
    let dpdv = g.shading_dpdv + (v_displace - displace) / dv * ns + displace * g.shading_dndv;
    let c = dpdu.cross(dpdv);
    let l2 = c.length_squared();
    if !(l2 > 0.0 && l2.is_finite()) {
        return (hit, g);
    }
    let mut out_hit = hit;
    out_hit.point.ns = face_forward(c.normalize(), hit.point.n);
    let mut out_geom = g;
    out_geom.shading_dpdu = dpdu;
    out_geom.shading_dpdv = dpdv;
    (out_hit, out_geom)
}
