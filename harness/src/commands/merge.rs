//! `rtbench merge DIR… --out DIR`: joins the results of the shards of one plan into one results set
//! (the joining itself is `runs/merge.rs`).

use crate::cli::MergeArgs;
use crate::error::{input, Result};
use crate::output::print_json;
use crate::runs::merge::{
    check_out, env_file, jsonl, load_shards, merged_records, png_bytes, shards_json, write_all,
    Files,
};
use crate::shard::MANIFEST_FILE;
use crate::workload::tiles::{self, TileOutput};
use serde_json::json;
use std::collections::BTreeSet;

pub fn run(a: &MergeArgs) -> Result<()> {
    if a.dirs.is_empty() {
        return Err(input("merge: give the shards' directories"));
    }
    let shards = load_shards(&a.dirs)?;
    check_out(&a.out, &a.dirs)?;
    let m = &shards[0].m;
    let mut files: Files = Vec::new();
    let summary = match m.kind.as_str() {
        "run" | "sweep" | "nightly" => {
            let records = merged_records(&shards)?;
            files.push(("results.jsonl".into(), jsonl(&records)));
            if m.kind == "nightly" {
                let measured = crate::nightly::shard::merge_measured(&shards)?;
                files.push((
                    crate::nightly::shard::MEASURED_FILE.into(),
                    serde_json::to_vec_pretty(&measured).expect("serialises"),
                ));
            }
            let machines: BTreeSet<&str> = shards.iter().map(|s| s.m.hostname.as_str()).collect();
            json!({
                "kind": m.kind, "shards": m.of, "runs": records.len(),
                "failed": records.iter().filter(|r| !r.ok()).count(),
                "machines": machines, "commit": m.git_commit,
            })
        }
        "tile" => {
            let tiles: Vec<TileOutput> = shards
                .iter()
                .map(|s| TileOutput::read(&s.dir))
                .collect::<Result<_>>()?;
            let merged = tiles::merge(&shards, &tiles)?;
            files.push(("image.png".into(), png_bytes(&merged.pixels, merged.size)?));
            let v = merged.json();
            files.push((
                "render.json".into(),
                serde_json::to_vec_pretty(&v).expect("serialises"),
            ));
            v
        }
        k => {
            return Err(input(format!(
                "{}: unknown shard kind '{k}' in {MANIFEST_FILE}",
                shards[0].dir.display()
            )))
        }
    };
    if let Some(f) = env_file(&shards)? {
        files.push(f);
    }
    files.push(("shards.json".into(), shards_json(&shards)?));
    write_all(&a.out, files)?;
    if a.json {
        print_json(&summary);
    } else {
        let what = match m.kind.as_str() {
            "tile" => format!(
                "image sha256 {}, {} rays",
                summary["image"]["sha256"].as_str().unwrap_or("?"),
                summary["rays"]["total"]
            ),
            _ => format!(
                "{} runs ({} failed) from {} machine(s)",
                summary["runs"],
                summary["failed"],
                summary["machines"].as_array().map(|a| a.len()).unwrap_or(0)
            ),
        };
        eprintln!(
            "merge: {} {} shards into {}: {what}",
            m.of,
            m.kind,
            a.out.display()
        );
    }
    Ok(())
}
