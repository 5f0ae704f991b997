//! `rtbench check --suite hard`: the hard cases, acne and speed against error, per engine
//! variant (see `mod.rs`).

use super::acne::{self, Acne};
use super::cases::{self, CaseSet};
use super::score::{self, Tally};
use super::speed::{self, Speed};
use super::truth::{self, Truth};
use super::Variant;
use crate::error::{Failure, Result};
use crate::workload::camera::Camera;
use crate::workload::trace;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput, Counters, Hit, Ray};
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;
use std::time::Instant;

/// Eye rays through the corners of a `SIZE`×`SIZE` image on each standard scene, for acne.
const ACNE_SIZE: u32 = 64;

/// What one engine variant gave.
pub struct VariantResult {
    pub variant: Variant,
    /// Per case set (in `cases::all` order): the category and the tally.
    pub tallies: Vec<(String, Tally)>,
    /// Acne per case set, and per standard scene.
    pub acne_cases: Vec<(String, Acne)>,
    pub acne_standard: Vec<(String, Acne)>,
    pub speed: Option<Speed>,
    /// Builds that failed (an engine that cannot take a case scene), with the reason.
    pub errors: Vec<String>,
    pub seconds: f64,
}

impl VariantResult {
    /// The tally over the sets whose category starts with `prefix` ("" for all).
    pub fn total(&self, prefix: &str) -> Tally {
        let mut t = Tally::default();
        for (c, x) in &self.tallies {
            if c.starts_with(prefix) {
                t.add(x);
            }
        }
        t
    }

    pub fn acne_standard_total(&self) -> Acne {
        let mut a = Acne::default();
        for (_, x) in &self.acne_standard {
            a.add(x);
        }
        a
    }
}

/// Everything the suite measured.
pub struct HardResults {
    pub results: Vec<VariantResult>,
    /// Per case set: category, rays, rays whose right answer is ambiguous.
    pub case_rays: Vec<(String, usize, usize)>,
    pub seconds: f64,
}

fn input_of(scene: Arc<rtbench_scenes::Scene>) -> BuildInput {
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    }
}

/// Runs the cases of `sets` (with their right answers) and the acne measurement on `standard`
/// for one variant.
fn run_variant(
    v: &Variant,
    sets: &[(CaseSet, Vec<Truth>)],
    standard: &[(String, BuildInput, Vec<Ray>)],
    speed_inputs: &[BuildInput],
) -> VariantResult {
    let t0 = Instant::now();
    let mut r = VariantResult {
        variant: v.clone(),
        tallies: Vec::new(),
        acne_cases: Vec::new(),
        acne_standard: Vec::new(),
        speed: None,
        errors: Vec::new(),
        seconds: 0.0,
    };
    for (set, truth) in sets {
        let input = BuildInput {
            scene: set.scene.clone(),
            geometry: set.geometry.clone(),
        };
        let engine = match build_engine(&v.engine, &input, v.settings.clone()) {
            Ok(e) => e,
            Err(e) => {
                r.errors.push(format!("{}: {e}", set.category));
                continue;
            }
        };
        let mut hits = Vec::new();
        trace::query_all(
            engine.batch_hint(),
            &set.rays,
            &mut hits,
            Hit::MISS,
            &mut Counters::default(),
            |a, h, c| engine.intersect(a, h, c),
        );
        let tally = score::score(
            &set.rays,
            &hits,
            truth,
            &set.must_hit_by,
            set.scene.objects.len(),
        );
        r.tallies.push((set.category.clone(), tally));
        r.acne_cases.push((
            set.category.clone(),
            acne::measure(&set.scene, engine.as_ref(), &set.rays),
        ));
    }
    for (name, input, rays) in standard {
        match build_engine(&v.engine, input, v.settings.clone()) {
            Ok(e) => r
                .acne_standard
                .push((name.clone(), acne::measure(&input.scene, e.as_ref(), rays))),
            Err(e) => r.errors.push(format!("{name}: {e}")),
        }
    }
    match speed::measure(v, speed_inputs) {
        Ok(s) => r.speed = Some(s),
        Err(e) => r.errors.push(format!("speed: {e}")),
    }
    r.seconds = t0.elapsed().as_secs_f64();
    r
}

