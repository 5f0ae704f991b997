//! mount: a fractal mountain of 2·4^SF triangles (Carpenter's midpoint displacement on a square
//! grid) with a pyramid of four glass spheres in front of it (SPD 3.14 `mount.c`, Eric Haines).
//! One light.
//!
//! The midpoint heights come from `lib_gauss_rand` seeded by a hash of the grid position. mount.c
//! has two hashes: the original one (faulty: the mountain repeats itself, but it is the one of
//! the published images and timings) and Bob Jenkins' (`-DJENKINS_HASH`). Both are reproduced
//! with the integer widths of the LP64 Linux build that made the fixtures: C `int` is `i32`,
//! `unsigned long` and `long` are 64-bit.

use super::vec::{self, Coord3, Coord4, PI, Z_AXIS};
use super::{MountHash, Output};

/// `FRACTAL_DIMENSION`: affects the variance of z; between 2 and 3.
const FRACTAL_DIMENSION: f64 = 2.2;
/// `MOUNTAIN_NO`: added to every seed; change it for another mountain.
const MOUNTAIN_NO: i64 = 21;
/// Lower left corner and width of the mountain (`X_CORNER`, `Y_CORNER`, `WIDTH`).
const X_CORNER: f64 = -1.0;
const Y_CORNER: f64 = -1.0;
const WIDTH: f64 = 2.0;

/// The original `hash_rand(A,B,C)` macro:
/// `(((unsigned long)A << (23-C)) + ((unsigned long)B << (15-C)) + ((unsigned long)A << (7-C))) & 0xffff`.
///
/// C quirk: for SF > 7 (then > 15, > 23) a shift count is negative, which C leaves undefined.
/// The x86-64 `shl` that gcc emits for this run-time count uses the count modulo 64, so
/// `7 - 8` shifts by 63; `wrapping_shl` masks the same way, so large size factors match the
/// C program as built on x86-64 Linux. The sum wraps modulo 2^64 (`unsigned long`).
fn hash_original(a: i64, b: i64, c: i64) -> i64 {
    // (unsigned long)(int): sign extension, then reinterpretation.
    let (ua, ub) = (a as i32 as u64, b as i32 as u64);
    let sh = |n: i64| n as u32; // wrapping_shl masks to the low 6 bits, like x86-64
    let h = ua
        .wrapping_shl(sh(23 - c))
        .wrapping_add(ub.wrapping_shl(sh(15 - c)))
        .wrapping_add(ua.wrapping_shl(sh(7 - c)));
    (h & 0xffff) as i64
}

/// Bob Jenkins' `mix(a,b,c)` on C `int`s (wrapping, arithmetic right shifts); `hash_rand`
/// returns `c & 0xffff`.
fn hash_jenkins(a: i64, b: i64, c: i64) -> i64 {
    let (mut a, mut b, mut c) = (a as i32, b as i32, c as i32);
    a = a.wrapping_sub(b).wrapping_sub(c) ^ (c >> 13);
    b = b.wrapping_sub(c).wrapping_sub(a) ^ a.wrapping_shl(8);
    c = c.wrapping_sub(a).wrapping_sub(b) ^ (b >> 13);
    a = a.wrapping_sub(b).wrapping_sub(c) ^ (c >> 12);
    b = b.wrapping_sub(c).wrapping_sub(a) ^ a.wrapping_shl(16);
    c = c.wrapping_sub(a).wrapping_sub(b) ^ (b >> 5);
    a = a.wrapping_sub(b).wrapping_sub(c) ^ (c >> 3);
    b = b.wrapping_sub(c).wrapping_sub(a) ^ a.wrapping_shl(10);
    c = c.wrapping_sub(a).wrapping_sub(b) ^ (b >> 15);
    (c & 0xffff) as i64
}

