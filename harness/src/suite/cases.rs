//! The hard cases: small scenes, each with rays chosen to hit a numerical weak spot.
//! Every case is made in f64 and rounded to the `f32` rays engines take; its right answer is
//! computed afterwards in f64 on those rays (`truth.rs`). Categories:
//!
//! - `watertight-tetra`, `-sphere`, `-cone`, `-gear`: rays through points on the edges and at the vertices of closed meshes
//!   (`meshes.rs`), along the axes (exactly through the rounded point) and along the faces'
//!   normals and random directions. Only directions that cross the surface there are kept
//!   (every adjacent face sees the ray on the same side, by a margin), so each ray must hit the
//!   solid at or before the point: a miss, or a first hit beyond it, is a leak.
//! - `zero-dir`: axis-aligned rays (zero direction components, +0.0 and −0.0) and rays with one
//!   zero component, all lying in planes through object bounds, the scene's bounds and its
//!   halves, thirds … eighths (where grid cells and BVH nodes have their boundaries).
//! - `grazing`: rays in the planes of box faces and of tilted quads, and just above and below.
//! - `tangent`: rays tangent to spheres, and 1e-7 and 1e-4 (relative) inside and outside.
//! - `inside`: rays starting inside spheres (refraction rays do), towards anywhere.
//! - `near`, `far-1e3`, `far-1e5`, `far-1e7`, `scale-1e-4` … `scale-1e4`: one mixed scene
//!   (spheres, cones, a cylinder, boxes, a tetrahedron) with random rays, as is and translated
//!   or scaled.
//! - `degenerate`: the teapot's lid (SPD teapot, whose patches at the lid's and the body's poles
//!   collapse to zero area), triangles with repeated or collinear vertices, slivers, spheres of
//!   radius zero and cones of height zero. Zero-area, zero-radius and zero-height objects have
//!   no surface: the right answer never names them.
//! - `coplanar`: overlapping squares in one plane; the right answer is the lowest object id.

use super::meshes::{self, Mesh};
use glam::DVec3;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::Ray;
use rtbench_scenes::spd::{Options, Program};
use rtbench_scenes::{generate_scene, Light, Material, Object, Scene, Shape, View};
use std::sync::Arc;

/// One scene of cases and its rays.
pub struct CaseSet {
    pub category: String,
    pub scene: Arc<Scene>,
    pub geometry: Arc<Geometry>,
    pub rays: Vec<Ray>,
    /// For rays known to cross a closed surface: the t by which they must have hit it.
    pub must_hit_by: Vec<Option<f32>>,
}

/// A ray in f64, before the set's transform and the rounding to f32.
#[derive(Clone, Copy)]
struct Spec {
    o: DVec3,
    d: DVec3,
    /// A point of a closed surface on the ray: the ray must hit by then.
    through: Option<DVec3>,
}

/// Deterministic random numbers (SplitMix64), so every run tests the same rays.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
    /// Uniform on the unit sphere.
    pub fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A scene of `shapes` (one white material, two lights) with the view looking at the origin.
fn scene(name: &str, shapes: Vec<Shape>, s: f64, t: DVec3) -> Scene {
    Scene {
        name: name.to_string(),
        view: View {
            from: DVec3::new(2.0, 3.0, 8.0) * s + t,
            at: t,
            up: DVec3::Z,
            angle: 40.0,
            hither: 0.0,
            resolution: [64, 64],
        },
        background: DVec3::ZERO,
        lights: [DVec3::new(5.0, 6.0, 7.0), DVec3::new(-6.0, 4.0, -5.0)]
            .into_iter()
            .map(|p| Light {
                position: p * s + t,
                color: None,
            })
            .collect(),
        materials: vec![Material::default()],
        objects: shapes
            .into_iter()
            .map(|shape| Object { material: 0, shape })
            .collect(),
    }
}

fn transform(shape: &Shape, s: f64, t: DVec3) -> Shape {
    let p = |v: DVec3| v * s + t;
    match shape {
        Shape::Sphere { center, radius } => Shape::Sphere {
            center: p(*center),
            radius: radius * s,
        },
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => Shape::Cone {
            base: p(*base),
            base_radius: base_radius * s,
            apex: p(*apex),
            apex_radius: apex_radius * s,
        },
        Shape::Polygon(v) => Shape::Polygon(v.iter().map(|&v| p(v)).collect()),
        Shape::Patch { vertices, normals } => Shape::Patch {
            vertices: vertices.iter().map(|&v| p(v)).collect(),
            normals: normals.clone(),
        },
    }
}

