//! `rtbench plan [--shards N] [--json] run|sweep|nightly …`: what a plan would run and how it splits,
//! without running it, so a cluster job array can be sized from the plan (scripts/slurm/): the jobs,
//! the groups (the units a shard takes whole) and each shard's slice.

use crate::cli::{PlanCmdArgs, PlanWhat};
use crate::commands::runs::run_plan;
use crate::error::{input, Result};
use crate::output::print_json;
use crate::runs::plan::run_group;
use crate::shard::{group_count, ShardSpec, MAX_SHARDS};
use serde_json::json;

pub fn run(a: &PlanCmdArgs) -> Result<()> {
    // The plan's items (job keys, or a sweep's engine/scene units) and each one's group.
    let (kind, items): (&str, Vec<(String, String)>) = match &a.what {
        PlanWhat::Run(r) => {
            let (jobs, _) = run_plan(r)?;
            let items = jobs
                .iter()
                .map(|j| (j.key(), format!("{:?}", run_group(j))))
                .collect();
            ("run", items)
        }
        PlanWhat::Nightly(n) => {
            let suite = crate::nightly::suite::load_runnable(&n.suite)?;
            let items = crate::nightly::jobs(&suite)
                .iter()
                .map(|j| (j.key(), format!("{:?}", run_group(j))))
                .collect();
            ("nightly", items)
        }
        PlanWhat::Sweep(s) => {
            let engines = crate::select::engines(Some(&s.plan.engines), "--engines")?;
            let programs: Vec<String> = crate::commands::runs::plan_scenes(&s.plan)?
                .iter()
                .map(crate::runs::plan::PlanScene::name)
                .collect();
            let items = programs
                .iter()
                .flat_map(|p| {
                    engines.iter().map(move |(e, set)| {
                        let set: std::collections::BTreeMap<_, _> = set.iter().cloned().collect();
                        (
                            format!("{}/{p}", rtbench_reports::engine_label(e, &set)),
                            p.clone(),
                        )
                    })
                })
                .collect();
            ("sweep", items)
        }
    };
    let groups = group_count(&items, |x| x.1.clone());
    let n = match a.shards {
        None => groups.max(1) as u32,
        Some(0) => return Err(input("--shards: must be at least 1")),
        Some(n) if n > MAX_SHARDS => {
            return Err(input(format!("--shards {n}: at most {MAX_SHARDS}")))
        }
        Some(n) => n,
    };
    let slices: Vec<serde_json::Value> = (1..=n)
        .map(|k| {
            let spec = ShardSpec { k, n };
            let mine = spec.select(&items, |x| x.1.clone());
            json!({
                "shard": k,
                "groups": group_count(&mine, |x| x.1.clone()),
                "jobs": mine.iter().map(|x| x.0.clone()).collect::<Vec<_>>(),
            })
        })
        .collect();
    let empty = slices
        .iter()
        .filter(|s| s["jobs"].as_array().is_some_and(|j| j.is_empty()))
        .count();
    if a.json {
        print_json(&json!({
            "kind": kind,
            "jobs": items.len(),
            "groups": groups,
            "shards": n,
            "empty_shards": empty,
            "slices": slices,
        }));
    } else {
        println!(
            "{kind}: {} jobs in {groups} groups, {n} shards ({empty} empty)",
            items.len()
        );
        for s in &slices {
            println!(
                "  shard {}/{n}: {} groups, {} jobs",
                s["shard"],
                s["groups"],
                s["jobs"].as_array().map(|j| j.len()).unwrap_or(0)
            );
        }
    }
    Ok(())
}
