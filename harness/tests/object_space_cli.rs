//! The `object-space` engine from the command line: bad machine settings are one-line
//! input errors, and the simulated clocks of a render are the same on 1 and 2 threads.

mod common;

use common::{expect_input_error, rtbench};
use serde_json::Value;

#[test]
fn bad_machine_settings_exit_2() {
    let render = |set: &str, needle: &str| {
        expect_input_error(
            &[
                "render",
                "--scene",
                "tetra",
                "--sf",
                "1",
                "--size",
                "8",
                "--engine",
                "object-space",
                "--set",
                set,
            ],
            needle,
        )
    };
    render("pes=12", "does not divide the subspaces");
    render("pes=0", "zero processing elements");
    render("pes=8x0", "zero processing elements");
    render("cost.hop=0", "cost.hop");
    render("cost.sphere=-3", "cost.sphere");
    render("allocation=sideways", "allocation");
    expect_input_error(
        &[
            "reproduce",
            "spd-stats",
            "--size",
            "64",
            "--out",
            "out/never-written",
        ],
        "option 'size' does not apply",
    );
}

fn sim_clocks(threads: &str) -> (u64, Value) {
    let out = rtbench(&[
        "render",
        "--scene",
        "rings",
        "--sf",
        "1",
        "--size",
        "48",
        "--engine",
        "object-space",
        "--set",
        "pes=4x4",
        "--threads",
        threads,
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    (
        v["counters"]["extra"]["sim_clocks"].as_u64().unwrap(),
        v["rays"].clone(),
    )
}

/// Two threads where the process may run two at once, else one: rtbench refuses more threads
/// than it can run (exit 2), and CI or a `taskset -c 1` run may give it a single core.
fn two_threads() -> &'static str {
    match std::thread::available_parallelism().map(|n| n.get()) {
        Ok(n) if n >= 2 => "2",
        _ => "1",
    }
}

#[test]
fn simulated_clocks_are_deterministic() {
    let (a, rays_a) = sim_clocks("1");
    let (b, rays_b) = sim_clocks(two_threads());
    assert!(a > 0);
    assert_eq!(a, b);
    assert_eq!(rays_a, rays_b);
}

#[test]
fn yamauchi_static_lb_small_run_reports_every_machine() {
    let dir = std::env::temp_dir().join(format!("rtbench-yamauchi-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = rtbench(&[
        "reproduce",
        "yamauchi-static-lb",
        "--scenes",
        "tetra",
        "--size",
        "32",
        "--max-pes",
        "16",
        "--threads",
        "1",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["measured"][0]["runs"].as_array().unwrap();
    // 1 PE, then 1D: 3 allocations × 4 counts, 2D: 3 × 4, 3D: 2 × 4.
    assert_eq!(runs.len(), 1 + 12 + 12 + 8);
    let busy: Vec<f64> = runs
        .iter()
        .map(|r| {
            r["utilisation"].as_f64().unwrap()
                * r["clocks"].as_f64().unwrap()
                * r["pes"].as_f64().unwrap()
        })
        .collect();
    for (r, b) in runs.iter().zip(&busy) {
        let e = r["efficiency"].as_f64().unwrap();
        assert!(e > 0.0 && e <= 1.0 + 1e-9, "{r}");
        // Every machine does the same work, only spread differently.
        assert!((b / busy[0] - 1.0).abs() < 1e-9);
    }
    assert!(dir.join("yamauchi-static-lb.md").exists());
    assert!(dir
        .join("plots/yamauchi-static-lb-tetra6-efficiency.svg")
        .exists());
    // Each machine was saved: resumed (on two threads), every one is loaded, with the same clocks.
    let again = rtbench(&[
        "reproduce",
        "yamauchi-static-lb",
        "--scenes",
        "tetra",
        "--size",
        "32",
        "--max-pes",
        "16",
        "--threads",
        two_threads(),
        "--resume",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    assert!(again.status.success());
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(stderr.contains("33 of 33 machines loaded"), "{stderr}");
    let w: Value = serde_json::from_slice(&again.stdout).unwrap();
    let clocks = |v: &Value| -> Vec<u64> {
        v["measured"][0]["runs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r["clocks"].as_u64().unwrap())
            .collect()
    };
    assert_eq!(clocks(&v), clocks(&w));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn yamauchi_options_are_checked() {
    for (id, flag, value, needle) in [
        (
            "yamauchi-cfbs",
            "--max-sf",
            "3",
            "option 'max-sf' does not apply",
        ),
        ("yamauchi-static-lb", "--size", "0", "size '0'"),
        ("yamauchi-static-lb", "--max-pes", "0", "max-pes '0'"),
        (
            "yamauchi-dynamic-lb",
            "--max-pes",
            "8",
            "max-pes must be at least 16",
        ),
        (
            "yamauchi-cfbs",
            "--scenes",
            "bogus",
            "unknown scene 'bogus'",
        ),
        (
            "yamauchi-cfbs",
            "--engines",
            "grid",
            "option 'engines' does not apply",
        ),
        (
            "yamauchi-radiosity",
            "--set",
            "threshold=0",
            "threshold must be above 0",
        ),
        (
            "yamauchi-radiosity",
            "--set",
            "threshold=-1",
            "threshold must be above 0",
        ),
        (
            "yamauchi-radiosity",
            "--set",
            "pes=12",
            "does not divide the 32x32 subspaces",
        ),
        (
            "yamauchi-radiosity",
            "--set",
            "room=0",
            "0 gives a room of 0 patches",
        ),
        (
            "yamauchi-static-lb",
            "--set",
            "threshold=0",
            "threshold must be above 0",
        ),
        ("nakamaru-3.2", "--fault-ms", "0", "fault-ms '0'"),
        (
            "nakamaru-3.2",
            "--size",
            "64",
            "option 'size' does not apply",
        ),
    ] {
        expect_input_error(
            &["reproduce", id, flag, value, "--out", "out/never-written"],
            needle,
        );
    }
}
