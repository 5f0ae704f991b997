//! Out-of-core renders split by image tiles (`rtbench render --scene STORE --tile K/N --out DIR`),
//! for a cluster: every node streams the whole store from shared storage and traces the ray trees
//! of its own pixel corners only, as the thesis's ray-parallel reading of the breadth-first method
//! allows (seed 000 §3: rays are independent; the scene is read, never written). `rtbench merge`
//! joins the tiles.
//!
//! A tile set is every N-th band of [`BAND_ROWS`] rows of pixel corners (band b belongs to tile
//! (b mod N) + 1): bands spread the image's costly parts (a mountain's slope, a sky) over the tiles.
//! A corner's colour depends on its own ray tree only, summed in the same order whatever else is
//! traced, so the merged image equals the one-machine image to the bit, and the ray statistics and
//! counters add up.
//!
//! A tile's directory: `shard.json` (kind `tile`), `corners.bin` (the colours of its corners, f32
//! little-endian RGB, its rows in ascending order) and `tile.json` ([`TileOutput`]).

use super::trace::{pixels_of, RayStats};
use crate::error::{input, Result};
use crate::shard::Shard;
use crate::shard::ShardSpec;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Rows of pixel corners in one band.
pub const BAND_ROWS: u32 = 16;

/// Whether corner row `j` belongs to the tile.
pub fn owns_row(spec: ShardSpec, j: u32) -> bool {
    spec.owns_group((j / BAND_ROWS) as usize)
}

/// The corner rows of the tile, ascending, of an image of `size` pixels.
pub fn rows(spec: ShardSpec, size: u32) -> Vec<u32> {
    (0..=size).filter(|&j| owns_row(spec, j)).collect()
}

/// What a tile measured (`DIR/tile.json`); its corners are in `DIR/corners.bin`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TileOutput {
    pub size: u32,
    pub store: String,
    pub rays: RayStats,
    /// The engine's exact counters, flattened.
    pub counters: BTreeMap<String, u64>,
    /// The workload's own I/O (spill files, shading's reads).
    pub io: BTreeMap<String, u64>,
    pub preprocess_s: f64,
    pub trace_s: f64,
    pub intersect_s: f64,
    pub shade_s: f64,
    pub peak_rss_bytes: Option<u64>,
    /// The colours of the tile's corners, row by row ([`rows`]); not in tile.json.
    #[serde(skip)]
    pub corners: Vec<Vec3>,
}

pub const TILE_FILE: &str = "tile.json";
pub const CORNERS_FILE: &str = "corners.bin";

