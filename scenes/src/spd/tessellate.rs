//! Tessellation of curved primitives and the triangle splitter, ported from SPD 3.14's libply.c:
//! `lib_output_polygon_sphere`, `lib_output_polygon_cylcone`, `lib_output_polygon_height` and
//! the static `split_polygon` machinery behind `lib_output_polypatch`.
//!
//! The C library writes the generated vertices in the object's own coordinates and leaves the
//! current transform to `split_polygon` (vertices through the matrix, normals through the
//! inverse's transpose) or to `lib_output_polygon`; the same happens here, so tessellated
//! shapes under jacks' or tree's transform stack come out where the C puts them.

use super::output::Output;
use super::vec::{self, Coord3, Coord4, EPSILON2, X_AXIS, Y_AXIS, Z_AXIS};

/// `lib_output_polygon_sphere`: a sphere as the six faces of a cube projected onto it, each face
/// a `u_resolution` x `v_resolution` grid of quads split into two triangle patches (108 patches
/// at resolution 3). Normals are the unit grid directions (not renormalized after a transform,
/// as the C's NFF output does not).
pub fn sphere(out: &mut Output, center: Coord4) {
    let ures = out.u_resolution as usize;
    let vres = out.v_resolution as usize;

    // Axes used to find the grid points: x axes rotated about Y, y axes rotated about X, both
    // spanning -45..45 degrees.
    let x_axis: Vec<Coord3> = (0..=ures)
        .map(|e| {
            let angle = (vec::PI / 4.0) * (2.0 * e as f64 / ures as f64 - 1.0);
            let rot = vec::rotate_matrix(Y_AXIS, angle);
            vec::transform_vector(&[1.0, 0.0, 0.0], &rot)
        })
        .collect();
    let y_axis: Vec<Coord3> = (0..=vres)
        .map(|e| {
            let angle = (vec::PI / 4.0) * (2.0 * e as f64 / vres as f64 - 1.0);
            let rot = vec::rotate_matrix(X_AXIS, angle);
            vec::transform_vector(&[0.0, 1.0, 0.0], &rot)
        })
        .collect();

    // Grid of points on the +Z face. (The C loops `v_pol` up to gU_resolution here, a slip that
    // only matters when U != V; SPD programs always set both to the same value.)
    let mut pt: Vec<Vec<Coord3>> = x_axis
        .iter()
        .map(|xa| {
            y_axis
                .iter()
                .map(|ya| {
                    let mut p = vec::cross(xa, ya);
                    vec::normalize_vector(&mut p);
                    p
                })
                .collect()
        })
        .collect();

    let mut edge_pt = [[0.0; 3]; 3];
    let mut edge_norm = [[0.0; 3]; 3];
    for num_face in 0..6 {
        // Rotate the whole grid to the next cube face (cumulatively, so face 0 is already
        // rotated once: the C does the same).
        for row in pt.iter_mut() {
            for p in row.iter_mut() {
                vec::rotate_cube_face(p, Z_AXIS, num_face);
            }
        }
        for u in 0..ures {
            for v in 0..vres {
                for num_tri in 0..2 {
                    for num_edge in 0..3 {
                        let p = match (num_tri * 2 + num_edge) % 4 {
                            0 => pt[u][v],
                            1 => pt[u][v + 1],
                            2 => pt[u + 1][v + 1],
                            _ => pt[u + 1][v],
                        };
                        edge_norm[num_edge] = p;
                        edge_pt[num_edge] = [
                            p[0] * center[3] + center[0],
                            p[1] * center[3] + center[1],
                            p[2] * center[3] + center[2],
                        ];
                    }
                    split_polygon(out, &edge_pt, &edge_norm);
                }
            }
        }
    }
}

