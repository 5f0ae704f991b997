//! tree: a binary tree of cone branches with spheres at the joints, grown with Aono & Kunii's
//! method (IEEE CG&A, May 1984), on a square field (SPD 3.14 `tree.c`, Eric Haines). Seven
//! lights.

use super::vec::{self, Coord4, Matrix, PI, X_AXIS, Z_AXIS};
use super::Output;

// The shape of the tree.
const BR_ANGLE_0: f64 = 40.0;
const BR_ANGLE_1: f64 = 25.0;
const BR_CONTR_0: f64 = 0.65;
const BR_CONTR_1: f64 = 0.70;
const BR_DIAMETER: f64 = 0.67;
const DIV_ANGLE: f64 = 140.0;
const WIDTH_HEIGHTH_RATIO: f64 = 0.15;

/// `grow_tree`: output the branch (the unit Z segment under `cur_mx`) and the sphere at its tip,
/// then grow the two child branches.
fn grow_tree(out: &mut Output<'_>, rst_mx: &[Matrix; 2], cur_mx: &Matrix, scale: f64, depth: u32) {
    let b = vec::transform_point(&[0.0, 0.0, 0.0], cur_mx);
    let base: Coord4 = [b[0], b[1], b[2], scale * WIDTH_HEIGHTH_RATIO];
    let a = vec::transform_point(&[0.0, 0.0, 1.0], cur_mx);
    let apex: Coord4 = [a[0], a[1], a[2], base[3] * BR_DIAMETER];

    out.cylcone(base, apex);
    out.sphere(apex);

    if depth > 0 {
        for rst in rst_mx {
            let new_mx = vec::matrix_multiply(rst, cur_mx);
            grow_tree(out, rst_mx, &new_mx, scale * BR_DIAMETER, depth - 1);
        }
    }
}

/// `create_tree`: the branch matrices relative to the parent (rotate by the branching angle
/// about X and the divergence about Z, contract, move to the parent's tip), then the tree.
fn create_tree(out: &mut Output<'_>, size_factor: u32) {
    let mut rst_mx = [vec::identity_matrix(); 2];
    for (i, rst) in rst_mx.iter_mut().enumerate() {
        let (branch_angle, divergence, branch_contraction) = if i == 0 {
            (BR_ANGLE_0, 90.0, BR_CONTR_0)
        } else {
            (BR_ANGLE_1, DIV_ANGLE + 90.0, BR_CONTR_1)
        };
        let temp1_mx = vec::rotate_matrix(X_AXIS, branch_angle * PI / 180.0);
        let temp2_mx = vec::rotate_matrix(Z_AXIS, divergence * PI / 180.0);
        let tempr_mx = vec::matrix_multiply(&temp1_mx, &temp2_mx);

        // scale, and translate to the tip of the parent
        let mut tempst_mx = vec::identity_matrix();
        tempst_mx[0][0] = branch_contraction;
        tempst_mx[1][1] = branch_contraction;
        tempst_mx[2][2] = branch_contraction;
        tempst_mx[3][2] = 1.0;

        *rst = vec::matrix_multiply(&tempr_mx, &tempst_mx);
    }

    grow_tree(out, &rst_mx, &vec::identity_matrix(), 1.0, size_factor);
}

/// tree.c `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    // UNC sky blue
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [4.5, 0.4, 2.0],
        [0.0, 0.0, 1.5],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );

    // NFF lights are not scaled (lscale = 1 for OUTPUT_NFF).
    let lights: [Coord4; 7] = [
        [-5.0, 5.0, 50.0, 1.0],
        [30.0, -30.0, 30.0, 1.0],
        [-40.0, -30.0, 20.0, 1.0],
        [10.0, 30.0, 40.0, 1.0],
        [-30.0, 40.0, 10.0, 1.0],
        [50.0, 25.0, 20.0, 1.0],
        [-10.0, -60.0, 30.0, 1.0],
    ];
    for l in lights {
        out.light(l);
    }

    // field polygon - green
    out.color([0.2, 0.7, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let field = [
        [50.0, 50.0, 0.0],
        [-50.0, 50.0, 0.0],
        [-50.0, -50.0, 0.0],
        [50.0, -50.0, 0.0],
    ];
    out.polygon(&field);

    // tree - brown
    out.color([0.55, 0.4, 0.2], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    create_tree(out, size_factor);
}

/// 2^(SF+1) − 1 branches, each a cone and a sphere, plus the field: 2^(SF+2) − 1.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let shift = u32::try_from(size_factor.checked_add(1)?).ok()?;
    let branches = 1u64.checked_shl(shift)? - 1;
    branches.checked_mul(2)?.checked_add(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, DEFAULT_RESOLUTION};

    fn count(sf: u32, format: CurveFormat) -> CountingSink {
        let mut sink = CountingSink::default();
        let mut out = Output::new(&mut sink, format, DEFAULT_RESOLUTION);
        generate(&mut out, sf);
        sink
    }

    #[test]
    fn object_count_standard() {
        assert_eq!(object_count(11), Some(8_191));
        assert_eq!(object_count(1), Some(7));
        assert_eq!(object_count(62), Some(u64::MAX));
        assert_eq!(object_count(63), None);
    }

    #[test]
    fn stream_matches_object_count() {
        for sf in [1u32, 2, 4, 8, 11] {
            let s = count(sf, CurveFormat::Curves);
            assert_eq!(
                s.counts.objects(),
                object_count(sf as u64).unwrap(),
                "sf {sf}"
            );
            assert_eq!(s.counts.sphere, (1u64 << (sf + 1)) - 1);
            assert_eq!(s.counts.cone, s.counts.sphere);
        }
    }

    #[test]
    fn tessellated_triangles() {
        let s = count(10, CurveFormat::Patches);
        assert_eq!(s.counts.triangles, 270_206);
    }
}
