//! What one `rtbench reproduce` invocation cost: wall and CPU seconds and the load average at its
//! start and end, kept in every reproduction's JSON (`invocation`) and stated under its document.
//!
//! Why: a time measured beside other work is only recognisable as such afterwards by CPU / wall
//! well under 100 % per thread, or by the load. The out-of-core ids keep both per run; the others
//! (Chapter 3's tables, 001–003) kept neither before. With `--resume` it is this invocation's
//! share of the work: rows loaded from the checkpoint cost nothing here.

use super::grid_runs::{cpu_share, load_average};
use super::Output;
use serde_json::{json, Value};
use std::time::Instant;

pub struct Invocation {
    t: Instant,
    cpu0: f64,
    load: String,
}

impl Invocation {
    pub fn start() -> Invocation {
        Invocation {
            t: Instant::now(),
            cpu0: crate::measure::clock::process_cpu_seconds(),
            load: load_average(),
        }
    }

    /// Adds the figures to `o`'s JSON and a sentence to its document.
    pub fn stamp(self, o: &mut Output, resumed: bool) {
        let wall_s = self.t.elapsed().as_secs_f64();
        let cpu_s = crate::measure::clock::process_cpu_seconds() - self.cpu0;
        let end = load_average();
        if let Value::Object(m) = &mut o.result {
            m.insert(
                "invocation".into(),
                json!({"wall_s": wall_s, "cpu_s": cpu_s, "load_average_start": self.load,
                       "load_average_end": end, "resumed": resumed}),
            );
        }
        o.doc.paragraph(format!(
            "This invocation: {wall_s:.1} s wall, {cpu_s:.1} s CPU over all threads (CPU / wall {}); load average {} at its start, {end} at its end{}.",
            cpu_share(cpu_s, wall_s),
            self.load,
            if resumed { " (resumed: rows taken from the checkpoint cost nothing here)" } else { "" },
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtbench_reports::Document;

    #[test]
    fn an_invocation_keeps_its_cpu_and_wall_seconds() {
        let inv = Invocation::start();
        // Burn some CPU so that the figures cannot both be zero.
        let mut x = 0u64;
        let t = Instant::now();
        while t.elapsed().as_millis() < 30 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(std::hint::black_box(1));
        }
        std::hint::black_box(x);
        let mut o = Output::new(json!({"id": "x"}), Vec::new(), Document::new("x"));
        inv.stamp(&mut o, false);
        let v = &o.result["invocation"];
        assert!(v["wall_s"].as_f64().unwrap() >= 0.03, "{v}");
        assert!(v["cpu_s"].as_f64().unwrap() > 0.0, "{v}");
        assert_eq!(v["resumed"], false);
        assert!(o.doc.to_markdown().contains("This invocation: "));
    }
}
