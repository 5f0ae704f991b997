//! `compare` on synthetic result sets.

mod common;

use common::{failed, run, samples, write_set, TempDir};
use rtbench_reports::{compare, Comparison, FindingKind, ReportError, RunRecord};

/// embree, bvh2 and grid on balls3 and balls4.
fn base() -> Vec<RunRecord> {
    let mut v = Vec::new();
    for sf in [3, 4] {
        v.push(run("embree", "balls", sf, 1.0 * sf as f64));
        v.push(run("bvh2", "balls", sf, 2.0 * sf as f64));
        v.push(run("grid", "balls", sf, 0.5 * sf as f64));
    }
    v
}

/// `set` as `run --rounds 3` records it: each run's three repeats (and its pairs, a third a round)
/// from three processes. Embree's second and first repeats change places, so each round's ratio
/// to Embree differs from the next by about 1 %, as rounds do.
fn in_rounds(set: &mut [RunRecord]) {
    for r in set.iter_mut() {
        if r.engine == "embree" {
            r.time_s.trace.samples.swap(0, 1);
        }
        let third = |n: usize| n / 3;
        r.rounds = vec![
            rtbench_reports::Round {
                repeats: third(r.time_s.trace.samples.len()),
                pairs: third(r.paired_ratio.as_ref().map_or(0, |p| p.samples.len())),
                thread_pairs: third(
                    r.thread_scaling
                        .as_ref()
                        .map_or(0, |t| t.speedup.samples.len())
                ),
            };
            3
        ];
    }
}

/// [`compare_sets`] with both sets in rounds ([`in_rounds`]).
fn compare_rounds(a: &[RunRecord], b: &[RunRecord], threshold: f64) -> Comparison {
    let (mut a, mut b) = (a.to_vec(), b.to_vec());
    in_rounds(&mut a);
    in_rounds(&mut b);
    compare_sets(&a, &b, threshold)
}

fn compare_sets(a: &[RunRecord], b: &[RunRecord], threshold: f64) -> Comparison {
    let (da, db) = (TempDir::new("cmp-a"), TempDir::new("cmp-b"));
    write_set(da.path(), a);
    write_set(db.path(), b);
    compare(da.path(), db.path(), threshold).unwrap()
}

/// Scales a run's trace times (median, min, max, samples) by `f`, keeping its relative spread.
fn scale_trace(r: &mut RunRecord, f: f64) {
    let t = &mut r.time_s.trace;
    t.min *= f;
    t.median *= f;
    t.max *= f;
    t.samples.iter_mut().for_each(|s| *s *= f);
    r.mrays_per_s /= f;
}

fn find<'a>(runs: &'a mut [RunRecord], key: &str) -> &'a mut RunRecord {
    runs.iter_mut().find(|r| r.key == key).unwrap()
}

#[test]
fn identical_sets_do_not_regress() {
    let c = compare_sets(&base(), &base(), 5.0);
    assert!(!c.is_regression(), "{}", c.to_markdown());
    assert!(c.improvements.is_empty() && c.notes.is_empty());
    assert_eq!(c.matched, 6);
    assert_eq!(
        c.times_compared, 4,
        "bvh2 and grid on two scenes; Embree is the yardstick"
    );
    assert_eq!(c.counters_compared, 12);
    assert_eq!(c.a_commit.as_deref(), Some("abc1234"));
    assert!(c.to_markdown().contains("**No regression.**"));
}