/// Makes a case set: shapes and rays scaled by `s` and moved by `t`, then rounded to f32.
fn finish(category: &str, shapes: &[Shape], specs: &[Spec], s: f64, t: DVec3) -> CaseSet {
    let shapes: Vec<Shape> = shapes.iter().map(|x| transform(x, s, t)).collect();
    let scene = Arc::new(scene(category, shapes, s, t));
    let geometry = Arc::new(Geometry::from_scene(&scene));
    let (mut rays, mut must) = (Vec::new(), Vec::new());
    for sp in specs {
        let o = (sp.o * s + t).as_vec3();
        let d = sp.d.as_vec3();
        rays.push(Ray::new(o, d, 0.0, f32::INFINITY));
        must.push(sp.through.map(|p| {
            let (p, o, d) = (p * s + t, o.as_dvec3(), d.as_dvec3());
            let tp = (p - o).dot(d) / d.dot(d);
            // Rounding the ray to f32 moves its crossing by far less than this.
            (tp * (1.0 + 1e-4)) as f32
        }));
    }
    CaseSet {
        category: category.to_string(),
        scene,
        geometry,
        rays,
        must_hit_by: must,
    }
}

fn polygons(m: Mesh) -> Vec<Shape> {
    m.into_iter().map(Shape::Polygon).collect()
}

/// Every case set, in report order.
pub fn all() -> Vec<CaseSet> {
    let mut v = Vec::new();
    v.extend(watertight());
    v.push(zero_dir());
    v.push(grazing());
    v.push(tangent());
    v.push(inside());
    v.extend(far_and_scaled());
    v.push(degenerate());
    v.push(coplanar());
    v
}

/// The closed meshes, each its own set (so no other mesh stands in front).
pub fn watertight() -> Vec<CaseSet> {
    [
        ("watertight-tetra", meshes::tetrahedron()),
        ("watertight-sphere", meshes::uv_sphere(8, 16)),
        ("watertight-cone", meshes::capped_cone(24, 1.0, 0.4)),
        ("watertight-gear", meshes::gear(36)),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, (name, m))| {
        let shapes = polygons(m);
        let probe = finish(name, &shapes, &[], 1.0, DVec3::ZERO);
        let specs = edge_rays(&probe.geometry, &mut Rng::new(0x5eed + i as u64));
        finish(name, &shapes, &specs, 1.0, DVec3::ZERO)
    })
    .collect()
}

/// Rays through points on the prepared triangles' edges (halves and thirds) and vertices, in
/// directions that cross the surface there: along the axes exactly through the f32 point, along
/// the normal of each triangle there, and two random ones.
fn edge_rays(g: &Geometry, rng: &mut Rng) -> Vec<Spec> {
    let tris: Vec<[DVec3; 3]> = g
        .prims
        .iter()
        .filter_map(|p| match p {
            rtbench_engines::geometry::Prim::Triangle(t) => {
                Some([t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3()])
            }
            _ => None,
        })
        .collect();
    // The polygons are wound outwards and ear clipping keeps the winding.
    let normals: Vec<DVec3> = tris
        .iter()
        .map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero())
        .collect();
    let mut points = Vec::new();
    for t in &tris {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            points.push(a);
            for f in [0.5, 1.0 / 3.0] {
                points.push((a + (b - a) * f).as_vec3().as_dvec3());
            }
        }
    }
    points.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
    points.dedup();
    let mut specs = Vec::new();
    let length = 4.0;
    for p in points {
        // The triangles the point lies on (on an edge or at a vertex).
        let near: Vec<DVec3> = tris
            .iter()
            .zip(&normals)
            .filter(|(t, _)| on_triangle_boundary(p, t))
            .map(|(_, n)| *n)
            .collect();
        if near.is_empty() {
            continue;
        }
        let mut dirs: Vec<DVec3> = vec![
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ];
        let avg = near.iter().copied().sum::<DVec3>().normalize_or_zero();
        dirs.extend([avg, -avg, rng.unit(), rng.unit()]);
        for d in dirs {
            let crosses =
                near.iter().all(|n| n.dot(d) > 0.1) || near.iter().all(|n| n.dot(d) < -0.1);
            if crosses {
                specs.push(Spec {
                    o: p - d * length,
                    d,
                    through: Some(p),
                });
            }
        }
    }
    specs
}

/// Whether `p` is (to rounding) on an edge of triangle `t`.
fn on_triangle_boundary(p: DVec3, t: &[DVec3; 3]) -> bool {
    (0..3).any(|e| {
        let (a, b) = (t[e], t[(e + 1) % 3]);
        let ab = b - a;
        let s = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        (a + ab * s - p).length() < 1e-6
    })
}

