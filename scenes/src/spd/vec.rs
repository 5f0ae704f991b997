//! Port of SPD 3.14's `libvec.c` (vector and matrix helpers, `lib_gauss_rand`) and of the
//! matrix decomposition `lib_tx_unwind` from `libtx.c`.
//!
//! Matrices are row-major and points are row vectors multiplied on the left (`p * M`), as in
//! the C code. The arithmetic is written in the same order as the C so that results are
//! bit-for-bit the same where the compiler does not reassociate (it does not: no fast-math).

pub type Coord3 = [f64; 3];
pub type Coord4 = [f64; 4];
pub type Matrix = [[f64; 4]; 4];

pub const X_AXIS: usize = 0;
pub const Y_AXIS: usize = 1;
pub const Z_AXIS: usize = 2;

/// def.h's `PI` (the non-Mac value, 3.141592653589793, which is exactly this double).
pub const PI: f64 = std::f64::consts::PI;

/// def.h's `EPSILON` / `EPSILON2` as compiled on Unix (the Mac block uses other values).
pub const EPSILON: f64 = 1.0e-8;
pub const EPSILON2: f64 = 1.0e-6;

/// Indices into the 16-entry array `lib_tx_unwind` fills (lib.h `U_*`).
pub const U_SCALEX: usize = 0;
pub const U_SCALEY: usize = 1;
pub const U_SCALEZ: usize = 2;
pub const U_SHEARXY: usize = 3;
pub const U_SHEARXZ: usize = 4;
pub const U_SHEARYZ: usize = 5;
pub const U_ROTATEX: usize = 6;
pub const U_ROTATEY: usize = 7;
pub const U_ROTATEZ: usize = 8;
pub const U_TRANSX: usize = 9;
pub const U_TRANSY: usize = 10;
pub const U_TRANSZ: usize = 11;
pub const U_PERSPX: usize = 12;
pub const U_PERSPY: usize = 13;
pub const U_PERSPZ: usize = 14;
pub const U_PERSPW: usize = 15;

/// `lib_normalize_vector`: normalizes the first three components in place and returns the
/// length; a zero vector is left alone.
pub fn normalize_vector(v: &mut [f64]) -> f64 {
    let divisor = dot(v, v).sqrt();
    if divisor > 0.0 {
        v[0] /= divisor;
        v[1] /= divisor;
        v[2] /= divisor;
    }
    divisor
}

/// `DOT_PRODUCT` (three components).
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `CROSS(r, a, b)`.
#[inline]
pub fn cross(a: &[f64], b: &[f64]) -> Coord3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `SUB3_COORD3(r, a, b)`: `a - b`.
#[inline]
pub fn sub3(a: &[f64], b: &[f64]) -> Coord3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `ADD3_COORD3(r, a, b)`: `a + b`.
#[inline]
pub fn add3(a: &[f64], b: &[f64]) -> Coord3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `COMB_COORD(r, a, b, ca, cb)`: `ca*a + cb*b`.
#[inline]
pub fn comb3(a: &[f64], b: &[f64], ca: f64, cb: f64) -> Coord3 {
    [
        ca * a[0] + cb * b[0],
        ca * a[1] + cb * b[1],
        ca * a[2] + cb * b[2],
    ]
}

