//! The fuzzer over the NFF, store, results and mesh readers at small scale (a few seconds); the large
//! run is `cargo run --release -p rtbench-tests --example fuzz`.

use rtbench_tests::fuzz::{corpus_dir, run, Target};

#[test]
fn mutated_inputs_never_panic_nor_hang() {
    // One test for the three readers: the driver swaps the process's panic hook while it runs.
    for (t, n) in [
        (Target::Nff, 5_000),
        (Target::Store, 400),
        (Target::Results, 800),
        (Target::Gltf, 3_000),
        (Target::Ply, 3_000),
        (Target::Obj, 3_000),
    ] {
        let o = run(t, n, 14, &corpus_dir());
        assert_eq!(o.inputs, n);
        if let Some((input, msg)) = &o.first_panic {
            panic!(
                "{}: {} of {n} inputs panicked; first: {msg} on {:?}",
                t.name(),
                o.panics,
                String::from_utf8_lossy(input)
            );
        }
        assert_eq!(
            o.corrupt_accepted,
            0,
            "{}: a changed store was read as good",
            t.name()
        );
        // Both answers occur: the mutations reach past the first check. A store changed in any
        // byte must be refused (checksums), so only a mutation that left its file as it was can
        // be accepted, which may not happen in 400 draws; `run` checks that every seed store
        // reads before mutating it.
        assert!(
            (o.accepted > 0 || t == Target::Store) && o.accepted < n,
            "{}: {} accepted",
            t.name(),
            o.accepted
        );
        assert!(
            o.slowest.as_secs_f64() < 10.0,
            "{}: {:?}",
            t.name(),
            o.slowest
        );
    }
}
