//! Runs shared by `nakamaru-4.2` and `nakamaru-fig4.4` (seed 000 §4.3–4.4): a scene written once
//! as a split store, then traced out of core by the improved method (S+G+B) with a given grid
//! (`grid=single cap=N`, the thesis's "-l"; `grid=two-level`, the high-resolution grid), each run
//! with its peak RSS reset, its load average, its exact counters and its image hash.

use crate::error::{input, Result};
use crate::output::hex;
use crate::source::Source as SceneSource;
use crate::workload::out_of_core;
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::store::{Codec, Layout, StoreHeader, StoreWriter};
use rtbench_engines::{Engine, Settings};
use rtbench_scenes::spd::MountHash;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::Path;

/// One traced run.
#[derive(Serialize, Deserialize, Default, Clone, Debug)]
pub struct GridRun {
    /// The settings beyond the common ones (`grid=…`).
    pub settings: Vec<(String, String)>,
    pub preprocess_s: f64,
    pub trace_s: f64,
    pub passes: u64,
    pub sha256: String,
    pub peak_rss_bytes: u64,
    /// Cells per axis of the grid rays were registered in, and its levels' shape.
    pub res: [u64; 3],
    pub levels: u64,
    pub upper: [u64; 3],
    pub lower: u64,
    /// Exact counters: voxels walked, ray–box tests, registrations (lower / direct), lower
    /// grids used summed over passes, direct registrations a box's range check turned away,
    /// grid bytes and seeks of the block traversals, subspaces of preprocessing.
    pub cells_visited: u64,
    pub box_tests: u64,
    pub registrations: u64,
    pub lower_registrations: u64,
    pub direct_registrations: u64,
    pub lower_grids_used: u64,
    pub direct_misses: u64,
    pub grid_bytes_read: u64,
    pub grid_seeks: u64,
    pub blocks_read: u64,
    pub subspaces: u64,
    pub grid_build_s: f64,
    pub load_average: String,
    /// The process's CPU seconds over the run (0 in runs saved before it was kept).
    #[serde(default)]
    pub cpu_s: f64,
    /// Rays held in memory at once (what the budget left after the grid and its buffers, or a
    /// `rays=` cap): the rays of one pass. 0 in runs saved before it was kept.
    #[serde(default)]
    pub rays_in_memory: u64,
}

impl GridRun {
    pub fn total_s(&self) -> f64 {
        self.preprocess_s + self.trace_s
    }

    /// CPU / wall of the run: well under 100% when it waited for a core or for the disk, so
    /// that a time measured beside other work is seen as such ("-" when not kept).
    pub fn cpu_share(&self) -> String {
        cpu_share(self.cpu_s, self.total_s())
    }
}

/// CPU / wall of a run as "NN%", "-" when its CPU seconds were not kept (0): the one format of
/// the out-of-core reproductions' "CPU / wall" columns.
pub fn cpu_share(cpu_s: f64, wall_s: f64) -> String {
    if cpu_s > 0.0 {
        format!("{:.0}%", 100.0 * cpu_s / wall_s.max(1e-9))
    } else {
        "-".into()
    }
}

pub fn resolve(scene: &str, sf: u32) -> Result<SceneSource> {
    let hash = (scene == "mount").then_some(MountHash::Jenkins);
    SceneSource::resolve(scene, Some(sf), None, hash)
}

pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

/// Streams the scene into a split store at `dir`.
pub fn write_split_store(src: &SceneSource, dir: &Path) -> Result<StoreHeader> {
    let mut w = StoreWriter::create_with(dir, &src.label(), Layout::Split, Codec::None)
        .map_err(|e| input(format!("{}: {e}", dir.display())))?;
    src.stream(&mut w)?;
    w.finish()
        .map_err(|e| input(format!("{}: cannot write: {e}", dir.display())))?;
    StoreHeader::read(dir).map_err(|e| input(e.to_string()))
}

/// The common settings of every run.
#[derive(Clone)]
pub struct Setup {
    pub size: u32,
    pub memory: String,
    pub cache: String,
    pub spill: Option<String>,
}

/// The engine's configuration for the store at `dir`: S+G+B and `grid` settings.
fn config(s: &Setup, grid: &[(&str, String)]) -> Result<BreadthFirstConfig> {
    let mut pairs: Vec<(String, String)> = vec![
        ("memory".into(), s.memory.clone()),
        ("verify".into(), "records".into()),
        ("cache".into(), s.cache.clone()),
        ("layout".into(), "split".into()),
        ("hierarchy".into(), "on".into()),
    ];
    if let Some(sp) = &s.spill {
        pairs.push(("spill".into(), sp.clone()));
    }
    let settings: Vec<(String, String)> = grid
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    pairs.extend(settings);
    Ok(BreadthFirstConfig::from_settings(Settings::new(
        "breadth-first",
        pairs,
    ))?)
}

