//! The fuzzer at scale: `cargo run --release -p rtbench-tests --example fuzz -- [N] [SEED]
//! [nff|store|results|gltf|ply|obj|all]` (default 1000000 inputs per reader, seed 1, all readers). Prints one
//! line per reader; exits 1 when an input panicked (and writes it to fuzz-panic-READER.bin). Put
//! TMPDIR on a tmpfs (e.g. /dev/shm): store inputs are files, 25 times slower on a disk.

use rtbench_tests::fuzz::{corpus_dir, run, Target};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: u64 = args.first().map_or(1_000_000, |a| a.parse().expect("N"));
    let seed: u64 = args.get(1).map_or(1, |a| a.parse().expect("SEED"));
    let which = args.get(2).map_or("all", |s| s.as_str());
    let mut failed = false;
    for t in Target::ALL {
        if which != "all" && which != t.name() {
            continue;
        }
        let o = run(t, n, seed, &corpus_dir());
        println!(
            "{:<8} {} inputs in {:.1} s: {} accepted ({} of them changed stores), {} panics, \
             slowest input {:.3} s",
            t.name(),
            o.inputs,
            o.elapsed.as_secs_f64(),
            o.accepted,
            o.corrupt_accepted,
            o.panics,
            o.slowest.as_secs_f64()
        );
        failed |= o.corrupt_accepted > 0;
        if let Some((input, msg)) = &o.first_panic {
            failed = true;
            let file = format!("fuzz-panic-{}.bin", t.name());
            std::fs::write(&file, input).expect("write the failing input");
            println!("  first panic: {msg} (input in {file})");
        }
    }
    std::process::exit(i32::from(failed));
}
