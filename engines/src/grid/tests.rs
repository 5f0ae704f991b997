//! Tests of the `grid` engine: resolution policies, overlap tests, the cells a ray visits, and
//! agreement with brute force (same `f32` kernels: identical answers) and with the `reference`
//! engine (f64, original polygons) on small SPD scenes, for every policy and insertion mode.

use super::config::{Count, Floor, GridConfig, Insertion, Resolution};
use super::resolution::{cells_per_axis, total, MAX_CELLS};
use super::traverse::cells_along;
use super::{overlap, Grid};
use crate::engine::{BuildInput, Counters, Engine, EngineError, Settings};
use crate::geometry::Geometry;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use glam::{DVec3, Vec3};
use rtbench_scenes::spd::{Options, Program};
use rtbench_scenes::{generate_scene, Object, Scene, Shape};
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// Helpers

/// SplitMix64: a small deterministic generator, so every run traces the same rays.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(self.unit(), self.unit(), self.unit())
    }

    fn direction(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - Vec3::ONE;
            let l = v.length();
            if l > 0.05 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

fn input_of(scene: Scene) -> BuildInput {
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene: Arc::new(scene),
    }
}

fn spd(program: Program, sf: u32) -> BuildInput {
    let scene = generate_scene(
        program,
        &Options {
            size_factor: sf,
            ..Options::standard(program)
        },
    )
    .unwrap();
    input_of(scene)
}

fn shapes(shapes: Vec<Shape>) -> BuildInput {
    input_of(Scene {
        objects: shapes
            .into_iter()
            .map(|shape| Object { material: 0, shape })
            .collect(),
        ..Default::default()
    })
}

