use super::*;

#[test]
fn config_defaults_and_device_string() {
    let c = EmbreeConfig::from_settings(Settings::new("embree", vec![])).unwrap();
    assert_eq!(c, EmbreeConfig::default());
    assert_eq!(c.device_config(), "threads=1,verbose=0");
    let kv = |k: &str, v: &str| (k.to_string(), v.to_string());
    let c = EmbreeConfig::from_settings(Settings::new(
        "embree",
        vec![
            kv("threads", "0"),
            kv("quality", "high"),
            kv("robust", "true"),
            kv("isa", "avx2"),
        ],
    ))
    .unwrap();
    assert_eq!(
        (c.threads, c.quality, c.robust, c.compact),
        (0, Quality::High, true, false)
    );
    assert_eq!(c.device_config(), "threads=0,verbose=0,isa=avx2");
}

#[test]
fn config_rejects_unknown_keys_and_values() {
    let kv = |k: &str, v: &str| vec![(k.to_string(), v.to_string())];
    let err = |s| EmbreeConfig::from_settings(Settings::new("embree", s)).unwrap_err();
    assert!(matches!(
        err(kv("leaf", "4")),
        EngineError::UnknownKey { .. }
    ));
    assert!(matches!(
        err(kv("quality", "best")),
        EngineError::BadValue { .. }
    ));
    assert!(matches!(
        err(kv("isa", "avx2,threads=8")),
        EngineError::BadValue { .. }
    ));
    assert!(matches!(
        err(kv("threads", "-1")),
        EngineError::BadValue { .. }
    ));
}

#[cfg(not(feature = "embree"))]
#[test]
fn unavailable_without_the_feature() {
    assert_eq!(
        (info().available)(),
        Err("built without the embree feature".to_string())
    );
    assert!(version().is_err());
}

#[cfg(feature = "embree")]
mod with_embree {
    use super::super::*;
    use crate::engine::Counters;
    use crate::geometry::Geometry;
    use crate::ray::{Hit, Ray};
    use glam::{DVec3, Vec3};
    use rtbench_scenes::{Object, Scene, Shape};
    use std::sync::Arc;

    fn input(shapes: Vec<Shape>) -> BuildInput {
        let scene = Scene {
            objects: shapes
                .into_iter()
                .map(|shape| Object { material: 0, shape })
                .collect(),
            ..Default::default()
        };
        BuildInput {
            geometry: Arc::new(Geometry::from_scene(&scene)),
            scene: Arc::new(scene),
        }
    }

    /// Builds through the registry entry itself (whether or not `registry()` lists it).
    fn build_embree(
        input: &BuildInput,
        settings: Vec<(String, String)>,
    ) -> Result<Box<dyn Engine>, EngineError> {
        (info().build)(input, Settings::new("embree", settings))
    }

    fn engine(shapes: Vec<Shape>, settings: &[(&str, &str)]) -> Box<dyn Engine> {
        let settings = settings
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        build_embree(&input(shapes), settings).unwrap()
    }

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Shape {
        Shape::Patch {
            vertices: vec![a.into(), b.into(), c.into()],
            normals: vec![DVec3::Z; 3],
        }
    }

    fn trace(e: &dyn Engine, r: Ray) -> (Hit, bool, Counters) {
        let mut c = Counters::default();
        let mut h = [Hit::MISS];
        let mut o = [false];
        e.intersect(&[r], &mut h, &mut c);
        e.occluded(&[r], &mut o, &mut c);
        (h[0], o[0], c)
    }

    #[test]
    fn available_and_versioned() {
        assert_eq!((info().available)(), Ok(()));
        let v = version().unwrap();
        assert!(v.starts_with("4."), "{v}");
    }