/// Generates the cases and their answers, runs every variant, writes the report to `out`.
pub fn run(variants: &[Variant]) -> Result<HardResults> {
    let t0 = Instant::now();
    let sets: Vec<(CaseSet, Vec<Truth>)> = cases::all()
        .into_iter()
        .map(|s| {
            let t = truth::answers(&s.scene, &s.rays);
            (s, t)
        })
        .collect();
    eprintln!(
        "hard cases: {} sets, {} rays, answers in f64 ({:.1} s)",
        sets.len(),
        sets.iter().map(|(s, _)| s.rays.len()).sum::<usize>(),
        t0.elapsed().as_secs_f64()
    );
    let standard: Vec<(String, BuildInput, Vec<Ray>)> = Program::STANDARD
        .iter()
        .map(|&p| {
            let scene =
                generate_scene(p, &Options::standard(p)).expect("standard SPD options are valid");
            let cam = Camera::new(&scene.view);
            let mut rays = Vec::new();
            for j in 0..=ACNE_SIZE {
                for i in 0..=ACNE_SIZE {
                    rays.push(cam.corner_ray(i, j, ACNE_SIZE));
                }
            }
            (
                format!("{}{}", p.name(), p.standard_sf()),
                input_of(Arc::new(scene)),
                rays,
            )
        })
        .collect();
    let speed_inputs: Vec<BuildInput> = speed::scenes()
        .into_iter()
        .map(|(p, sf)| {
            let mut scene =
                generate_scene(p, &speed::options(p, sf)).expect("speed scenes are valid");
            scene.name = format!("{}{sf}", p.name());
            input_of(Arc::new(scene))
        })
        .collect();
    let mut results = Vec::new();
    for v in variants {
        let r = run_variant(v, &sets, &standard, &speed_inputs);
        let total = r.total("");
        eprintln!(
            "{}: {} rays, {} leaks, {} false hits, {} misses, acne on standard scenes {}/{} ({:.1} s)",
            v.label(),
            total.rays,
            total.leaks,
            total.false_hits,
            total.misses,
            r.acne_standard_total().acne,
            r.acne_standard_total().secondary,
            r.seconds
        );
        results.push(r);
    }
    let h = HardResults {
        results,
        case_rays: sets
            .iter()
            .map(|(s, t)| {
                (
                    s.category.clone(),
                    s.rays.len(),
                    t.iter().filter(|x| !x.stable).count(),
                )
            })
            .collect(),
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok(h)
}

/// Exit status 1 when an engine broke the hit contract (NaN t, t outside (tmin, tmax), unknown
/// object): that is a bug wherever it happens. Leaks, acne and errors are findings, reported.
pub fn verdict(h: &HardResults) -> Result<()> {
    let bad: Vec<String> = h
        .results
        .iter()
        .filter(|r| r.total("").invalid > 0)
        .map(|r| {
            format!(
                "{} ({} invalid hits)",
                r.variant.label(),
                r.total("").invalid
            )
        })
        .collect();
    if bad.is_empty() {
        Ok(())
    } else {
        Err(Failure::Check(format!(
            "hits outside (tmin, tmax), NaN or naming no object: {}",
            bad.join(", ")
        )))
    }
}

#[cfg(test)]
mod tests {
    //! The suite's machinery on planted faults: a triangle test that drops rays on edges must
    //! show leaks, a tracer without the offset policy must show acne, and the shared watertight
    //! kernel must show neither.

    use super::*;
    use rtbench_engines::geometry::kernels::f32 as k;
    use rtbench_engines::geometry::Prim;
    use rtbench_engines::{Engine, TriangleTest};

    /// Brute force over the prepared triangles; `strict_edges` plants the classic bug (a hit
    /// needs every barycentric strictly inside), `no_offset` makes rays start behind where the
    /// offset put them (as a tracer without an offset would).
    struct Planted {
        prims: Vec<Prim>,
        objects: Vec<u32>,
        strict_edges: bool,
        no_offset: bool,
    }

    impl Planted {
        fn build(set: &CaseSet, strict_edges: bool, no_offset: bool) -> Planted {
            Planted {
                prims: set.geometry.prims.clone(),
                objects: set.geometry.prim_object.clone(),
                strict_edges,
                no_offset,
            }
        }

        fn trace(&self, ray: &Ray) -> Hit {
            let mut r = *ray;
            if self.no_offset {
                r.origin -= r.dir * 1e-3;
                r.tmin = 0.0;
            }
            let wt = k::WatertightRay::new(r.dir);
            let mut best = Hit::MISS;
            for (i, p) in self.prims.iter().enumerate() {
                let found = p.intersect(&r, TriangleTest::Watertight, &wt);
                if let Some((t, u, v)) = found {
                    let on_edge = u <= 0.0 || v <= 0.0 || u + v >= 1.0;
                    if t < best.t && !(self.strict_edges && on_edge) {
                        best = Hit {
                            t,
                            object: self.objects[i],
                            u,
                            v,
                        };
                    }
                }
            }
            best
        }
    }

    impl Engine for Planted {
        fn intersect(&self, rays: &[Ray], hits: &mut [Hit], _: &mut Counters) {
            for (r, h) in rays.iter().zip(hits) {
                *h = self.trace(r);
            }
        }
        fn occluded(&self, rays: &[Ray], o: &mut [bool], _: &mut Counters) {
            for (r, x) in rays.iter().zip(o) {
                *x = self.trace(r).is_hit();
            }
        }
        fn structure_bytes(&self) -> u64 {
            0
        }
    }

    fn leaks_and_acne(set: &CaseSet, e: &Planted) -> (u64, u64, u64) {
        let truth = truth::answers(&set.scene, &set.rays);
        let mut hits = vec![Hit::MISS; set.rays.len()];
        e.intersect(&set.rays, &mut hits, &mut Counters::default());
        let t = score::score(
            &set.rays,
            &hits,
            &truth,
            &set.must_hit_by,
            set.scene.objects.len(),
        );
        let a = acne::measure(&set.scene, e, &set.rays);
        (t.leaks, t.must_hit, a.acne)
    }

    #[test]
    fn planted_leaks_and_acne_are_found_and_the_watertight_kernel_has_neither() {
        let tetra = cases::watertight().swap_remove(0);
        let (leaks, must, acne) = leaks_and_acne(&tetra, &Planted::build(&tetra, false, false));
        assert!(must > 50, "too few must-hit rays: {must}");
        assert_eq!((leaks, acne), (0, 0), "the watertight kernel");
        let (leaks, _, _) = leaks_and_acne(&tetra, &Planted::build(&tetra, true, false));
        assert!(
            leaks > 10,
            "a kernel that drops edges leaked only {leaks} times"
        );
        let (_, _, acne) = leaks_and_acne(&tetra, &Planted::build(&tetra, false, true));
        assert!(
            acne > 10,
            "a tracer without an offset showed only {acne} acne"
        );
    }
}
