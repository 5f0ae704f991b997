//! `rtbench render`: the SPD workload for one scene and one engine.

use crate::cli::RenderArgs;
use crate::error::Result;
use crate::output::{print_json, write_atomic};
use crate::source::Source;
use crate::workload::{self, trace};
use serde_json::json;
use sha2::{Digest, Sha256};

pub fn run(a: &RenderArgs) -> Result<()> {
    workload::check_size(a.size)?;
    let settings = workload::parse_settings(&a.set)?;
    let src = Source::resolve(
        &a.scene.scene,
        a.scene.opts.sf,
        a.scene.opts.tessellate,
        a.scene.opts.hash,
    )?;
    let pool = workload::pool(a.threads)?;
    let prepared = workload::prepare(&src)?;
    let (engine, build_s) = workload::build(&a.engine, &prepared.input, settings)?;
    let r = pool.install(|| trace::render(&prepared.input.scene, engine.as_ref(), a.size, None));
    let pixels = r.pixels();
    let sha = hex(&Sha256::digest(&pixels));
    if let Some(png) = &a.png {
        write_atomic(png, |w| {
            image::write_buffer_with_format(
                w,
                &pixels,
                a.size,
                a.size,
                image::ExtendedColorType::Rgb8,
                image::ImageFormat::Png,
            )
            .map_err(std::io::Error::other)
        })?;
    }
    let scene = &prepared.input.scene;
    let g = &prepared.input.geometry;
    let v = json!({
        "engine": a.engine,
        "scene": {
            "name": src.label(),
            "program": src.program().map(|p| p.name()),
            "sf": src.size_factor(),
            "objects": scene.objects.len(),
            "primitives": g.prims.len(),
            "lights": scene.lights.len(),
        },
        "threads": pool.current_num_threads(),
        "rays": r.stats,
        "time_s": {
            "generate": prepared.generate_s,
            "preprocess": prepared.prepare_s + build_s,
            "build": build_s,
            "trace": r.trace_s,
            "intersect": r.intersect_s,
            "shade": r.shade_s,
        },
        "memory": {"structure_bytes": engine.structure_bytes(), "geometry_bytes": g.bytes(), "peak_rss_bytes": workload::peak_rss_bytes()},
        "counters": r.counters,
        "build_stats": engine.build_stats(),
        "image": {"width": a.size, "height": a.size, "sha256": sha},
    });
    if a.json {
        print_json(&v);
    } else {
        let s = &r.stats;
        println!(
            "{} on {}: {} rays in {:.3} s ({:.2} Mrays/s), build {:.3} s",
            a.engine,
            src.label(),
            s.total,
            r.trace_s,
            s.total as f64 / r.trace_s / 1e6,
            build_s
        );
        println!(
            "  eye {} (hit {}), reflect {}, refract {}, shadow {} (blocked {})",
            s.eye, s.eye_hit, s.reflect, s.refract, s.shadow, s.shadow_blocked
        );
    }
    Ok(())
}

pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
