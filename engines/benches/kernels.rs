//! criterion micro-benchmarks of the shared ray–primitive kernels: `cargo bench -p rtbench-engines`
//! (the nightly suite runs them with short times and stores every estimate in its history).
//!
//! Each iteration answers the same 64 rays (fixed, spread over the primitive so that some hit and
//! some miss), so a benchmark's time is per 64 tests. `dda/walk_N_cells` walks one ray through N
//! grid cells: one DDA step costs its time over N.
//!
//! The 4- and 8-wide box tests are the scalar `ChildTest` forms and the 4-wide SSE form (`Sse4`, the
//! x86-64 baseline); the 8-wide AVX2 form runs only inside the engines' AVX2 entry points
//! (`bvh::dispatch`), so it is benchmarked through the bvh8 engine in the nightly suite. The 4- and
//! 8-wide SIMD triangle packets (`triangle_simd::closest4/8`) are benchmarked here.

use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec3;
use rtbench_engines::bvh::box_test::ChildTest;
use rtbench_engines::bvh::node::{WideNode, PLANES};
use rtbench_engines::geometry::aabb::SlabRay;
use rtbench_engines::geometry::kernels::f32 as k;
use rtbench_engines::geometry::lanes::{Scalar, Sse4};
use rtbench_engines::geometry::triangle_simd::{closest4, closest8, TrianglePacket};
use rtbench_engines::{Ray, TriangleTest};
use std::hint::black_box;

/// 64 rays from z = −5 towards the unit square around the origin, on an 8 × 8 lattice
/// spanning [−1.2, 1.2]²: those near the centre hit the primitives below, those at the rim miss.
fn rays() -> Vec<(Vec3, Vec3)> {
    let mut out = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            let target = Vec3::new(
                -1.2 + 2.4 * i as f32 / 7.0,
                -1.2 + 2.4 * j as f32 / 7.0,
                0.0,
            );
            let o = Vec3::new(0.1, -0.05, -5.0);
            out.push((o, (target - o).normalize()));
        }
    }
    out
}

const TRI: [Vec3; 3] = [
    Vec3::new(-1.0, -1.0, 0.0),
    Vec3::new(1.0, -1.0, 0.1),
    Vec3::new(0.0, 1.0, -0.1),
];

fn primitives(c: &mut Criterion) {
    let rays = rays();
    let mut g = c.benchmark_group("kernels");
    g.bench_function("triangle_watertight_x64", |b| {
        let w: Vec<_> = rays
            .iter()
            .map(|(_, d)| k::WatertightRay::new(*d))
            .collect();
        b.iter(|| {
            let mut n = 0u32;
            for ((o, _), w) in rays.iter().zip(&w) {
                n += k::triangle_watertight(*o, w, 0.0, f32::INFINITY, TRI[0], TRI[1], TRI[2])
                    .is_some() as u32;
            }
            black_box(n)
        })
    });
    g.bench_function("triangle_moller_x64", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (o, d) in &rays {
                n += k::triangle_moller(*o, *d, 0.0, f32::INFINITY, TRI[0], TRI[1], TRI[2])
                    .is_some() as u32;
            }
            black_box(n)
        })
    });
    g.bench_function("sphere_x64", |b| {
        b.iter(|| {
            let mut n = 0u32;
            for (o, d) in &rays {
                n += k::sphere(*o, *d, 0.0, f32::INFINITY, Vec3::ZERO, 0.8).is_some() as u32;
            }
            black_box(n)
        })
    });
    g.bench_function("cone_x64", |b| {
        let (base, apex) = (Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        b.iter(|| {
            let mut n = 0u32;
            for (o, d) in &rays {
                n += k::cone(*o, *d, 0.0, f32::INFINITY, base, 0.8, apex, 0.3).is_some() as u32;
            }
            black_box(n)
        })
    });
    // A hexagon as the engines see a polygon: its normal, then a fan of 4 watertight triangles.
    g.bench_function("polygon_hexagon_x64", |b| {
        let hex: Vec<Vec3> = (0..6)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 6.0;
                Vec3::new(a.cos(), a.sin(), 0.05 * i as f32)
            })
            .collect();
        let w: Vec<_> = rays
            .iter()
            .map(|(_, d)| k::WatertightRay::new(*d))
            .collect();
        b.iter(|| {
            let nrm = k::polygon_normal(black_box(&hex));
            let mut n = 0u32;
            for ((o, _), w) in rays.iter().zip(&w) {
                for t in 1..5 {
                    if k::triangle_watertight(*o, w, 0.0, f32::INFINITY, hex[0], hex[t], hex[t + 1])
                        .is_some()
                    {
                        n += 1;
                        break;
                    }
                }
            }
            black_box((n, nrm))
        })
    });
    g.finish();
}

