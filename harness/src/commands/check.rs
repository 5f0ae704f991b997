//! `rtbench check`: an engine's answers against Embree's or the reference engine's on the same
//! rays (see `workload/crosscheck.rs` for what agreement and t error mean); with `--suite`, the
//! hard-case and tessellation suites (`suite/`).

use crate::cli::CheckArgs;
use crate::error::{input, Failure, Result};
use crate::output::print_json;
use crate::source::Source;
use crate::suite;
use crate::workload::{self, crosscheck};
use serde_json::json;

pub fn run(a: &CheckArgs) -> Result<()> {
    if let Some(name) = &a.suite {
        return run_suite(a, name);
    }
    let scene = a
        .scene
        .as_deref()
        .ok_or_else(|| input("check: give --scene (or --suite hard|tessellation)"))?;
    let engine = a
        .engine
        .as_deref()
        .ok_or_else(|| input("check: give --engine"))?;
    if engine.contains(',') {
        return Err(input(format!(
            "--engine {engine}: one engine with --scene (lists are for --suite)"
        )));
    }
    if a.out.is_some() {
        return Err(input("--out applies to --suite only"));
    }
    let against = a.against.as_deref().unwrap_or("embree");
    let size = a.size.unwrap_or(512);
    let threshold = a.threshold.unwrap_or(0.9999);
    workload::check_size(size)?;
    if !(0.0..=1.0).contains(&threshold) {
        return Err(input(format!(
            "--threshold {threshold}: must be from 0 to 1"
        )));
    }
    let settings = workload::parse_settings(&a.set)?;
    workload::check_json_settings(a.json, &settings)?;
    let src = Source::from_args(scene, &a.opts)?;
    workload::check_scene_fits(&src, &[engine, against], a.opts.force)?;
    let pool = crate::measure::threads::pool(a.threads.count())?;
    let prepared = workload::prepare(&src)?;
    if let Some(w) = workload::precision_warning(&prepared.input.scene) {
        eprintln!("rtbench: warning: {w}");
    }
    let (tested, _) = workload::build(engine, &prepared.input, settings)?;
    let (yardstick, _) = workload::build(against, &prepared.input, vec![])?;
    let c = pool.install(|| {
        crosscheck::cross_check(
            &prepared.input.scene,
            tested.as_ref(),
            yardstick.as_ref(),
            size,
        )
    });
    if let Some(f) = tested.failure() {
        return Err(input(f));
    }
    let agreement = c.agreement();
    let primitive = c.primitive_agreement();
    let pass = agreement >= threshold && primitive >= crosscheck::MIN_PRIMITIVE_AGREEMENT;
    let v = json!({
        "engine": engine,
        "against": against,
        "scene": src.label(),
        "rays": c.rays(),
        "closest_rays": c.closest_rays,
        "any_rays": c.any_rays,
        "hit_agreement": agreement,
        "primitive_agreement": primitive,
        "disagreements": c.rays() - c.agree,
        "t_rel_err": c.t_rel_err.to_json(),
        "t_rel_err_raw": c.t_rel_err_raw.to_json(),
        "image_psnr_db": c.image_psnr_db.map(|p| json!(p)).unwrap_or(json!("inf")),
        "image_where_hits_agree": {
            "pixels": c.pixels_same_hits,
            "pixels_differing": c.pixels_same_hits_differing,
            "max_abs_diff": c.pixels_same_hits_max_diff,
        },
        "threshold": threshold,
        "pass": pass,
        "mismatches": c.mismatches,
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{} vs {} on {}: {} rays, agreement {:.6} ({} differ), primitive agreement {:.6}, t rel err p99 {:.2e} max {:.2e}, image PSNR {}",
            engine,
            against,
            src.label(),
            c.rays(),
            agreement,
            c.rays() - c.agree,
            primitive,
            c.t_rel_err.p99,
            c.t_rel_err.max,
            c.image_psnr_db.map(|p| format!("{p:.1} dB")).unwrap_or_else(|| "inf (identical)".into())
        );
    }
    if agreement < threshold {
        return Err(Failure::Check(format!(
            "{} vs {} on {}: hit agreement {:.6} is under the threshold {}",
            engine,
            against,
            src.label(),
            agreement,
            threshold
        )));
    }
    if primitive < crosscheck::MIN_PRIMITIVE_AGREEMENT {
        return Err(Failure::Check(format!(
            "{} vs {} on {}: primitive agreement {:.6} is under {} (hits at the right distance on the wrong object)",
            engine,
            against,
            src.label(),
            primitive,
            crosscheck::MIN_PRIMITIVE_AGREEMENT
        )));
    }
    Ok(())
}

/// `check --suite hard|tessellation [--engine a,b] [--out DIR] [--json]`.
fn run_suite(a: &CheckArgs, name: &str) -> Result<()> {
    let given = [
        ("--scene", a.scene.is_some()),
        ("--sf", a.opts.sf.is_some()),
        ("--tessellate", a.opts.tessellate.is_some()),
        ("--hash", a.opts.hash.is_some()),
        ("--set", !a.set.is_empty()),
        ("--against", a.against.is_some()),
        ("--threshold", a.threshold.is_some()),
        ("--size", a.size.is_some() && name != "tessellation"),
    ];
    if let Some((flag, _)) = given.iter().find(|(_, g)| *g) {
        return Err(input(format!(
            "{flag} does not apply to --suite {name} (the suite chooses its scenes, rays and settings)"
        )));
    }
    let engines = suite::engines(a.engine.as_deref())?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir)
            .map_err(|e| input(format!("--out {}: cannot create: {e}", dir.display())))?;
    }
    let pool = crate::measure::threads::pool(a.threads.count())?;
    match name {
        "hard" => {
            let probe = suite::probe_input();
            let variants = suite::variants(&engines, &probe)?;
            let h = pool.install(|| suite::hard::run(&variants))?;
            let (doc, json) = (suite::hard_document(&h), suite::hard_json(&h));
            suite_report(a, "hard", doc, &json, &suite::hard_charts(&h))?;
            suite::hard::verdict(&h)
        }
        "tessellation" => {
            let size = a.size.unwrap_or(128);
            workload::check_size(size)?;
            let t = pool.install(|| suite::tessellation::run(&engines, size))?;
            let (doc, json) = (suite::tess_document(&t), suite::tess_json(&t));
            suite_report(a, "tessellation", doc, &json, &suite::tess_charts(&t))
        }
        other => Err(input(format!(
            "--suite {other}: unknown suite (known: hard, tessellation)"
        ))),
    }
}

/// A suite's report: with `--out DIR`, `DIR/<stem>.md`, `.json`, `.html` and `DIR/plots/` through the
/// reproductions' writer; then the Markdown (or, with `--json`, the JSON) on stdout.
fn suite_report(
    a: &CheckArgs,
    stem: &str,
    mut doc: rtbench_reports::Document,
    json: &serde_json::Value,
    charts: &[rtbench_reports::plot::Chart],
) -> Result<()> {
    if let Some(dir) = &a.out {
        let stems = crate::reproduce::write_charts(dir, charts)?;
        if !stems.is_empty() {
            doc.heading("Plots");
            for s in stems {
                doc.figure(format!("plots/{s}.png"), s);
            }
        }
        crate::reproduce::write_document(dir, stem, &doc, json)?;
    }
    if a.json {
        print_json(json);
    } else {
        print!("{}", doc.to_markdown());
    }
    Ok(())
}
