//! C's `printf("%g")`: six significant digits, trailing zeros removed, exponent form when the
//! decimal exponent is below −4 or at least 6. The SPD programs print every number this way.

use std::io::Write;

/// Appends `x` formatted as C's `%g` to `out`.
pub fn write_g(out: &mut Vec<u8>, x: f64) {
    if x.is_nan() {
        out.extend_from_slice(if x.is_sign_negative() {
            b"-nan"
        } else {
            b"nan"
        });
        return;
    }
    if x.is_infinite() {
        out.extend_from_slice(if x < 0.0 { b"-inf" } else { b"inf" });
        return;
    }
    if x == 0.0 {
        out.extend_from_slice(if x.is_sign_negative() { b"-0" } else { b"0" });
        return;
    }
    let (neg, exp, digits) = match fast_digits(x) {
        Some(d) => d,
        None => exact_digits(x),
    };
    let mut nd = 6;
    while nd > 1 && digits[nd - 1] == b'0' {
        nd -= 1;
    }
    if neg {
        out.push(b'-');
    }
    if !(-4..6).contains(&exp) {
        out.push(digits[0]);
        if nd > 1 {
            out.push(b'.');
            out.extend_from_slice(&digits[1..nd]);
        }
        out.push(b'e');
        out.push(if exp < 0 { b'-' } else { b'+' });
        let a = exp.unsigned_abs();
        if a < 10 {
            out.push(b'0');
        }
        let _ = write!(out, "{a}");
    } else if exp >= 0 {
        let int_digits = exp as usize + 1;
        for (i, d) in digits.iter().enumerate().take(int_digits.min(6)) {
            out.push(if i < nd { *d } else { b'0' });
        }
        for _ in 6..int_digits {
            out.push(b'0');
        }
        if nd > int_digits {
            out.push(b'.');
            out.extend_from_slice(&digits[int_digits..nd]);
        }
    } else {
        out.extend_from_slice(b"0.");
        for _ in 0..(-exp - 1) {
            out.push(b'0');
        }
        out.extend_from_slice(&digits[..nd]);
    }
}

/// Powers of ten that are exact in f64 (10^0 … 10^22).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The six significant digits of finite, non-zero `x` and its decimal exponent, the fast way:
/// x·10^(5−e) with one rounding (the power of ten is exact), then rounded to an integer. Gives
/// up (`None`) when that product lies so near a rounding tie that the one rounding could have
/// decided it, or when the power of ten would not be exact; the exact path then answers.
fn fast_digits(x: f64) -> Option<(bool, i32, [u8; 6])> {
    let a = x.abs();
    let mut e = a.log10().floor() as i32;
    for _ in 0..2 {
        let k = 5 - e;
        if k.unsigned_abs() as usize >= POW10.len() {
            return None;
        }
        let scaled = if k >= 0 {
            a * POW10[k as usize]
        } else {
            a / POW10[(-k) as usize]
        };
        if scaled < 99999.5 {
            e -= 1;
            continue;
        }
        if (999999.5..1e6 - 1e-3).contains(&scaled) {
            return None;
        }
        if scaled >= 1e6 {
            e += 1;
            continue;
        }
        let floor = scaled.floor();
        let frac = scaled - floor;
        // scaled < 2^20, so its rounding error is below 2^-32 ≈ 2.3e-10.
        if (frac - 0.5).abs() < 1e-9 {
            return None;
        }
        let mut m = floor as u32 + u32::from(frac > 0.5);
        if m >= 1_000_000 {
            m /= 10;
            e += 1;
        }
        if m < 100_000 {
            return None;
        }
        let mut d = [0u8; 6];
        for i in (0..6).rev() {
            d[i] = b'0' + (m % 10) as u8;
            m /= 10;
        }
        return Some((x < 0.0, e, d));
    }
    None
}

/// The same, exactly: Rust's `{:.5e}` rounds the exact binary value correctly (half to even on
/// exact ties), as glibc's printf does.
fn exact_digits(x: f64) -> (bool, i32, [u8; 6]) {
    let mut buf = [0u8; 32];
    let mut cur = std::io::Cursor::new(&mut buf[..]);
    write!(cur, "{:.5e}", x).expect("32 bytes hold any {:.5e}");
    let len = cur.position() as usize;
    let s = &buf[..len];
    let epos = s.iter().position(|&c| c == b'e').expect("exponent");
    let exp: i32 = std::str::from_utf8(&s[epos + 1..])
        .expect("ascii")
        .parse()
        .expect("exponent");
    let (neg, mant) = if s[0] == b'-' {
        (true, &s[1..epos])
    } else {
        (false, &s[..epos])
    };
    let mut digits = [0u8; 6];
    digits[0] = mant[0];
    digits[1..].copy_from_slice(&mant[2..7]);
    (neg, exp, digits)
}

/// `x` formatted as C's `%g`.
pub fn g(x: f64) -> String {
    let mut v = Vec::new();
    write_g(&mut v, x);
    String::from_utf8(v).expect("ascii")
}

#[cfg(test)]
mod tests {
    use super::g;

    #[test]
    fn matches_c_printf_g() {
        // Expected strings are what glibc's printf("%g") prints for these values.
        let cases: &[(f64, &str)] = &[
            (0.0, "0"),
            (1.0, "1"),
            (-12.0, "-12"),
            (0.5, "0.5"),
            (0.078, "0.078"),
            (100000.0, "100000"),
            (1000000.0, "1e+06"),
            (123456.7, "123457"),
            (1.11022302462516e-16, "1.11022e-16"),
            (0.0001, "0.0001"),
            (0.00001234, "1.234e-05"),
            (3.0827, "3.0827"),
            (0.272166, "0.272166"),
            (2.0 / 3.0, "0.666667"),
            (-0.0930784, "-0.0930784"),
            (999999.5, "1e+06"),
            (9.999995, "10"),
            (1e100, "1e+100"),
            (0.00350044, "0.00350044"),
        ];
        for (x, want) in cases {
            assert_eq!(g(*x), *want, "formatting {x:e}");
        }
    }

    #[test]
    fn fast_path_agrees_with_the_exact_one() {
        // Pseudo-random doubles over the ranges SPD prints, plus exact ties and their neighbours.
        let mut rng = fastrand::Rng::with_seed(0x9E3779B97F4A7C15);
        let mut next = || rng.u64(..);
        let mut checked = 0;
        for i in 0..400_000 {
            let r = next();
            let x = match i % 4 {
                0 => f64::from_bits(r),
                1 => (r as f64 / u64::MAX as f64 - 0.5) * 10f64.powi((r % 40) as i32 - 20),
                2 => ((r % 2_000_000) as f64 + 0.5) / 10f64.powi((r % 12) as i32),
                _ => f64::from_bits(((r % 2_000_000) as f64 * 0.5).to_bits() + (r >> 62) - 1),
            };
            if !x.is_finite() || x == 0.0 {
                continue;
            }
            if let Some(fast) = super::fast_digits(x) {
                assert_eq!(fast, super::exact_digits(x), "{x:e}");
                checked += 1;
            }
        }
        assert!(checked > 200_000, "fast path taken only {checked} times");
    }
}
