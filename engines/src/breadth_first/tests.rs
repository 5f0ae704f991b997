//! The breadth-first engine answers as the grid engine does (same cells, same kernels) under
//! every registration policy and memory size, counts its passes and I/O, honours its budget,
//! and fails cleanly on bad settings and an unwritable spill directory.

use super::config::{Bytes, Registration};
use super::*;
use crate::geometry::Geometry;
use crate::test_support::{answers, kv, spd};
use crate::{build_engine, Counters, Hit, Ray};
use rtbench_scenes::spd::Program;

/// SplitMix64: the same rays every run.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        lo + (hi - lo) * Vec3::new(self.unit(), self.unit(), self.unit())
    }
}

/// Closest-hit rays from around the scene towards points in it, and segments between points.
fn rays_for(g: &Geometry, n: usize) -> (Vec<Ray>, Vec<Ray>) {
    let mut rng = Rng(7);
    let (lo, hi) = (g.bounds_min, g.bounds_max);
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let (wlo, whi) = (c - h * 1.5, c + h * 1.5);
    let mut closest = Vec::new();
    let mut any = Vec::new();
    for _ in 0..n {
        let o = rng.in_box(wlo, whi);
        let t = rng.in_box(lo, hi);
        closest.push(Ray::new(o, (t - o).normalize(), 0.0, f32::INFINITY));
        let a = rng.in_box(wlo, whi);
        let d = rng.in_box(lo, hi) - a;
        any.push(Ray::new(a, d / d.length(), 0.0, d.length()));
    }
    (closest, any)
}

#[test]
fn agrees_with_the_grid_under_every_policy_and_budget() {
    for (program, sf) in [
        (Program::Tetra, 3),
        (Program::Gears, 1),
        (Program::Balls, 2),
    ] {
        let input = spd(program, sf);
        let rays = rays_for(&input.geometry, 3000);
        let grid = build_engine("grid", &input, kv(&[("preset", "rss-r")])).unwrap();
        let (want_h, want_o) = answers(grid.as_ref(), &rays, &mut Counters::default());
        for settings in [
            vec![],
            vec![("registration", "fixed:1")],
            vec![("registration", "thesis"), ("floor", "in")],
            // A few hundred rays in memory: many refills; a small buffer: many read calls.
            vec![("memory", "200KiB"), ("buffer", "4KiB")],
        ] {
            let e = build_engine("breadth-first", &input, kv(&settings)).unwrap();
            let mut c = Counters::default();
            let (h, o) = answers(e.as_ref(), &rays, &mut c);
            let same_h = h
                .iter()
                .zip(&want_h)
                .filter(|(a, b)| a.object == b.object && a.t == b.t)
                .count();
            let same_o = o.iter().zip(&want_o).filter(|(a, b)| a == b).count();
            // The same cells and kernels: only ties of equal t may name another object.
            assert!(
                same_h >= h.len() - 2 && same_o == o.len(),
                "{program:?} {settings:?}: {same_h}/{} hits, {same_o}/{} any",
                h.len(),
                o.len()
            );
            assert!(want_h.iter().filter(|h| h.is_hit()).count() > 500);
            assert_eq!(c.rays, 6000);
            assert!(c.extra["bf_passes"] >= 2);
            assert!(e.failure().is_none());
        }
    }
}

#[test]
fn small_memory_means_more_passes_and_reads() {
    let input = spd(Program::Tetra, 4);
    let rays = rays_for(&input.geometry, 2000);
    let run = |settings: &[(&str, &str)]| {
        let e = build_engine("breadth-first", &input, kv(settings)).unwrap();
        let stats = e.build_stats();
        let mut c = Counters::default();
        answers(e.as_ref(), &rays, &mut c);
        (c, stats)
    };
    let (big, big_stats) = run(&[("registration", "fixed:1")]);
    let (small, small_stats) = run(&[
        ("registration", "fixed:1"),
        ("memory", "300KiB"),
        ("buffer", "1KiB"),
    ]);
    assert!(big_stats["rays_in_memory"] > 4000.0);
    let cap = small_stats["rays_in_memory"];
    assert!(cap > 10.0 && cap < 2000.0, "{cap}");
    // Everything the budget covers fits in it.
    let held = small_stats["voxels"] * 5.0 + 2.0 * 1024.0 + cap * small_stats["bytes_per_ray"];
    assert!(held <= 300.0 * 1024.0);
    assert!(small.extra["bf_passes"] > big.extra["bf_passes"]);
    // 1 KiB buffers over a store of many KiB: every sweep reads the files again.
    assert!(small.extra["io_read_calls"] > small.extra["bf_passes"]);
    assert!(small.extra["io_bytes_read"] > 0);
}

