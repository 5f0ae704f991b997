//! Beyond one machine: a run split with `--shard K/N` and joined with `rtbench merge`
//! equals the unsharded run (times aside); a tiled out-of-core render merges to the one-machine
//! image; `merge` refuses mixed, missing and doubled shards with one line and writes nothing; and,
//! where `scripts/slurm/local-cluster.sh` can start a one-node Slurm cluster, a 4-task job array of
//! a run and its dependent merge job produce the merged report.

mod common;

use common::{expect_input_error, rtbench};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtbench-shards-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn ok(args: &[&str]) -> String {
    let out = rtbench(args);
    assert!(
        out.status.success(),
        "{args:?}: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The records of a results directory, with what varies from run to run taken out (times, memory,
/// the machine, when it finished), keyed by run key.
fn comparable(dir: &Path) -> Vec<(String, Value)> {
    let text = std::fs::read_to_string(dir.join("results.jsonl")).unwrap();
    let mut v: Vec<(String, Value)> = text
        .lines()
        .map(|l| {
            let mut r: Value = serde_json::from_str(l).unwrap();
            let o = r.as_object_mut().unwrap();
            for k in [
                "time_s",
                "mrays_per_s",
                "wall_s",
                "finished_at",
                "peak_rss_bytes",
                "paired_ratio",
                "thread_scaling",
                "machine",
                "samples",
                "ratio_to_embree",
            ] {
                o.remove(k);
            }
            // Build statistics hold build times next to counts: keep the counts.
            if let Some(Value::Object(b)) = o.get_mut("build_stats") {
                b.retain(|k, _| {
                    !k.ends_with("_s") && !k.contains("time") && !k.contains("seconds")
                });
            }
            (o["key"].as_str().unwrap().to_string(), r)
        })
        .collect();
    v.sort_by(|a, b| a.0.cmp(&b.0));
    v
}

const PLAN: [&str; 12] = [
    "--engines",
    "embree,grid,bvh4",
    "--scenes",
    "tetra,balls,gears",
    "--sf",
    "1",
    "--size",
    "24",
    "--repeat",
    "1",
    "--threads",
    "1",
];

fn run_into(dir: &Path, shard: Option<&str>) {
    let mut args: Vec<&str> = vec!["run"];
    args.extend(PLAN);
    let d = dir.to_str().unwrap().to_string();
    args.extend(["--out", &d]);
    if let Some(s) = shard {
        args.extend(["--shard", s]);
    }
    ok(&args);
}

#[test]
fn a_sharded_run_merged_equals_the_unsharded_run() {
    let d = tmp("run");
    let whole = d.join("whole");
    run_into(&whole, None);
    let shards: Vec<PathBuf> = (1..=2).map(|k| d.join(format!("s{k}"))).collect();
    for (k, s) in shards.iter().enumerate() {
        run_into(s, Some(&format!("{}/2", k + 1)));
    }
    // Shard 1 has tetra and gears (groups 0 and 2), shard 2 balls, Embree with each.
    let s1 = comparable(&shards[0]);
    assert_eq!(
        s1.len(),
        6,
        "{:?}",
        s1.iter().map(|x| &x.0).collect::<Vec<_>>()
    );
    assert!(s1.iter().all(|(k, _)| !k.contains("balls")));
    let merged = d.join("merged");
    let mut args = vec!["merge".to_string()];
    args.extend(shards.iter().map(|p| p.display().to_string()));
    args.extend([
        "--out".into(),
        merged.display().to_string(),
        "--json".into(),
    ]);
    let out = ok(&args.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let summary: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(summary["runs"], 9);
    assert_eq!(comparable(&merged), comparable(&whole));
    // The merged set makes a report like any other.
    ok(&["report", merged.to_str().unwrap()]);
    assert!(merged.join("report.md").is_file());
    // `plan` sizes an array: 3 scene groups; 4 shards leave one empty.
    let mut p = vec!["plan", "--json", "--shards", "4", "run"];
    p.extend(PLAN);
    let unused = d.join("unused");
    p.extend(["--out", unused.to_str().unwrap()]);
    let plan: Value = serde_json::from_str(&ok(&p)).unwrap();
    assert_eq!(plan["jobs"], 9);
    assert_eq!(plan["groups"], 3);
    assert_eq!(plan["empty_shards"], 1);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn merge_refuses_mixed_missing_and_doubled_shards_and_writes_nothing() {
    let d = tmp("refuse");
    let mut small = vec!["run", "--engines", "embree,grid", "--scenes", "tetra,balls"];
    small.extend(["--sf", "1", "--size", "16", "--repeat", "1", "--no-check"]);
    let dirs: Vec<String> = (1..=2)
        .map(|k| d.join(format!("s{k}")).display().to_string())
        .collect();
    for (k, dir) in dirs.iter().enumerate() {
        let mut a = small.clone();
        let spec = format!("{}/2", k + 1);
        a.extend(["--shard", &spec, "--out", dir]);
        ok(&a);
    }
    let out = d.join("out").display().to_string();
    // A missing shard.
    expect_input_error(&["merge", &dirs[0], "--out", &out], "shard 2/2 missing");
    // A shard given twice.
    expect_input_error(
        &["merge", &dirs[0], &dirs[0], &dirs[1], "--out", &out],
        "shard 1/2 given twice",
    );
    // A shard of another commit: the manifest says so.
    let other = d.join("other").display().to_string();
    std::fs::create_dir_all(&other).unwrap();
    for f in ["results.jsonl", "env.json", "shard.json"] {
        std::fs::copy(Path::new(&dirs[1]).join(f), Path::new(&other).join(f)).unwrap();
    }
    let m = Path::new(&other).join("shard.json");
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(&m).unwrap()).unwrap();
    v["git_commit"] = Value::from("0123456789abcdef0123456789abcdef01234567");
    std::fs::write(&m, serde_json::to_string(&v).unwrap()).unwrap();
    expect_input_error(
        &["merge", &dirs[0], &other, "--out", &out],
        "shards of different commits",
    );
    // A shard that did not finish.
    v["git_commit"] = serde_json::from_str::<Value>(
        &std::fs::read_to_string(Path::new(&dirs[0]).join("shard.json")).unwrap(),
    )
    .unwrap()["git_commit"]
        .clone();
    v["finished_at"] = Value::Null;
    std::fs::write(&m, serde_json::to_string(&v).unwrap()).unwrap();
    expect_input_error(
        &["merge", &dirs[0], &other, "--out", &out],
        "did not finish",
    );
    // A directory that is no shard.
    let plain = d.join("plain").display().to_string();
    std::fs::create_dir_all(&plain).unwrap();
    expect_input_error(&["merge", &dirs[0], &plain, "--out", &out], "not a shard");
    assert!(!Path::new(&out).exists(), "a refused merge wrote {out}");
    // Bad --shard values.
    let mut a = small.clone();
    a.extend(["--shard", "3/2", "--out", &out]);
    expect_input_error(&a, "expected K/N");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_tiled_store_render_merges_to_the_one_machine_image() {
    let d = tmp("tiles");
    let store = d.join("store").display().to_string();
    ok(&["scene", "store", "tetra", "--sf", "3", "-o", &store]);
    let common = [
        "render",
        "--scene",
        &store,
        "--engine",
        "breadth-first",
        "--size",
        "64",
        "--set",
        "memory=16MiB",
    ];
    let mut whole = common.to_vec();
    whole.push("--json");
    let one: Value = serde_json::from_str(&ok(&whole)).unwrap();
    let tiles: Vec<String> = (1..=3)
        .map(|k| d.join(format!("t{k}")).display().to_string())
        .collect();
    for (k, t) in tiles.iter().enumerate() {
        let mut a = common.to_vec();
        let spec = format!("{}/3", k + 1);
        a.extend(["--tile", &spec, "--out", t]);
        ok(&a);
    }
    let merged = d.join("merged").display().to_string();
    let mut a = vec!["merge"];
    a.extend(tiles.iter().map(|s| s.as_str()));
    a.extend(["--out", &merged]);
    ok(&a);
    let m: Value = serde_json::from_str(
        &std::fs::read_to_string(Path::new(&merged).join("render.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(m["image"]["sha256"], one["image"]["sha256"]);
    assert_eq!(m["rays"], one["rays"], "ray statistics add up");
    assert!(Path::new(&merged).join("image.png").is_file());
    // A tile of an in-memory scene is refused.
    expect_input_error(
        &[
            "render", "--scene", "tetra", "--engine", "grid", "--tile", "1/2", "--out", &merged,
        ],
        "tiles split the out-of-core render",
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Runs a shell command in the repository, returning (status, stdout, stderr).
fn sh(cmd: &str, envs: &[(&str, &str)]) -> (i32, String, String) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut c = Command::new("bash");
    c.arg("-c").arg(cmd).current_dir(&root);
    for (k, v) in envs {
        c.env(k, v);
    }
    let o = c.output().expect("bash runs");
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn a_job_array_on_a_local_slurm_cluster_merges_into_one_report() {
    let d = tmp("slurm");
    let cluster = d.join("cluster").display().to_string();
    let (code, _, err) = sh(
        &format!("bash scripts/slurm/local-cluster.sh start {cluster}"),
        &[],
    );
    if code != 0 {
        println!(
            "skipped: no local Slurm cluster here (exit {code}): {}",
            err.trim()
        );
        return;
    }
    let conf = format!("{cluster}/slurm.conf");
    let envs = [
        ("SLURM_CONF", conf.as_str()),
        ("RTBENCH", env!("CARGO_BIN_EXE_rtbench")),
    ];
    let shared = d.join("shared").display().to_string();
    let result = (|| -> Result<(), String> {
        let (code, out, err) = sh(
            &format!(
                "bash scripts/slurm/submit.sh run {shared} --shards 4 -- --engines embree,grid \
                 --scenes tetra,balls,gears,teapot --sf 1 --size 24 --repeat 1"
            ),
            &envs,
        );
        if code != 0 {
            return Err(format!("submit.sh: exit {code}: {err}"));
        }
        let ids: Vec<String> = out
            .lines()
            .last()
            .unwrap_or("")
            .split_whitespace()
            .map(String::from)
            .collect();
        if ids.len() != 2 {
            return Err(format!("submit.sh printed no job ids: {out}"));
        }
        let start = Instant::now();
        loop {
            let (_, q, _) = sh("squeue -h -o %i", &envs);
            if q.trim().is_empty() {
                break;
            }
            if start.elapsed() > Duration::from_secs(600) {
                return Err(format!("jobs still queued after 600 s: {q}"));
            }
            std::thread::sleep(Duration::from_millis(500));
        }
        let (_, acct, _) = sh("sacct -c -n -o JobID,JobName,State", &envs);
        let merged = Path::new(&shared).join("merged");
        if !merged.join("report.md").is_file() {
            let logs = sh(&format!("cat {shared}/slurm-*.out"), &[]).1;
            return Err(format!("no merged report; sacct:\n{acct}\nlogs:\n{logs}"));
        }
        let text = std::fs::read_to_string(merged.join("results.jsonl")).unwrap();
        if text.lines().count() != 8 {
            return Err(format!("merged {} runs, expected 8", text.lines().count()));
        }
        let completed = acct.lines().filter(|l| l.contains("COMPLETED")).count();
        if completed < 5 {
            return Err(format!("sacct: {completed} completed jobs of 5:\n{acct}"));
        }
        Ok(())
    })();
    sh(
        &format!("bash scripts/slurm/local-cluster.sh stop {cluster}"),
        &[],
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    let _ = std::fs::remove_dir_all(&d);
}
