//! `obvhs`: the obvhs crate's BVHs as a peer of our own: its PLOC builder (Meister and
//! Bittner 2018) with reinsertion, as a BVH2 or collapsed into a compressed wide BVH8 (CWBVH,
//! Ylitie, Karras and Laine 2017), traversed by its own CPU code. Its leaves call our shared
//! kernels through its intersection callback, so it differs from `bvh2`/`bvh8` only in how it
//! finds candidates.
//!
//! | key | values | default |
//! |---|---|---|
//! | `layout` | `bvh2`, `cwbvh` | `cwbvh` |
//! | `preset` | obvhs's build presets: `fastest`, `very-fast`, `fast`, `medium`, `slow`, `very-slow` | `medium` |
//! | `leaf` | most primitives per leaf (0: the preset's; CWBVH caps it at 3) | 0 |
//! | `triangle` | `watertight`, `moller` | `watertight` |
//!
//! obvhs counts no nodes; the counters give primitive tests and hits only.

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::Prim;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use obvhs::aabb::Aabb as OAabb;
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as ORay, RayHit};
use obvhs::BvhBuildParams;
use std::collections::BTreeMap;
use std::str::FromStr;
use std::time::{Duration, Instant};

pub fn info() -> EngineInfo {
    EngineInfo {
        name: "obvhs",
        description:
            "the obvhs crate (0.4): PLOC-built BVH2 or compressed wide BVH8, its CPU traversal",
        available: || Ok(()),
        build,
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    Bvh2,
    Cwbvh,
}

impl FromStr for Layout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "bvh2" => Ok(Layout::Bvh2),
            "cwbvh" => Ok(Layout::Cwbvh),
            _ => Err("expected bvh2 or cwbvh".into()),
        }
    }
}

/// obvhs's named build quality presets (`BvhBuildParams::*_build`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset(&'static str);

impl FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        const NAMES: [&str; 6] = [
            "fastest",
            "very-fast",
            "fast",
            "medium",
            "slow",
            "very-slow",
        ];
        NAMES
            .iter()
            .find(|&&n| n == s)
            .map(|&n| Preset(n))
            .ok_or_else(|| format!("expected one of {}", NAMES.join(", ")))
    }
}

impl Preset {
    fn params(self) -> BvhBuildParams {
        match self.0 {
            "fastest" => BvhBuildParams::fastest_build(),
            "very-fast" => BvhBuildParams::very_fast_build(),
            "fast" => BvhBuildParams::fast_build(),
            "slow" => BvhBuildParams::slow_build(),
            "very-slow" => BvhBuildParams::very_slow_build(),
            _ => BvhBuildParams::medium_build(),
        }
    }
}