#[test]
fn settings_and_spill_errors() {
    let input = spd(Program::Tetra, 1);
    let bad = |pairs: &[(&str, &str)]| build_engine("breadth-first", &input, kv(pairs)).err();
    assert!(bad(&[("memory", "0")]).is_some());
    assert!(bad(&[("memory", "12XB")]).is_some());
    assert!(bad(&[("registration", "fixed:0")]).is_some());
    assert!(bad(&[("colour", "red")]).is_some());
    // Too small for the grid and one ray: refused, naming the budget.
    let e = bad(&[("memory", "100")]).unwrap().to_string();
    assert!(e.contains("too small"), "{e}");
    // A spill directory that does not exist (or cannot be written) is a build error.
    let e = bad(&[("spill", "/proc/no-such-dir")]).unwrap().to_string();
    assert!(e.contains("spill directory /proc/no-such-dir"), "{e}");
    assert_eq!("32MiB".parse::<Bytes>(), Ok(Bytes(32 << 20)));
    assert_eq!(
        "fixed:2".parse::<Registration>(),
        Ok(Registration::Fixed(2))
    );
    assert_eq!(Registration::thesis_count(19), 3);
}

#[test]
fn spill_directory_is_removed_on_drop() {
    let parent = std::env::temp_dir().join(format!("rtbench-bf-spill-test-{}", std::process::id()));
    std::fs::create_dir_all(&parent).unwrap();
    let input = spd(Program::Tetra, 1);
    let e = build_engine(
        "breadth-first",
        &input,
        kv(&[("spill", parent.to_str().unwrap())]),
    )
    .unwrap();
    assert_eq!(std::fs::read_dir(&parent).unwrap().count(), 1);
    drop(e);
    assert_eq!(std::fs::read_dir(&parent).unwrap().count(), 0);
    std::fs::remove_dir(&parent).unwrap();
}

/// The basic layout and every switch of §3.2–3.3 change how the answers are found, never the
/// answers: the same hits (object and t) and the same occlusion as the default engine.
#[test]
fn layouts_and_switches_give_the_same_answers() {
    for (program, sf) in [(Program::Tetra, 3), (Program::Balls, 2)] {
        let input = spd(program, sf);
        let rays = rays_for(&input.geometry, 1500);
        let base = build_engine("breadth-first", &input, vec![]).unwrap();
        let want = answers(base.as_ref(), &rays, &mut Counters::default());
        for settings in [
            vec![("layout", "basic")],
            vec![("lazy", "off")],
            vec![("boundary", "off")],
            vec![("prevskip", "off")],
            vec![("refill", "off"), ("memory", "200KiB")],
            vec![
                ("layout", "basic"),
                ("registration", "fixed:1"),
                ("count", "objects"),
            ],
        ] {
            let e = build_engine("breadth-first", &input, kv(&settings)).unwrap();
            let mut c = Counters::default();
            let got = answers(e.as_ref(), &rays, &mut c);
            let same = got
                .0
                .iter()
                .zip(&want.0)
                .all(|(a, b)| a.object == b.object && a.t == b.t);
            assert!(same && got.1 == want.1, "{program:?} {settings:?}");
            assert!(e.failure().is_none());
            let reads = c.extra["bf_geometry_records_read"];
            if settings[0].0 == "layout" || settings[0].0 == "lazy" {
                // Every object's geometry read in every sweep.
                let objects = input.scene.objects.len() as u64;
                assert!(reads >= objects * c.extra["bf_passes"], "{reads}");
            }
        }
        // Without boundary registration rays are registered in more voxels; without the
        // previous-voxel skip there are more box tests.
        let count = |s: &[(&str, &str)], key: &str| {
            let e = build_engine("breadth-first", &input, kv(s)).unwrap();
            let mut c = Counters::default();
            answers(e.as_ref(), &rays, &mut c);
            if key == "box_tests" {
                c.box_tests
            } else {
                c.extra[key]
            }
        };
        let reg1 = [("registration", "fixed:1")];
        assert!(
            count(&[reg1[0], ("boundary", "off")], "bf_passes") > count(&reg1, "bf_passes"),
            "{program:?}"
        );
        assert!(count(&[reg1[0], ("prevskip", "off")], "box_tests") > count(&reg1, "box_tests"));
    }
}

/// Registration 1 and the grid counted on objects: the ray–object tests equal the rss-r grid's
/// primitive tests (one primitive per object here), the premise of seed 000's Table 3.1.
#[test]
fn registration_one_makes_the_grids_tests() {
    for (program, sf, floor) in [(Program::Tetra, 3, "in"), (Program::Balls, 2, "out")] {
        let input = spd(program, sf);
        let rays = rays_for(&input.geometry, 2000);
        let grid = build_engine(
            "grid",
            &input,
            kv(&[("preset", "rss-r"), ("count", "objects"), ("floor", floor)]),
        )
        .unwrap();
        let mut gc = Counters::default();
        let mut hits = vec![Hit::MISS; rays.0.len()];
        grid.intersect(&rays.0, &mut hits, &mut gc);
        let bf = build_engine(
            "breadth-first",
            &input,
            kv(&[
                ("registration", "fixed:1"),
                ("count", "objects"),
                ("floor", floor),
                ("layout", "basic"),
            ]),
        )
        .unwrap();
        let mut bc = Counters::default();
        let mut hits = vec![Hit::MISS; rays.0.len()];
        bf.intersect(&rays.0, &mut hits, &mut bc);
        let bf_tests = bc.box_tests + bc.extra.get("bf_floor_tests").copied().unwrap_or(0);
        assert_eq!(bf.build_stats()["res_x"], grid.build_stats()["res_x"]);
        let diff = (bf_tests as f64 - gc.primitive_tests as f64).abs();
        assert!(
            diff <= 0.02 * gc.primitive_tests as f64,
            "{program:?}: bf {bf_tests} grid {}",
            gc.primitive_tests
        );
    }
}