    #[test]
    fn one_ray_one_triangle() {
        let e = engine(
            vec![tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])],
            &[],
        );
        let (h, occ, c) = trace(
            &*e,
            Ray::new(Vec3::new(0.25, 0.5, -1.0), Vec3::Z, 0.0, f32::INFINITY),
        );
        assert_eq!(h.object, 0);
        assert!((h.t - 1.0).abs() < 1e-6, "{h:?}");
        // u, v weigh vertices 1 and 2, as the shared kernels do.
        assert!(
            (h.u - 0.25).abs() < 1e-6 && (h.v - 0.5).abs() < 1e-6,
            "{h:?}"
        );
        assert!(occ);
        assert_eq!(c.rays, 2);
        // Miss beside it, and a segment that ends before it.
        let (h, occ, _) = trace(
            &*e,
            Ray::new(Vec3::new(0.75, 0.75, -1.0), Vec3::Z, 0.0, f32::INFINITY),
        );
        assert!(!h.is_hit() && !occ);
        let (h, occ, _) = trace(
            &*e,
            Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, 0.0, 0.5),
        );
        assert!(!h.is_hit() && !occ);
    }

    #[test]
    fn spheres_and_cones_through_the_shared_kernels() {
        let e = engine(
            vec![
                tri([-10.0, -10.0, 10.0], [10.0, -10.0, 10.0], [0.0, 10.0, 10.0]),
                Shape::Sphere {
                    center: DVec3::new(0.0, 0.0, 0.0),
                    radius: 1.0,
                },
                Shape::Cone {
                    base: DVec3::new(5.0, 0.0, -1.0),
                    base_radius: 1.0,
                    apex: DVec3::new(5.0, 0.0, 1.0),
                    apex_radius: 0.0,
                },
            ],
            &[],
        );
        // Sphere from outside, then from inside (a refraction ray): the far side.
        let (h, occ, c) = trace(
            &*e,
            Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, f32::INFINITY),
        );
        assert_eq!(h.object, 1);
        assert!((h.t - 4.0).abs() < 1e-5 && occ, "{h:?}");
        // The occlusion query may stop at the triangle behind without testing the sphere.
        assert!(
            c.extra["user_primitive_tests"] >= 1 && c.extra["user_primitive_hits"] >= 1,
            "{c:?}"
        );
        let (h, _, _) = trace(&*e, Ray::new(Vec3::ZERO, Vec3::Z, 1e-4, f32::INFINITY));
        assert_eq!(h.object, 1);
        assert!((h.t - 1.0).abs() < 1e-5, "{h:?}");
        // Cone: radius 0.5 at z = 0, so a ray along x at z = 0 hits at x = 4.5.
        let (h, occ, _) = trace(
            &*e,
            Ray::new(Vec3::new(2.0, 0.0, 0.0), Vec3::X, 0.0, f32::INFINITY),
        );
        assert_eq!(h.object, 2);
        assert!((h.t - 2.5).abs() < 1e-5 && occ, "{h:?}");
        // Open: in through the missing base cap, onto the inside wall where the radius is 0.5.
        let (h, _, _) = trace(
            &*e,
            Ray::new(Vec3::new(5.0, 0.5, -5.0), Vec3::Z, 0.0, f32::INFINITY),
        );
        assert_eq!(h.object, 2, "{h:?}");
        assert!((h.t - 5.0).abs() < 1e-4, "{h:?}");
        // Past the cone, onto the triangle.
        let (h, _, _) = trace(
            &*e,
            Ray::new(Vec3::new(5.0, -5.0, -5.0), Vec3::Z, 0.0, f32::INFINITY),
        );
        assert_eq!(h.object, 0, "{h:?}");
        assert!((h.t - 15.0).abs() < 1e-4, "{h:?}");
    }

    #[test]
    fn concave_polygon_hits_name_the_polygon() {
        // An L-shaped polygon (object 1) behind a small triangle (object 0) off to the side.
        let l: Vec<DVec3> = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let e = engine(
            vec![
                tri([5.0, 5.0, 0.0], [6.0, 5.0, 0.0], [5.0, 6.0, 0.0]),
                Shape::Polygon(l),
            ],
            &[],
        );
        let at = |x: f32, y: f32| trace(&*e, Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z, 0.0, 10.0)).0;
        assert_eq!(at(0.5, 0.5).object, 1);
        assert_eq!(at(0.5, 1.5).object, 1);
        assert_eq!(at(1.7, 0.3).object, 1);
        assert!(!at(1.5, 1.5).is_hit());
        assert_eq!(at(5.2, 5.2).object, 0);
    }

    #[test]
    fn empty_scene_misses() {
        let e = engine(vec![], &[]);
        let (h, occ, _) = trace(&*e, Ray::new(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY));
        assert!(!h.is_hit() && !occ);
    }

    /// A seeded generator: the same scenes and rays every run.
    struct Rng(fastrand::Rng);
    impl Rng {
        fn new(seed: u64) -> Rng {
            Rng(fastrand::Rng::with_seed(seed))
        }
        fn f(&mut self) -> f64 {
            self.0.f64()
        }
        fn v(&mut self, lo: f64, hi: f64) -> DVec3 {
            DVec3::new(self.f(), self.f(), self.f()) * (hi - lo) + DVec3::splat(lo)
        }
    }

    fn random_scene(rng: &mut Rng) -> Vec<Shape> {
        let mut shapes = Vec::new();
        for i in 0..300 {
            let c = rng.v(-10.0, 10.0);
            shapes.push(match i % 4 {
                0 => Shape::Sphere {
                    center: c,
                    radius: 0.2 + rng.f(),
                },
                1 => Shape::Cone {
                    base: c,
                    base_radius: 0.2 + 0.5 * rng.f(),
                    apex: c + rng.v(-1.5, 1.5),
                    apex_radius: 0.5 * rng.f(),
                },
                2 => tri(
                    (c + rng.v(-1.0, 1.0)).into(),
                    (c + rng.v(-1.0, 1.0)).into(),
                    (c + rng.v(-1.0, 1.0)).into(),
                ),
                _ => {
                    let (a, b) = (rng.v(-1.0, 1.0), rng.v(-1.0, 1.0));
                    Shape::Polygon(vec![c, c + a, c + a + b, c + b])
                }
            });
        }
        shapes
    }

    /// Embree's packet calls (`api=packet8`, `packet16`) answer exactly as its single-ray calls,
    /// spheres and cones (user geometry, called with N lanes) included; 1,003 rays leave a
    /// short, masked last packet.
    #[test]
    fn packets_answer_as_single_rays() {
        let mut rng = Rng::new(0x2545F4914F6CDD1D);
        let inp = input(random_scene(&mut rng));
        let rays: Vec<Ray> = (0..1003)
            .map(|_| {
                let o = rng.v(-15.0, 15.0).as_vec3();
                let d = (rng.v(-12.0, 12.0).as_vec3() - o).normalize();
                Ray::new(o, d, 0.0, if rng.f() < 0.3 { 10.0 } else { f32::INFINITY })
            })
            .collect();
        let answers = |api: &str| {
            let e = build_embree(&inp, vec![("api".to_string(), api.to_string())]).unwrap();
            let mut h = vec![Hit::MISS; rays.len()];
            let mut o = vec![false; rays.len()];
            let mut c = Counters::default();
            e.intersect(&rays, &mut h, &mut c);
            e.occluded(&rays, &mut o, &mut c);
            assert_eq!(c.rays, 2 * rays.len() as u64);
            (
                h,
                o,
                c.extra.get("user_primitive_tests").copied().unwrap_or(0) > 0,
            )
        };
        let single = answers("single");
        assert!(single.0.iter().filter(|h| h.is_hit()).count() > 200);
        assert!(single.2, "no sphere or cone was tested");
        for api in ["packet8", "packet16"] {
            let p = answers(api);
            assert_eq!((&p.0, &p.1), (&single.0, &single.1), "{api}");
        }
    }

    #[test]
    fn agrees_with_the_reference_engine() {
        let mut rng = Rng::new(0x9E3779B97F4A7C15);
        let shapes = random_scene(&mut rng);
        let inp = input(shapes);
        let reference = crate::build_engine("reference", &inp, vec![]).unwrap();
        for settings in [vec![], vec![("robust".to_string(), "true".to_string())]] {
            let embree = build_embree(&inp, settings).unwrap();
            let rays: Vec<Ray> = (0..4000)
                .map(|_| {
                    let o = rng.v(-15.0, 15.0).as_vec3();
                    let d = (rng.v(-12.0, 12.0).as_vec3() - o).normalize();
                    Ray::new(o, d, 0.0, if rng.f() < 0.3 { 10.0 } else { f32::INFINITY })
                })
                .collect();
            let (mut he, mut hr) = (vec![Hit::MISS; rays.len()], vec![Hit::MISS; rays.len()]);
            let (mut oe, mut or) = (vec![false; rays.len()], vec![false; rays.len()]);
            let mut c = Counters::default();
            embree.intersect(&rays, &mut he, &mut c);
            reference.intersect(&rays, &mut hr, &mut c);
            embree.occluded(&rays, &mut oe, &mut c);
            reference.occluded(&rays, &mut or, &mut c);
            let hits = hr.iter().filter(|h| h.is_hit()).count();
            assert!(hits > rays.len() / 4, "too few hits to compare: {hits}");
            let mut disagree = 0;
            for (e, r) in he.iter().zip(&hr) {
                if e.object != r.object {
                    disagree += 1;
                } else if r.is_hit() {
                    assert!((e.t - r.t).abs() <= 1e-3 * r.t.max(1.0), "{e:?} vs {r:?}");
                }
            }
            let occ_disagree = oe.iter().zip(&or).filter(|(a, b)| a != b).count();
            // f32 against f64 disagrees only on grazing rays and shared edges: a handful at most.
            assert!(
                disagree <= rays.len() / 500,
                "{disagree} of {} rays disagree",
                rays.len()
            );
            assert!(
                occ_disagree <= rays.len() / 500,
                "{occ_disagree} occlusion answers disagree"
            );
            assert_eq!(c.rays, 4 * rays.len() as u64);
        }
    }

    /// Engines of one configuration share the process's one device, never released (releasing
    /// it let oneTBB start a worker that spun beside the trace), and each still
    /// reports its own scene's bytes: two builds of one scene read the same, before and after
    /// another engine on the device is dropped.
    #[test]
    fn engines_share_one_device_and_count_their_own_bytes() {
        let cfg = EmbreeConfig::default().device_config();
        let d = raw::Device::shared(&cfg).unwrap();
        assert!(std::ptr::eq(d, raw::Device::shared(&cfg).unwrap()));
        let mut rng = Rng::new(11);
        let inp = input(random_scene(&mut rng));
        let bytes = |e: &dyn crate::engine::Engine| {
            let s = e.build_stats();
            (s["embree_bytes"], s["embree_peak_bytes"])
        };
        let a = build_embree(&inp, vec![]).unwrap();
        let b = build_embree(&inp, vec![]).unwrap();
        let (ab, bb) = (bytes(a.as_ref()), bytes(b.as_ref()));
        assert!(ab.0 > 0.0 && ab.1 >= ab.0, "{ab:?}");
        assert_eq!(ab, bb);
        drop(a);
        let c = build_embree(&inp, vec![]).unwrap();
        assert_eq!(bytes(c.as_ref()), ab);
        assert_eq!(b.structure_bytes(), c.structure_bytes());
    }

    #[test]
    fn memory_and_stats_are_reported() {
        let mut rng = Rng::new(7);
        let inp = input(random_scene(&mut rng));
        let e = build_embree(&inp, vec![]).unwrap();
        let s = e.build_stats();
        assert!(
            s["embree_bytes"] > 0.0 && s["embree_peak_bytes"] >= s["embree_bytes"],
            "{s:?}"
        );
        assert!(s["embree_bytes"] >= s["embree_buffer_bytes"], "{s:?}");
        assert!(e.structure_bytes() as f64 >= s["embree_bytes"] + s["own_bytes"] - 0.5);
        assert_eq!(
            s["triangles"] as usize,
            inp.geometry
                .prims
                .iter()
                .filter(|p| matches!(p, crate::geometry::Prim::Triangle(_)))
                .count()
        );
        assert_eq!(s["user_primitives"], 150.0);
        assert!(s["embree_version"] >= 40000.0);
    }

    #[test]
    fn answers_from_several_threads_at_once() {
        let mut rng = Rng::new(11);
        let inp = input(random_scene(&mut rng));
        let e = build_embree(&inp, vec![("threads".into(), "2".into())]).unwrap();
        let rays: Vec<Ray> = (0..2000)
            .map(|_| {
                Ray::new(
                    rng.v(-15.0, 15.0).as_vec3(),
                    rng.v(-1.0, 1.0).as_vec3(),
                    0.0,
                    f32::INFINITY,
                )
            })
            .collect();
        let run = || {
            let mut h = vec![Hit::MISS; rays.len()];
            e.intersect(&rays, &mut h, &mut Counters::default());
            h
        };
        let (a, b) = std::thread::scope(|s| {
            let a = s.spawn(run);
            let b = s.spawn(run);
            (a.join().unwrap(), b.join().unwrap())
        });
        assert_eq!(a, b);
        assert_eq!(a, run());
    }
}
