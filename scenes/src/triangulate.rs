//! Polygons to triangles for engines that take only triangles.
//!
//! Ear clipping in the plane of the polygon (the projection that drops the largest axis of its
//! Newell normal). Concave polygons are common in the SPD: gears' faces are 144-gons whose gaps
//! between the teeth a fan from vertex 0 would fill (docs/concepts.md). An n-gon gives n − 2
//! triangles, wound as the polygon is.

use glam::{DVec2, DVec3};

/// Newell's normal (not normalised) of a polygon, in its winding order.
pub fn newell_normal(v: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    n
}

fn cross2(o: DVec2, a: DVec2, b: DVec2) -> f64 {
    (a - o).perp_dot(b - o)
}

/// Every corner turns left (strictly) and the corners turn once around in all (a pentagram's
/// corners all turn left, twice around): no vertex can lie in or on another corner's ear.
fn strictly_convex(p: &[DVec2]) -> bool {
    let n = p.len();
    let mut turning = 0.0;
    for k in 0..n {
        let (a, b, c) = (p[(k + n - 1) % n], p[k], p[(k + 1) % n]);
        let cross = cross2(a, b, c);
        if cross <= 0.0 {
            return false;
        }
        turning += cross.atan2((b - a).dot(c - b));
    }
    (turning - std::f64::consts::TAU).abs() < 1.0
}

/// Appends the triangles of polygon `v` (indices into `v`) to `out`.
pub fn triangulate(v: &[DVec3], out: &mut Vec<[usize; 3]>) {
    ear_clip(v, out, true)
}

/// Ear clipping; `convex_shortcut` takes the O(n) path for strictly convex polygons.
fn ear_clip(v: &[DVec3], out: &mut Vec<[usize; 3]>, convex_shortcut: bool) {
    let n = v.len();
    if n < 3 {
        return;
    }
    if n == 3 {
        out.push([0, 1, 2]);
        return;
    }
    let normal = newell_normal(v);
    let a = normal.abs();
    // Project so that the polygon keeps a positive (counter-clockwise) orientation in 2D.
    let (i, j, flip) = if a.x >= a.y && a.x >= a.z {
        (1, 2, normal.x < 0.0)
    } else if a.y >= a.z {
        (2, 0, normal.y < 0.0)
    } else {
        (0, 1, normal.z < 0.0)
    };
    let p: Vec<DVec2> = v
        .iter()
        .map(|q| {
            if flip {
                DVec2::new(q[j], q[i])
            } else {
                DVec2::new(q[i], q[j])
            }
        })
        .collect();
    if convex_shortcut && strictly_convex(&p) {
        // Ear clipping of a strictly convex polygon clips, in turn, the corner at the front of
        // the list: the ears (n−1, k, k+1), then the last three. The same triangles in O(n)
        // (clipping took 18.9 s for a 100,000-gon).
        for k in 0..n - 3 {
            out.push([n - 1, k, k + 1]);
        }
        out.push([n - 3, n - 2, n - 1]);
        return;
    }
    let mut idx: Vec<usize> = (0..n).collect();
    let mut guard = 0;
    while idx.len() > 3 {
        let m = idx.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
            let (pa, pb, pc) = (p[ia], p[ib], p[ic]);
            // Convex corner (strictly), and no other remaining vertex inside the ear.
            if cross2(pa, pb, pc) <= 0.0 {
                continue;
            }
            let blocked = idx.iter().any(|&q| {
                if q == ia || q == ib || q == ic {
                    return false;
                }
                let x = p[q];
                if x == pa || x == pb || x == pc {
                    return false;
                }
                cross2(pa, pb, x) >= 0.0 && cross2(pb, pc, x) >= 0.0 && cross2(pc, pa, x) >= 0.0
            });
            if !blocked {
                out.push([ia, ib, ic]);
                idx.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            // Degenerate input (collinear runs, self-touching): drop a zero-area corner if there
            // is one, else fall back to a fan for what remains.
            if let Some(k) = (0..m).find(|&k| {
                cross2(p[idx[(k + m - 1) % m]], p[idx[k]], p[idx[(k + 1) % m]]).abs()
                    <= f64::EPSILON
            }) {
                idx.remove(k);
                guard += 1;
                if guard > n {
                    break;
                }
                continue;
            }
            for k in 1..idx.len() - 1 {
                out.push([idx[0], idx[k], idx[k + 1]]);
            }
            return;
        }
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(v: &[DVec3], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]).length() / 2.0)
            .sum()
    }

    #[test]
    fn concave_l_shape_keeps_its_area() {
        let l: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let mut t = Vec::new();
        triangulate(&l, &mut t);
        assert_eq!(t.len(), 4);
        assert!((area(&l, &t) - 3.0).abs() < 1e-12);
        // Same winding as the polygon.
        for tri in &t {
            let n = (l[tri[1]] - l[tri[0]]).cross(l[tri[2]] - l[tri[0]]);
            assert!(n.z > 0.0);
        }
    }

    #[test]
    fn star_clockwise_in_yz() {
        // A 5-pointed star (concave 10-gon), clockwise, in the y–z plane.
        let mut s = Vec::new();
        for k in 0..10 {
            let r = if k % 2 == 0 { 1.0 } else { 0.4 };
            let a = -(k as f64) * std::f64::consts::PI / 5.0;
            s.push(DVec3::new(3.0, r * a.cos(), r * a.sin()));
        }
        let mut t = Vec::new();
        triangulate(&s, &mut t);
        assert_eq!(t.len(), 8);
        let want = newell_normal(&s).length() / 2.0;
        assert!(
            (area(&s, &t) - want).abs() < 1e-9,
            "{} vs {}",
            area(&s, &t),
            want
        );
    }

    #[test]
    fn convex_shortcut_gives_ear_clippings_triangles_fast() {
        // Regular and irregular convex polygons, both windings: the same triangles either way.
        for n in [4usize, 5, 17, 144, 1000] {
            for flip in [false, true] {
                let v: Vec<DVec3> = (0..n)
                    .map(|k| {
                        let a = k as f64 * std::f64::consts::TAU / n as f64
                            * if flip { -1.0 } else { 1.0 };
                        let r =
                            1.0 + 0.3 * ((k * 7919) % 13) as f64 / 13.0 * (n <= 17) as u8 as f64;
                        DVec3::new(r * a.cos(), 0.5, r * a.sin())
                    })
                    .collect();
                let (mut fast, mut slow) = (Vec::new(), Vec::new());
                triangulate(&v, &mut fast);
                ear_clip(&v, &mut slow, false);
                assert_eq!(fast, slow, "{n}-gon, flip {flip}");
            }
        }
        // A pentagram's corners all turn left, but it is no convex polygon.
        let star: Vec<DVec3> = (0..5)
            .map(|k| {
                let a = (k * 2) as f64 * std::f64::consts::TAU / 5.0;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        triangulate(&star, &mut fast);
        ear_clip(&star, &mut slow, false);
        assert_eq!(fast, slow);
        // 100,000 vertices: milliseconds (18.9 s by clipping).
        let n = 100_000;
        let big: Vec<DVec3> = (0..n)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / n as f64;
                DVec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let t = std::time::Instant::now();
        let mut out = Vec::new();
        triangulate(&big, &mut out);
        assert_eq!(out.len(), n - 2);
        assert!(t.elapsed().as_secs_f64() < 2.0, "{:?}", t.elapsed());
    }
}