/// A primitive as obvhs's builder sees it: its box.
struct PrimBox {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl obvhs::Boundable for PrimBox {
    fn aabb(&self) -> OAabb {
        OAabb::new(self.lo.into(), self.hi.into())
    }
}

enum Tree {
    Bvh2(Bvh2),
    Cwbvh(CwBvh),
}

pub struct Obvhs {
    tree: Tree,
    /// Primitives reordered by obvhs's `primitive_indices`, so its ids index them directly.
    prims: Vec<Prim>,
    objects: Vec<u32>,
    triangle: TriangleTest,
    stats: BTreeMap<String, f64>,
}

/// Widening of the primitives' boxes, relative to the scene's largest coordinate (64 ε).
const BOX_PAD: f32 = 64.0 * f32::EPSILON;

/// Largest coordinate handed to the obvhs crate (the scene limit, rtbench_scenes::validate).
const OBVHS_MAX_COORD: f32 = 1e7;

fn build(input: &BuildInput, mut settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let layout = settings.get("layout", Layout::Cwbvh)?;
    let preset = settings.get("preset", Preset("medium"))?;
    let leaf = settings.get("leaf", 0u32)?;
    let triangle = settings.get("triangle", TriangleTest::default())?;
    settings.finish()?;
    let g = &input.geometry;
    let start = Instant::now();
    // obvhs's slab test has no rounding bound: a ray through an edge or vertex lying on a box
    // face could find the box missed and leak through a closed mesh (57 of 26 461 edge rays of
    // `rtbench check --suite hard` after the −0.0 fix below). Each primitive's box is widened by
    // BOX_PAD of the scene's largest coordinate, which covers the rounding of rays starting
    // within about ten scene sizes of the origin, and costs no work per box.
    let extent = g.bounds_min.abs().max(g.bounds_max.abs()).max_element();
    let pad = if extent.is_finite() {
        extent * BOX_PAD
    } else {
        0.0
    };
    let boxes: Vec<PrimBox> = g
        .prims
        .iter()
        .map(|p| {
            let (lo, hi) = p.bounds();
            PrimBox {
                lo: (lo - pad).to_array(),
                hi: (hi + pad).to_array(),
            }
        })
        .collect();
    let mut params = preset.params();
    if leaf > 0 {
        params.max_prims_per_leaf = leaf;
    }
    // The crate's compressed wide BVH quantises boxes relative to the scene and panicked on far
    // coordinates (a sphere at 1e30: index out of bounds in bvh2_to_cwbvh). Scenes are checked at
    // load (rtbench_scenes::validate::MAX_COORD); a scene built another way is refused here, and
    // a panic inside the crate all the same is reported as the peer's failure.
    if !g.prims.is_empty() && (extent.is_nan() || extent > OBVHS_MAX_COORD)
        || boxes
            .iter()
            .any(|b| !b.lo.iter().chain(&b.hi).all(|x| x.is_finite()))
    {
        return Err(EngineError::Build {
            engine: "obvhs".into(),
            reason: format!(
                "coordinates up to {extent:e} (the obvhs crate is given at most \
                 {OBVHS_MAX_COORD:e})"
            ),
        });
    }
    let mut core = Duration::default();
    let built = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        build_tree(&boxes, layout, params, &mut core)
    }));
    let (tree, indices, node_bytes, nodes) = match built {
        Ok(t) => t,
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            return Err(EngineError::Build {
                engine: "obvhs".into(),
                reason: format!("the obvhs crate failed while building: {what}"),
            });
        }
    };
    let prims: Vec<Prim> = indices.iter().map(|&i| g.prims[i as usize]).collect();
    let objects: Vec<u32> = indices.iter().map(|&i| g.prim_object[i as usize]).collect();
    let build_s = start.elapsed().as_secs_f64();
    let mut stats = BTreeMap::new();
    stats.insert("build_s".into(), build_s);
    stats.insert("core_build_s".into(), core.as_secs_f64());
    stats.insert("nodes".into(), nodes as f64);
    stats.insert("node_bytes".into(), node_bytes as f64);
    stats.insert(
        "max_prims_per_leaf".into(),
        params.max_prims_per_leaf as f64,
    );
    Ok(Box::new(Obvhs {
        tree,
        prims,
        objects,
        triangle,
        stats,
    }))
}

/// The crate's tree over `boxes`: (tree, primitive order, node bytes, nodes).
fn build_tree(
    boxes: &[PrimBox],
    layout: Layout,
    params: BvhBuildParams,
    core: &mut Duration,
) -> (Tree, Vec<u32>, usize, usize) {
    if boxes.is_empty() {
        (Tree::Bvh2(Bvh2::default()), Vec::new(), 0, 0)
    } else {
        match layout {
            Layout::Bvh2 => {
                let t = obvhs::bvh2::builder::build_bvh2(boxes, params, core);
                let idx = t.primitive_indices.clone();
                let nb = std::mem::size_of_val(t.nodes.as_slice());
                let n = t.nodes.len();
                (Tree::Bvh2(t), idx, nb, n)
            }
            Layout::Cwbvh => {
                let t = obvhs::cwbvh::builder::build_cwbvh(boxes, params, core);
                let idx = t.primitive_indices.clone();
                let nb = std::mem::size_of_val(t.nodes.as_slice());
                let n = t.nodes.len();
                (Tree::Cwbvh(t), idx, nb, n)
            }
        }
    }
}

