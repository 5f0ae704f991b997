//! `rtbench check`: an engine's answers against Embree's or the reference engine's on the same
//! rays (see `workload/crosscheck.rs` for what agreement and t error mean).

use crate::cli::CheckArgs;
use crate::error::{input, Failure, Result};
use crate::output::print_json;
use crate::source::Source;
use crate::workload::{self, crosscheck};
use serde_json::json;

pub fn run(a: &CheckArgs) -> Result<()> {
    workload::check_size(a.size)?;
    if !(0.0..=1.0).contains(&a.threshold) {
        return Err(input(format!(
            "--threshold {}: must be from 0 to 1",
            a.threshold
        )));
    }
    let settings = workload::parse_settings(&a.set)?;
    let src = Source::resolve(
        &a.scene.scene,
        a.scene.opts.sf,
        a.scene.opts.tessellate,
        a.scene.opts.hash,
    )?;
    let pool = workload::pool(a.threads)?;
    let prepared = workload::prepare(&src)?;
    let (tested, _) = workload::build(&a.engine, &prepared.input, settings)?;
    let (yardstick, _) = workload::build(&a.against, &prepared.input, vec![])?;
    let c = pool.install(|| {
        crosscheck::cross_check(
            &prepared.input.scene,
            tested.as_ref(),
            yardstick.as_ref(),
            a.size,
        )
    });
    if let Some(f) = tested.failure() {
        return Err(input(f));
    }
    let agreement = c.agreement();
    let v = json!({
        "engine": a.engine,
        "against": a.against,
        "scene": src.label(),
        "rays": c.rays(),
        "closest_rays": c.closest_rays,
        "any_rays": c.any_rays,
        "hit_agreement": agreement,
        "disagreements": c.rays() - c.agree,
        "t_rel_err": c.t_rel_err.to_json(),
        "t_rel_err_raw": c.t_rel_err_raw.to_json(),
        "image_psnr_db": c.image_psnr_db.map(|p| json!(p)).unwrap_or(json!("inf")),
        "image_where_hits_agree": {
            "pixels": c.pixels_same_hits,
            "pixels_differing": c.pixels_same_hits_differing,
            "max_abs_diff": c.pixels_same_hits_max_diff,
        },
        "threshold": a.threshold,
        "pass": agreement >= a.threshold,
        "mismatches": c.mismatches,
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{} vs {} on {}: {} rays, agreement {:.6} ({} differ), t rel err p99 {:.2e} max {:.2e}, image PSNR {}",
            a.engine,
            a.against,
            src.label(),
            c.rays(),
            agreement,
            c.rays() - c.agree,
            c.t_rel_err.p99,
            c.t_rel_err.max,
            c.image_psnr_db.map(|p| format!("{p:.1} dB")).unwrap_or_else(|| "inf (identical)".into())
        );
    }
    if agreement < a.threshold {
        return Err(Failure::Check(format!(
            "{} vs {} on {}: hit agreement {:.6} is under the threshold {}",
            a.engine,
            a.against,
            src.label(),
            agreement,
            a.threshold
        )));
    }
    Ok(())
}