/// `lib_create_orthogonal_vectors`: two unit vectors forming an orthogonal basis with `axis`
/// (assumed non-zero). Returns `(basis1, basis2)`.
pub fn create_orthogonal_vectors(axis: &[f64]) -> (Coord3, Coord3) {
    let mut basis1: Coord3 = if axis[2].abs() < EPSILON {
        [0.0, 0.0, 1.0]
    } else if axis[1].abs() < EPSILON {
        [0.0, 1.0, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let mut basis2 = cross(axis, &basis1);
    normalize_vector(&mut basis2);
    basis1 = cross(&basis2, axis);
    normalize_vector(&mut basis1);
    (basis1, basis2)
}

/// `lib_zero_matrix`.
pub fn zero_matrix() -> Matrix {
    [[0.0; 4]; 4]
}

/// `lib_create_identity_matrix`.
pub fn identity_matrix() -> Matrix {
    let mut m = zero_matrix();
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// `lib_create_rotate_matrix`: rotation by `angle` radians about a coordinate axis.
/// The C exits on a bad axis; callers here only pass `X_AXIS..=Z_AXIS`.
pub fn rotate_matrix(axis: usize, angle: f64) -> Matrix {
    let mut mx = zero_matrix();
    let cosine = angle.cos();
    let sine = angle.sin();
    match axis {
        X_AXIS => {
            mx[0][0] = 1.0;
            mx[1][1] = cosine;
            mx[2][2] = cosine;
            mx[1][2] = sine;
            mx[2][1] = -sine;
        }
        Y_AXIS => {
            mx[1][1] = 1.0;
            mx[0][0] = cosine;
            mx[2][2] = cosine;
            mx[2][0] = sine;
            mx[0][2] = -sine;
        }
        Z_AXIS => {
            mx[2][2] = 1.0;
            mx[0][0] = cosine;
            mx[1][1] = cosine;
            mx[0][1] = sine;
            mx[1][0] = -sine;
        }
        _ => panic!("rotate_matrix: bad axis {axis}"),
    }
    mx[3][3] = 1.0;
    mx
}

/// `lib_create_axis_rotate_matrix`: rotation by `angle` about the unit vector `axis`.
pub fn axis_rotate_matrix(axis: &[f64], angle: f64) -> Matrix {
    let cosine = angle.cos();
    let sine = angle.sin();
    let one_minus_cosine = 1.0 - cosine;
    let (x, y, z) = (axis[0], axis[1], axis[2]);
    let mut mx = zero_matrix();
    mx[0][0] = x * x + (1.0 - x * x) * cosine;
    mx[0][1] = x * y * one_minus_cosine + z * sine;
    mx[0][2] = x * z * one_minus_cosine - y * sine;
    mx[1][0] = x * y * one_minus_cosine - z * sine;
    mx[1][1] = y * y + (1.0 - y * y) * cosine;
    mx[1][2] = y * z * one_minus_cosine + x * sine;
    mx[2][0] = x * z * one_minus_cosine + y * sine;
    mx[2][1] = y * z * one_minus_cosine - x * sine;
    mx[2][2] = z * z + (1.0 - z * z) * cosine;
    mx[3][3] = 1.0;
    mx
}

/// `lib_create_translate_matrix`.
pub fn translate_matrix(v: &[f64]) -> Matrix {
    let mut mx = identity_matrix();
    mx[3][0] = v[0];
    mx[3][1] = v[1];
    mx[3][2] = v[2];
    mx
}

/// `lib_create_scale_matrix`.
pub fn scale_matrix(v: &[f64]) -> Matrix {
    let mut mx = zero_matrix();
    mx[0][0] = v[0];
    mx[1][1] = v[1];
    mx[2][2] = v[2];
    mx[3][3] = 1.0;
    mx
}

/// `lib_create_canonical_matrix`: the transform taking the canonical frame (origin, +Z up) to
/// the frame at `origin` with direction `up`, and its inverse. Returns `(trans, itrans)`.
pub fn canonical_matrix(origin: &[f64], up: &[f64]) -> (Matrix, Matrix) {
    let trans1 = translate_matrix(&[-origin[0], -origin[1], -origin[2]]);
    let mut tmpv: Coord3 = if up[2].abs() == 1.0 {
        [1.0, 0.0, 0.0]
    } else {
        [-up[1], up[0], 0.0]
    };
    normalize_vector(&mut tmpv);
    let ang = up[2].acos();
    let trans2 = axis_rotate_matrix(&tmpv, -ang);
    let trans = matrix_multiply(&trans1, &trans2);
    let trans1 = axis_rotate_matrix(&tmpv, ang);
    let trans2 = translate_matrix(origin);
    let itrans = matrix_multiply(&trans1, &trans2);
    (trans, itrans)
}

/// `lib_transform_vector`: `v * M` without translation.
pub fn transform_vector(v: &[f64], mx: &Matrix) -> Coord3 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2],
    ]
}

/// `lib_transform_normal`: `v * transpose(M)` (upper 3x3).
pub fn transform_normal(v: &[f64], mx: &Matrix) -> Coord3 {
    [
        v[0] * mx[0][0] + v[1] * mx[0][1] + v[2] * mx[0][2],
        v[0] * mx[1][0] + v[1] * mx[1][1] + v[2] * mx[1][2],
        v[0] * mx[2][0] + v[1] * mx[2][1] + v[2] * mx[2][2],
    ]
}

/// `lib_transform_point`: `v * M` with translation (w = 1, no divide).
pub fn transform_point(v: &[f64], mx: &Matrix) -> Coord3 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0] + mx[3][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1] + mx[3][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2] + mx[3][2],
    ]
}