/// An axis-aligned box of half-size `h` at `c` as six quads wound outwards.
fn cube(c: DVec3, h: f64) -> Vec<Shape> {
    let q = |n: DVec3, u: DVec3, v: DVec3| {
        Shape::Polygon(vec![
            c + (n - u - v) * h,
            c + (n + u - v) * h,
            c + (n + u + v) * h,
            c + (n - u + v) * h,
        ])
    };
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    vec![
        q(x, y, z),
        q(-x, z, y),
        q(y, z, x),
        q(-y, x, z),
        q(z, x, y),
        q(-z, y, x),
    ]
}

/// 3×3×3 spheres and boxes on the integer lattice, rays in boundary planes.
fn zero_dir() -> CaseSet {
    let mut shapes = Vec::new();
    for i in -1..=1 {
        for j in -1..=1 {
            for k in -1..=1 {
                let c = DVec3::new(i as f64, j as f64, k as f64);
                if (i + j + k) % 2 == 0 {
                    shapes.push(Shape::Sphere {
                        center: c,
                        radius: 0.3,
                    });
                } else {
                    shapes.extend(cube(c, 0.3));
                }
            }
        }
    }
    // Planes: object bounds, the scene's bounds, and its n-ths (cell and node boundaries).
    let (lo, hi) = (-1.3, 1.3);
    let mut planes = vec![-1.3, -1.0, -0.7, -0.3, 0.0, 0.3, 0.7, 1.0, 1.3];
    for n in [2, 3, 4, 5, 8] {
        for i in 1..n {
            planes.push(((lo + (hi - lo) * i as f64 / n as f64) as f32) as f64);
        }
    }
    planes.sort_by(f64::total_cmp);
    planes.dedup();
    let mut specs = Vec::new();
    for axis in 0..3 {
        let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
        for sign in [1.0, -1.0] {
            for (za, zb) in [(0.0, 0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, -0.0)] {
                let mut d = DVec3::ZERO;
                d[axis] = sign;
                d[a] = za;
                d[b] = zb;
                for &u in &planes {
                    for &v in &planes {
                        let mut o = DVec3::ZERO;
                        o[axis] = -sign * 3.0;
                        o[a] = u;
                        o[b] = v;
                        specs.push(Spec {
                            o,
                            d,
                            through: None,
                        });
                    }
                }
            }
        }
    }
    // One zero component (either sign), the ray in a boundary plane.
    let mut rng = Rng::new(7);
    for &u in &planes {
        for _ in 0..40 {
            let axis = (rng.next_u64() % 3) as usize;
            let mut d = rng.unit();
            d[axis] = if rng.f() < 0.5 { 0.0 } else { -0.0 };
            let d = d.normalize();
            let mut o = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            o[axis] = u;
            specs.push(Spec {
                o: o - d * 3.0,
                d,
                through: None,
            });
        }
    }
    finish("zero-dir", &shapes, &specs, 1.0, DVec3::ZERO)
}

/// Rays along the faces of boxes and tilted quads, and just off them.
fn grazing() -> CaseSet {
    let mut shapes = cube(DVec3::ZERO, 1.0);
    let tilt = [
        DVec3::new(2.0, -1.0, -1.0),
        DVec3::new(4.0, -1.0, 0.3),
        DVec3::new(4.0, 1.0, 0.3),
        DVec3::new(2.0, 1.0, -1.0),
    ];
    shapes.push(Shape::Polygon(tilt.to_vec()));
    let mut rng = Rng::new(11);
    let mut specs = Vec::new();
    // In the box's faces: the plane x = ±1 (and y, z), directions in the plane.
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            for off in [0.0, 1e-7, -1e-7, 1e-4, -1e-4] {
                for _ in 0..60 {
                    let mut d = rng.unit();
                    d[axis] = 0.0;
                    let d = d.normalize();
                    let mut p = DVec3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    );
                    p[axis] = side * (1.0 + off);
                    specs.push(Spec {
                        o: p - d * 4.0,
                        d,
                        through: None,
                    });
                }
            }
        }
    }
    // In the tilted quad's plane and just off it.
    let n = (tilt[1] - tilt[0]).cross(tilt[3] - tilt[0]).normalize();
    for off in [0.0, 1e-7, -1e-7, 1e-4] {
        for _ in 0..200 {
            let (a, b) = (rng.f(), rng.f());
            let p = tilt[0] + (tilt[1] - tilt[0]) * a + (tilt[3] - tilt[0]) * b + n * off;
            let mut d = rng.unit();
            d -= n * d.dot(n);
            let d = d.normalize();
            specs.push(Spec {
                o: p - d * 4.0,
                d,
                through: None,
            });
        }
    }
    finish("grazing", &shapes, &specs, 1.0, DVec3::ZERO)
}

