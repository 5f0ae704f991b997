//! Where the ticks of a log axis go. plotters' own choice leaves a range inside one decade (a memory
//! plot from 14 to 28 MB, SF 3 to 6) with one label or none; these always give a few.

/// Ticks of a log axis over [lo, hi]: labelled ones at 1, 2, 5 or 1…9 times powers of ten (whichever
/// first gives three to twelve), every few decades on a wide range, evenly spaced round numbers on a range
/// too narrow for any of those; grid lines at 1…9 × 10^k.
pub fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    // Decades of the finite positive doubles only: an infinite or zero end made the range of
    // decades i32::MAX long (a report with a figure of 1e308 never ended).
    let decade = |x: f64, round: fn(f64) -> f64| {
        let d = round(x.log10());
        if d.is_nan() {
            0
        } else {
            d.clamp(-330.0, 310.0) as i32
        }
    };
    let (k0, k1) = (decade(lo, f64::floor), decade(hi, f64::ceil));
    let within = |mults: &[f64], step: i32| -> Vec<f64> {
        (k0..=k1)
            .filter(|k| (k - k0) % step == 0)
            // m / 10^−k, not m × 10^k, so that 0.3 is the double nearest 0.3
            .flat_map(|k| {
                mults.iter().map(move |m| {
                    if k < 0 {
                        m / 10f64.powi(-k)
                    } else {
                        m * 10f64.powi(k)
                    }
                })
            })
            .filter(|v| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9))
            .collect()
    };
    let all: Vec<f64> = (1..=9).map(f64::from).collect();
    let decades = k1 - k0;
    let light = if decades <= 8 {
        within(&all, 1)
    } else {
        within(&[1.0], 1)
    };
    let bold = [&[1.0][..], &[1.0, 2.0, 5.0][..], &all[..]]
        .into_iter()
        .map(|m| within(m, 1))
        .find(|t| (3..=12).contains(&t.len()));
    match bold {
        Some(b) => (b, light),
        None if decades > 10 => (within(&[1.0], (decades + 7) / 8), light),
        None => {
            let even = linear_ticks(lo, hi);
            (even.clone(), light.into_iter().chain(even).collect())
        }
    }
}

/// Round numbers (1, 2 or 5 × 10^k apart) over [lo, hi], about four of them.
fn linear_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let raw = (hi - lo) / 4.0;
    if !(raw > 0.0 && raw.is_finite()) {
        return vec![lo];
    }
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(raw);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

#[cfg(test)]
mod tests {
    use super::{linear_ticks, log_ticks};

    #[test]
    fn log_axis_ticks() {
        assert_eq!(log_ticks(0.015, 800.0).0, [0.1, 1.0, 10.0, 100.0]);
        assert_eq!(log_ticks(0.09, 0.35).0, [0.09, 0.1, 0.2, 0.3]);
        assert_eq!(log_ticks(0.09, 0.6).0, [0.1, 0.2, 0.5]);
        assert_eq!(log_ticks(13.0, 29.0).0, [15.0, 20.0, 25.0]);
        let wide = log_ticks(1e-30, 1.0).0;
        assert_eq!(wide.len(), 8, "every fourth decade: {wide:?}");
        assert!((wide[1] / wide[0] - 1e4).abs() < 1e-6);
        assert_eq!(linear_ticks(59.0, 62.5), [59.0, 60.0, 61.0, 62.0]);
        // Extreme ends end, with few ticks.
        for (lo, hi) in [
            (1e-3, f64::INFINITY),
            (0.0, 1e308),
            (f64::NAN, 1.0),
            (1e-300, 1e308),
        ] {
            let (bold, light) = log_ticks(lo, hi);
            assert!(bold.len() <= 100 && light.len() <= 1000, "{lo} {hi}");
        }
    }
}