/// `lib_output_polygon_cylcone`: an open cone or cylinder as `4 * u_resolution` slices of two
/// triangle patches each (24 patches at resolution 3), swept about the axis starting from
/// `axis x +Z` (or `axis x +X` when the axis is along Z).
pub fn cylcone(out: &mut Output, base: Coord4, apex: Coord4) {
    let axis = vec::sub3(&apex, &base);
    let mut norm_axis = axis;
    let height = vec::normalize_vector(&mut norm_axis);

    let mut start_dir = vec::cross(&axis, &[0.0, 0.0, 1.0]);
    let divisor = vec::normalize_vector(&mut start_dir);
    if divisor.abs() < EPSILON2 {
        start_dir = vec::cross(&axis, &[1.0, 0.0, 0.0]);
        vec::normalize_vector(&mut start_dir);
    }

    let start_radius0 = [
        start_dir[0] * base[3],
        start_dir[1] * base[3],
        start_dir[2] * base[3],
    ];
    let start_radius1 = [
        start_dir[0] * apex[3],
        start_dir[1] * apex[3],
        start_dir[2] * apex[3],
    ];
    let mut vert: [Coord3; 3] = [[0.0; 3]; 3];
    let mut norm: [Coord3; 3] = [[0.0; 3]; 3];
    vert[2] = vec::add3(&base, &start_radius0);
    vert[1] = vec::add3(&apex, &start_radius1);

    let start_norm = if base[3] == apex[3] {
        // A cylinder: the radial direction is the normal.
        start_dir
    } else {
        // A cone: tilt the radial direction by the slope.
        let ba = base[3] - apex[3];
        let mut n = [
            start_dir[0] * height + norm_axis[0] * ba,
            start_dir[1] * height + norm_axis[1] * ba,
            start_dir[2] * height + norm_axis[2] * ba,
        ];
        vec::normalize_vector(&mut n);
        n
    };
    norm[2] = start_norm;
    norm[1] = start_norm;

    let steps = 4 * out.u_resolution;
    let delta_angle = 2.0 * vec::PI / steps as f64;
    // The angle is accumulated, as in the C `for` loop, not recomputed as i * delta.
    let mut angle = delta_angle;
    for _ in 1..=steps {
        let mx = vec::axis_rotate_matrix(&norm_axis, angle);
        let nmx = vec::invert_matrix(&mx);
        let p = vec::transform_point(&start_radius1, &mx);
        vert[0] = [p[0] + apex[0], p[1] + apex[1], p[2] + apex[2]];
        norm[0] = vec::transform_normal(&start_norm, &nmx);
        split_polygon(out, &vert, &norm);
        vert[1] = vert[0];
        norm[1] = norm[0];
        let p = vec::transform_point(&start_radius0, &mx);
        vert[0] = [p[0] + base[0], p[1] + base[1], p[2] + base[2]];
        split_polygon(out, &vert, &norm);
        vert[2] = vert[0];
        norm[2] = norm[0];
        angle += delta_angle;
    }
}

/// `lib_output_polygon_height`, which is all NFF does with `lib_output_height`: two triangles
/// (`p 3`, through `lib_output_polygon`) per grid cell, the grid spanning `x0..x1` and `z0..z1`
/// with heights `y0 + data[i][j]` (`y1` is unused, as in the C).
///
/// Rows of `data` (each `width` floats) are requested in order `0..height` through
/// `fill_row(i, row)`, each exactly once, so a large field need not be held in memory.
#[allow(clippy::too_many_arguments)]
pub fn height(
    out: &mut Output,
    height: usize,
    width: usize,
    fill_row: &mut dyn FnMut(usize, &mut [f32]),
    x0: f64,
    x1: f64,
    y0: f64,
    _y1: f64,
    z0: f64,
    z1: f64,
) {
    if height < 2 || width < 2 {
        return;
    }
    let xdelta = (x1 - x0) / (width - 1) as f64;
    let zdelta = (z1 - z0) / (height - 1) as f64;
    let mut cur = vec![0.0f32; width];
    let mut next = vec![0.0f32; width];
    fill_row(0, &mut cur);
    let mut verts: [Coord3; 3] = [[0.0; 3]; 3];
    for i in 0..height - 1 {
        fill_row(i + 1, &mut next);
        let (fi, fi1) = (i as f64, (i + 1) as f64);
        for j in 0..width - 1 {
            let (fj, fj1) = (j as f64, (j + 1) as f64);
            verts[0] = [x0 + fj * xdelta, y0 + cur[j] as f64, z0 + fi * zdelta];
            verts[1] = [
                x0 + fj1 * xdelta,
                y0 + next[j + 1] as f64,
                z0 + fi1 * zdelta,
            ];
            verts[2] = [x0 + fj1 * xdelta, y0 + cur[j + 1] as f64, z0 + fi * zdelta];
            // lib_output_polygon works on the caller's array in place (merging and
            // transforming), and the C then reuses verts[1] from it; keep that.
            out.polygon_in_place(&mut verts);
            verts[2] = verts[1];
            verts[1] = [x0 + fj * xdelta, y0 + next[j] as f64, z0 + fi1 * zdelta];
            out.polygon_in_place(&mut verts);
        }
        std::mem::swap(&mut cur, &mut next);
    }
}