/// Rays tangent to spheres of several sizes, and just inside and outside.
fn tangent() -> CaseSet {
    let spheres = [
        (DVec3::ZERO, 1.0),
        (DVec3::new(3.0, 0.5, 0.0), 0.01),
        (DVec3::new(-3.0, 0.0, 1.0), 2.0),
        (DVec3::new(0.0, 4.0, -1.0), 0.5),
    ];
    let shapes: Vec<Shape> = spheres
        .iter()
        .map(|&(center, radius)| Shape::Sphere { center, radius })
        .collect();
    let mut rng = Rng::new(13);
    let mut specs = Vec::new();
    for &(c, r) in &spheres {
        for f in [1.0, 1.0 - 1e-7, 1.0 + 1e-7, 1.0 - 1e-4, 1.0 + 1e-4] {
            for _ in 0..150 {
                let d = rng.unit();
                let u = d.any_orthonormal_vector();
                let w = d.cross(u);
                let a = rng.range(0.0, std::f64::consts::TAU);
                let side = u * a.cos() + w * a.sin();
                let p = c + side * (r * f);
                specs.push(Spec {
                    o: p - d * (3.0 * r + 1.0),
                    d,
                    through: None,
                });
            }
        }
    }
    finish("tangent", &shapes, &specs, 1.0, DVec3::ZERO)
}

/// Rays starting inside spheres, at the centre and out to just under the surface.
fn inside() -> CaseSet {
    let spheres = [
        (DVec3::ZERO, 1.0),
        (DVec3::new(3.0, 0.0, 0.0), 0.05),
        (DVec3::new(-3.0, 1.0, 0.0), 2.0),
    ];
    let shapes: Vec<Shape> = spheres
        .iter()
        .map(|&(center, radius)| Shape::Sphere { center, radius })
        .collect();
    let mut rng = Rng::new(17);
    let mut specs = Vec::new();
    for &(c, r) in &spheres {
        for f in [0.0, 0.5, 0.99, 1.0 - 1e-5] {
            for _ in 0..200 {
                specs.push(Spec {
                    o: c + rng.unit() * (r * f),
                    d: rng.unit(),
                    through: None,
                });
            }
        }
    }
    finish("inside", &shapes, &specs, 1.0, DVec3::ZERO)
}

/// The mixed scene (as is, far from the origin, scaled) and its random rays.
fn far_and_scaled() -> Vec<CaseSet> {
    let mut shapes = vec![
        Shape::Sphere {
            center: DVec3::new(1.5, 0.0, 0.0),
            radius: 0.6,
        },
        Shape::Sphere {
            center: DVec3::new(-1.0, 1.2, 0.3),
            radius: 0.4,
        },
        Shape::Sphere {
            center: DVec3::new(0.2, -1.4, -0.5),
            radius: 0.25,
        },
        Shape::Cone {
            base: DVec3::new(-1.5, -1.0, -1.0),
            base_radius: 0.5,
            apex: DVec3::new(-1.2, -0.8, 0.6),
            apex_radius: 0.1,
        },
        Shape::Cone {
            base: DVec3::new(0.5, 1.5, -1.0),
            base_radius: 0.3,
            apex: DVec3::new(0.5, 1.5, 1.0),
            apex_radius: 0.3,
        },
    ];
    shapes.extend(cube(DVec3::new(0.0, 0.0, -1.6), 0.5));
    shapes.extend(polygons(
        meshes::tetrahedron()
            .into_iter()
            .map(|p| p.into_iter().map(|v| v * 0.5).collect())
            .collect(),
    ));
    let mut rng = Rng::new(19);
    let specs: Vec<Spec> = (0..1500)
        .map(|_| {
            let o = rng.unit() * 6.0;
            let target = DVec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 1.0),
            );
            Spec {
                o,
                d: (target - o).normalize(),
                through: None,
            }
        })
        .collect();
    let dir = DVec3::new(1.0, 0.6, -0.8);
    let mut v = vec![finish("near", &shapes, &specs, 1.0, DVec3::ZERO)];
    for (name, t) in [("far-1e3", 1e3), ("far-1e5", 1e5), ("far-1e7", 1e7)] {
        v.push(finish(name, &shapes, &specs, 1.0, dir * t));
    }
    for (name, s) in [
        ("scale-1e-4", 1e-4),
        ("scale-1e-2", 1e-2),
        ("scale-1e2", 1e2),
        ("scale-1e4", 1e4),
    ] {
        v.push(finish(name, &shapes, &specs, s, DVec3::ZERO));
    }
    v
}