#[test]
fn slower_relative_to_embree_is_a_regression() {
    let mut b = base();
    // The whole machine 30% slower (cancels), and bvh2 on balls4 15% slower than that.
    b.iter_mut().for_each(|r| scale_trace(r, 1.3));
    scale_trace(find(&mut b, "bvh2/balls4@1"), 1.15);
    let c = compare_rounds(&base(), &b, 5.0);
    assert!(c.is_regression());
    assert_eq!(c.regressions.len(), 1, "{}", c.to_markdown());
    let f = &c.regressions[0];
    assert_eq!(f.key, "bvh2/balls4@1");
    assert_eq!(f.kind, FindingKind::TimeRatio);
    assert!(
        (f.change_pct.unwrap() - 15.0).abs() < 1e-9,
        "{:?}",
        f.change_pct
    );
    assert!((f.tolerance_pct.unwrap() - 5.0).abs() < 1e-9);
    let [lo, hi] = f.interval_pct.unwrap();
    assert!(lo > 5.0 && lo < 15.0 && hi > 15.0, "{lo} {hi}");
    assert_eq!(f.samples, Some([3, 3]), "three rounds a set");
    assert!(
        (f.old.as_f64().unwrap() - 2.0).abs() < 1e-12
            && (f.new.as_f64().unwrap() - 2.3).abs() < 1e-12
    );
    assert!(
        f.message.contains("bvh2/balls4@1") && f.message.contains("2.00 → 2.30"),
        "{}",
        f.message
    );
    let md = c.to_markdown();
    assert!(
        md.contains("**1 regression.**")
            && md.contains("| `bvh2/balls4@1` | trace time / Embree | 2.00 | 2.30 | +15% | [+")
            && md.contains("| 3/3 | 5% |"),
        "{md}"
    );
    let json = serde_json::to_value(&c).unwrap();
    assert_eq!(json["regressions"][0]["key"], "bvh2/balls4@1");
    assert_eq!(json["regressions"][0]["kind"], "time_ratio");

    // The same change between sets of one process a run is not decided: one process's repeats
    // cannot show how far two processes differ.
    let c = compare_sets(&base(), &b, 5.0);
    assert!(!c.is_regression(), "{}", c.to_markdown());
    assert_eq!(c.undecided, 1);
    let f = &c.notes[0];
    assert_eq!(
        (f.kind, f.key.as_str()),
        (FindingKind::Undecided, "bvh2/balls4@1")
    );
    assert!(
        f.message
            .contains("past the threshold 5%): not decided: a side ran in one process")
            && f.message.contains("--rounds 2 or more")
            && f.message.contains("6 samples in A, 6 in B"),
        "{}",
        f.message
    );
    assert!(
        c.to_markdown().contains("(1 undecided)"),
        "{}",
        c.to_markdown()
    );
}

#[test]
fn a_regression_needs_its_whole_interval_past_the_threshold() {
    let mut b = base();
    scale_trace(find(&mut b, "bvh2/balls4@1"), 1.15);
    let c = compare_rounds(&base(), &b, 10.0);
    assert!(c.is_regression(), "{}", c.to_markdown());
    let [lo, _] = c.regressions[0].interval_pct.unwrap();
    // The estimate is past 14.9% but the interval reaches back inside: no verdict, said so.
    let c = compare_rounds(&base(), &b, 14.9);
    assert!(!c.is_regression());
    assert_eq!(c.undecided, 1);
    assert_eq!(c.notes[0].kind, FindingKind::Undecided);
    assert!(
        c.notes[0].message.contains("too few samples to decide")
            && c.notes[0].message.contains("3 rounds in A, 3 in B"),
        "{}",
        c.notes[0].message
    );
    assert!(lo < 14.9);
    // Inside the threshold: nothing to say.
    let c = compare_rounds(&base(), &b, 15.1);
    assert!(
        !c.is_regression() && c.notes.is_empty(),
        "{}",
        c.to_markdown()
    );

    // A run whose rounds are noisy (±10%) needs more to count: its interval is wider.
    let mut a = base();
    find(&mut a, "bvh2/balls4@1").time_s.trace = samples(8.0, 0.2);
    let mut b = a.clone();
    scale_trace(find(&mut b, "bvh2/balls4@1"), 1.15);
    let c = compare_rounds(&a, &b, 5.0);
    assert!(!c.is_regression(), "{}", c.to_markdown());
    assert_eq!(c.undecided, 1);
    scale_trace(find(&mut b, "bvh2/balls4@1"), 1.5);
    let c = compare_rounds(&a, &b, 5.0);
    assert!(c.is_regression(), "{}", c.to_markdown());

    // One repeat a side has no spread to judge by: too few samples, never a guess.
    let mut a = base();
    let mut b = base();
    for set in [&mut a, &mut b] {
        for r in set.iter_mut() {
            r.time_s.trace = samples(r.time_s.trace.median, 0.02);
            r.time_s.trace.samples.truncate(1);
        }
    }
    scale_trace(find(&mut b, "bvh2/balls4@1"), 1.5);
    let c = compare_sets(&a, &b, 5.0);
    assert!(!c.is_regression());
    assert!(c.notes.iter().any(|f| f.kind == FindingKind::Undecided
        && f.message
            .contains("too few samples to decide (2 samples in A, 2 in B")));
}

