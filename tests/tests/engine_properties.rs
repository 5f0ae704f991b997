//! Properties every engine must have, on random scenes and random rays: a hit
//! has a finite t inside (tmin, tmax) and names an object of the scene; an any-hit answer agrees
//! with the closest-hit answer; and the engines agree with the f64 reference.

use glam::DVec3;
use proptest::prelude::*;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, registry, BuildInput, Counters, Hit, Ray};
use rtbench_scenes::{Material, Object, Scene, Shape};
use std::sync::Arc;

fn engines() -> Vec<&'static str> {
    registry()
        .into_iter()
        // `plugin` is built from a library named after it (`plugin:PATH`); its examples have their own tests.
        .filter(|e| (e.available)().is_ok() && !e.name.starts_with("test-") && e.name != "plugin")
        .map(|e| e.name)
        .collect()
}

fn v3() -> impl Strategy<Value = DVec3> {
    (-4.0..4.0f64, -4.0..4.0f64, -4.0..4.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (v3(), 0.01..1.5f64).prop_map(|(center, radius)| Shape::Sphere { center, radius }),
        (v3(), v3(), 0.0..0.8f64, 0.0..0.8f64).prop_map(|(base, apex, a, b)| Shape::Cone {
            base,
            base_radius: a + 0.01,
            apex: if (apex - base).length() < 1e-3 {
                base + DVec3::X
            } else {
                apex
            },
            apex_radius: b
        }),
        (v3(), v3(), v3()).prop_map(|(a, b, c)| Shape::Polygon(vec![a, b, c])),
        (v3(), 0.1..2.0f64).prop_map(|(c, s)| Shape::Polygon(vec![
            c,
            c + DVec3::new(s, 0.0, 0.0),
            c + DVec3::new(s, s, 0.0),
            c + DVec3::new(0.0, s, 0.0)
        ])),
    ]
}

fn scene() -> impl Strategy<Value = Scene> {
    proptest::collection::vec(shape(), 1..24).prop_map(|shapes| Scene {
        materials: vec![Material::default()],
        objects: shapes
            .into_iter()
            .map(|shape| Object { material: 0, shape })
            .collect(),
        ..Scene::default()
    })
}

fn ray() -> impl Strategy<Value = Ray> {
    (
        v3(),
        v3(),
        0.0..1.0f32,
        prop_oneof![Just(f32::INFINITY), 0.5..20.0f32],
    )
        .prop_filter_map("zero direction", |(o, d, tmin, tmax)| {
            let d = d.as_vec3();
            (d.length() > 1e-3).then(|| {
                Ray::new(
                    o.as_vec3() * 3.0,
                    d.normalize(),
                    tmin,
                    tmax.max(tmin + 1e-3),
                )
            })
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn hits_are_inside_the_segment_and_agree_with_any_hit(scene in scene(), rays in proptest::collection::vec(ray(), 64)) {
        let scene = Arc::new(scene);
        let input = BuildInput { geometry: Arc::new(Geometry::from_scene(&scene)), scene: scene.clone() };
        let reference = build_engine("reference", &input, vec![]).unwrap();
        let mut want = vec![Hit::MISS; rays.len()];
        reference.intersect(&rays, &mut want, &mut Counters::default());
        for name in engines() {
            let e = build_engine(name, &input, vec![]).unwrap();
            let mut hits = vec![Hit::MISS; rays.len()];
            let mut occ = vec![false; rays.len()];
            e.intersect(&rays, &mut hits, &mut Counters::default());
            e.occluded(&rays, &mut occ, &mut Counters::default());
            for ((r, h), (o, w)) in rays.iter().zip(&hits).zip(occ.iter().zip(&want)) {
                if h.is_hit() {
                    prop_assert!(h.t.is_finite(), "{name}: NaN or infinite t {h:?} for {r:?}");
                    prop_assert!(h.t >= r.tmin && h.t <= r.tmax, "{name}: t {} outside [{}, {}] for {r:?}", h.t, r.tmin, r.tmax);
                    prop_assert!((h.object as usize) < scene.objects.len(), "{name}: object {} of {}", h.object, scene.objects.len());
                }
                // Any-hit and closest-hit must agree on whether something is there, except for
                // hits grazing the segment's ends, where f32 rounding may fall either side.
                if *o != h.is_hit() {
                    let near_end = |t: f32| (t - r.tmin).abs() < 1e-4 * t.abs().max(1.0) || (t - r.tmax).abs() < 1e-4 * t.abs().max(1.0);
                    prop_assert!(w.is_hit() && near_end(w.t), "{name}: occluded {o} but closest hit {h:?} for {r:?}");
                }
            }
        }
    }
}

#[test]
fn every_available_engine_is_tested() {
    let names = engines();
    for must in [
        "reference",
        "grid",
        "bvh2",
        "bvh4",
        "bvh8",
        "obvhs",
        "object-space",
    ] {
        assert!(names.contains(&must), "{must} missing from {names:?}");
    }
}

/// A ray with a NaN or infinite origin or direction (a zero-radius sphere's NaN normal made
/// one) is a miss and not occluded in every engine: bvh4 and bvh8 used an empty slot's
/// sentinel as an index and panicked.
#[test]
fn untraceable_rays_are_misses_everywhere() {
    let mut scene = Scene::default();
    scene.materials.push(Material::default());
    for x in [-1.0, 0.0, 1.0, 2.0, 3.0] {
        scene.objects.push(Object {
            material: 0,
            shape: Shape::Sphere {
                center: DVec3::new(x, 0.0, 0.0),
                radius: 0.4,
            },
        });
    }
    let scene = Arc::new(scene);
    let input = BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    };
    let (n, i) = (f32::NAN, f32::INFINITY);
    let o = glam::Vec3::new(0.0, 0.0, -5.0);
    let z = glam::Vec3::Z;
    let rays = [
        Ray::new(glam::Vec3::splat(n), z, 0.0, i),
        Ray::new(o, glam::Vec3::splat(n), 0.0, i),
        Ray::new(o, glam::Vec3::new(n, 0.0, 1.0), 0.0, i),
        Ray::new(glam::Vec3::new(i, 0.0, -5.0), z, 0.0, i),
        Ray::new(o, glam::Vec3::new(0.0, -i, 1.0), 0.0, i),
        Ray::new(o, z, n, i),
        Ray::new(o, z, 0.0, n),
    ];
    for name in engines() {
        let e = build_engine(name, &input, vec![]).unwrap();
        let mut hits = vec![Hit::MISS; rays.len()];
        let mut occ = vec![true; rays.len()];
        e.intersect(&rays, &mut hits, &mut Counters::default());
        e.occluded(&rays, &mut occ, &mut Counters::default());
        for (k, (h, o)) in hits.iter().zip(&occ).enumerate() {
            assert!(!h.is_hit(), "{name}: ray {k} {:?} hit {h:?}", rays[k]);
            assert!(!o, "{name}: ray {k} {:?} occluded", rays[k]);
        }
    }
}