/// The teapot's lid and hand-made degenerate primitives.
fn degenerate() -> CaseSet {
    let teapot = generate_scene(
        Program::Teapot,
        &Options {
            size_factor: 2,
            ..Options::standard(Program::Teapot)
        },
    )
    .expect("teapot at size factor 2 is valid");
    let mut shapes: Vec<Shape> = teapot.objects.into_iter().map(|o| o.shape).collect();
    let mut rng = Rng::new(23);
    let mut specs = Vec::new();
    // Aim at the vertices and centres of the teapot's zero-area and sliver patches.
    let mut targets = Vec::new();
    for s in &shapes {
        if let Shape::Patch { vertices, .. } = s {
            let (a, b, c) = (vertices[0], vertices[1], vertices[2]);
            let area = (b - a).cross(c - a).length();
            let longest = (b - a).length().max((c - a).length()).max((c - b).length());
            if area <= 1e-3 * longest * longest {
                targets.extend([a, b, c, (a + b + c) / 3.0]);
            }
        }
    }
    // Hand-made: repeated and collinear vertices, slivers, zero radius, zero height.
    let base = DVec3::new(0.0, 0.0, 6.0);
    let (a, b) = (
        base + DVec3::new(-1.0, 0.0, 0.0),
        base + DVec3::new(1.0, 0.3, 0.0),
    );
    for tri in [
        [a, a, b],
        [a, b, (a + b) * 0.5],
        [a, b, (a + b) * 0.5 + DVec3::new(0.0, 0.0, 1e-6)],
        [a, b, (a + b) * 0.5 + DVec3::new(0.0, 1e-5, 0.0)],
        [a, b, a + (b - a) * 1e-6 + DVec3::new(0.0, 1.0, 0.0)],
    ] {
        shapes.push(Shape::Polygon(tri.to_vec()));
        targets.extend([tri[0], tri[1], tri[2], (tri[0] + tri[1] + tri[2]) / 3.0]);
    }
    for (i, c) in [DVec3::new(3.0, 0.0, 6.0), DVec3::new(3.0, 1.0, 6.0)]
        .into_iter()
        .enumerate()
    {
        shapes.push(Shape::Sphere {
            center: c,
            radius: 0.0,
        });
        let p = c + DVec3::X * 2.0;
        shapes.push(Shape::Cone {
            base: p,
            base_radius: 0.5,
            apex: p,
            apex_radius: 0.5 * i as f64,
        });
        targets.extend([c, p, p + DVec3::Y * 0.25]);
    }
    for t in targets {
        for _ in 0..12 {
            let d = rng.unit();
            specs.push(Spec {
                o: t - d * 5.0,
                d,
                through: None,
            });
        }
    }
    finish("degenerate", &shapes, &specs, 1.0, DVec3::ZERO)
}

/// Squares overlapping in the plane z = 0 (and a tilted plane); rays through the overlaps.
fn coplanar() -> CaseSet {
    let mut shapes = Vec::new();
    let tilt = |p: DVec3| DVec3::new(p.x, p.y * 0.8 + p.z * 0.6, -p.y * 0.6 + p.z * 0.8);
    for plane in 0..2 {
        for k in 0..6 {
            let o =
                DVec3::new(0.13 * k as f64, 0.07 * k as f64, 0.0) + DVec3::X * 4.0 * plane as f64;
            let sq = [o, o + DVec3::X, o + DVec3::new(1.0, 1.0, 0.0), o + DVec3::Y];
            let f = |p: DVec3| if plane == 1 { tilt(p) } else { p };
            shapes.push(Shape::Polygon(sq.iter().map(|&p| f(p)).collect()));
        }
    }
    let mut rng = Rng::new(29);
    let mut specs = Vec::new();
    for plane in 0..2 {
        for _ in 0..600 {
            let p = DVec3::new(rng.range(0.6, 1.1), rng.range(0.3, 1.0), 0.0)
                + DVec3::X * 4.0 * plane as f64;
            let p = if plane == 1 { tilt(p) } else { p };
            let mut d = rng.unit();
            if d.z.abs() < 0.2 {
                d.z = 0.5;
            }
            let d = d.normalize();
            specs.push(Spec {
                o: p - d * 3.0,
                d,
                through: None,
            });
        }
    }
    finish("coplanar", &shapes, &specs, 1.0, DVec3::ZERO)
}