#[test]
fn faster_relative_to_embree_is_an_improvement() {
    let mut b = base();
    scale_trace(find(&mut b, "grid/balls3@1"), 0.8);
    let c = compare_rounds(&base(), &b, 5.0);
    assert!(!c.is_regression());
    assert_eq!(c.improvements.len(), 1);
    assert_eq!(c.improvements[0].key, "grid/balls3@1");
    assert!((c.improvements[0].change_pct.unwrap() + 20.0).abs() < 1e-9);
}

#[test]
fn a_changed_counter_is_a_regression_at_any_size() {
    let mut b = base();
    *find(&mut b, "grid/balls3@1")
        .counters
        .get_mut("nodes_visited")
        .unwrap() += 1;
    // Embree's counters count too; its times do not (they are the yardstick).
    find(&mut b, "embree/balls4@1")
        .counters
        .insert("sweeps".to_string(), 2);
    let c = compare_sets(&base(), &b, 50.0);
    assert!(c.is_regression());
    assert_eq!(c.regressions.len(), 2, "{}", c.to_markdown());
    let grid = c
        .regressions
        .iter()
        .find(|f| f.key == "grid/balls3@1")
        .unwrap();
    assert_eq!(grid.kind, FindingKind::Counter);
    assert_eq!(grid.what, "nodes_visited");
    assert_eq!(
        (grid.old.as_u64(), grid.new.as_u64()),
        (Some(3004), Some(3005))
    );
    assert_eq!(
        grid.message,
        "grid/balls3@1: counter nodes_visited: 3004 → 3005"
    );
    let embree = c
        .regressions
        .iter()
        .find(|f| f.key == "embree/balls4@1")
        .unwrap();
    assert_eq!(
        embree.message,
        "embree/balls4@1: counter sweeps: absent → 2"
    );
}

#[test]
fn failures_and_unmatched_runs_are_reported() {
    let mut a = base();
    a.push(failed("bvh2", "teapot", 3, "panic"));
    a.push(run("grid", "rings", 2, 1.0));
    let mut b = base();
    *find(&mut b, "bvh2/balls3@1") = failed("bvh2", "balls", 3, "memory limit");
    b.push(run("bvh2", "teapot", 3, 1.0));
    b.push(run("grid", "gears", 2, 1.0));
    let c = compare_sets(&a, &b, 5.0);

    assert_eq!(c.regressions.len(), 1, "{}", c.to_markdown());
    assert_eq!(c.regressions[0].kind, FindingKind::Failed);
    assert_eq!(
        c.regressions[0].message,
        "bvh2/balls3@1: failed in B: memory limit"
    );
    assert_eq!(c.improvements.len(), 1);
    assert_eq!(c.improvements[0].kind, FindingKind::Recovered);
    let kinds: Vec<(FindingKind, &str)> =
        c.notes.iter().map(|f| (f.kind, f.key.as_str())).collect();
    assert!(
        kinds.contains(&(FindingKind::OnlyInA, "grid/rings2@1")),
        "{kinds:?}"
    );
    assert!(
        kinds.contains(&(FindingKind::OnlyInB, "grid/gears2@1")),
        "{kinds:?}"
    );
}

#[test]
fn lost_runs_and_no_match_are_no_clean_bill() {
    let a = base();
    let mut b = base();
    b.pop();
    let c = compare_sets(&a, &b, 5.0);
    assert!(!c.is_regression());
    assert_eq!(c.missing_in_b(), 1);
    assert!(
        c.to_markdown().contains("B lacks 1 of A's runs"),
        "{}",
        c.to_markdown()
    );
    // An empty set is refused (nothing to compare is an input error); a set that shares no run
    // with A compares nothing.
    let c = compare_sets(&a, &[run("bvh2", "teapot", 3, 1.0)], 5.0);
    assert_eq!(c.matched, 0);
    assert!(
        c.to_markdown().contains("Nothing compared"),
        "{}",
        c.to_markdown()
    );
}

#[test]
fn no_embree_no_time_comparison() {
    let a = vec![run("bvh2", "teapot", 3, 1.0)];
    let mut b = a.clone();
    scale_trace(&mut b[0], 2.0);
    let c = compare_sets(&a, &b, 5.0);
    assert!(
        !c.is_regression(),
        "a time without a yardstick cannot regress"
    );
    assert_eq!(c.notes.len(), 1);
    assert_eq!(c.notes[0].kind, FindingKind::NoYardstick);
    assert!(
        c.notes[0].message.contains("in A and B"),
        "{}",
        c.notes[0].message
    );
}