/// libply.c's static `split_polygon`: splits a polygon into triangles (the patch's normals go
/// along), applies the current transform (normals by the inverse matrix through
/// `lib_transform_normal`, not renormalized) and prints each as `pp 3`, or `p 3` when `norm` is
/// empty (the C's `norm == NULL`).
pub fn split_polygon(out: &mut Output, vert: &[Coord3], norm: &[Coord3]) {
    let n = vert.len();
    if n < 3 {
        return;
    }
    let has_norm = !norm.is_empty();
    let tx = if out.tx_active() {
        Some(*out.current_tx())
    } else {
        None
    };
    let nmx = tx.map(|m| vec::invert_matrix(&m));

    let emit = |out: &mut Output, tv: &[Coord3; 3], tn: &[Coord3; 3]| {
        let (mut v, mut nn) = (*tv, *tn);
        if let (Some(m), Some(nm)) = (tx.as_ref(), nmx.as_ref()) {
            for i in 0..3 {
                v[i] = vec::transform_point(&v[i], m);
                if has_norm {
                    nn[i] = vec::transform_normal(&nn[i], nm);
                }
            }
        }
        if has_norm {
            out.emit_patch(&v, &nn);
        } else {
            out.emit_polygon(&v);
        }
    };

    if n == 3 {
        // split_buffered_polygon's first step: a triangle is output as given.
        let tv = [vert[0], vert[1], vert[2]];
        let tn = if has_norm {
            [norm[0], norm[1], norm[2]]
        } else {
            [[0.0; 3]; 3]
        };
        emit(out, &tv, &tn);
        return;
    }

    // The C computes every triangle first, then transforms and prints them all.
    let tris = split_indices(vert);
    for t in tris {
        let tv = [vert[t[0]], vert[t[1]], vert[t[2]]];
        let tn = if has_norm {
            [norm[t[0]], norm[t[1]], norm[t[2]]]
        } else {
            [[0.0; 3]; 3]
        };
        emit(out, &tv, &tn);
    }
}

/// The index machinery of `split_buffered_polygon` (with `find_axes`, `leftmost_vertex`,
/// `split_vertex`, `perform_split`): repeatedly cuts the polygon at its leftmost vertex in the
/// projection plane until only triangles remain. Returns the triangles as vertex indices, in the
/// C's output order.
fn split_indices(verts: &[Coord3]) -> Vec<[usize; 3]> {
    let cnt = verts.len();
    let (axis1, axis2) = find_axes(verts);
    // gPoly_vbuffer: grows as perform_split writes past the end (the C has a fixed 1024).
    let mut vb: Vec<usize> = (0..cnt).collect();
    let mut poly_end: Vec<isize> = vec![-1, cnt as isize - 1];
    let mut out = Vec::with_capacity(cnt - 2);

    let at = |vb: &[usize], i: usize, a: usize| verts[vb[i]][a];
    let mut i = 1usize;
    while i > 0 {
        let m = (poly_end[i - 1] + 1) as usize;
        let n = poly_end[i] as usize;
        if n - m == 2 {
            // linear_vertices() always answers "no" in the C.
            out.push([vb[m], vb[m + 1], vb[m + 2]]);
            i -= 1;
        } else {
            // leftmost_vertex
            let mut l = m;
            let mut x = at(&vb, m, axis1);
            for k in m + 1..=n {
                if at(&vb, k, axis1) < x {
                    l = k;
                    x = at(&vb, k, axis1);
                }
            }
            let la = if l == n { m } else { l + 1 };
            let lb = if l == m { n } else { l - 1 };
            let ls = split_vertex(&vb, verts, axis1, axis2, l, la, lb, m, n);
            let (m1, n1) = if ls == la || ls == lb {
                (la.min(lb), la.max(lb))
            } else {
                (l.min(ls), l.max(ls))
            };
            perform_split(&mut vb, m, m1, n, n1);
            if poly_end.len() <= i + 1 {
                poly_end.resize(i + 2, 0);
            }
            poly_end[i] = (m + n1 - m1) as isize;
            i += 1;
            poly_end[i] = (n + 2) as isize;
        }
    }
    out
}