/// `lib_transform_coord`: the full homogeneous product of a 4-vector and `M`.
pub fn transform_coord(v: &[f64], mx: &Matrix) -> Coord4 {
    [
        v[0] * mx[0][0] + v[1] * mx[1][0] + v[2] * mx[2][0] + v[3] * mx[3][0],
        v[0] * mx[0][1] + v[1] * mx[1][1] + v[2] * mx[2][1] + v[3] * mx[3][1],
        v[0] * mx[0][2] + v[1] * mx[1][2] + v[2] * mx[2][2] + v[3] * mx[3][2],
        v[0] * mx[0][3] + v[1] * mx[1][3] + v[2] * mx[2][3] + v[3] * mx[3][3],
    ]
}

/// libvec.c's static `det3x3`.
#[allow(clippy::too_many_arguments)]
fn det3x3(a1: f64, a2: f64, a3: f64, b1: f64, b2: f64, b3: f64, c1: f64, c2: f64, c3: f64) -> f64 {
    a1 * (b2 * c3 - b3 * c2) - b1 * (a2 * c3 - a3 * c2) + c1 * (a2 * b3 - a3 * b2)
}

/// libvec.c's static `adjoint` (already transposed).
fn adjoint(m: &Matrix) -> Matrix {
    let (a1, b1, c1, d1) = (m[0][0], m[0][1], m[0][2], m[0][3]);
    let (a2, b2, c2, d2) = (m[1][0], m[1][1], m[1][2], m[1][3]);
    let (a3, b3, c3, d3) = (m[2][0], m[2][1], m[2][2], m[2][3]);
    let (a4, b4, c4, d4) = (m[3][0], m[3][1], m[3][2], m[3][3]);
    let mut o = zero_matrix();
    o[0][0] = det3x3(b2, b3, b4, c2, c3, c4, d2, d3, d4);
    o[1][0] = -det3x3(a2, a3, a4, c2, c3, c4, d2, d3, d4);
    o[2][0] = det3x3(a2, a3, a4, b2, b3, b4, d2, d3, d4);
    o[3][0] = -det3x3(a2, a3, a4, b2, b3, b4, c2, c3, c4);

    o[0][1] = -det3x3(b1, b3, b4, c1, c3, c4, d1, d3, d4);
    o[1][1] = det3x3(a1, a3, a4, c1, c3, c4, d1, d3, d4);
    o[2][1] = -det3x3(a1, a3, a4, b1, b3, b4, d1, d3, d4);
    o[3][1] = det3x3(a1, a3, a4, b1, b3, b4, c1, c3, c4);

    o[0][2] = det3x3(b1, b2, b4, c1, c2, c4, d1, d2, d4);
    o[1][2] = -det3x3(a1, a2, a4, c1, c2, c4, d1, d2, d4);
    o[2][2] = det3x3(a1, a2, a4, b1, b2, b4, d1, d2, d4);
    o[3][2] = -det3x3(a1, a2, a4, b1, b2, b4, c1, c2, c4);

    o[0][3] = -det3x3(b1, b2, b3, c1, c2, c3, d1, d2, d3);
    o[1][3] = det3x3(a1, a2, a3, c1, c2, c3, d1, d2, d3);
    o[2][3] = -det3x3(a1, a2, a3, b1, b2, b3, d1, d2, d3);
    o[3][3] = det3x3(a1, a2, a3, b1, b2, b3, c1, c2, c3);
    o
}

/// `lib_matrix_det4x4`.
pub fn matrix_det4x4(m: &Matrix) -> f64 {
    let (a1, b1, c1, d1) = (m[0][0], m[0][1], m[0][2], m[0][3]);
    let (a2, b2, c2, d2) = (m[1][0], m[1][1], m[1][2], m[1][3]);
    let (a3, b3, c3, d3) = (m[2][0], m[2][1], m[2][2], m[2][3]);
    let (a4, b4, c4, d4) = (m[3][0], m[3][1], m[3][2], m[3][3]);
    a1 * det3x3(b2, b3, b4, c2, c3, c4, d2, d3, d4)
        - b1 * det3x3(a2, a3, a4, c2, c3, c4, d2, d3, d4)
        + c1 * det3x3(a2, a3, a4, b2, b3, b4, d2, d3, d4)
        - d1 * det3x3(a2, a3, a4, b2, b3, b4, c2, c3, c4)
}

/// `lib_invert_matrix`: adjoint / determinant; a (near-)singular matrix gives the identity,
/// as in the C.
pub fn invert_matrix(m: &Matrix) -> Matrix {
    let mut out = adjoint(m);
    let det = matrix_det4x4(m);
    if det.abs() < EPSILON {
        return identity_matrix();
    }
    for row in out.iter_mut() {
        for e in row.iter_mut() {
            *e /= det;
        }
    }
    out
}