#[test]
fn bad_input_is_an_error() {
    let (da, db) = (TempDir::new("bad-a"), TempDir::new("bad-b"));
    write_set(da.path(), &base());
    let e = compare(da.path(), db.path(), 5.0).unwrap_err();
    assert!(
        matches!(e, ReportError::NoResults { .. }) && e.to_string().contains("results.jsonl"),
        "{e}"
    );
    write_set(db.path(), &base());
    assert!(matches!(
        compare(da.path(), db.path(), -1.0),
        Err(ReportError::BadThreshold(_))
    ));
    assert!(matches!(
        compare(da.path(), db.path(), f64::NAN),
        Err(ReportError::BadThreshold(_))
    ));
}

/// Paired ratios (engine and Embree timed back to back in one process), 1% spread around `q`.
fn pair(r: &mut RunRecord, q: f64) {
    r.paired_ratio = Some(samples(q, 0.01));
}

#[test]
fn paired_ratios_are_compared_when_both_runs_have_them() {
    let (mut a, mut b) = (base(), base());
    // Embree's separate run in B was unlucky: the separate-run ratio of grid/balls3 moves 40%...
    scale_trace(find(&mut b, "embree/balls3@1"), 0.6);
    // ...while the pairs timed in one process say grid is as fast as before.
    pair(find(&mut a, "grid/balls3@1"), 0.5);
    pair(find(&mut b, "grid/balls3@1"), 0.5);
    let c = compare_rounds(&a, &b, 5.0);
    assert!(
        c.regressions
            .iter()
            .all(|f| !f.key.starts_with("grid/balls3")),
        "{}",
        c.to_markdown()
    );
    // bvh2 on balls3 has no pairs: its separate-run ratio shows Embree's luck as a regression.
    assert!(c.regressions.iter().any(|f| f.key == "bvh2/balls3@1"));
    // A 20% slower engine in its pairs is a regression.
    pair(find(&mut b, "grid/balls3@1"), 0.6);
    let c = compare_rounds(&a, &b, 5.0);
    let f = regression(&c, "grid/balls3@1");
    assert!((f.change_pct.unwrap() - 20.0).abs() < 0.5, "{f:?}");
}

/// The regression `compare` found on `key`.
fn regression<'a>(c: &'a Comparison, key: &str) -> &'a rtbench_reports::Finding {
    c.regressions
        .iter()
        .find(|f| f.key == key)
        .unwrap_or_else(|| panic!("no regression on {key}: {}", c.to_markdown()))
}

/// Paired ratios in three rounds (`run --rounds 3`), each round's four pairs within 0.2 % of its
/// own figure: `q` scaled by `shifts[i]` in round i.
fn rounds(r: &mut RunRecord, q: f64, shifts: [f64; 3]) {
    let mut v = Vec::new();
    for s in shifts {
        v.extend([0.998, 1.0, 1.001, 1.002].map(|x| q * s * x));
    }
    r.paired_ratio = Some(rtbench_reports::Spread::of_ratios(&v));
    r.rounds = vec![
        rtbench_reports::Round {
            repeats: 1,
            pairs: 4,
            thread_pairs: 0
        };
        3
    ];
}

#[test]
fn with_rounds_a_process_shifted_as_a_whole_is_noise_and_a_slowdown_is_not() {
    // Same code: in B one process ran 7 % fast against Embree (all its pairs), as processes do.
    // Pooled, the pairs' median moves less but its interval is narrower still; by rounds, the
    // shift is the spread it is.
    let (mut a, mut b) = (base(), base());
    rounds(find(&mut a, "grid/balls3@1"), 7.7, [1.0, 1.0, 1.0]);
    rounds(find(&mut b, "grid/balls3@1"), 7.7, [1.0, 1.07, 1.0]);
    let c = compare_sets(&a, &b, 5.0);
    assert!(!c.is_regression(), "{}", c.to_markdown());
    // 10 % slower in every round: a regression, judged on 3 rounds a side.
    rounds(find(&mut a, "grid/balls3@1"), 7.7, [1.0, 1.01, 0.99]);
    rounds(find(&mut b, "grid/balls3@1"), 8.47, [1.0, 0.99, 1.01]);
    let c = compare_sets(&a, &b, 5.0);
    let f = regression(&c, "grid/balls3@1");
    assert_eq!(f.samples, Some([3, 3]));
    assert!(f.message.contains("3 rounds in A, 3 in B"), "{}", f.message);
    assert!((f.change_pct.unwrap() - 10.0).abs() < 0.5, "{f:?}");
}