/// `create_spheres`: a pyramid of four crystal spheres of radius `center[3]`.
fn create_spheres(out: &mut Output<'_>, center: Coord4) {
    let mut axis = [1.0, 1.0, 0.0];
    vec::normalize_vector(&mut axis);
    let angle = (-1.0f64 / 3.0).acos();

    // the top sphere, above the center
    let pt: Coord3 = [0.0, 0.0, center[3] * (3.0f64 / 2.0).sqrt()];
    let mut sphere = center;
    for k in 0..3 {
        sphere[k] += pt[k];
    }
    out.sphere(sphere);

    // the other three: the top one tilted down by the tetrahedral angle, then turned about Z
    let mx = vec::axis_rotate_matrix(&axis, angle);
    let new_pt = vec::transform_vector(&pt, &mx);
    for i in 0..3 {
        let mx = vec::rotate_matrix(Z_AXIS, i as f64 * 2.0 * PI / 3.0);
        let p = vec::transform_vector(&new_pt, &mx);
        // sphere[W] keeps the radius copied from center
        for k in 0..3 {
            sphere[k] = p[k] + center[k];
        }
        out.sphere(sphere);
    }
}

struct Mountain<'a, 'o> {
    out: &'a mut Output<'o>,
    fnum_pts: f64,
    roughness: f64,
    size_factor: i64,
    hash: MountHash,
}

impl Mountain<'_, '_> {
    /// `iz = MOUNTAIN_NO + hash_rand(a, b, size_factor)`, then `lib_gauss_rand(iz)`.
    fn gauss(&self, a: i64, b: i64) -> f64 {
        let h = match self.hash {
            MountHash::Original => hash_original(a, b, self.size_factor),
            MountHash::Jenkins => hash_jenkins(a, b, self.size_factor),
        };
        vec::gauss_rand(MOUNTAIN_NO + h)
    }

    /// `grow_mountain`: split the square into four (displacing the edge midpoints and the
    /// center) until it is one grid cell wide, then output it as two triangles.
    #[allow(clippy::too_many_arguments)]
    fn grow(
        &mut self,
        width: i64,
        ll_x: i64,
        ll_y: i64,
        ll_fz: f64,
        lr_fz: f64,
        ur_fz: f64,
        ul_fz: f64,
    ) {
        if width == 1 {
            let l_fx = X_CORNER + ll_x as f64 * WIDTH / self.fnum_pts;
            let r_fx = X_CORNER + (ll_x + 1) as f64 * WIDTH / self.fnum_pts;
            let l_fy = Y_CORNER + ll_y as f64 * WIDTH / self.fnum_pts;
            let u_fy = Y_CORNER + (ll_y + 1) as f64 * WIDTH / self.fnum_pts;
            let corners = [
                [l_fx, l_fy, ll_fz],
                [r_fx, l_fy, lr_fz],
                [r_fx, u_fy, ur_fz],
                [l_fx, u_fy, ul_fz],
            ];
            // triangles (0,1,2) and (2,3,0): vertex (num_vert + num_tri*2) % 4
            self.out.polygon(&[corners[0], corners[1], corners[2]]);
            self.out.polygon(&[corners[2], corners[3], corners[0]]);
            return;
        }

        let half_width = width >> 1;
        let hside_length = half_width as f64 * WIDTH / self.fnum_pts;
        let rise_height = hside_length * self.roughness;

        // for each midpoint, find z
        let lower_fz = (ll_fz + lr_fz) / 2.0 + rise_height * self.gauss(ll_x + half_width, ll_y);
        let right_fz =
            (lr_fz + ur_fz) / 2.0 + rise_height * self.gauss(ll_x + width, ll_y + half_width);
        let upper_fz =
            (ur_fz + ul_fz) / 2.0 + rise_height * self.gauss(ll_x + half_width, ll_y + width);
        let left_fz = (ul_fz + ll_fz) / 2.0 + rise_height * self.gauss(ll_x, ll_y + half_width);
        // The C's 1.4142136 (not exactly √2) is kept so that heights match the C output.
        #[allow(clippy::approx_constant)]
        let middle_fz = (ll_fz + lr_fz + ur_fz + ul_fz) / 4.0
            + 1.4142136 * rise_height * self.gauss(ll_x + half_width, ll_y + half_width);

        self.grow(half_width, ll_x, ll_y, ll_fz, lower_fz, middle_fz, left_fz);
        self.grow(
            half_width,
            ll_x + half_width,
            ll_y,
            lower_fz,
            lr_fz,
            right_fz,
            middle_fz,
        );
        self.grow(
            half_width,
            ll_x + half_width,
            ll_y + half_width,
            middle_fz,
            right_fz,
            ur_fz,
            upper_fz,
        );
        self.grow(
            half_width,
            ll_x,
            ll_y + half_width,
            left_fz,
            middle_fz,
            upper_fz,
            ul_fz,
        );
    }
}