/// `lib_transpose_matrix`.
pub fn transpose_matrix(m: &Matrix) -> Matrix {
    let mut r = zero_matrix();
    for (i, row) in m.iter().enumerate() {
        for (j, &e) in row.iter().enumerate() {
            r[j][i] = e;
        }
    }
    r
}

/// `lib_matrix_multiply(res, a, b)`: `a * b`.
pub fn matrix_multiply(a: &Matrix, b: &Matrix) -> Matrix {
    let mut r = zero_matrix();
    for i in 0..4 {
        for j in 0..4 {
            r[i][j] = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j] + a[i][3] * b[3][j];
        }
    }
    r
}

/// `lib_rotate_cube_face`: rotates `vec` by 90 degrees towards the next cube face.
pub fn rotate_cube_face(vec: &mut [f64], major_axis: usize, mod_face: usize) {
    let mod_face = (mod_face + major_axis) % 3;
    if mod_face == 0 {
        let swap = vec[0];
        vec[0] = -vec[1];
        vec[1] = swap;
    } else if mod_face == 1 {
        let swap = vec[1];
        vec[1] = -vec[2];
        vec[2] = swap;
    } else {
        let swap = vec[0];
        vec[0] = -vec[2];
        vec[2] = swap;
    }
}

/// `lib_gauss_rand` (Numerical Recipes' GASDEV with a tiny LCG). C `long` is 64 bits on the
/// LP64 Linux that made the fixtures, so `i64` arithmetic (with `%` truncating like C).
pub fn gauss_rand(iseed: i64) -> f64 {
    const M1: i64 = 134456;
    const IA1: i64 = 8121;
    const IC1: i64 = 28411;
    // `#define RM1 1.0/M1` is expanded textually: `ix1 * 2.0 * RM1` is `ix1 * 2.0 * 1.0 / M1`,
    // i.e. ((ix1 * 2.0) * 1.0) / 134456.0, which is what we compute.
    let mut ix2 = iseed;
    let (mut v1, mut r);
    loop {
        let ix1 = (IC1 + ix2 * IA1) % M1;
        ix2 = (IC1 + ix1 * IA1) % M1;
        v1 = ix1 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        let v2 = ix2 as f64 * 2.0 * 1.0 / M1 as f64 - 1.0;
        r = v1 * v1 + v2 * v2;
        if r < 1.0 {
            break;
        }
    }
    let fac = (-2.0 * r.ln() / r).sqrt();
    v1 * fac
}

