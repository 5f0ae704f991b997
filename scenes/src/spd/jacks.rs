//! jacks, ported from SPD 3.14's jacks.c (Alexander Enzmann): a "jack" (three cylinders along the
//! axes with a sphere at each of the six ends) with a half-size jack in each of the eight
//! octants, recursively, SF levels in all, under a rotation of the whole scene.
//!
//! Everything is placed through the transform stack (`lib_tx_*`); NFF gets the transformed
//! primitives (radii scaled by the unwound X scale).
//!
//! jacks.c calls `lib_set_polygonalization(2, 2)` after reading the options, so its tessellated
//! output is at resolution 2 whatever `-t` says (each sphere 48 patches, each cylinder 16).

use super::vec::{self, X_AXIS, Y_AXIS};
use super::Output;

/// Primitives in the curved output: 9 per jack (3 cylinders, 6 spheres), and
/// 1 + 8 + ... + 8^(SF-1) = (8^SF - 1) / 7 jacks.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let mut jacks: u64 = 0;
    let mut level: u64 = 1;
    for d in 0..size_factor {
        jacks = jacks.checked_add(level)?;
        if d + 1 < size_factor {
            level = level.checked_mul(8)?;
        }
    }
    jacks.checked_mul(9)
}

/// The C `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    out.set_polygonalization(2, 2);
    // Dark purple.
    out.background([0.2, 0.05, 0.2]);
    out.viewpoint(
        [0.0, 0.0, -8.0],
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        25.0,
        1.0,
        0.001,
        256,
        256,
    );
    out.light([-10.0, 3.0, -20.0, 1.0]);

    out.tx_push();
    out.tx_rotate(X_AXIS, -30.0 * vec::PI / 180.0);
    out.tx_rotate(Y_AXIS, -20.0 * vec::PI / 180.0);
    // Pink.
    out.color([0.737, 0.561, 0.561], 0.1, 0.7, 0.7, 0.4, 20.0, 0.0, 1.0);
    make_rec_jack(out, 1, size_factor);
    out.tx_pop();
}

/// jacks.c `make_jack_obj`: one jack, scaled by 0.75 so neighbours do not overlap.
fn make_jack_obj(out: &mut Output<'_>) {
    out.tx_push();
    out.tx_scale([0.75, 0.75, 0.75]);
    out.cylcone([-1.0, 0.0, 0.0, 0.1], [1.0, 0.0, 0.0, 0.1]);
    out.cylcone([0.0, -1.0, 0.0, 0.1], [0.0, 1.0, 0.0, 0.1]);
    out.cylcone([0.0, 0.0, -1.0, 0.1], [0.0, 0.0, 1.0, 0.1]);
    for c in [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, -1.0],
    ] {
        out.sphere([c[0], c[1], c[2], 0.2]);
    }
    out.tx_pop();
}

/// jacks.c `make_rec_jack`: a jack, then (below `max_depth`) a half-size jack recursively in
/// each octant, at offsets ±0.5 (the C's `for (i=-0.5;i<=0.5;i+=1)` loops).
fn make_rec_jack(out: &mut Output<'_>, depth: u32, max_depth: u32) {
    make_jack_obj(out);
    if depth < max_depth {
        for i in [-0.5, 0.5] {
            for j in [-0.5, 0.5] {
                for k in [-0.5, 0.5] {
                    out.tx_push();
                    out.tx_translate([i, j, k]);
                    out.tx_scale([0.5, 0.5, 0.5]);
                    make_rec_jack(out, depth + 1, max_depth);
                    out.tx_pop();
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, Output};

    #[test]
    fn object_counts() {
        assert_eq!(object_count(1), Some(9));
        assert_eq!(object_count(2), Some(81));
        assert_eq!(object_count(3), Some(657));
        assert_eq!(object_count(5), Some(9 * 4_681));
        assert!(object_count(21).is_some());
        assert_eq!(object_count(22), None);
    }

    #[test]
    fn generated_counts_match() {
        for sf in 1..=3 {
            let mut sink = CountingSink::default();
            generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), sf);
            assert_eq!(sink.counts.objects(), object_count(sf as u64).unwrap());
            assert_eq!(sink.counts.sphere, 2 * sink.counts.cone);
        }
        // Tessellated at resolution 2 (set by jacks.c itself): 6 x 48 + 3 x 16 patches a jack.
        let mut sink = CountingSink::default();
        generate(&mut Output::new(&mut sink, CurveFormat::Patches, 3), 1);
        assert_eq!(sink.counts.patch, 6 * 48 + 3 * 16);
    }
}
