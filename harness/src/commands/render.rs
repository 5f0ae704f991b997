//! `rtbench render`: the SPD workload for one scene and one engine.

use crate::cli::RenderArgs;
use crate::error::{input, Result};
use crate::measure::memory;
use crate::output::{hex, print_json, write_png};
use crate::shard::{Manifest, ShardSpec};
use crate::source::Source;
use crate::workload::{self, trace};
use serde_json::json;
use sha2::{Digest, Sha256};

pub fn run(a: &RenderArgs) -> Result<()> {
    workload::check_size(a.size)?;
    let settings = workload::parse_settings(&a.set)?;
    workload::check_json_settings(a.json, &settings)?;
    let store = std::path::Path::new(&a.scene.scene);
    if store.join(rtbench_engines::store::HEADER_FILE).is_file() {
        return run_store(a, store, settings);
    }
    if a.tile.is_some() {
        return Err(input(format!(
            "--tile: tiles split the out-of-core render of a scene store (breadth-first); {} is not a store",
            a.scene.scene
        )));
    }
    let src = Source::from_args(&a.scene.scene, &a.scene.opts)?;
    workload::check_scene_fits(&src, &[&a.engine], a.scene.opts.force)?;
    let pool = crate::measure::threads::pool(a.threads.count())?;
    memory::phase("start");
    let prepared = workload::prepare(&src)?;
    if let Some(w) = workload::precision_warning(&prepared.input.scene) {
        eprintln!("rtbench: warning: {w}");
    }
    memory::phase("scene");
    let (engine, build_s) = workload::build(&a.engine, &prepared.input, settings)?;
    memory::phase("build");
    // What the output reports of the geometry, read before it is let go: the trace shades from
    // the scene (materials, lights, view) and asks the engine; engines that answer from the
    // prepared primitives keep their own reference to them.
    let (generate_s, prepare_s) = (prepared.generate_s, prepared.prepare_s);
    let (primitives, geometry_bytes) = (
        prepared.input.geometry.prims.len(),
        prepared.input.geometry.bytes(),
    );
    let scene = prepared.input.scene;
    drop(prepared.input.geometry);
    memory::release_free_heap();
    memory::phase("release");
    let r = pool
        .install(|| trace::render_chunked(&scene, engine.as_ref(), a.size, a.chunk, false, None));
    memory::phase("trace");
    if let Some(f) = engine.failure() {
        return Err(input(f));
    }
    let pixels = r.pixels();
    // A run the pass cap stopped (`max_passes`) has no image: the rays left were not traced.
    let capped = crate::workload::out_of_core::pass_capped(&r.counters);
    let sha = (!capped).then(|| hex(&Sha256::digest(pixels)));
    if capped {
        eprintln!("render: the pass cap (max_passes) stopped the run: its counters and times are its first passes'; no image");
    } else if let Some(png) = &a.png {
        write_png(png, pixels, a.size)?;
    }
    let v = json!({
        "engine": a.engine,
        "scene": {
            "name": src.label(),
            "program": src.program().map(|p| p.name()),
            "sf": src.size_factor(),
            "objects": scene.objects.len(),
            "primitives": primitives,
            "lights": scene.lights.len(),
        },
        "threads": pool.current_num_threads(),
        "chunk": a.chunk,
        "rays": r.stats,
        "time_s": {
            "generate": generate_s,
            "preprocess": prepare_s + build_s,
            "build": build_s,
            "trace": r.trace_s,
            "intersect": r.intersect_s,
            "shade": r.shade_s,
        },
        "memory": {"structure_bytes": engine.structure_bytes(), "geometry_bytes": geometry_bytes, "peak_rss_bytes": crate::measure::rss::peak_rss_bytes()},
        "counters": r.counters,
        "build_stats": engine.build_stats(),
        "image": {"width": a.size, "height": a.size, "sha256": sha, "incomplete": capped},
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

/// The manifest of one tile of a store's render: the plan is the store (its header's SHA-256), the
/// image size and the engine's settings.
fn tile_manifest(
    dir: &std::path::Path,
    spec: ShardSpec,
    size: u32,
    settings: &[(String, String)],
) -> Result<Manifest> {
    let header = dir.join(rtbench_engines::store::HEADER_FILE);
    let bytes = std::fs::read(&header)
        .map_err(|e| input(format!("{}: cannot read: {e}", header.display())))?;
    let mut s = settings.to_vec();
    s.sort();
    let text = format!(
        "tile store {} size {size} settings {s:?}",
        hex(&Sha256::digest(&bytes))
    );
    let plan: Vec<String> = (1..=spec.n)
        .map(|k| format!("tile {k}/{}", spec.n))
        .collect();
    let mut m = Manifest::new(
        "tile",
        spec,
        &text,
        plan,
        vec![format!("tile {}/{}", spec.k, spec.n)],
    );
    m.extra
        .insert("store".into(), dir.display().to_string().into());
    Ok(m)
}

/// `rtbench render --scene STORE_DIR --engine breadth-first`: the out-of-core workload
/// ([`workload::out_of_core`]); the scene is never loaded.
fn run_store(a: &RenderArgs, dir: &std::path::Path, settings: Vec<(String, String)>) -> Result<()> {
    use rtbench_engines::breadth_first::{config::BreadthFirstConfig, BreadthFirst};
    let o = &a.scene.opts;
    if o.sf.is_some() || o.tessellate.is_some() || o.hash.is_some() {
        return Err(input(format!(
            "{}: a scene store is fixed; --sf, --tessellate and --hash apply to programs",
            dir.display()
        )));
    }
    if a.engine != "breadth-first" {
        return Err(input(format!(
            "{}: a scene store is traced by the breadth-first engine only, not '{}'",
            dir.display(),
            a.engine
        )));
    }
    let tile = a
        .tile
        .as_deref()
        .map(|t| ShardSpec::parse(t, "--tile"))
        .transpose()?;
    let t = std::time::Instant::now();
    let config = BreadthFirstConfig::from_settings(rtbench_engines::Settings::new(
        "breadth-first",
        settings.clone(),
    ))?;
    let engine = BreadthFirst::open(dir, config)?;
    let build_s = t.elapsed().as_secs_f64();
    let mut manifest = match (tile, &a.out) {
        (Some(spec), Some(out)) => {
            let m = tile_manifest(dir, spec, a.size, &settings)?;
            m.write(out)?;
            Some((m, out.clone(), spec))
        }
        _ => None,
    };
    let ooc = workload::out_of_core::render_tile(&engine, a.size, tile)
        .map_err(|e| input(format!("{}: out-of-core render: {e}", dir.display())))?;
    if let Some((m, out, spec)) = manifest.as_mut() {
        let r = &ooc.render;
        let w = a.size as usize + 1;
        let corners = workload::tiles::rows(*spec, a.size)
            .into_iter()
            .flat_map(|j| r.corners[j as usize * w..(j as usize + 1) * w].to_vec())
            .collect();
        let io = serde_json::to_value(ooc.io)
            .ok()
            .and_then(|v| serde_json::from_value(v).ok())
            .unwrap_or_default();
        let counters = crate::runs::one::flatten_counters(&r.counters);
        let t = workload::tiles::TileOutput {
            size: a.size,
            store: dir.display().to_string(),
            rays: r.stats.clone(),
            counters,
            io,
            preprocess_s: build_s,
            trace_s: r.trace_s,
            intersect_s: r.intersect_s,
            shade_s: r.shade_s,
            peak_rss_bytes: crate::measure::rss::peak_rss_bytes(),
            corners,
        };
        t.write(out)?;
        m.finished_at = Some(crate::measure::environment::now_utc());
        m.write(out)?;
        eprintln!(
            "render: tile {}/{} of {}: {} rays in {:.3} s into {}",
            spec.k,
            spec.n,
            dir.display(),
            r.stats.total,
            r.trace_s,
            out.display()
        );
    }
    let r = &ooc.render;
    let pixels = r.pixels();
    // A run the pass cap stopped (`max_passes`) has no image: the rays left were not traced.
    let capped = crate::workload::out_of_core::pass_capped(&r.counters);
    let sha = (!capped).then(|| hex(&Sha256::digest(pixels)));
    if capped {
        eprintln!("render: the pass cap (max_passes) stopped the run: its counters and times are its first passes'; no image");
    } else if let Some(png) = &a.png {
        write_png(png, pixels, a.size)?;
    }
    let h = engine.header();
    let v = json!({
        "engine": a.engine,
        "scene": {
            "name": h.name,
            "store": dir.display().to_string(),
            "objects": h.objects,
            "primitives": h.primitives,
            "lights": h.lights.len(),
        },
        "threads": 1,
        "rays": r.stats,
        "time_s": {
            "preprocess": build_s,
            "build": build_s,
            "trace": r.trace_s,
            "intersect": r.intersect_s,
            "shade": r.shade_s,
        },
        "memory": {"structure_bytes": rtbench_engines::Engine::structure_bytes(&engine),
                   "peak_rss_bytes": crate::measure::rss::peak_rss_bytes()},
        "counters": r.counters,
        "io": {"workload": ooc.io},
        "shading": {"group_rays": ooc.shade_group, "store_sweeps": ooc.shade_sweeps, "cap_rays": ooc.shade_cap},
        "build_stats": rtbench_engines::Engine::build_stats(&engine),
        "image": {"width": a.size, "height": a.size, "sha256": sha, "incomplete": capped},
    });
    if a.json {
        print_json(&v);
    } else {
        let s = &r.stats;
        println!(
            "{} on store {}: {} rays in {:.3} s, preprocess {:.3} s, peak RSS {:.1} MiB",
            a.engine,
            dir.display(),
            s.total,
            r.trace_s,
            build_s,
            crate::measure::rss::peak_rss_bytes().unwrap_or(0) as f64 / 1048576.0
        );
    }
    Ok(())
}