impl TileOutput {
    /// Writes `tile.json` and `corners.bin` (the manifest is the caller's).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let mut bytes = Vec::with_capacity(self.corners.len() * 12);
        for c in &self.corners {
            for x in [c.x, c.y, c.z] {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        crate::output::write_atomic(&dir.join(CORNERS_FILE), |w| {
            std::io::Write::write_all(w, &bytes)
        })?;
        let text = serde_json::to_string_pretty(self).expect("tile serialises");
        crate::output::write_atomic(&dir.join(TILE_FILE), |w| {
            std::io::Write::write_all(w, text.as_bytes())
        })
    }

    pub fn read(dir: &Path) -> Result<TileOutput> {
        let p = dir.join(TILE_FILE);
        let text = std::fs::read_to_string(&p)
            .map_err(|e| input(format!("{}: cannot read: {e}", p.display())))?;
        let mut t: TileOutput = serde_json::from_str(&text)
            .map_err(|e| input(format!("{}: not a tile's output: {e}", p.display())))?;
        let c = dir.join(CORNERS_FILE);
        let bytes =
            std::fs::read(&c).map_err(|e| input(format!("{}: cannot read: {e}", c.display())))?;
        if bytes.len() % 12 != 0 {
            return Err(input(format!(
                "{}: {} bytes, not whole RGB f32 corners",
                c.display(),
                bytes.len()
            )));
        }
        let f = |i: usize| f32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
        t.corners = (0..bytes.len() / 12)
            .map(|i| Vec3::new(f(3 * i), f(3 * i + 1), f(3 * i + 2)))
            .collect();
        Ok(t)
    }
}

/// The tiles joined.
pub struct Merged {
    pub size: u32,
    pub pixels: Vec<u8>,
    pub rays: RayStats,
    pub counters: BTreeMap<String, u64>,
    pub io: BTreeMap<String, u64>,
    pub tiles: Vec<(u32, String, f64, f64, Option<u64>)>,
}

impl Merged {
    pub fn json(&self) -> serde_json::Value {
        use sha2::Digest;
        serde_json::json!({
            "engine": "breadth-first",
            "rays": self.rays,
            "counters": self.counters,
            "io": {"workload": self.io},
            "image": {"width": self.size, "height": self.size,
                      "sha256": crate::output::hex(&sha2::Sha256::digest(&self.pixels))},
            "tiles": self.tiles.iter().map(|(k, host, pre, trace, rss)| serde_json::json!({
                "tile": k, "machine": host, "preprocess_s": pre, "trace_s": trace,
                "peak_rss_bytes": rss})).collect::<Vec<_>>(),
            "time_s": {
                "trace_max": self.tiles.iter().map(|t| t.3).fold(0.0, f64::max),
                "trace_sum": self.tiles.iter().map(|t| t.3).sum::<f64>(),
            },
        })
    }
}

fn add_maps(into: &mut BTreeMap<String, u64>, from: &BTreeMap<String, u64>) {
    for (k, v) in from {
        *into.entry(k.clone()).or_default() += v;
    }
}

/// Joins the tiles of `shards` (checked by `merge` to be the N finished tiles of one render).
pub fn merge(shards: &[Shard], tiles: &[TileOutput]) -> Result<Merged> {
    let size = tiles[0].size;
    let w = size as usize + 1;
    let mut corners = vec![Vec3::ZERO; w * w];
    let mut rays = RayStats::default();
    let (mut counters, mut io) = (BTreeMap::new(), BTreeMap::new());
    let mut per_tile = Vec::new();
    for (s, t) in shards.iter().zip(tiles) {
        if t.size != size {
            return Err(input(format!(
                "{}: a {}² tile, but {} is {size}²",
                s.dir.display(),
                t.size,
                shards[0].dir.display()
            )));
        }
        let spec = ShardSpec {
            k: s.m.shard,
            n: s.m.of,
        };
        let mine = rows(spec, size);
        if t.corners.len() != mine.len() * w {
            return Err(input(format!(
                "{}: {} corners, but tile {}/{} of a {size}² image has {}",
                s.dir.join(CORNERS_FILE).display(),
                t.corners.len(),
                spec.k,
                spec.n,
                mine.len() * w
            )));
        }
        for (r, &j) in mine.iter().enumerate() {
            let j = j as usize;
            corners[j * w..(j + 1) * w].copy_from_slice(&t.corners[r * w..(r + 1) * w]);
        }
        rays.add(&t.rays);
        add_maps(&mut counters, &t.counters);
        add_maps(&mut io, &t.io);
        per_tile.push((
            spec.k,
            s.m.hostname.clone(),
            t.preprocess_s,
            t.trace_s,
            t.peak_rss_bytes,
        ));
    }
    Ok(Merged {
        size,
        pixels: pixels_of(size, &corners),
        rays,
        counters,
        io,
        tiles: per_tile,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_corner_row_in_exactly_one_tile() {
        for size in [1u32, 15, 16, 64, 512] {
            for n in 1..=7 {
                let mut count = vec![0; size as usize + 1];
                for k in 1..=n {
                    for j in rows(ShardSpec { k, n }, size) {
                        count[j as usize] += 1;
                    }
                }
                assert!(count.iter().all(|&c| c == 1), "size {size} n {n}");
            }
        }
    }
}
