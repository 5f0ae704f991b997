//! sombrero, ported from SPD 3.14's sombrero.c (Alexander Enzmann, Eduard Schwan): a height
//! field of the damped cosine `cos(2 pi r) e^-r` on a `w x w` grid, `w = 32 * 2^(SF-1)`, which NFF
//! gets as `2 (w-1)^2` triangles (`lib_output_height` → `lib_output_polygon_height`).
//!
//! C quirks kept: the samples are `float`s; they are taken every `8 / w` from -4 (so the last
//! sample is at 4 - 8/w) but laid out every `8 / (w-1)` from -4 to 4; the accumulating `x += dx`,
//! `y += dy` loops are reproduced. The C computes `w` in `int`, which overflows from SF 27 on
//! (undefined behaviour); we use the mathematical value. The C holds the whole grid in memory;
//! we stream it row by row.

use super::Output;

/// Grid width (and height) of sombrero.c: `32 * (1 << (size_factor - 1))`.
fn grid_width(size_factor: u64) -> Option<u64> {
    let shift = u32::try_from(size_factor.checked_sub(1)?).ok()?;
    1u64.checked_shl(shift)
        .filter(|v| v.leading_zeros() >= 5)?
        .checked_mul(32)
}

/// Triangles: 2 (w-1)^2.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let w = grid_width(size_factor)?;
    let cells = (w - 1).checked_mul(w - 1)?;
    cells.checked_mul(2)
}

/// The C `main` after option parsing.
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    // sombrero.c sets the polygonalization (unused by height fields in NFF).
    out.set_polygonalization(3, 3);
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [0.0, 5.0, -8.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        40.0,
        1.0,
        0.01,
        512,
        512,
    );
    out.light([10.0, 10.0, -10.0, 1.0]);
    // Shiny red.
    out.color([1.0, 0.1, 0.1], 0.1, 0.8, 0.0, 0.5, 40.0, 0.0, 1.0);

    let Some(w) = grid_width(size_factor as u64) else {
        return;
    };
    let width = w as usize;
    let height = width;
    let (x0, x1, y0, y1) = (-4.0, 4.0, -4.0, 4.0);
    let mut rows = SombreroRows::new(width, height, x0, x1, y0, y1);
    out.height(
        width,
        height,
        &mut |i, row| rows.fill(i, row),
        -4.0,
        4.0,
        -3.0,
        3.0,
        -4.0,
        4.0,
    );
}

/// sombrero.c `create_sombrero`, one row at a time (rows must be asked for in order).
struct SombreroRows {
    width: usize,
    next_row: usize,
    x0: f64,
    deltax: f64,
    deltay: f64,
    y: f64,
    two_pi_a: f64,
}

impl SombreroRows {
    // sombrero.c's own truncated pi, 3.14159265358, not PI.
    #[allow(clippy::approx_constant)]
    fn new(width: usize, height: usize, x0: f64, x1: f64, y0: f64, y1: f64) -> SombreroRows {
        let a_const = 1.0;
        SombreroRows {
            width,
            next_row: 0,
            x0,
            deltax: (x1 - x0) / width as f64,
            deltay: (y1 - y0) / height as f64,
            y: y0,
            two_pi_a: 2.0 * 3.14159265358 * a_const,
        }
    }

    fn fill(&mut self, i: usize, row: &mut [f32]) {
        assert_eq!(i, self.next_row, "sombrero rows are generated in order");
        let (b_const, c_const) = (1.0, 3.0);
        let y = self.y;
        let mut x = self.x0;
        for v in row.iter_mut().take(self.width) {
            let r = (x * x + y * y).sqrt();
            *v = (c_const * (self.two_pi_a * r).cos() * (-b_const * r).exp() / 3.0) as f32;
            x += self.deltax;
        }
        self.y += self.deltay;
        self.next_row += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, Output};

    #[test]
    fn object_counts() {
        assert_eq!(object_count(1), Some(2 * 31 * 31));
        assert_eq!(object_count(2), Some(2 * 63 * 63));
        assert_eq!(object_count(4), Some(2 * 255 * 255));
        assert_eq!(
            object_count(27),
            Some(2 * ((1u64 << 31) - 1) * ((1u64 << 31) - 1))
        );
        assert_eq!(object_count(28), None);
        assert_eq!(object_count(0), None);
    }

    #[test]
    fn generated_counts_match() {
        for sf in 1..=3 {
            let mut sink = CountingSink::default();
            generate(&mut Output::new(&mut sink, CurveFormat::Curves, 3), sf);
            assert_eq!(sink.counts.polygon, object_count(sf as u64).unwrap());
        }
    }
}