/// The rays the engine would hold in memory with these settings (it is opened, not traced).
pub fn rays_in_memory(dir: &Path, s: &Setup, grid: &[(&str, String)]) -> Result<u64> {
    let engine = BreadthFirst::open(dir, config(s, grid)?)?;
    Ok(engine
        .build_stats()
        .get("rays_in_memory")
        .copied()
        .unwrap_or(0.0) as u64)
}

/// Traces the store at `dir` with S+G+B and `grid` settings.
pub fn trace(dir: &Path, s: &Setup, grid: &[(&str, String)]) -> Result<GridRun> {
    crate::measure::rss::reset_peak_rss();
    let load_average = load_average();
    let settings: Vec<(String, String)> = grid
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    let config = config(s, grid)?;
    let cpu0 = crate::measure::clock::process_cpu_seconds();
    let t = std::time::Instant::now();
    let engine = BreadthFirst::open(dir, config)?;
    let preprocess_s = t.elapsed().as_secs_f64();
    let ooc = out_of_core::render(&engine, s.size)
        .map_err(|e| input(format!("{}: out-of-core render: {e}", dir.display())))?;
    let r = &ooc.render;
    let x = |k: &str| r.counters.extra.get(k).copied().unwrap_or(0);
    let b = engine.build_stats();
    let bs = |k: &str| b.get(k).copied().unwrap_or(0.0);
    let levels = bs("hr_levels") as u64;
    Ok(GridRun {
        settings,
        preprocess_s,
        trace_s: r.trace_s,
        passes: x("bf_passes"),
        sha256: hex(&Sha256::digest(r.pixels())),
        peak_rss_bytes: crate::measure::rss::peak_rss_bytes().unwrap_or(0),
        res: [bs("res_x") as u64, bs("res_y") as u64, bs("res_z") as u64],
        levels: levels.max(1),
        upper: if levels > 0 {
            [bs("hr_upper_x"), bs("hr_upper_y"), bs("hr_upper_z")].map(|v| v as u64)
        } else {
            [bs("res_x") as u64, bs("res_y") as u64, bs("res_z") as u64]
        },
        lower: (bs("hr_lower") as u64).max(1),
        cells_visited: r.counters.cells_visited,
        box_tests: r.counters.box_tests,
        registrations: x("bf_registrations"),
        lower_registrations: x("hr_lower_registrations"),
        direct_registrations: x("hr_direct_registrations"),
        lower_grids_used: x("hr_lower_grids_used"),
        direct_misses: x("hr_direct_misses"),
        grid_bytes_read: x("hr_grid_bytes_read"),
        grid_seeks: x("hr_grid_seeks"),
        blocks_read: x("hr_blocks_read"),
        subspaces: bs("hr_subspaces") as u64,
        grid_build_s: bs("hr_build_s"),
        load_average,
        cpu_s: crate::measure::clock::process_cpu_seconds() - cpu0,
        rays_in_memory: bs("rays_in_memory") as u64,
    })
}

/// Parses `rows=balls8,mount12` into (scene, SF) pairs, each scene one of `scenes`.
pub fn parse_rows(id: &str, list: &[String], scenes: &[&str]) -> Result<Vec<(String, u32)>> {
    list.iter()
        .map(|item| {
            let split = item.find(|c: char| c.is_ascii_digit()).ok_or_else(|| {
                input(format!(
                    "{id}: rows '{item}': expected scene and SF, e.g. mount9"
                ))
            })?;
            let (scene, sf) = item.split_at(split);
            let sf: u32 = sf
                .parse()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| input(format!("{id}: rows '{item}': bad size factor")))?;
            if !scenes.contains(&scene) {
                return Err(input(format!(
                    "{id}: rows '{item}': the scenes are {}",
                    scenes.join(", ")
                )));
            }
            Ok((scene.to_string(), sf))
        })
        .collect()
}

/// Least-squares slope of log(y) against log(x): the exponent of a power law y ∝ x^k.
pub fn log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slope_of_a_power_law_is_its_exponent() {
        let lin: Vec<(f64, f64)> = [1e3, 1e4, 1e5].iter().map(|&x| (x, 3.0 * x)).collect();
        assert!((log_slope(&lin).unwrap() - 1.0).abs() < 1e-9);
        let root: Vec<(f64, f64)> = [1e3f64, 1e4, 1e5]
            .iter()
            .map(|&x| (x, x.powf(0.3)))
            .collect();
        assert!((log_slope(&root).unwrap() - 0.3).abs() < 1e-9);
        assert!(log_slope(&lin[..1]).is_none());
    }
}
