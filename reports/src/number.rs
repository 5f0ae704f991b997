//! How numbers are written in tables and on axes: a few significant figures, never a wall of digits.

/// `x` to `sig` significant figures, keeping significant zeros (`0.290`, `2.00`) and without an exponent
/// in the range tables use (1e-4 ≤ |x| < 1e6); outside it, `1.23e-5`. Integers wider than `sig` digits
/// keep all their digits (`1235`).
pub fn sig(x: f64, sig: usize) -> String {
    if !x.is_finite() {
        return if x.is_nan() {
            "–".to_string()
        } else if x > 0.0 {
            "∞".to_string()
        } else {
            "−∞".to_string()
        };
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let sig = sig.max(1);
    let ax = x.abs();
    if !(1e-4..1e6).contains(&ax) {
        return format!("{:.*e}", sig - 1, x);
    }
    let magnitude = ax.log10().floor() as i32;
    let decimals = (sig as i32 - 1 - magnitude).max(0) as usize;
    let s = format!("{:.*}", decimals, x);
    // Rounding may carry into a new digit (9.996 → 10.00): one decimal fewer then.
    let carried = s
        .parse::<f64>()
        .is_ok_and(|r| r.abs() >= 10f64.powi(magnitude + 1));
    if carried && decimals > 0 {
        format!("{:.*}", decimals - 1, x)
    } else {
        s
    }
}

/// Like [`sig`], without trailing zeros after the point (`0.29`, `2`): for axis ticks.
pub fn short(x: f64, sig_digits: usize) -> String {
    let s = sig(x, sig_digits);
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{}", trim_zeros(m), e),
        None => trim_zeros(&s),
    }
}

fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// Seconds, 3 significant figures.
pub fn seconds(s: f64) -> String {
    sig(s, 3)
}

/// Bytes as MB (10^6 bytes), 3 significant figures; small sizes keep their digits (0.0123).
pub fn megabytes(bytes: u64) -> String {
    sig(bytes as f64 / 1e6, 3)
}

/// A ratio such as trace time over Embree's: two decimals near 1, three significant figures elsewhere.
pub fn ratio(r: f64) -> String {
    if (0.1..100.0).contains(&r) {
        format!("{r:.2}")
    } else {
        sig(r, 3)
    }
}

/// Hit agreement in percent. Never rounds a disagreement away: 0.9999996 is `>99.9999%`, not `100%`.
pub fn agreement(a: f64) -> String {
    if a >= 1.0 {
        return "100%".to_string();
    }
    let pct = a * 100.0;
    let s = format!("{pct:.4}");
    if s == "100.0000" {
        return ">99.9999%".to_string();
    }
    format!("{}%", trim_zeros(&s))
}

/// PSNR in dB; identical images have none (infinite).
pub fn psnr(db: Option<f64>) -> String {
    match db {
        Some(d) => format!("{d:.1}"),
        None => "∞".to_string(),
    }
}

/// Axis tick labels: short, exponent only where plain digits would be long.
pub fn axis(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    let av = v.abs();
    if (1e-3..1e5).contains(&av) {
        short(v, 3)
    } else {
        let s = format!("{v:.1e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim_zeros(m)),
            None => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_figures() {
        assert_eq!(sig(0.0012345, 3), "0.00123");
        assert_eq!(sig(12.345, 3), "12.3");
        assert_eq!(sig(1234.6, 3), "1235");
        assert_eq!(sig(2.0, 3), "2.00");
        assert_eq!(sig(0.2899999, 3), "0.290");
        assert_eq!(sig(9.9996, 3), "10.0");
        assert_eq!(sig(0.09996, 3), "0.100");
        assert_eq!(sig(1.5e-5, 3), "1.50e-5");
        assert_eq!(short(1.5e-5, 3), "1.5e-5");
        assert_eq!(short(0.2899999, 3), "0.29");
        assert_eq!(sig(-0.25, 2), "-0.25");
        assert_eq!(sig(f64::NAN, 3), "–");
    }

    #[test]
    fn agreement_never_rounds_to_whole() {
        assert_eq!(agreement(1.0), "100%");
        assert_eq!(agreement(0.99995), "99.995%");
        assert_eq!(agreement(0.9999999), ">99.9999%");
        assert_eq!(agreement(0.5), "50%");
    }

    #[test]
    fn ratios_megabytes_axis() {
        assert_eq!(ratio(1.0), "1.00");
        assert_eq!(ratio(2.345), "2.35");
        assert_eq!(ratio(0.01234), "0.0123");
        assert_eq!(megabytes(12_345_678), "12.3");
        assert_eq!(megabytes(0), "0");
        assert_eq!(axis(1e-6), "1e-6");
        assert_eq!(axis(0.5), "0.5");
        assert_eq!(axis(200000.0), "2e5");
        assert_eq!(psnr(None), "∞");
        assert_eq!(psnr(Some(41.26)), "41.3");
    }
}
