//! `rtbench tree-stats`: 001's node statistics (node counts, leaf depths, Eq. 3.3 memory) of a
//! BVH of any of 001's branching factors, 2 to 16, without tracing. The engines traverse widths
//! 2, 4 and 8; 001's tables go to 16.

use crate::cli::TreeStatsArgs;
use crate::error::{input, Result};
use crate::output::print_json;
use crate::source::Source;
use crate::workload;
use rtbench_engines::bvh::{config::Config, tree_statistics};
use rtbench_engines::Settings;
use serde_json::json;
use std::collections::BTreeMap;

pub fn run(a: &TreeStatsArgs) -> Result<()> {
    let settings = workload::parse_settings(&a.set)?;
    // Statistics only: no SIMD traversal or leaf packets are made, whatever the width.
    let mut pairs = vec![
        ("simd".to_string(), "off".to_string()),
        ("packets".to_string(), "off".to_string()),
    ];
    pairs.retain(|(k, _)| !settings.iter().any(|(s, _)| s == k));
    pairs.extend(settings);
    let config = Config::parse(a.width, Settings::new(&format!("bvh{}", a.width), pairs))
        .map_err(|e| input(e.to_string()))?;
    let src = Source::from_args(&a.scene.scene, &a.scene.opts)?;
    workload::check_scene_fits(&src, &[&format!("bvh{}", a.width)], a.scene.opts.force)?;
    let prepared = workload::prepare(&src)?;
    let g = &prepared.input.geometry;
    if g.prims.is_empty() {
        return Err(input(format!(
            "{}: the scene has no primitives",
            src.label()
        )));
    }
    let (s, build_s) = tree_statistics(g, &config);
    let mut stats = BTreeMap::new();
    s.insert_into(&mut stats);
    stats.insert("build_s".into(), build_s);
    if a.json {
        print_json(&json!({
            "scene": src.label(),
            "primitives": g.prims.len(),
            "width": a.width,
            "builder": config.builder.name(),
            "wide": format!("{:?}", config.wide).to_lowercase(),
            "leaf": config.leaf,
            "stats": stats,
        }));
        return Ok(());
    }
    println!(
        "{} ({} primitives), N = {}, builder {}, wide {:?}, leaf {}",
        src.label(),
        g.prims.len(),
        a.width,
        config.builder.name(),
        config.wide,
        config.leaf
    );
    for (k, v) in &stats {
        println!("  {k:<26} {v}");
    }
    Ok(())
}