/// A store of the other layout is refused with one line naming both layouts.
#[test]
fn wrong_layout_is_refused() {
    let input = spd(Program::Tetra, 1);
    let dir = crate::store::tests::TempDir::new("bf-layout");
    StoreWriter::create_layout(&dir.0, "x", crate::store::Layout::Basic)
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    let open = |layout: &str| {
        let s = Settings::new("breadth-first", kv(&[("layout", layout)]));
        BreadthFirst::open(&dir.0, BreadthFirstConfig::from_settings(s).unwrap())
    };
    let e = open("split").err().unwrap().to_string();
    assert!(e.contains("basic layout") && !e.contains('\n'), "{e}");
    assert!(open("basic").is_ok());
    let s = Settings::new("breadth-first", kv(&[("layout", "basic"), ("lazy", "on")]));
    assert!(BreadthFirstConfig::from_settings(s).is_err());
}

/// The calls of an in-memory trace may be served in any order (several threads take bands):
/// each call's counters, the I/O ones included, are the same whichever call came before it.
#[test]
fn a_call_counts_the_same_whichever_call_came_before() {
    let input = spd(Program::Gears, 1);
    let (rays, _) = rays_for(&input.geometry, 2000);
    let (a, b) = rays.split_at(1000);
    // Call `first`, then `then`, on a fresh engine: the second call's counters.
    let second = |first: &[Ray], then: &[Ray]| {
        let e = build_engine("breadth-first", &input, kv(&[])).unwrap();
        let mut hits = vec![Hit::MISS; first.len()];
        e.intersect(first, &mut hits, &mut Counters::default());
        let mut c = Counters::default();
        let mut hits = vec![Hit::MISS; then.len()];
        e.intersect(then, &mut hits, &mut c);
        (c, hits)
    };
    // `b` alone on a fresh engine, after `a`, and after `b` itself.
    let after_a = second(a, b);
    let after_b = second(b, b);
    let mut alone = Counters::default();
    let e = build_engine("breadth-first", &input, kv(&[])).unwrap();
    let mut hits = vec![Hit::MISS; b.len()];
    e.intersect(b, &mut hits, &mut alone);
    assert!(after_a.0.extra.get("io_bytes_read").copied().unwrap_or(0) > 0);
    for (what, (c, h)) in [("after a", &after_a), ("after b", &after_b)] {
        assert_eq!(c, &alone, "{what}: other counters than the call alone");
        assert_eq!(h, &hits, "{what}: other hits");
    }
}

/// A call made while another holds the engine's work (another thread's band) traces on a work
/// of its own over the same grid, with the hierarchy too, and answers and counts as it would
/// on the engine's work; calls from two threads at once do the same.
#[test]
fn calls_at_once_answer_and_count_as_calls_in_turn() {
    let input = spd(Program::Gears, 1);
    let (closest, any) = rays_for(&input.geometry, 2000);
    for sets in [&[][..], &[("hierarchy", "on")][..]] {
        let config = Settings::new("breadth-first", kv(sets));
        let e =
            BreadthFirst::from_scene(&input, BreadthFirstConfig::from_settings(config).unwrap())
                .unwrap();
        let call = |rays: &[Ray], shadow: bool| {
            let mut c = Counters::default();
            if shadow {
                let mut o = vec![false; rays.len()];
                e.occluded(rays, &mut o, &mut c);
                (
                    c,
                    o.iter()
                        .map(|&b| f32::from(u8::from(b)))
                        .collect::<Vec<_>>(),
                )
            } else {
                let mut h = vec![Hit::MISS; rays.len()];
                e.intersect(rays, &mut h, &mut c);
                (c, h.iter().map(|h| h.t).collect())
            }
        };
        let bands: Vec<(&[Ray], bool)> = closest
            .chunks(250)
            .map(|b| (b, false))
            .chain(any.chunks(250).map(|b| (b, true)))
            .collect();
        let in_turn: Vec<_> = bands.iter().map(|&(b, s)| call(b, s)).collect();
        {
            let _held = e.work.lock().unwrap();
            for (i, &(b, s)) in bands.iter().enumerate() {
                assert_eq!(call(b, s), in_turn[i], "{sets:?}: band {i} on a spare work");
            }
        }
        assert_eq!(
            e.spares.lock().unwrap().len(),
            1,
            "{sets:?}: one spare, kept"
        );
        let at_once: Vec<_> = std::thread::scope(|s| {
            let halves: Vec<_> = bands
                .chunks(bands.len() / 2)
                .map(|h| s.spawn(|| h.iter().map(|&(b, sh)| call(b, sh)).collect::<Vec<_>>()))
                .collect();
            halves.into_iter().flat_map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(at_once, in_turn, "{sets:?}: two threads at once");
        assert!(e.failure().is_none());
    }
}