/// `lib_tx_unwind` (libtx.c, Spencer Thomas' "unmatrix" from Graphics Gems II): decomposes a
/// transform into scale, shear, rotation, translation and perspective (the `U_*` indices).
/// `None` when the upper 3x3 is singular (the C returns 0).
pub fn tx_unwind(tx_mat: &Matrix) -> Option<[f64; 16]> {
    let mut tran = [0.0; 16];
    let mut locmat = *tx_mat;
    if locmat[3][3] != 0.0 {
        // The C divides every entry by locmat[3][3] in place, so the last one divides by the
        // already-normalized value (1.0); reproduce the same sequence.
        for i in 0..4 {
            for j in 0..4 {
                locmat[i][j] /= locmat[3][3];
            }
        }
    }
    let mut pmat = locmat;
    for row in pmat.iter_mut().take(3) {
        row[3] = 0.0;
    }
    pmat[3][3] = 1.0;
    if matrix_det4x4(&pmat) == 0.0 {
        return None;
    }
    if locmat[0][3] != 0.0 || locmat[1][3] != 0.0 || locmat[2][3] != 0.0 {
        let prhs = [locmat[0][3], locmat[1][3], locmat[2][3], locmat[3][3]];
        let invpmat = invert_matrix(&pmat);
        let psol = transform_coord(&prhs, &invpmat);
        tran[U_PERSPX] = psol[0];
        tran[U_PERSPY] = psol[1];
        tran[U_PERSPZ] = psol[2];
        tran[U_PERSPW] = psol[3];
        locmat[0][3] = 0.0;
        locmat[1][3] = 0.0;
        locmat[2][3] = 0.0;
        locmat[3][3] = 1.0;
    }
    for i in 0..3 {
        tran[U_TRANSX + i] = locmat[3][i];
        locmat[3][i] = 0.0;
    }
    let mut row: [Coord3; 3] = [[0.0; 3]; 3];
    for i in 0..3 {
        row[i] = [locmat[i][0], locmat[i][1], locmat[i][2]];
    }
    tran[U_SCALEX] = normalize_vector(&mut row[0]);

    tran[U_SHEARXY] = dot(&row[0], &row[1]);
    row[1] = comb3(&row[1], &row[0], 1.0, -tran[U_SHEARXY]);
    tran[U_SCALEY] = normalize_vector(&mut row[1]);
    tran[U_SHEARXY] /= tran[U_SCALEY];

    tran[U_SHEARXZ] = dot(&row[0], &row[2]);
    row[2] = comb3(&row[2], &row[0], 1.0, -tran[U_SHEARXZ]);
    tran[U_SHEARYZ] = dot(&row[1], &row[2]);
    row[2] = comb3(&row[2], &row[1], 1.0, -tran[U_SHEARYZ]);

    tran[U_SCALEZ] = normalize_vector(&mut row[2]);
    tran[U_SHEARXZ] /= tran[U_SCALEZ];
    tran[U_SHEARYZ] /= tran[U_SCALEZ];

    let prhs = cross(&row[1], &row[2]);
    if dot(&row[0], &prhs) < 0.0 {
        for i in 0..3 {
            tran[U_SCALEX + i] *= -1.0;
            row[i][0] *= -1.0;
            row[i][1] *= -1.0;
            row[i][2] *= -1.0;
        }
    }

    tran[U_ROTATEY] = (-row[0][2]).asin();
    if tran[U_ROTATEY].cos() != 0.0 {
        tran[U_ROTATEX] = if row[1][2].abs() < EPSILON && row[2][2].abs() < EPSILON {
            0.0
        } else {
            row[1][2].atan2(row[2][2])
        };
        tran[U_ROTATEZ] = if row[0][1].abs() < EPSILON && row[0][0].abs() < EPSILON {
            0.0
        } else {
            row[0][1].atan2(row[0][0])
        };
    } else {
        tran[U_ROTATEX] = row[1][0].atan2(row[1][1]);
        tran[U_ROTATEZ] = 0.0;
    }
    Some(tran)
}

/// `trans[U_SCALEX]` of `lib_tx_unwind`, which libpr2.c multiplies sphere and cone radii by
/// (through `fabs`) when a transform is active. The C leaves `trans` uninitialized when the
/// unwind fails (singular matrix); we return 0 then, which never happens in the SPD programs.
pub fn tx_unwind_scale_x(m: &Matrix) -> f64 {
    tx_unwind(m).map_or(0.0, |t| t[U_SCALEX])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn rotate_z_quarter_turn() {
        // Row vectors: (1,0,0) * Rz(90°) = (cos, sin, 0) = (0,1,0).
        let m = rotate_matrix(Z_AXIS, PI / 2.0);
        let p = transform_point(&[1.0, 0.0, 0.0], &m);
        assert!(
            close(p[0], 0.0) && close(p[1], 1.0) && close(p[2], 0.0),
            "{p:?}"
        );
        let a = axis_rotate_matrix(&[0.0, 0.0, 1.0], PI / 2.0);
        for i in 0..4 {
            for j in 0..4 {
                assert!(close(a[i][j], m[i][j]));
            }
        }
    }

    #[test]
    fn invert_times_m_is_identity() {
        let m = matrix_multiply(
            &matrix_multiply(&rotate_matrix(X_AXIS, 0.3), &scale_matrix(&[2.0, 3.0, 0.5])),
            &translate_matrix(&[1.0, -2.0, 5.0]),
        );
        let p = matrix_multiply(&invert_matrix(&m), &m);
        let id = identity_matrix();
        for i in 0..4 {
            for j in 0..4 {
                assert!(close(p[i][j], id[i][j]), "{p:?}");
            }
        }
    }

    #[test]
    fn unwind_scale() {
        let m = matrix_multiply(&scale_matrix(&[2.5, 2.5, 2.5]), &rotate_matrix(Y_AXIS, 1.0));
        assert!(close(tx_unwind_scale_x(&m), 2.5));
        let t = tx_unwind(&translate_matrix(&[1.0, 2.0, 3.0])).unwrap();
        assert_eq!(&t[U_TRANSX..=U_TRANSZ], &[1.0, 2.0, 3.0]);
    }

    #[test]
    fn gauss_rand_is_deterministic_and_bounded() {
        let a = gauss_rand(12345);
        assert_eq!(a, gauss_rand(12345));
        assert!(a.is_finite() && a.abs() < 10.0);
    }
}