fn kv(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

fn grid(input: &BuildInput, pairs: &[(&str, &str)]) -> Grid {
    let config = GridConfig::from_settings(Settings::new("grid", kv(pairs))).unwrap();
    Grid::build(input, config).unwrap()
}

fn sphere(c: [f64; 3], r: f64) -> Shape {
    Shape::Sphere {
        center: c.into(),
        radius: r,
    }
}

/// Nearest hit over every primitive with the same kernels as the grid.
fn brute_closest(g: &Geometry, ray: &Ray) -> Hit {
    let wt = crate::geometry::kernels::f32::WatertightRay::new(ray.dir);
    let mut r = *ray;
    let mut best = Hit::MISS;
    for (i, p) in g.prims.iter().enumerate() {
        if let Some((t, u, v)) = p.intersect(&r, TriangleTest::Watertight, &wt) {
            r.tmax = t;
            best = Hit {
                t,
                object: g.prim_object[i],
                u,
                v,
            };
        }
    }
    best
}

fn brute_any(g: &Geometry, ray: &Ray) -> bool {
    let wt = crate::geometry::kernels::f32::WatertightRay::new(ray.dir);
    g.prims
        .iter()
        .any(|p| p.intersect(ray, TriangleTest::Watertight, &wt).is_some())
}

/// Rays for a scene: half from random points around the scene in random directions, half from
/// outside towards random points inside (so that most hit something); and segments between two
/// random points (for any-hit).
fn rays_for(g: &Geometry, n: usize, seed: u64) -> (Vec<Ray>, Vec<Ray>) {
    let mut rng = Rng(seed);
    let (lo, hi) = (g.bounds_min, g.bounds_max);
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let (wlo, whi) = (c - h * 1.5, c + h * 1.5);
    let mut closest = Vec::with_capacity(n);
    for i in 0..n {
        if i % 2 == 0 {
            let o = rng.in_box(wlo, whi);
            closest.push(Ray::new(o, rng.direction(), 0.0, f32::INFINITY));
        } else {
            let target = rng.in_box(lo, hi);
            let o = c + rng.direction() * h.length() * 3.0;
            closest.push(Ray::new(o, (target - o).normalize(), 0.0, f32::INFINITY));
        }
    }
    let mut any = Vec::with_capacity(n);
    for _ in 0..n {
        let a = rng.in_box(wlo, whi);
        let b = rng.in_box(lo, hi);
        let d = b - a;
        let len = d.length();
        any.push(Ray::new(a, d / len, 0.0, len));
    }
    (closest, any)
}

/// Same answer as `check`'s rule: both miss, the same object, or the same t within 1e-5.
fn agrees(want: &Hit, got: &Hit) -> bool {
    match (want.is_hit(), got.is_hit()) {
        (false, false) => true,
        (true, true) => {
            want.object == got.object
                || (want.t - got.t).abs() <= 1e-5 * want.t.abs().max(f32::MIN_POSITIVE)
        }
        _ => false,
    }
}

// ---------------------------------------------------------------------------------------------
// Settings

#[test]
fn config_defaults_presets_and_errors() {
    let c = |p: &[(&str, &str)]| GridConfig::from_settings(Settings::new("grid", kv(p)));
    let d = c(&[]).unwrap();
    assert_eq!(d, GridConfig::default());
    assert_eq!(d.resolution, Resolution::CubeRoot);
    assert_eq!(d.insertion, Insertion::BoundingBox);
    assert!(d.mailbox && d.shadow_cache && d.voxel_cull && d.floor == Floor::In);
    let rss = c(&[("preset", "rss")]).unwrap();
    assert!(rss.shadow_cache && rss.voxel_cull);
    let rssr = c(&[("preset", "rss-r")]).unwrap();
    assert!(!rssr.shadow_cache && !rssr.voxel_cull);
    let mixed = c(&[("preset", "rss-r"), ("voxel_cull", "true")]).unwrap();
    assert!(!mixed.shadow_cache && mixed.voxel_cull);
    let full = c(&[
        ("res", "woo"),
        ("density", "4"),
        ("insert", "exact"),
        ("floor", "out"),
        ("count", "objects"),
        ("mailbox", "false"),
        ("triangle", "moller"),
    ])
    .unwrap();
    assert_eq!(full.resolution, Resolution::Woo);
    assert_eq!(full.density, 4.0);
    assert_eq!(full.insertion, Insertion::Exact);
    assert_eq!(full.floor, Floor::Out);
    assert_eq!(full.count, Count::Objects);
    assert!(!full.mailbox);
    assert_eq!(full.triangle, TriangleTest::Moller);
    assert_eq!(
        c(&[("res", "8, 4,2")]).unwrap().resolution,
        Resolution::Explicit([8, 4, 2])
    );
    for bad in [
        vec![("res", "8,4")],
        vec![("res", "0,1,1")],
        vec![("res", "fine")],
        vec![("density", "2")],
        vec![("res", "woo"), ("density", "0")],
        vec![("res", "klimaszewski"), ("density", "lots")],
        vec![("insert", "clip")],
        vec![("preset", "rayshade")],
        vec![("floor", "maybe")],
    ] {
        assert!(
            matches!(c(&bad), Err(EngineError::BadValue { .. })),
            "{bad:?} should be a bad value"
        );
    }
    assert!(matches!(
        c(&[("leaf", "4")]),
        Err(EngineError::UnknownKey { .. })
    ));
}

// ---------------------------------------------------------------------------------------------
// Resolution

#[test]
fn resolution_policies_on_a_known_box() {
    let b = [4.0, 2.0, 1.0];
    let one = [1.0; 3];
    assert_eq!(
        cells_per_axis(Resolution::CubeRoot, b, 1000, 1.0, one),
        [10; 3]
    );
    // ⌊n^(1/3) + 0.5⌋: 91^(1/3) = 4.498 → 4, 92^(1/3) = 4.514 → 5.
    assert_eq!(
        cells_per_axis(Resolution::CubeRoot, b, 91, 1.0, one),
        [4; 3]
    );
    assert_eq!(
        cells_per_axis(Resolution::CubeRoot, b, 92, 1.0, one),
        [5; 3]
    );
    assert_eq!(cells_per_axis(Resolution::CubeRoot, b, 0, 1.0, one), [1; 3]);
    // Woo: (D·n / V)^(1/3) = (1000 / 8)^(1/3) = 5 cells per unit.
    assert_eq!(
        cells_per_axis(Resolution::Woo, b, 1000, 1.0, one),
        [20, 10, 5]
    );
    assert_eq!(
        cells_per_axis(Resolution::Woo, b, 1000, 8.0, one),
        [40, 20, 10]
    );
    // A flat box: the density goes to the two remaining axes.
    assert_eq!(
        cells_per_axis(Resolution::Woo, [4.0, 2.0, 0.0], 8, 1.0, one),
        [4, 2, 1]
    );
    // Klimaszewski: cubic primitives give Woo's cubes; primitives twice as long in x give cells
    // twice as long in x: s³ = (4/2)(2/1)(1/1) / 1000, cells 4/(2s), 2/s, 1/s = 12.6, 12.6, 6.3.
    assert_eq!(
        cells_per_axis(Resolution::Klimaszewski, b, 1000, 1.0, one),
        [20, 10, 5]
    );
    assert_eq!(
        cells_per_axis(Resolution::Klimaszewski, b, 1000, 1.0, [2.0, 1.0, 1.0]),
        [13, 13, 6]
    );
    // Flat primitives (extent 0 in z) are held at 1:16 of the others.
    let flat = cells_per_axis(
        Resolution::Klimaszewski,
        [1.0; 3],
        1000,
        1.0,
        [1.0, 1.0, 0.0],
    );
    assert_eq!(flat[0], flat[1]);
    assert!(flat[2] > flat[0] * 8, "{flat:?}");
    assert_eq!(
        cells_per_axis(Resolution::Explicit([3, 5, 7]), b, 1000, 1.0, one),
        [3, 5, 7]
    );
    // The cap keeps proportions.
    let big = cells_per_axis(Resolution::Woo, [1.0; 3], 1_000_000_000, 1.0, one);
    assert!(total(big) <= MAX_CELLS && big[0] == big[1] && big[1] == big[2] && big[0] > 300);
}

// ---------------------------------------------------------------------------------------------
// Overlap

#[test]
fn overlap_tests() {
    let (lo, hi) = (DVec3::ZERO, DVec3::ONE);
    let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // A triangle through the box; two on the planes x + y + z = 3.1 (missing the box's corner,
    // though their bounding boxes overlap it) and 2.9 (cutting the corner); and one separated
    // only by an edge axis.
    assert!(overlap::triangle_box(
        d(-1.0, 0.5, 0.5),
        d(2.0, 0.5, 0.5),
        d(0.5, 2.0, 0.5),
        lo,
        hi
    ));
    assert!(!overlap::triangle_box(
        d(0.1, 1.5, 1.5),
        d(1.5, 0.1, 1.5),
        d(1.5, 1.5, 0.1),
        lo,
        hi
    ));
    assert!(overlap::triangle_box(
        d(0.1, 1.4, 1.4),
        d(1.4, 0.1, 1.4),
        d(1.4, 1.4, 0.1),
        lo,
        hi
    ));
    assert!(!overlap::triangle_box(
        d(1.5, -0.5, 0.5),
        d(-0.5, 1.5, 0.5),
        d(1.5, 1.5, 0.5),
        d(0.0, 0.0, 0.0),
        d(0.4, 0.4, 1.0)
    ));
    assert!(overlap::triangle_box(
        d(1.5, -0.5, 0.5),
        d(-0.5, 1.5, 0.5),
        d(1.5, 1.5, 0.5),
        d(0.0, 0.0, 0.0),
        d(0.6, 0.6, 1.0)
    ));
    // Sphere surface: crossing, missing, and a box wholly inside the ball.
    assert!(overlap::sphere_surface_box(d(0.5, 0.5, 1.5), 0.7, lo, hi));
    assert!(!overlap::sphere_surface_box(d(0.5, 0.5, 2.5), 0.7, lo, hi));
    assert!(!overlap::sphere_surface_box(d(0.5, 0.5, 0.5), 5.0, lo, hi));
    // Cylinder along z through the box, one beside it (its bounding box reaches the box's
    // corner but the cylinder does not), one wholly past the end.
    assert!(overlap::cone_box(
        d(0.5, 0.5, -1.0),
        0.2,
        d(0.5, 0.5, 2.0),
        0.2,
        lo,
        hi
    ));
    // Along the line x + y = 2.3 (0.21 from the box's corner), radius 0.1: its bounding box
    // overlaps the box, the axis e_z × w separates them; radius 0.3 reaches the corner.
    let (b, a) = (d(2.8, -0.5, 0.5), d(-0.5, 2.8, 0.5));
    assert!(!overlap::cone_box(b, 0.1, a, 0.1, lo, hi));
    assert!(overlap::cone_box(b, 0.3, a, 0.3, lo, hi));
    assert!(!overlap::cone_box(
        d(0.5, 0.5, 1.5),
        0.3,
        d(0.5, 0.5, 3.0),
        0.0,
        lo,
        hi
    ));
}

// ---------------------------------------------------------------------------------------------
// Build and walk on a hand-made scene

/// Two unit spheres in the corners of a 4×4×4 box: cells are unit cubes (up to the padding).
fn corners() -> BuildInput {
    shapes(vec![
        sphere([0.5, 0.5, 0.5], 0.5),
        sphere([3.5, 3.5, 3.5], 0.5),
    ])
}

#[test]
fn compact_layout_and_build_stats() {
    let input = corners();
    let bbox = grid(&input, &[("res", "4,4,4")]);
    let c = bbox.cells();
    assert_eq!(c.lattice.res, [4, 4, 4]);
    assert_eq!(c.offsets.len(), 65);
    // Each sphere's box [0,1]³ reaches the neighbouring cells by the padding: 8 cells each.
    assert_eq!(c.refs.len(), 16);
    assert_eq!(*c.offsets.last().unwrap() as usize, c.refs.len());
    assert_eq!(c.prims_in(c.lattice.index([0, 0, 0])), &[0]);
    assert_eq!(c.prims_in(c.lattice.index([1, 1, 1])), &[0]);
    assert_eq!(c.prims_in(c.lattice.index([2, 2, 2])), &[1]);
    assert!(c.prims_in(c.lattice.index([3, 0, 0])).is_empty());
    let s = bbox.build_stats();
    assert_eq!(s["cells"], 64.0);
    assert_eq!(s["references"], 16.0);
    assert_eq!(s["empty_cells"], 64.0 - 16.0);
    // Exact: the surface reaches only its own cell and, at single points, the three face
    // neighbours (by the padding); not the edge and corner neighbours.
    let exact = grid(&input, &[("res", "4,4,4"), ("insert", "exact")]);
    let c = exact.cells();
    assert_eq!(c.refs.len(), 8);
    assert_eq!(c.prims_in(c.lattice.index([1, 0, 0])), &[0]);
    assert!(c.prims_in(c.lattice.index([1, 1, 0])).is_empty());
    assert!(c.prims_in(c.lattice.index([1, 1, 1])).is_empty());
    assert!(exact.structure_bytes() >= (65 + 8) * 4);
    // A resolution with an axis of no cells, which the parser refuses, is refused when built in
    // code too: the walk reads every lattice cell's offsets unchecked.
    let zero = GridConfig {
        resolution: Resolution::Explicit([0, 4, 4]),
        ..GridConfig::default()
    };
    assert!(matches!(
        Grid::build(&input, zero),
        Err(EngineError::Build { .. })
    ));
}

#[test]
fn ray_visits_the_expected_cells() {
    let g = grid(&corners(), &[("res", "4,4,4")]);
    // In the z = 0 layer, y = 0.25 + 0.5·(x + 1): crosses y = 1 at x = 0.5 and y = 2 at x = 2.5.
    let r = Ray::new(
        Vec3::new(-1.0, 0.25, 0.5),
        Vec3::new(1.0, 0.5, 0.0).normalize(),
        0.0,
        f32::INFINITY,
    );
    assert_eq!(
        cells_along(&g, &r),
        vec![
            [0, 0, 0],
            [0, 1, 0],
            [1, 1, 0],
            [2, 1, 0],
            [2, 2, 0],
            [3, 2, 0]
        ]
    );
    // The same line backwards, starting inside the grid, and ending (tmax) in cell (1, 1, 0).
    let p = Vec3::new(3.5, 2.5, 0.5);
    let back = Ray::new(p, -r.dir, 0.0, (p - Vec3::new(1.5, 1.5, 0.5)).length());
    assert_eq!(
        cells_along(&g, &back),
        vec![[3, 2, 0], [2, 2, 0], [2, 1, 0], [1, 1, 0]]
    );
    // Along an axis (two direction components zero), and a ray that misses the box.
    let axis = Ray::new(Vec3::new(2.5, 1.5, 9.0), -Vec3::Z, 0.0, f32::INFINITY);
    assert_eq!(
        cells_along(&g, &axis),
        vec![[2, 1, 3], [2, 1, 2], [2, 1, 1], [2, 1, 0]]
    );
    let miss = Ray::new(Vec3::new(-1.0, 5.0, 0.5), Vec3::X, 0.0, f32::INFINITY);
    assert!(cells_along(&g, &miss).is_empty());
}

#[test]
fn hits_wait_for_their_cell_and_mailboxes_count() {
    // A: a slanted triangle listed in every cell along the ray, hit at x = 2.217; B: a small
    // sphere hit at x = 1.313. The grid has 4 cells of 0.95 along x from 0.1, so A is tested in
    // the first cell but its hit lies two cells on, beyond B's hit in the second cell.
    let a = Shape::Polygon(vec![
        DVec3::new(0.1, 0.0, -1.5),
        DVec3::new(0.1, 1.0, -1.5),
        DVec3::new(3.9, 0.5, 2.0),
    ]);
    let b = sphere([1.5, 0.5, 0.5], 0.2);
    let (ta, tb) = (1.0 + 0.1 + 3.8 * 1.95 / 3.5, 1.0 + 1.5 - 0.035f32.sqrt());
    let ray = Ray::new(Vec3::new(-1.0, 0.45, 0.45), Vec3::X, 0.0, f32::INFINITY);
    for pairs in [
        vec![("res", "4,4,4"), ("preset", "rss-r")],
        vec![("res", "4,4,4"), ("preset", "rss-r"), ("mailbox", "false")],
        vec![("res", "4,4,4")],
    ] {
        let both = grid(&shapes(vec![a.clone(), b.clone()]), &pairs);
        let mut h = [Hit::MISS];
        let mut c = Counters::default();
        both.intersect(&[ray], &mut h, &mut c);
        assert_eq!(h[0].object, 1, "{pairs:?}");
        assert!((h[0].t - tb).abs() < 1e-4, "{pairs:?}: {:?}", h[0]);
        assert_eq!((c.rays, c.cells_visited), (1, 2), "{pairs:?}");
        // Past B, A's hit comes out.
        let past = Ray::new(Vec3::new(1.8, 0.45, 0.45), Vec3::X, 0.0, f32::INFINITY);
        both.intersect(&[past], &mut h, &mut c);
        assert_eq!(h[0].object, 0, "{pairs:?}");
        assert!((h[0].t - (ta - 2.8)).abs() < 1e-4, "{pairs:?}: {:?}", h[0]);
        // Without B, A's hit, found in the first cell, must still come out two cells later
        // although the mailbox keeps A from being tested again there.
        let alone = grid(&shapes(vec![a.clone()]), &pairs);
        let mut c = Counters::default();
        alone.intersect(&[ray], &mut h, &mut c);
        assert_eq!(h[0].object, 0, "{pairs:?}");
        assert!((h[0].t - ta).abs() < 1e-4, "{pairs:?}: {:?}", h[0]);
        assert_eq!(c.cells_visited, 3, "{pairs:?}");
        // A segment that ends before A's hit misses.
        let short = Ray::new(ray.origin, ray.dir, 0.0, ta - 0.01);
        alone.intersect(&[short], &mut h, &mut c);
        assert!(!h[0].is_hit(), "{pairs:?}");
    }
    // Mailboxes: a ray through a big sphere's bounding box but past the sphere meets it in every
    // cell: tested once with mailboxes, once per cell without.
    let input = shapes(vec![
        sphere([2.0, 2.0, 2.0], 1.9),
        sphere([0.5, 0.5, 0.5], 0.3),
        sphere([3.9, 3.9, 3.9], 0.1),
    ]);
    let ray = Ray::new(Vec3::new(-1.0, 3.7, 0.3), Vec3::X, 0.0, f32::INFINITY);
    let count = |pairs: &[(&str, &str)]| {
        let g = grid(&input, pairs);
        let mut h = [Hit::MISS];
        let mut c = Counters::default();
        g.intersect(&[ray], &mut h, &mut c);
        assert!(!h[0].is_hit());
        c
    };
    let with = count(&[("res", "8,8,8"), ("preset", "rss-r")]);
    let without = count(&[("res", "8,8,8"), ("preset", "rss-r"), ("mailbox", "false")]);
    assert_eq!(with.cells_visited, 8);
    assert_eq!((with.primitive_tests, with.mailbox_skips), (1, 7));
    assert_eq!((without.primitive_tests, without.mailbox_skips), (8, 0));
    // Voxel culling: the sphere's box holds the ray's piece of the first cell, so it passes the
    // box test there and the mailbox answers for the other cells.
    let culled = count(&[("res", "8,8,8")]);
    assert_eq!((culled.box_tests, culled.primitive_tests), (1, 1));
    // An exact grid lists the sphere only in cells its surface reaches: the ray's row near the
    // box corner holds fewer listings.
    let exact = count(&[("res", "8,8,8"), ("insert", "exact")]);
    assert!(exact.primitive_tests <= 1 && exact.empty_cells_visited > 0);
}

// ---------------------------------------------------------------------------------------------
// Agreement on SPD scenes

/// Small SPD scenes, each with a few hundred objects at most.
fn small_scenes() -> Vec<(Program, BuildInput)> {
    [
        (Program::Balls, 2),
        (Program::Gears, 1),
        (Program::Mount, 2),
        (Program::Rings, 1),
        (Program::Teapot, 2),
        (Program::Tetra, 3),
        (Program::Tree, 4),
    ]
    .into_iter()
    .map(|(p, sf)| (p, spd(p, sf)))
    .collect()
}

#[test]
fn agrees_with_brute_force_and_reference_for_every_policy_and_insertion() {
    let policies = ["cuberoot", "woo", "klimaszewski", "5,3,4"];
    let inserts = ["bbox", "exact"];
    let mut extras: Vec<Vec<(&str, &str)>> = Vec::new();
    for p in policies {
        for i in inserts {
            extras.push(vec![("res", p), ("insert", i)]);
        }
    }
    extras.push(vec![("res", "woo"), ("density", "8"), ("insert", "exact")]);
    extras.push(vec![("preset", "rss-r")]);
    extras.push(vec![
        ("preset", "rss"),
        ("insert", "exact"),
        ("floor", "out"),
    ]);
    extras.push(vec![("floor", "out"), ("res", "klimaszewski")]);
    extras.push(vec![("mailbox", "false"), ("count", "objects")]);
    for (program, input) in small_scenes() {
        let geo = &input.geometry;
        let (closest, any) = rays_for(geo, 300, 7 + program as u64);
        let want: Vec<Hit> = closest.iter().map(|r| brute_closest(geo, r)).collect();
        let want_any: Vec<bool> = any.iter().map(|r| brute_any(geo, r)).collect();
        let reference = crate::build_engine("reference", &input, vec![]).unwrap();
        let mut ref_hits = vec![Hit::MISS; closest.len()];
        reference.intersect(&closest, &mut ref_hits, &mut Counters::default());
        let mut ref_any = vec![false; any.len()];
        reference.occluded(&any, &mut ref_any, &mut Counters::default());
        let hits = want.iter().filter(|h| h.is_hit()).count();
        assert!(hits > 60, "{program:?}: only {hits} of 300 rays hit");
        for pairs in &extras {
            let g = grid(&input, pairs);
            let mut got = vec![Hit::MISS; closest.len()];
            let mut c = Counters::default();
            g.intersect(&closest, &mut got, &mut c);
            let mut got_any = vec![false; any.len()];
            g.occluded(&any, &mut got_any, &mut c);
            assert_eq!(c.rays, 600);
            for (i, (w, h)) in want.iter().zip(&got).enumerate() {
                // Same kernels on the same primitives: the nearest t is the same number.
                assert!(
                    w.is_hit() == h.is_hit() && (!w.is_hit() || w.t == h.t),
                    "{program:?} {pairs:?} ray {i} {:?}: brute force {w:?}, grid {h:?}",
                    closest[i]
                );
            }
            for (i, (w, h)) in want_any.iter().zip(&got_any).enumerate() {
                assert_eq!(w, h, "{program:?} {pairs:?} any-hit ray {i} {:?}", any[i]);
            }
            let agree = ref_hits
                .iter()
                .zip(&got)
                .filter(|(w, h)| agrees(w, h))
                .count()
                + ref_any.iter().zip(&got_any).filter(|(w, h)| w == h).count();
            assert!(
                agree >= 598,
                "{program:?} {pairs:?}: {agree} of 600 agree with the reference"
            );
        }
    }
}

#[test]
fn threads_tracing_at_once_get_the_serial_answers_and_counts() {
    let input = spd(Program::Tetra, 4);
    let g = grid(&input, &[("preset", "rss")]);
    let (closest, any) = rays_for(&input.geometry, 2000, 99);
    let mut serial = vec![Hit::MISS; closest.len()];
    let mut sc = Counters::default();
    g.intersect(&closest, &mut serial, &mut sc);
    let mut serial_any = vec![false; any.len()];
    g.occluded(&any, &mut serial_any, &mut sc);

    let mut par = vec![Hit::MISS; closest.len()];
    let mut par_any = vec![false; any.len()];
    let counters: Vec<Counters> = std::thread::scope(|s| {
        let handles: Vec<_> = closest
            .chunks(250)
            .zip(par.chunks_mut(250))
            .zip(any.chunks(250).zip(par_any.chunks_mut(250)))
            .map(|((r, h), (ra, o))| {
                let g = &g;
                s.spawn(move || {
                    let mut c = Counters::default();
                    g.intersect(r, h, &mut c);
                    g.occluded(ra, o, &mut c);
                    c
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(serial, par);
    assert_eq!(serial_any, par_any);
    let mut pc = Counters::default();
    for c in &counters {
        pc.add(c);
    }
    // Every counter but the shadow cache's is per ray; the cache lives per batch, so the split
    // into batches may change which rays it answers (never the answers).
    assert_eq!(
        (pc.rays, pc.cells_visited, pc.empty_cells_visited),
        (sc.rays, sc.cells_visited, sc.empty_cells_visited)
    );
}

#[test]
fn shadow_cache_answers_the_same_and_hits() {
    let input = spd(Program::Balls, 2);
    let lights: Vec<Vec3> = input
        .scene
        .lights
        .iter()
        .map(|l| l.position.as_vec3())
        .collect();
    // Shadow rays as the workload makes them: from each hit point (in scan order) towards each
    // light in turn, ending a millionth short of it.
    let eye = input.scene.view.from.as_vec3();
    let plain = grid(&input, &[("preset", "rss-r")]);
    let mut eye_rays = Vec::new();
    let (lo, hi) = (Vec3::new(-2.0, -2.0, 0.0), Vec3::new(2.0, 2.0, 1.0));
    for j in 0..30 {
        for i in 0..30 {
            let target = lo + (hi - lo) * Vec3::new(i as f32 / 29.0, j as f32 / 29.0, 0.0);
            eye_rays.push(Ray::new(
                eye,
                (target - eye).normalize(),
                0.0,
                f32::INFINITY,
            ));
        }
    }
    let mut hits = vec![Hit::MISS; eye_rays.len()];
    plain.intersect(&eye_rays, &mut hits, &mut Counters::default());
    let mut shadow = Vec::new();
    for (r, h) in eye_rays.iter().zip(&hits).filter(|(_, h)| h.is_hit()) {
        let p = r.at(h.t * 0.9999);
        for l in &lights {
            let d = *l - p;
            shadow.push(Ray::new(p, d.normalize(), 0.0, d.length() * (1.0 - 1e-6)));
        }
    }
    let mut want = vec![false; shadow.len()];
    let mut cw = Counters::default();
    plain.occluded(&shadow, &mut want, &mut cw);
    let blocked = want.iter().filter(|b| **b).count();
    assert!(blocked > 20, "only {blocked} of {} blocked", shadow.len());
    assert_eq!(cw.shadow_cache_hits, 0);
    for pairs in [
        vec![("preset", "rss-r"), ("shadow_cache", "true")],
        vec![("insert", "exact")],
    ] {
        let cached = grid(&input, &pairs);
        let mut got = vec![false; shadow.len()];
        let mut c = Counters::default();
        cached.occluded(&shadow, &mut got, &mut c);
        assert_eq!(want, got, "{pairs:?}");
        assert!(c.shadow_cache_hits > 0, "{pairs:?}: no cache hits");
        assert!(c.primitive_tests < cw.primitive_tests, "{pairs:?}");
        let misses = c.extra.get("shadow_cache_misses").copied().unwrap_or(0);
        assert!(misses + c.shadow_cache_hits <= shadow.len() as u64);
    }
}

#[test]
fn floor_goes_out_of_the_grid_when_asked() {
    for (program, sf, expect_floor) in [
        (Program::Balls, 1, true),
        (Program::Gears, 1, true),
        (Program::Rings, 1, true),
        (Program::Tree, 2, true),
        (Program::Tetra, 2, false),
        (Program::Teapot, 2, false),
        (Program::Mount, 2, false),
    ] {
        let input = spd(program, sf);
        let inside = grid(&input, &[]);
        let out = grid(&input, &[("floor", "out")]);
        assert!(inside.floor().is_empty());
        assert_eq!(
            !out.floor().is_empty(),
            expect_floor,
            "{program:?}: {} floor primitives",
            out.floor().len()
        );
        let s = out.build_stats();
        assert_eq!(
            s["grid_primitives"] + s["floor_primitives"],
            input.geometry.prims.len() as f64
        );
        if expect_floor {
            // Without the floor the grid shrinks to the objects standing on it.
            let (a, b) = (inside.cells(), out.cells());
            assert!(
                (b.lattice.hi - b.lattice.lo).length() < (a.lattice.hi - a.lattice.lo).length(),
                "{program:?}"
            );
        }
    }
}