/// Our ray in obvhs's form. A −0.0 direction component is passed as +0.0 (the same ray): the
/// CWBVH traversal takes the ray's octant from `direction < 0` but its inverse from the sign bit
/// (`signum(−0.0) / ε` is negative), and with the two disagreeing it missed every box on such a
/// ray — 1 629 axis-aligned rays and 36 of 91 edge rays on the tetrahedron in
/// `rtbench check --suite hard`.
fn to_oray(r: &Ray) -> ORay {
    // x + 0.0 is +0.0 for x = −0.0 and x otherwise.
    let d = r.dir + glam::Vec3::ZERO;
    ORay::new(
        r.origin.to_array().into(),
        d.to_array().into(),
        r.tmin,
        r.tmax,
    )
}

impl Obvhs {
    /// The leaf test obvhs calls: our shared kernel on primitive `id` within obvhs's current
    /// segment; the t of a hit, or +∞. `last` keeps (id, u, v) of the latest hit, which obvhs
    /// always accepts (the kernel only reports t < tmax).
    #[inline]
    fn test(
        &self,
        ray: &Ray,
        oray: &ORay,
        id: usize,
        wt: &WatertightRay,
        last: &mut (usize, f32, f32),
        c: &mut Counters,
    ) -> f32 {
        let mut r = *ray;
        r.tmax = oray.tmax;
        c.primitive_tests += 1;
        match self.prims[id].intersect(&r, self.triangle, wt) {
            // obvhs keeps a hit only when it is strictly nearer than its best so far; a tie at
            // exactly that t keeps the earlier primitive, so its barycentrics must stay too.
            Some((t, u, v)) if t < oray.tmax => {
                c.primitive_hits += 1;
                *last = (id, u, v);
                t
            }
            Some(_) => {
                c.primitive_hits += 1;
                f32::INFINITY
            }
            None => f32::INFINITY,
        }
    }

    fn closest(&self, ray: &Ray, c: &mut Counters) -> Hit {
        if !ray.is_traceable() {
            return Hit::MISS;
        }
        let wt = WatertightRay::new(ray.dir);
        let mut last = (usize::MAX, 0.0, 0.0);
        let mut hit = RayHit::none();
        let oray = to_oray(ray);
        let found = match &self.tree {
            Tree::Bvh2(t) if !t.nodes.is_empty() => t.ray_traverse(oray, &mut hit, |o, id| {
                self.test(ray, o, id, &wt, &mut last, c)
            }),
            Tree::Bvh2(_) => false,
            Tree::Cwbvh(t) => t.ray_traverse(oray, &mut hit, |o, id| {
                self.test(ray, o, id, &wt, &mut last, c)
            }),
        };
        if !found {
            return Hit::MISS;
        }
        let id = hit.primitive_id as usize;
        debug_assert_eq!(id, last.0);
        Hit {
            t: hit.t,
            object: self.objects[id],
            u: last.1,
            v: last.2,
        }
    }

    fn any(&self, ray: &Ray, c: &mut Counters) -> bool {
        if !ray.is_traceable() {
            return false;
        }
        let wt = WatertightRay::new(ray.dir);
        let mut last = (usize::MAX, 0.0, 0.0);
        let oray = to_oray(ray);
        let miss = match &self.tree {
            Tree::Bvh2(t) if !t.nodes.is_empty() => {
                t.ray_traverse_miss(oray, |o, id| self.test(ray, o, id, &wt, &mut last, c))
            }
            Tree::Bvh2(_) => true,
            Tree::Cwbvh(t) => {
                t.ray_traverse_miss(oray, |o, id| self.test(ray, o, id, &wt, &mut last, c))
            }
        };
        !miss
    }
}