/// mount.c `main` after option parsing.
///
/// C quirk: `num_pts = 1<<size_factor` is an `int`, so the C program breaks at SF ≥ 31 (its
/// count, 2·4^31 + 4, still fits 64 bits); here the grid is 64-bit and the hash arguments are
/// truncated to `int` as the C would see them.
pub fn generate(out: &mut Output<'_>, size_factor: u32, hash: MountHash) {
    // UNC sky blue
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [-1.6, 1.6, 1.7],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        0.01,
        512,
        512,
    );

    // NFF lights are not scaled (lscale = 1 for OUTPUT_NFF).
    out.light([-100.0, -100.0, 100.0, 1.0]);

    // crystal spheres - clear white
    out.color([1.0, 1.0, 1.0], 0.0, 0.1, 0.1, 0.4, 6.7, 0.9, 1.5);
    create_spheres(out, [-0.8, 0.8, 1.00, 0.17]);

    // mountain - grey
    out.color([0.5, 0.45, 0.35], 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);

    let num_pts: i64 = 1i64 << size_factor.min(62);
    let ratio = 2.0 / ((2.0f64).ln() / (FRACTAL_DIMENSION - 1.0)).exp();
    let roughness = (ratio * ratio - 1.0).sqrt();
    let mut m = Mountain {
        out,
        fnum_pts: num_pts as f64,
        roughness,
        size_factor: size_factor as i64,
        hash,
    };
    m.grow(num_pts, 0, 0, 0.0, 0.0, 0.0, 0.0);
}