/// libply.c's `find_axes`: the two coordinates to project on, dropping the largest component
/// of the normal of the first three vertices.
fn find_axes(v: &[Coord3]) -> (usize, usize) {
    let p1 = vec::sub3(&v[1], &v[0]);
    let p2 = vec::sub3(&v[2], &v[0]);
    let x = (p1[1] * p2[2] - p1[2] * p2[1]).abs();
    let y = (p1[2] * p2[0] - p1[0] * p2[2]).abs();
    let z = (p1[0] * p2[1] - p1[1] * p2[0]).abs();
    if x > y && x > z {
        (1, 2)
    } else if y > x && y > z {
        (0, 2)
    } else {
        (0, 1)
    }
}

/// libply.c's `split_vertex`: a vertex that can be joined to the leftmost vertex `l` without
/// leaving the polygon.
#[allow(clippy::too_many_arguments)]
fn split_vertex(
    vb: &[usize],
    verts: &[Coord3],
    a1: usize,
    a2: usize,
    l: usize,
    la: usize,
    lb: usize,
    m: usize,
    n: usize,
) -> usize {
    let v = |i: usize, a: usize| verts[vb[i]][a];
    let yu = v(l, a2).max(v(la, a2).max(v(lb, a2)));
    let yl = v(l, a2).min(v(la, a2).min(v(lb, a2)));
    // C's MAX/MIN macros: `(A) > (B) ? (A) : (B)`; f64::max differs only for NaN.
    let (lpu, lpl) = if v(lb, a2) > v(la, a2) {
        (lb, la)
    } else {
        (la, lb)
    };
    let mut t = if v(lb, a1) > v(la, a1) { lb } else { la };
    for k in m..n {
        let inside = k != la && k != l && k != lb && v(k, a2) <= yu && v(k, a2) >= yl;
        if inside
            && v(k, a1) < v(t, a1)
            && (v(k, a2) - v(l, a2)) * (v(lpu, a1) - v(l, a1))
                <= (v(lpu, a2) - v(l, a2)) * (v(k, a1) - v(l, a1))
            && (v(k, a2) - v(l, a2)) * (v(lpl, a1) - v(l, a1))
                >= (v(lpl, a2) - v(l, a2)) * (v(k, a1) - v(l, a1))
        {
            t = k;
        }
    }
    t
}

/// libply.c's `perform_split`: rearranges the index buffer so that the sub-polygon `m1..=n1`
/// sits before the remaining polygon.
fn perform_split(vb: &mut Vec<usize>, m: usize, m1: usize, n: usize, n1: usize) {
    let need = 2 * n + 4;
    if vb.len() < need {
        vb.resize(need, 0);
    }
    let k = n + 3 - m;
    for j in m1..=n1 {
        vb[j + k] = vb[j];
    }
    let mut j = n as isize;
    while j >= n1 as isize {
        vb[j as usize + 2] = vb[j as usize];
        j -= 1;
    }
    let k = n1 - m1 + 1;
    let mut j = m1 as isize;
    while j >= m as isize {
        vb[j as usize + k] = vb[j as usize];
        j -= 1;
    }
    let i = n + 3 - m;
    // k = m - m1 (negative or zero): destination j + m - m1.
    for j in m1..=n1 {
        vb[j + m - m1] = vb[j + i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_square_into_two_triangles() {
        let sq = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let t = split_indices(&sq);
        assert_eq!(t.len(), 2);
        let mut all: Vec<usize> = t.iter().flatten().copied().collect();
        all.sort();
        all.dedup();
        assert_eq!(all, vec![0, 1, 2, 3]);
    }

    #[test]
    fn split_concave_polygon() {
        // An L shape (6 vertices) gives 4 triangles.
        let l = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
        ];
        assert_eq!(split_indices(&l).len(), 4);
    }
}
