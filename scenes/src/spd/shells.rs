//! shells, ported from SPD 3.14's shells.c: Pickover's spiral shell (IEEE CG&A, November 1989),
//! a logarithmic spiral of overlapping spheres, one light. Only the default shape parameters
//! (the C's `-a -b -g -e` options are not part of the benchmark): gamma 1, alpha 0, beta -2,
//! a 0.15, k 1.
//!
//! Spheres: `steps = (long)(180 * 2^SF)`, for i in -steps*2/3 ..= steps/3; since steps is a
//! multiple of 3 that is steps + 1 = 180 * 2^SF + 1 spheres. (The comment of shells.c says
//! 180 * 2^SF spheres and one square; the code prints no square.)
//!
//! shells.c parses its own options (`shells_get_opts`), whose `-t` takes no resolution: the C
//! program tessellates only at the default resolution 3 (`shells -t 3` is rejected as an unknown
//! argument). Other resolutions here are an extension; at 3 the output is the C's.

use super::vec::{self, Coord4};
use super::Output;

const FGAMMA: f64 = 1.0;
const ALPHA: f64 = 0.0;
const BETA: f64 = -2.0;
const A: f64 = 0.15;
const K: f64 = 1.0;

/// `steps` of shells.c, or `None` once `-steps*2` would overflow the C `long` (SF >= 55; the
/// C program is undefined there).
fn steps(size_factor: u64) -> Option<i64> {
    if size_factor > 54 {
        return None;
    }
    let s = (180.0 * 2.0f64.powf(size_factor as f64)) as i64;
    s.checked_mul(2)?;
    Some(s)
}

/// Spheres in the output: 180 * 2^SF + 1 (`None` past SF 54, where the C overflows).
pub fn object_count(size_factor: u64) -> Option<u64> {
    let s = steps(size_factor)?;
    let lo = -s * 2 / 3;
    let hi = s / 3;
    Some((hi - lo + 1) as u64)
}

/// The C `main` after option parsing (size factors up to 54; see [`object_count`]).
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [-6.0, -60.0, 35.0],
        [0.0, 8.0, -15.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.5,
        512,
        512,
    );
    out.light([-100.0, -100.0, 100.0, 1.0]);
    out.color([1.0, 0.8, 0.4], 0.0, 0.8, 0.2, 0.5, 10.0, 0.0, 1.0);

    let Some(steps) = steps(size_factor as u64) else {
        return;
    };
    // C integer division truncates toward zero, as Rust's does.
    let mut i = -steps * 2 / 3;
    while i <= steps / 3 {
        let angle = 3.0 * 6.0 * vec::PI * i as f64 / steps as f64;
        let r = K * (A * angle).exp();
        let mut sphere: Coord4 = [r * angle.sin(), r * angle.cos(), 0.0, 0.0];
        sphere[2] = if ALPHA > 0.0 { ALPHA * angle } else { BETA * r };
        sphere[3] = r / FGAMMA;
        out.sphere(sphere);
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, Output};

    #[test]
    fn object_counts() {
        assert_eq!(object_count(1), Some(361));
        assert_eq!(object_count(5), Some(5_761));
        assert_eq!(object_count(54), Some(180 * (1u64 << 54) + 1));
        assert_eq!(object_count(55), None);
    }

    #[test]
    fn generated_count_matches() {
        for sf in 1..=3 {
            let mut sink = CountingSink::default();
            generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), sf);
            assert_eq!(sink.counts.sphere, object_count(sf as u64).unwrap());
        }
    }
}
