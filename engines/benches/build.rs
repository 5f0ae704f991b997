//! criterion micro-benchmarks of the parts of the BVH build: `cargo bench -p
//! rtbench-engines --bench build`. One binary SAH tree over the 36,610 triangles of gears4 (the
//! scene whose tree the change was made for), with 001's count (`block 1`, built to single
//! primitives, as the tree collapsed by default before) and with Embree's leaf rule (SAH in
//! blocks of 4, leaves of up to 16: `build_sah::binary_blocks`, the bvh4/bvh8 default now).

use criterion::{criterion_group, criterion_main, Criterion};
use rtbench_engines::bvh::build_sah::{binary, binary_blocks, Binned, BlockLeaves};
use rtbench_engines::bvh::tree::BuildPrims;
use rtbench_engines::geometry::Geometry;
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::hint::black_box;

fn builds(c: &mut Criterion) {
    let scene = generate_scene(Program::Gears, &Options::standard(Program::Gears)).unwrap();
    let prims = BuildPrims::new(&Geometry::from_scene(&scene));
    let all = vec![true; prims.len()];
    let mut g = c.benchmark_group("build");
    g.sample_size(10);
    g.bench_function("gears4_binned_block1_leaf1", |b| {
        b.iter(|| black_box(binary(Binned::new(black_box(&prims), 32), 1).nodes.len()))
    });
    g.bench_function("gears4_binned_block4_leaf4_16", |b| {
        let rule = BlockLeaves {
            min: 4,
            max: 16,
            block: 4,
            packable: &all,
        };
        b.iter(|| {
            let s = Binned::new(black_box(&prims), 32).with_block(4);
            black_box(binary_blocks(s, &rule).nodes.len())
        })
    });
    g.finish();
}

criterion_group!(benches, builds);
criterion_main!(benches);
