//! `results.csv`: one row per run (failed ones too), flat columns, for spreadsheets and scripts.
//! Raw figures, unrounded; counters get one column each (`counter.<name>`), empty where a run has none.

use crate::anchor::Anchors;
use crate::results::RunRecord;
use std::collections::BTreeSet;

const FIXED: &[&str] = &[
    "key",
    "status",
    "reason",
    "engine",
    "settings",
    "scene",
    "program",
    "sf",
    "tessellate",
    "objects",
    "primitives",
    "threads",
    "repeats",
    "size",
    "rays_total",
    "generate_s",
    "build_s_min",
    "build_s_median",
    "build_s_max",
    "trace_s_min",
    "trace_s_median",
    "trace_s_max",
    "intersect_s_median",
    "shade_s_median",
    "mrays_per_s",
    "ratio_to_embree",
    "structure_bytes",
    "structure_bytes_per_primitive",
    "peak_rss_bytes",
    "check_against",
    "hit_agreement",
    "t_rel_err_median",
    "t_rel_err_p99",
    "t_rel_err_max",
    "image_psnr_db",
    "image_sha256",
    "wall_s",
    "finished_at",
];

/// The CSV text of `records` (one record per key, as the report uses them).
pub fn results(records: &[RunRecord]) -> String {
    let anchors = Anchors::of(records);
    let counters: BTreeSet<&str> = records
        .iter()
        .flat_map(|r| r.counters.keys().map(String::as_str))
        .collect();
    let mut out = ::csv::Writer::from_writer(Vec::new());
    let header: Vec<String> = FIXED
        .iter()
        .map(|h| h.to_string())
        .chain(counters.iter().map(|c| format!("counter.{c}")))
        .collect();
    out.write_record(&header).expect("writing to memory");
    for r in records {
        let opt = |v: Option<String>| v.unwrap_or_default();
        let settings: Vec<String> = r.settings.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let c = r.check.as_ref();
        let mut cells = vec![
            r.key.clone(),
            r.status.clone(),
            opt(r.reason.clone()),
            r.engine.clone(),
            settings.join(";"),
            r.scene.name.clone(),
            opt(r.scene.program.clone()),
            opt(r.scene.sf.map(|v| v.to_string())),
            opt(r.scene.tessellate.map(|v| v.to_string())),
            r.scene.objects.to_string(),
            r.scene.primitives.to_string(),
            r.threads.to_string(),
            r.repeats.to_string(),
            r.size.to_string(),
            r.rays_total.to_string(),
            r.time_s.generate.to_string(),
            r.time_s.build.min.to_string(),
            r.time_s.build.median.to_string(),
            r.time_s.build.max.to_string(),
            r.time_s.trace.min.to_string(),
            r.time_s.trace.median.to_string(),
            r.time_s.trace.max.to_string(),
            r.time_s.intersect.median.to_string(),
            r.time_s.shade.median.to_string(),
            r.mrays_per_s.to_string(),
            opt(anchors.ratio(r).map(|v| v.to_string())),
            r.structure_bytes.to_string(),
            opt((r.scene.primitives > 0)
                .then(|| (r.structure_bytes as f64 / r.scene.primitives as f64).to_string())),
            r.peak_rss_bytes.to_string(),
            opt(c.map(|c| c.against.clone())),
            opt(c.map(|c| c.hit_agreement.to_string())),
            opt(c.map(|c| c.t_rel_err_median.to_string())),
            opt(c.map(|c| c.t_rel_err_p99.to_string())),
            opt(c.map(|c| c.t_rel_err_max.to_string())),
            opt(c.and_then(|c| c.image_psnr_db).map(|v| v.to_string())),
            opt(r.image_sha256.clone()),
            r.wall_s.to_string(),
            r.finished_at.clone(),
        ];
        cells.extend(
            counters
                .iter()
                .map(|name| opt(r.counters.get(*name).map(|v| v.to_string()))),
        );
        out.write_record(&cells).expect("writing to memory");
    }
    String::from_utf8(out.into_inner().expect("writing to memory")).expect("the cells are text")
}

#[cfg(test)]
mod tests {
    /// RFC 4180 through the `csv` crate: a field with a comma, quote or line break (`\n` or
    /// `\r`) is quoted, its quotes doubled.
    #[test]
    fn quoting() {
        let mut w = ::csv::Writer::from_writer(Vec::new());
        w.write_record(["grid[a=1,b=2]/balls4@1", "say \"hi\"", "plain", "a\rb", ""])
            .unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(
            text,
            "\"grid[a=1,b=2]/balls4@1\",\"say \"\"hi\"\"\",plain,\"a\rb\",\n"
        );
    }
}
