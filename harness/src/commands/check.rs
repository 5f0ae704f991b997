//! `rtbench check`: an engine's answers against Embree's or the reference engine's on the same
//! rays. The workload is traced once with the engine checked against, recording every query;
//! the engine under test answers exactly those queries. Its own render is compared as an image.
//!
//! A closest-hit query agrees when both miss, both name the same object, or both hit at the same
//! distance within 1e-5 relative (a tie between two objects meeting at the hit point). An
//! any-hit query agrees when both give the same answer.
//!
//! The t error of a hit on the same object is |t − t_ref| / max(t_ref, |origin|∞): relative to
//! the scale at which an `f32` engine can place a point at all. A secondary ray starting on a
//! surface at |origin| ≈ 1 that hits something at t = 0.001 cannot have its t right to better
//! than about 1e-7/0.001 = 1e-4 relative in single precision, however exact the kernel; dividing
//! by t alone would measure where rays start, not the engine. The plain |Δt|/t_ref is reported
//! too, as `t_rel_err_raw`.

use crate::cli::CheckArgs;
use crate::error::{Failure, Result};
use crate::output::print_json;
use crate::source::Source;
use crate::workload::{self, trace};
use rtbench_engines::{Counters, Hit};
use serde_json::json;

const TIE_REL: f32 = 1e-5;

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn psnr(a: &[u8], b: &[u8]) -> f64 {
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum::<f64>()
        / a.len().max(1) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

pub fn run(a: &CheckArgs) -> Result<()> {
    workload::check_size(a.size)?;
    if !(0.0..=1.0).contains(&a.threshold) {
        return Err(crate::error::input(format!(
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
    let scene = &prepared.input.scene;
    let (tested, _) = workload::build(&a.engine, &prepared.input, settings)?;
    let (yardstick, _) = workload::build(&a.against, &prepared.input, vec![])?;

    let mut rec = trace::Recording::default();
    let (want_img, got_img, got_closest, got_any) = pool.install(|| {
        let want = trace::render(scene, yardstick.as_ref(), a.size, Some(&mut rec));
        let got = trace::render(scene, tested.as_ref(), a.size, None);
        let rays: Vec<_> = rec.closest.iter().map(|(r, _)| *r).collect();
        let mut hits = vec![Hit::MISS; rays.len()];
        let mut c = Counters::default();
        use rayon::prelude::*;
        rays.par_chunks(4096)
            .zip(hits.par_chunks_mut(4096))
            .for_each(|(r, h)| tested.intersect(r, h, &mut Counters::default()));
        let srays: Vec<_> = rec.any.iter().map(|(r, _)| *r).collect();
        let mut occ = vec![false; srays.len()];
        srays
            .par_chunks(4096)
            .zip(occ.par_chunks_mut(4096))
            .for_each(|(r, o)| tested.occluded(r, o, &mut Counters::default()));
        let _ = &mut c;
        (want.pixels(), got.pixels(), hits, occ)
    });

    let mut agree = 0u64;
    let mut t_err = Vec::new();
    let mut t_err_raw = Vec::new();
    let mut mismatches = Vec::new();
    for (i, ((ray, want), got)) in rec.closest.iter().zip(&got_closest).enumerate() {
        let same = match (want.is_hit(), got.is_hit()) {
            (false, false) => true,
            (true, true) => {
                let rel = ((want.t - got.t).abs() / want.t.abs().max(f32::MIN_POSITIVE)) as f64;
                if want.object == got.object {
                    let scale = want
                        .t
                        .abs()
                        .max(ray.origin.abs().max_element())
                        .max(f32::MIN_POSITIVE);
                    t_err.push(((want.t - got.t).abs() / scale) as f64);
                    t_err_raw.push(rel);
                    true
                } else {
                    rel <= TIE_REL as f64
                }
            }
            _ => false,
        };
        if same {
            agree += 1;
        } else if mismatches.len() < 8 {
            mismatches.push(json!({"query": "closest", "index": i,
                "origin": ray.origin.to_array(), "dir": ray.dir.to_array(),
                "want": {"object": want.is_hit().then_some(want.object), "t": want.is_hit().then_some(want.t)},
                "got": {"object": got.is_hit().then_some(got.object), "t": got.is_hit().then_some(got.t)}}));
        }
    }
    for (i, ((ray, want), got)) in rec.any.iter().zip(&got_any).enumerate() {
        if want == got {
            agree += 1;
        } else if mismatches.len() < 8 {
            mismatches.push(
                json!({"query": "any", "index": i, "origin": ray.origin.to_array(),
                "dir": ray.dir.to_array(), "tmax": ray.tmax, "want": want, "got": got}),
            );
        }
    }
    let total = (rec.closest.len() + rec.any.len()) as u64;
    let agreement = agree as f64 / total.max(1) as f64;
    t_err.sort_by(|a, b| a.total_cmp(b));
    t_err_raw.sort_by(|a, b| a.total_cmp(b));
    let p = psnr(&want_img, &got_img);
    let v = json!({
        "engine": a.engine,
        "against": a.against,
        "scene": src.label(),
        "rays": total,
        "closest_rays": rec.closest.len(),
        "any_rays": rec.any.len(),
        "hit_agreement": agreement,
        "disagreements": total - agree,
        "t_rel_err": {"median": quantile(&t_err, 0.5), "p99": quantile(&t_err, 0.99), "max": t_err.last().copied().unwrap_or(0.0)},
        "t_rel_err_raw": {"median": quantile(&t_err_raw, 0.5), "p99": quantile(&t_err_raw, 0.99), "max": t_err_raw.last().copied().unwrap_or(0.0)},
        "image_psnr_db": if p.is_finite() { json!(p) } else { json!("inf") },
        "threshold": a.threshold,
        "pass": agreement >= a.threshold,
        "mismatches": mismatches,
    });
    if a.json {
        print_json(&v);
    } else {
        println!(
            "{} vs {} on {}: {} rays, agreement {:.6} ({} differ), t rel err p99 {:.2e} max {:.2e}, image PSNR {}",
            a.engine, a.against, src.label(), total, agreement, total - agree,
            quantile(&t_err, 0.99), t_err.last().copied().unwrap_or(0.0),
            if p.is_finite() { format!("{p:.1} dB") } else { "inf (identical)".into() }
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
