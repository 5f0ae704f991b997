//! `rtbench history export`: every metric of every night as CSV, or one night in Bencher Metric
//! Format (BMF) JSON, `{"benchmark": {"measure": {"value", "lower_value", "upper_value"}}}`, for
//! teams that keep a hosted dashboard.
//!
//! A metric's name is `subject/measure` (the measure after the last `/`): `grid tetra2@1/time_ratio`,
//! `grid tetra2@1/counter.prim_tests`, `bvh4 tetra1/instructions`, `kernels/sphere/criterion_ns`.

use super::{History, Metric};
use crate::error::Result;
use serde_json::{json, Map, Value};

/// Every night's metrics, one line per (night, metric), with the samples' min and max. Every
/// field goes through the `csv` crate's quoting (a name or suite with a comma, quote or line
/// break stays one field).
pub fn csv(h: &History) -> Result<String> {
    let mut out = ::csv::Writer::from_writer(Vec::new());
    let mem = "writing CSV to memory";
    out.write_record([
        "run_id",
        "started_at",
        "git_commit",
        "fingerprint",
        "suite",
        "metric",
        "kind",
        "unit",
        "value",
        "gated",
        "samples",
        "min",
        "max",
    ])
    .expect(mem);
    for r in h.runs(None, None)? {
        for m in h.metrics(r.id)? {
            let (lo, hi) = range(&m);
            out.write_record([
                r.id.to_string(),
                r.started_at.clone(),
                r.git_commit.clone(),
                crate::output::head(&r.fingerprint, 16).to_string(),
                r.suite.clone(),
                m.name.clone(),
                m.kind.clone(),
                m.unit.clone(),
                m.value.to_string(),
                u8::from(m.gated).to_string(),
                m.samples.len().to_string(),
                lo.map(|v| v.to_string()).unwrap_or_default(),
                hi.map(|v| v.to_string()).unwrap_or_default(),
            ])
            .expect(mem);
        }
    }
    Ok(String::from_utf8(out.into_inner().expect(mem)).expect("the fields are text"))
}

fn range(m: &Metric) -> (Option<f64>, Option<f64>) {
    let lo = m.samples.iter().copied().reduce(f64::min);
    let hi = m.samples.iter().copied().reduce(f64::max);
    (lo, hi)
}

/// One night in Bencher Metric Format.
pub fn bmf(metrics: &[Metric]) -> Value {
    let mut out = Map::new();
    for m in metrics {
        let (bench, measure) = m.name.rsplit_once('/').unwrap_or((&m.name, &m.kind));
        let mut v = Map::new();
        v.insert("value".into(), json!(m.value));
        let (lo, hi) = range(m);
        if let (Some(lo), Some(hi)) = (lo, hi) {
            v.insert("lower_value".into(), json!(lo));
            v.insert("upper_value".into(), json!(hi));
        }
        let entry = out
            .entry(bench.to_string())
            .or_insert_with(|| Value::Object(Map::new()));
        if let Value::Object(o) = entry {
            o.insert(measure.to_string(), Value::Object(v));
        }
    }
    Value::Object(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bmf_splits_the_measure_off_the_name_and_bounds_by_the_samples() {
        let m = Metric {
            name: "kernels/sphere/criterion_ns".into(),
            kind: "criterion".into(),
            unit: "ns".into(),
            value: 2.0,
            gated: false,
            samples: vec![1.0, 3.0],
        };
        let v = bmf(&[m]);
        assert_eq!(v["kernels/sphere"]["criterion_ns"]["value"], json!(2.0));
        assert_eq!(
            v["kernels/sphere"]["criterion_ns"]["lower_value"],
            json!(1.0)
        );
        assert_eq!(
            v["kernels/sphere"]["criterion_ns"]["upper_value"],
            json!(3.0)
        );
    }
}
