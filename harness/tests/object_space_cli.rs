//! The `object-space` engine from the command line (issue 8): bad machine settings are one-line
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
        &["reproduce", "spd-stats", "--size", "64", "--out", "/tmp/x"],
        "yamauchi-* tables only",
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

#[test]
fn simulated_clocks_are_deterministic() {
    let (a, rays_a) = sim_clocks("1");
    let (b, rays_b) = sim_clocks("2");
    assert!(a > 0);
    assert_eq!(a, b);
    assert_eq!(rays_a, rays_b);
}
