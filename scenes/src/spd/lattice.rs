//! lattice, ported from SPD 3.14's lattice.c (Antonio Costa): shiny spheres on a cubic lattice
//! joined by matte cylinders, six lights. Every primitive is preceded by its own `f` record, as
//! the C prints it.

use super::Output;

const RADIUS1: f64 = 1.0 / 4.0;
const RADIUS2: f64 = 1.0 / 16.0;

/// Primitives: (SF+1)^3 spheres and 3 * SF * (SF+1)^2 cylinders (each of the three axis
/// directions has SF links in each of (SF+1)^2 lines).
pub fn object_count(size_factor: u64) -> Option<u64> {
    let n1 = size_factor.checked_add(1)?;
    let sq = n1.checked_mul(n1)?;
    let spheres = sq.checked_mul(n1)?;
    let cylinders = sq.checked_mul(size_factor)?.checked_mul(3)?;
    spheres.checked_add(cylinders)
}

/// The C `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    let sf = size_factor as f64;
    // The C's macros inv_factor, radius1, radius2.
    let inv_factor = 1.0 / sf;
    let radius1 = RADIUS1 / sf;
    let radius2 = RADIUS2 / sf;
    let delta = (radius1 * (1.0 - (RADIUS2 / RADIUS1).sqrt())) * 0.99;

    out.background([0.078, 0.361, 0.753]);
    // `size_factor >> 1` and `size_factor << 1` are C int shifts; u64 here so large SFs do not
    // wrap (the C would overflow only past 2^30, far beyond any feasible count).
    let half = (size_factor >> 1) as f64;
    let twice = ((size_factor as u64) << 1) as f64;
    out.viewpoint(
        [(half + 0.5) * inv_factor, 1.0, 1.0 - 1.0 / twice],
        [(half + 0.5) * inv_factor, -1.0, -1.0 - 1.0 / twice],
        [0.2, 1.0, 0.0],
        60.0,
        1.0,
        0.0,
        512,
        512,
    );

    let lscale = 1.0 / 6.0f64.sqrt();
    for l in [
        [2.0, 0.5, 0.5],
        [-1.0, 0.5, 0.5],
        [0.5, 2.0, 0.5],
        [0.5, -1.0, 0.5],
        [0.5, 0.5, 2.0],
        [0.5, 0.5, -1.0],
    ] {
        out.light([l[0], l[1], l[2], lscale]);
    }

    for x in 0..=size_factor {
        let x0 = x as f64 / sf;
        for y in 0..=size_factor {
            let y0 = y as f64 / sf;
            for z in 0..=size_factor {
                let z0 = z as f64 / sf;
                out.color([0.9, 0.9, 0.9], 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 0.0);
                out.sphere([x0, y0, z0, radius1]);
                if x != size_factor {
                    out.color([0.9, 0.1, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    out.cylcone(
                        [x0 + delta, y0, z0, radius2],
                        [x0 + inv_factor - delta, y0, z0, radius2],
                    );
                }
                if y != size_factor {
                    out.color([0.1, 0.9, 0.1], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    out.cylcone(
                        [x0, y0 + delta, z0, radius2],
                        [x0, y0 + inv_factor - delta, z0, radius2],
                    );
                }
                if z != size_factor {
                    out.color([0.1, 0.1, 0.9], 0.1, 0.99, 0.0, 0.0, 0.0, 0.0, 0.0);
                    out.cylcone(
                        [x0, y0, z0 + delta, radius2],
                        [x0, y0, z0 + inv_factor - delta, radius2],
                    );
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
        assert_eq!(object_count(1), Some(8 + 12));
        assert_eq!(object_count(2), Some(27 + 54));
        assert_eq!(object_count(5), Some(216 + 540));
        assert_eq!(object_count(12), Some(2_197 + 6_084));
        assert_eq!(object_count(u64::MAX), None);
        assert_eq!(object_count(3_000_000), None);
    }

    #[test]
    fn generated_counts_match() {
        for sf in 1..=4 {
            let mut sink = CountingSink::default();
            generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), sf);
            assert_eq!(sink.counts.objects(), object_count(sf as u64).unwrap());
        }
    }
}