/// A node of N children: boxes in a row along x, some crossed by the rays, some not.
fn node<const N: usize>() -> WideNode<N> {
    let mut planes = [[0.0f32; N]; PLANES];
    #[allow(clippy::needless_range_loop)] // i indexes the lanes of all six planes
    for i in 0..N {
        let x0 = -1.2 + 2.4 * i as f32 / N as f32;
        let lo = [x0, -0.5 + 0.1 * i as f32, -0.2];
        let hi = [x0 + 2.0 / N as f32, 0.6, 0.2];
        for a in 0..3 {
            planes[2 * a][i] = lo[a];
            planes[2 * a + 1][i] = hi[a];
        }
    }
    WideNode {
        planes,
        child: [0; N],
        len: N as u32,
    }
}

fn boxes<const N: usize, T: ChildTest<N>>(c: &mut Criterion, name: &str) {
    let n = node::<N>();
    let slabs: Vec<_> = rays()
        .iter()
        .map(|(o, d)| {
            let s = SlabRay::new(&Ray::new(*o, *d, 0.0, f32::INFINITY), 10.0);
            T::prepare(&s)
        })
        .collect();
    c.bench_function(name, |b| {
        b.iter(|| {
            let mut dist = [0.0f32; N];
            let mut m = 0u32;
            for r in &slabs {
                m ^= T::test(black_box(&n), r, 0.0, f32::INFINITY, &mut dist);
            }
            black_box(m)
        })
    });
}

fn box_tests(c: &mut Criterion) {
    boxes::<4, Scalar>(c, "box4_scalar_x64");
    boxes::<4, Sse4>(c, "box4_sse_x64");
    boxes::<8, Scalar>(c, "box8_scalar_x64");
}

fn packets(c: &mut Criterion) {
    let rays = rays();
    let tris: Vec<[Vec3; 3]> = (0..8)
        .map(|i| {
            let s = 0.2 * i as f32;
            [
                TRI[0] + Vec3::new(s, 0.0, s),
                TRI[1] + Vec3::new(s, 0.0, s),
                TRI[2] + Vec3::new(s, 0.0, s),
            ]
        })
        .collect();
    let p4 = TrianglePacket::<4>::new(&tris[..4]);
    let p8 = TrianglePacket::<8>::new(&tris);
    for (name, test) in [
        ("watertight", TriangleTest::Watertight),
        ("moller", TriangleTest::Moller),
    ] {
        c.bench_function(&format!("triangle4_{name}_x64"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                for (o, d) in &rays {
                    n += closest4(black_box(&p4), *o, *d, test, 0.0, f32::INFINITY)
                        .map_or(0, |h| h.0);
                }
                black_box(n)
            })
        });
        c.bench_function(&format!("triangle8_{name}_x64"), |b| {
            b.iter(|| {
                let mut n = 0usize;
                for (o, d) in &rays {
                    n += closest8(black_box(&p8), *o, *d, test, 0.0, f32::INFINITY)
                        .map_or(0, |h| h.0);
                }
                black_box(n)
            })
        });
    }
}

fn dda(c: &mut Criterion) {
    use rtbench_engines::grid::{config::GridConfig, traverse::dda_cells, Grid};
    use rtbench_engines::{geometry::Geometry, BuildInput, Settings};
    use rtbench_scenes::{
        generate_scene,
        spd::{Options, Program},
    };
    use std::sync::Arc;
    let scene = Arc::new(
        generate_scene(
            Program::Balls,
            &Options {
                size_factor: 4,
                ..Options::standard(Program::Balls)
            },
        )
        .expect("balls4 generates"),
    );
    let input = BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    };
    let config = GridConfig::from_settings(Settings::new("grid", vec![])).expect("default grid");
    let grid = Grid::build(&input, config).expect("grid builds");
    // A ray along the grid's diagonal, through every cell it meets.
    let ray = Ray::new(
        Vec3::new(-10.0, -10.0, -10.0),
        Vec3::ONE.normalize(),
        0.0,
        f32::INFINITY,
    );
    let cells = dda_cells(&grid, &ray);
    c.bench_function(&format!("dda_walk_{cells}_cells"), |b| {
        b.iter(|| black_box(dda_cells(black_box(&grid), &ray)))
    });
}

criterion_group!(benches, primitives, box_tests, packets, dda);
criterion_main!(benches);