/// Four spheres and two triangles per grid cell: 2·4^SF + 4.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let sf = u32::try_from(size_factor).ok()?;
    4u64.checked_pow(sf)?.checked_mul(2)?.checked_add(4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, DEFAULT_RESOLUTION};

    fn count(sf: u32, hash: MountHash) -> CountingSink {
        let mut sink = CountingSink::default();
        let mut out = Output::new(&mut sink, CurveFormat::Curves, DEFAULT_RESOLUTION);
        generate(&mut out, sf, hash);
        sink
    }

    #[test]
    fn object_count_standard() {
        assert_eq!(object_count(6), Some(8_196));
        assert_eq!(object_count(1), Some(12));
        assert_eq!(object_count(31), Some(2 * (1u64 << 62) + 4));
        assert_eq!(object_count(32), None);
    }

    #[test]
    fn stream_matches_object_count() {
        for hash in [MountHash::Original, MountHash::Jenkins] {
            for sf in 1..=7 {
                let s = count(sf, hash);
                assert_eq!(
                    s.counts.objects(),
                    object_count(sf as u64).unwrap(),
                    "sf {sf}"
                );
                assert_eq!(s.counts.sphere, 4);
                assert_eq!(s.counts.triangles, 2 * 4u64.pow(sf));
            }
        }
    }

    #[test]
    fn original_hash_masks_negative_shifts() {
        // SF 8: the `7 - C` shift is -1, i.e. 63 on x86-64; an odd A then sets only bit 63,
        // which the `& 0xffff` drops.
        assert_eq!(hash_original(1, 0, 8), ((1u64 << 15) & 0xffff) as i64);
        assert_eq!(
            hash_original(3, 2, 6),
            ((3 << 17) + (2 << 9) + (3 << 1)) & 0xffff
        );
    }

    #[test]
    fn hashes_match_c_on_x86_64() {
        // (A, B, C, original hash_rand, Jenkins hash_rand) as printed by the two C hash_rand
        // definitions compiled with gcc on x86-64 Linux (-O0 and -O2 agree), with C a run-time
        // value as in mount.c: negative shift counts (C > 7, 15, 23) included.
        let cases: [(i64, i64, i64, i64, i64); 60] = [
            (12345, 54321, 9, 19520, 27517),
            (12345, 3, 9, 16576, 28533),
            (12345, 536870912, 9, 16384, 11284),
            (99999, 54321, 9, 52288, 42898),
            (99999, 3, 9, 49344, 59820),
            (99999, 536870912, 9, 49152, 40366),
            (1048576, 54321, 9, 3136, 40199),
            (1048576, 3, 9, 192, 62411),
            (1048576, 536870912, 9, 0, 19236),
            (77777777, 54321, 9, 19520, 57995),
            (77777777, 3, 9, 16576, 41288),
            (77777777, 536870912, 9, 16384, 11698),
            (12345, 54321, 16, 7296, 9747),
            (12345, 3, 16, 7296, 17941),
            (12345, 536870912, 16, 7296, 39427),
            (99999, 54321, 16, 20352, 24854),
            (99999, 3, 16, 20352, 57513),
            (99999, 536870912, 16, 20352, 42444),
            (1048576, 54321, 16, 0, 43955),
            (1048576, 3, 16, 0, 15611),
            (1048576, 536870912, 16, 0, 40047),
            (77777777, 54321, 16, 47232, 9823),
            (77777777, 3, 16, 47232, 54374),
            (77777777, 536870912, 16, 47232, 7653),
            (12345, 54321, 20, 33224, 28238),
            (12345, 3, 20, 33224, 8405),
            (12345, 536870912, 20, 33224, 53591),
            (99999, 54321, 20, 13560, 40687),
            (99999, 3, 20, 13560, 45611),
            (99999, 536870912, 20, 13560, 50355),
            (1048576, 54321, 20, 0, 33959),
            (1048576, 3, 20, 0, 10718),
            (1048576, 536870912, 20, 0, 42797),
            (77777777, 54321, 20, 23432, 49108),
            (77777777, 3, 20, 23432, 32924),
            (77777777, 536870912, 20, 23432, 21624),
            (12345, 54321, 24, 0, 54905),
            (12345, 3, 24, 0, 9200),
            (12345, 536870912, 24, 0, 11895),
            (99999, 54321, 24, 0, 48160),
            (99999, 3, 24, 0, 20800),
            (99999, 536870912, 24, 0, 44387),
            (1048576, 54321, 24, 0, 11870),
            (1048576, 3, 24, 0, 27802),
            (1048576, 536870912, 24, 0, 55572),
            (77777777, 54321, 24, 0, 8118),
            (77777777, 3, 24, 0, 61301),
            (77777777, 536870912, 24, 0, 4032),
            (12345, 54321, 30, 0, 28605),
            (12345, 3, 30, 0, 40316),
            (12345, 536870912, 30, 0, 43819),
            (99999, 54321, 30, 0, 33779),
            (99999, 3, 30, 0, 14689),
            (99999, 536870912, 30, 0, 33979),
            (1048576, 54321, 30, 0, 26701),
            (1048576, 3, 30, 0, 25758),
            (1048576, 536870912, 30, 0, 5061),
            (77777777, 54321, 30, 0, 6560),
            (77777777, 3, 30, 0, 33799),
            (77777777, 536870912, 30, 0, 50612),
        ];
        for (a, b, c, orig, jenkins) in cases {
            assert_eq!(hash_original(a, b, c), orig, "original ({a}, {b}, {c})");
            assert_eq!(hash_jenkins(a, b, c), jenkins, "jenkins ({a}, {b}, {c})");
        }
    }
}
