//! Primitive–cell overlap tests for exact insertion: may this primitive's surface touch this
//! axis-aligned box? A `false` must be certain (the primitive is then left out of the cell); a
//! `true` may be conservative (it only costs a wasted test later).
//!
//! The tests run at build time only, in `f64`, on boxes the caller has already padded against
//! the rounding of traversal. They are the grid's own; nothing else in the workspace needs them
//! yet (a BVH's spatial splits clip triangles rather than test them).

use crate::geometry::Prim;
use glam::DVec3;

/// Whether `prim` may touch the box `[lo, hi]`.
pub fn prim_box(prim: &Prim, lo: DVec3, hi: DVec3) -> bool {
    match *prim {
        Prim::Triangle([a, b, c]) => triangle_box(a.as_dvec3(), b.as_dvec3(), c.as_dvec3(), lo, hi),
        Prim::Sphere { center, radius } => {
            sphere_surface_box(center.as_dvec3(), radius as f64, lo, hi)
        }
        Prim::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => cone_box(
            base.as_dvec3(),
            base_radius as f64,
            apex.as_dvec3(),
            apex_radius as f64,
            lo,
            hi,
        ),
    }
}

/// Triangle–box overlap by the separating axis theorem (Akenine-Möller 2001, "Fast 3D
/// triangle-box overlap testing"): the box's three normals, the triangle's normal, and the nine
/// cross products of box axes with triangle edges. Exact (degenerate triangles are kept).
pub fn triangle_box(a: DVec3, b: DVec3, c: DVec3, lo: DVec3, hi: DVec3) -> bool {
    let center = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let v = [a - center, b - center, c - center];
    // Box normals: the triangle's bounding box against the box.
    let vmin = v[0].min(v[1]).min(v[2]);
    let vmax = v[0].max(v[1]).max(v[2]);
    if vmin.cmpgt(h).any() || vmax.cmplt(-h).any() {
        return false;
    }
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    // The nine edge × box-axis axes.
    for e in edges {
        for axis in [
            DVec3::new(0.0, -e.z, e.y),
            DVec3::new(e.z, 0.0, -e.x),
            DVec3::new(-e.y, e.x, 0.0),
        ] {
            if separated(axis, &v, h) {
                return false;
            }
        }
    }
    // The triangle's plane against the box.
    let n = edges[0].cross(edges[1]);
    let r = h.dot(n.abs());
    n.dot(v[0]).abs() <= r
}

/// Whether `axis` separates the triangle `v` from the box of half-sides `h` centred at 0.
#[inline]
fn separated(axis: DVec3, v: &[DVec3; 3], h: DVec3) -> bool {
    let p = [axis.dot(v[0]), axis.dot(v[1]), axis.dot(v[2])];
    let r = h.dot(axis.abs());
    let pmin = p[0].min(p[1]).min(p[2]);
    let pmax = p[0].max(p[1]).max(p[2]);
    pmin > r || pmax < -r
}

/// Sphere *surface*–box overlap: the box reaches the ball (Arvo 1990, "A simple method for
/// box-sphere intersection testing": squared distance from the centre to the box) and is not
/// wholly inside it (its farthest corner is not closer than the radius). Exact.
pub fn sphere_surface_box(center: DVec3, radius: f64, lo: DVec3, hi: DVec3) -> bool {
    let r2 = radius * radius;
    let nearest = center.clamp(lo, hi);
    if (nearest - center).length_squared() > r2 {
        return false;
    }
    let far = (lo - center).abs().max((hi - center).abs());
    far.length_squared() >= r2
}

/// Open cone (or cylinder)–box overlap, conservative: separating axes between the box and the
/// convex hull of the cone's two end discs (which holds the lateral surface). The axes are the
/// box normals, the cone's axis w, and the three e_k × w; on each the hull's projection is exact
/// (the discs lie across w). A box inside the hull but off the surface is kept.
pub fn cone_box(base: DVec3, rb: f64, apex: DVec3, ra: f64, lo: DVec3, hi: DVec3) -> bool {
    let (rb, ra) = (rb.abs(), ra.abs());
    let center = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let axis = apex - base;
    let len = axis.length();
    if len == 0.0 {
        // The kernel never hits a cone of zero height; any answer is safe, keep it simple.
        return true;
    }
    let w = axis / len;
    // Box normals: the hull's bounding box (a disc of radius r across w reaches
    // r·sqrt(1 − w_i²) along axis i).
    let e = (DVec3::ONE - w * w).max(DVec3::ZERO);
    let e = DVec3::new(e.x.sqrt(), e.y.sqrt(), e.z.sqrt());
    let hull_lo = (base - e * rb).min(apex - e * ra);
    let hull_hi = (base + e * rb).max(apex + e * ra);
    if hull_lo.cmpgt(hi).any() || hull_hi.cmplt(lo).any() {
        return false;
    }
    // The axis w: the hull spans [base·w, apex·w].
    let (p0, p1) = ((base - center).dot(w), (apex - center).dot(w));
    let r = h.dot(w.abs());
    if p0.min(p1) > r || p0.max(p1) < -r {
        return false;
    }
    // e_k × w: across the axis, both discs project to the same centre ± their radius.
    let rmax = rb.max(ra);
    for u in [DVec3::X.cross(w), DVec3::Y.cross(w), DVec3::Z.cross(w)] {
        let l = u.length();
        if l < 1e-9 {
            continue;
        }
        let u = u / l;
        let p = (base - center).dot(u);
        let r = h.dot(u.abs());
        if p - rmax > r || p + rmax < -r {
            return false;
        }
    }
    true
}