impl Engine for Obvhs {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters) {
        let mut c = Counters::default();
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = self.closest(r, &mut c);
        }
        c.rays = rays.len() as u64;
        counters.add(&c);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], counters: &mut Counters) {
        let mut c = Counters::default();
        for (r, o) in rays.iter().zip(occluded.iter_mut()) {
            *o = self.any(r, &mut c);
        }
        c.rays = rays.len() as u64;
        counters.add(&c);
    }

    /// obvhs's nodes and index list, plus the primitives copied in its order.
    fn structure_bytes(&self) -> u64 {
        let idx = match &self.tree {
            Tree::Bvh2(t) => t.primitive_indices.len(),
            Tree::Cwbvh(t) => t.primitive_indices.len(),
        };
        (self.stats["node_bytes"] as usize
            + 4 * idx
            + std::mem::size_of::<Prim>() * self.prims.len()
            + 4 * self.objects.len()) as u64
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.stats.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Geometry;
    use glam::Vec3;
    use rtbench_scenes::generate_scene;
    use rtbench_scenes::spd::{Options, Program};
    use std::sync::Arc;

    #[test]
    fn both_layouts_agree_with_reference() {
        for (program, sf) in [(Program::Tree, 3), (Program::Gears, 1)] {
            let scene = Arc::new(
                generate_scene(
                    program,
                    &Options {
                        size_factor: sf,
                        ..Options::standard(program)
                    },
                )
                .unwrap(),
            );
            let input = BuildInput {
                geometry: Arc::new(Geometry::from_scene(&scene)),
                scene,
            };
            let g = &input.geometry;
            let c = (g.bounds_min + g.bounds_max) * 0.5;
            let r = (g.bounds_max - g.bounds_min).length();
            // A fan of rays from outside through the scene, and shadow-like segments.
            let mut rays = Vec::new();
            for i in 0..200 {
                let a = i as f32 * 0.137;
                let o = c + Vec3::new(a.cos(), 0.3 + 0.2 * (a * 3.0).sin(), a.sin()) * r;
                let target =
                    c + Vec3::new((a * 7.0).sin(), (a * 5.0).cos(), (a * 3.0).sin()) * 0.3 * r;
                let d = (target - o).normalize();
                let tmax = if i % 2 == 0 { f32::INFINITY } else { r };
                rays.push(Ray::new(o, d, 0.0, tmax));
            }
            let refe = (crate::reference::info().build)(&input, Settings::new("reference", vec![]))
                .unwrap();
            let mut want = vec![Hit::MISS; rays.len()];
            refe.intersect(&rays, &mut want, &mut Counters::default());
            assert!(want.iter().filter(|h| h.is_hit()).count() > 20);
            for layout in ["bvh2", "cwbvh"] {
                let e = build(
                    &input,
                    Settings::new("obvhs", vec![("layout".into(), layout.into())]),
                )
                .unwrap();
                let mut got = vec![Hit::MISS; rays.len()];
                let mut cnt = Counters::default();
                e.intersect(&rays, &mut got, &mut cnt);
                let mut occ = vec![false; rays.len()];
                e.occluded(&rays, &mut occ, &mut Counters::default());
                let ok = got
                    .iter()
                    .zip(&want)
                    .filter(|(a, b)| {
                        a.is_hit() == b.is_hit()
                            && (!a.is_hit()
                                || a.object == b.object
                                || (a.t - b.t).abs() <= 1e-5 * b.t)
                    })
                    .count();
                assert!(
                    ok + 2 >= rays.len(),
                    "{layout} on {program}{sf}: {ok} agree"
                );
                for (o, h) in occ.iter().zip(&got) {
                    assert_eq!(*o, h.is_hit(), "{layout}");
                }
                assert_eq!(cnt.rays, rays.len() as u64);
                assert!(e.structure_bytes() > 0);
            }
        }
    }
}