/// A speed-up over one thread timed in pairs (`run --paired-threads`), 1% spread around `s`.
fn scaling(r: &mut RunRecord, s: f64) {
    let one: Vec<f64> = samples(1.0, 0.01).samples;
    let pairs: Vec<(f64, f64, f64, f64)> = one.iter().map(|&t| (t * s, t, t * s, t * s)).collect();
    r.thread_scaling = Some(rtbench_reports::ThreadScaling::of(2, &pairs));
}

#[test]
fn a_fallen_thread_speedup_is_a_regression() {
    let (mut a, mut b) = (base(), base());
    scaling(find(&mut a, "grid/balls3@1"), 1.9);
    scaling(find(&mut b, "grid/balls3@1"), 1.9);
    scaling(find(&mut a, "embree/balls3@1"), 1.8);
    scaling(find(&mut b, "embree/balls3@1"), 1.4);
    let c = compare_rounds(&a, &b, 5.0);
    let found: Vec<&str> = c
        .regressions
        .iter()
        .filter(|f| f.kind == FindingKind::ThreadSpeedup)
        .map(|f| f.key.as_str())
        .collect();
    assert_eq!(found, ["embree/balls3@1"], "{}", c.to_markdown());
    let f = c
        .regressions
        .iter()
        .find(|f| f.kind == FindingKind::ThreadSpeedup)
        .unwrap();
    assert!((f.change_pct.unwrap() + 22.2).abs() < 0.5, "{f:?}");
    // A risen speed-up is an improvement, not a regression.
    scaling(find(&mut b, "grid/balls3@1"), 2.0);
    let c = compare_rounds(&a, &b, 1.0);
    assert!(c
        .improvements
        .iter()
        .any(|f| f.kind == FindingKind::ThreadSpeedup && f.key == "grid/balls3@1"));
}

/// Sets from different machines say so (CPU flags, cores, memory, Embree), and the same machine
/// says nothing; a few MiB of memory between boots is the same machine.
#[test]
fn different_machines_are_named() {
    let (da, db) = (TempDir::new("mach-a"), TempDir::new("mach-b"));
    write_set(da.path(), &base());
    write_set(db.path(), &base());
    let same = compare(da.path(), db.path(), 5.0).unwrap();
    assert!(same.machine_differences.is_empty());
    assert!(!same.to_markdown().contains("different machines"));

    let mut env = common::environment();
    env.cpu_flags.push("avx512f".to_string());
    env.memory_bytes += 5 << 20;
    env.embree_version = Some("4.4.0".to_string());
    std::fs::write(
        db.path().join("env.json"),
        serde_json::to_string_pretty(&env).unwrap(),
    )
    .unwrap();
    let c = compare(da.path(), db.path(), 5.0).unwrap();
    assert_eq!(
        c.machine_differences,
        vec![
            "CPU flags only B has: avx512f".to_string(),
            "Embree 4.3.3 → 4.4.0".to_string()
        ]
    );
    let md = c.to_markdown();
    assert!(md.contains(
        "- **different machines**: CPU flags only B has: avx512f; Embree 4.3.3 → 4.4.0."
    ));
    // A note, not a verdict: the same runs still compare.
    assert!(!c.is_regression() && c.matched == 6);
}

#[test]
fn runs_of_another_image_size_are_not_compared() {
    let mut b = base();
    for r in b.iter_mut() {
        r.size = 128;
        r.counters.insert("primitive_tests".into(), 1);
    }
    let c = compare_sets(&base(), &b, 5.0);
    assert!(!c.is_regression(), "{}", c.to_markdown());
    assert_eq!(c.counters_compared + c.times_compared, 0);
    assert_eq!(c.notes.len(), 6);
    assert!(c
        .notes
        .iter()
        .all(|f| f.kind == FindingKind::DifferentWorkload && f.message.contains("128²")));
}
