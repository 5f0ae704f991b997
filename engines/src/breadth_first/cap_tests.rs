//! The pass cap (`max_passes`, [`super::cap`]): the run stops after N passes over all its calls,
//! the counters of those passes kept and the stop reported; below the run's own pass count it
//! changes nothing.

use super::cap::CAP_REACHED;
use crate::build_engine;
use crate::test_support::{answers, kv, rays_around, spd};
use crate::Counters;
use rtbench_scenes::spd::Program;

#[test]
fn the_pass_cap_stops_after_n_passes_and_says_so() {
    let input = spd(Program::Mount, 5);
    let r = rays_around(&input.geometry, 3000, 99);
    for grid in ["cuberoot", "two-level"] {
        // Few rays in memory (`rays=200`): many passes.
        let run = |cap: Option<u64>| {
            let n = cap.map(|n| n.to_string());
            let mut sets = vec![("rays", "200"), ("grid", grid)];
            if let Some(n) = &n {
                sets.push(("max_passes", n.as_str()));
            }
            let e = build_engine("breadth-first", &input, kv(&sets)).unwrap();
            let mut c = Counters::default();
            let a = answers(e.as_ref(), &r, &mut c);
            (a, c)
        };
        let (whole, cw) = run(None);
        let total = cw.extra["bf_passes"];
        assert!(total >= 4, "{grid}: {total} passes");
        assert!(!cw.extra.contains_key(CAP_REACHED));
        // A cap above the run's passes: the same run.
        let (same, cs) = run(Some(total + 1));
        assert_eq!(same, whole, "{grid}");
        assert_eq!(cs.extra["bf_passes"], total);
        assert!(!cs.extra.contains_key(CAP_REACHED));
        // Capped at 2: two passes, fewer tests, the stop reported, the first pass's rays kept.
        let (_, cc) = run(Some(2));
        assert_eq!(cc.extra["bf_passes"], 2, "{grid}");
        assert_eq!(cc.extra[CAP_REACHED], 1, "{grid}");
        assert!(cc.primitive_tests < cw.primitive_tests, "{grid}");
        assert!(
            cc.extra["bf_pass_001_rays"] <= cw.extra["bf_pass_001_rays"],
            "{grid}"
        );
    }
}
