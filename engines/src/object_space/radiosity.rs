//! 003's radiosity pass (Yamauchi 1997, §2.4.1, §3.2.3): progressive-refinement ("shooting")
//! radiosity with hemicube form factors, as a plain single-process solver ([`reference`]) and on
//! the simulated (Mπ)² machine ([`simulate`]).
//!
//! Shared by both, so that they differ only in the order of shooting:
//! - Patches are the scene's polygons; spheres and cones are specular elements, not patches (003:
//!   smooth quadrics are not meshed): a delta-radiosity ray hitting one reflects on with its
//!   power times k_s, up to [`MAX_REFLECTIONS`] times (003, Table 6), and their diffuse part is
//!   lost.
//! - A shot from patch i sends one delta-radiosity ray through the centre of each of the
//!   [`HEMICUBE_PIXELS`] pixels of a hemicube on i (20 × 20 on top, 20 × 10 on each side: 003's
//!   1,200), carrying ΔB_i · A_i · ΔF_p (ΔF_p the pixel's delta form factor, normalised so the
//!   1,200 sum to 1). A ray hitting the front of patch j adds ρ_j · power / A_j to j's radiosity
//!   and unshot radiosity (eq. 6, B_j due to B_i = ρ_j B_i F_ij A_i / A_j); the back of a patch
//!   absorbs it. Rays are traced through the subspaces by [`ObjectSpace::execute`].
//! - "Brightest" is the largest channel of the unshot radiosity (003 §3.2.3: 未放射); a patch
//!   shoots while that is above the threshold.
//!
//! The reference shoots the globally brightest patch, one shot after the other, each shot's
//! deposits made in pixel order. The machine: every PE's FRGU picks the brightest patch of its
//! own subspaces above the threshold (a patch belongs to the subspace holding its centre),
//! spends Table 4's hemicube set-up on the first ray (1,053,000 clocks) and 4,379 on each
//! further one (FRGU → RD → RP being a pipeline, it hands a ray on no sooner than one of its PE's
//! RP blocks is free: 003 gives no queue size, and an FRGU running ahead of its RP blocks would
//! pick patches on stale unshot values), and sends the rays as packets through the subspaces and PEs as the ray-tracing
//! pass does ([`super::sim`]: RD to the least-loaded RP block, per-subspace tests, 3D-DDA and
//! packet costs, links one packet at a time). At a hit the ICU (349 clocks) adds to the patch
//! and, when its unshot radiosity passes the threshold and its PE's FRGU is idle, notifies that
//! FRGU; a reflection costs the SRGU's 1,818. The pass ends when no ray is anywhere and no FRGU
//! has a patch above the threshold. Deposits are made at their simulated time, so the order of
//! shooting (and so the result, to within the threshold's residual) is the machine's own.
//!
//! A ray's path does not depend on when it is sent, only its power does, so a shot's rays (and
//! their reflections) are executed when the shot starts and replayed with their times.

use super::config::Costs;
use super::machine::Machine;
use super::trace::Segment;
use super::ObjectSpace;
use crate::engine::Counters;
use crate::geometry::Prim;
use crate::ray::Ray;
use glam::Vec3;
use rtbench_scenes::{Scene, Shape};
use serde::Serialize;

/// 003, Table 6: pixels on a hemicube.
pub const HEMICUBE_PIXELS: usize = 1200;
/// Hemicube resolution: the top face is RES × RES, each side RES × RES/2 (3·RES² = 1,200).
const RES: usize = 20;
/// 003, Table 6: at most 3 reflections.
pub const MAX_REFLECTIONS: u8 = 3;
/// 003, Table 4: the first ray of a shot, with the hemicube's set-up.
pub const HEMICUBE_SETUP: u64 = 1_053_000;
/// Offset of ray origins from surfaces (scene units; the room is metres).
const EPS: f32 = 1e-3;

/// The patches (one per scene object; non-polygons have zero area) and specular elements.
#[derive(Clone, Debug)]
pub struct Patches {
    pub area: Vec<f32>,
    pub centre: Vec<Vec3>,
    pub normal: Vec<Vec3>,
    /// First axis of the hemicube's frame on the patch.
    pub tangent: Vec<Vec3>,
    pub rho: Vec<Vec3>,
    pub emission: Vec<Vec3>,
    /// k_s of a specular element (0 for patches and for matte quadrics).
    pub ks: Vec<f32>,
    /// First primitive of each object (for the normals of specular elements).
    pub first_prim: Vec<u32>,
    /// Each patch's shot, executed once and kept ([`ShotCache`]).
    pub shots: ShotCache,
}

impl Patches {
    /// Patches of `scene` with `emission[m]` the emission of material m. Errors when no object
    /// is a patch.
    pub fn from_scene(
        scene: &Scene,
        prim_object: &[u32],
        emission: &[glam::DVec3],
    ) -> Result<Patches, String> {
        let n = scene.objects.len();
        let mut p = Patches {
            area: vec![0.0; n],
            centre: vec![Vec3::ZERO; n],
            normal: vec![Vec3::Z; n],
            tangent: vec![Vec3::X; n],
            rho: vec![Vec3::ZERO; n],
            emission: vec![Vec3::ZERO; n],
            ks: vec![0.0; n],
            first_prim: vec![u32::MAX; n],
            shots: ShotCache::new(n),
        };
        for (i, &o) in prim_object.iter().enumerate().rev() {
            p.first_prim[o as usize] = i as u32;
        }
        for (i, o) in scene.objects.iter().enumerate() {
            let m = &scene.materials[o.material as usize];
            if let Shape::Polygon(v) = &o.shape {
                let mut cross = glam::DVec3::ZERO;
                for k in 1..v.len().saturating_sub(1) {
                    cross += (v[k] - v[0]).cross(v[k + 1] - v[0]);
                }
                let area = cross.length() / 2.0;
                if area <= 0.0 {
                    continue;
                }
                let c = v.iter().sum::<glam::DVec3>() / v.len() as f64;
                p.area[i] = area as f32;
                p.centre[i] = c.as_vec3();
                p.normal[i] = cross.normalize().as_vec3();
                p.tangent[i] = (v[1] - v[0]).normalize().as_vec3();
                p.rho[i] = (m.color * m.kd).as_vec3();
                p.emission[i] = emission
                    .get(o.material as usize)
                    .copied()
                    .unwrap_or_default()
                    .as_vec3();
            } else {
                p.ks[i] = m.ks as f32;
            }
        }
        if !p.area.iter().any(|&a| a > 0.0) {
            return Err("the scene has no patches (polygons) for the radiosity pass".into());
        }
        Ok(p)
    }

    pub fn is_patch(&self, i: usize) -> bool {
        self.area[i] > 0.0
    }

    /// The point a patch's rays start from: its centre, just off its front.
    fn origin(&self, i: usize) -> Vec3 {
        self.centre[i] + self.normal[i] * EPS
    }
}

/// The hemicube's pixel directions (in the patch's frame: z along the normal) and delta form
/// factors (summing to 1).
pub fn hemicube() -> Vec<(Vec3, f32)> {
    let mut v = Vec::with_capacity(HEMICUBE_PIXELS);
    let h = 2.0 / RES as f32;
    let da = h * h;
    for j in 0..RES {
        for i in 0..RES {
            let (x, y) = (-1.0 + (i as f32 + 0.5) * h, -1.0 + (j as f32 + 0.5) * h);
            let r = x * x + y * y + 1.0;
            v.push((Vec3::new(x, y, 1.0), da / (std::f32::consts::PI * r * r)));
        }
    }
    // Sides: +x, −x, +y, −y; u across the side, z up from the base.
    for side in 0..4 {
        for j in 0..RES / 2 {
            for i in 0..RES {
                let (u, z) = (-1.0 + (i as f32 + 0.5) * h, (j as f32 + 0.5) * h);
                let r = u * u + z * z + 1.0;
                let d = match side {
                    0 => Vec3::new(1.0, u, z),
                    1 => Vec3::new(-1.0, u, z),
                    2 => Vec3::new(u, 1.0, z),
                    _ => Vec3::new(u, -1.0, z),
                };
                v.push((d, z * da / (std::f32::consts::PI * r * r)));
            }
        }
    }
    let sum: f32 = v.iter().map(|p| p.1).sum();
    for p in &mut v {
        p.1 /= sum;
        p.0 = p.0.normalize();
    }
    v
}

/// How a delta-radiosity ray ends.
#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    /// On the front of this patch, adding `gain` × the ray's power.
    Deposit { patch: u32, gain: Vec3 },
    /// Reflected by a specular element: the child ray is the next one of the shot.
    Reflect,
    /// Left the space, or hit a back face or a matte quadric.
    Lost { hit: bool },
}

/// One ray of a shot: its subspace visits, how it ends, its power as a fraction of the shot's
/// (the pixel's delta form factor times the k_s of the reflections on its way).
#[derive(Clone, Copy, Debug)]
struct ShotRay {
    seg_start: u32,
    seg_count: u32,
    end: End,
    fraction: f32,
    /// The pixel's root ray (made by the FRGU) rather than a reflection.
    root: bool,
}

/// A shot's rays executed: roots in pixel order, each followed by its reflections; per subspace
/// visit one word: the subspace and what the RP block does after its tests ([`FIRST`], [`LAST`],
/// [`TAIL`]), so that a packet's step reads one word of the shot.
#[derive(Default)]
pub struct Shot {
    rays: Vec<ShotRay>,
    segs: Vec<u32>,
}

/// Segment word: the ray's first subspace (3D-DDA with initialisation).
const FIRST: u32 = 1 << 31;
/// Segment word: the ray's last subspace; bits 28-29 then say what follows the tests.
const LAST: u32 = 1 << 30;
const TAIL_SHIFT: u32 = 28;
/// Segment word, last subspace: the hit's intensity (ICU), a reflection (SRGU), or the DDA
/// finding no next subspace.
const TAIL: u32 = 3 << TAIL_SHIFT;
const TAIL_ICU: u32 = 0;
const TAIL_SRGU: u32 = 1;
const TAIL_DDA: u32 = 2;
/// Segment word: the subspace (below 2^28).
const SUBSPACE: u32 = (1 << TAIL_SHIFT) - 1;

impl Shot {
    /// Bytes held.
    fn bytes(&self) -> u64 {
        (self.rays.capacity() * std::mem::size_of::<ShotRay>() + self.segs.capacity() * 4) as u64
    }
}

/// Every patch's shot, executed when first needed and kept: a shot's rays go where they go
/// whatever the machine and whenever it is made (only their power differs), so the reference
/// and every simulated machine on the same subspaces share one execution per patch (the
/// machines may run on several threads). Up to a budget of bytes; past it shots are executed
/// each time and not kept.
pub struct ShotCache {
    shots: Vec<std::sync::OnceLock<std::sync::Arc<Shot>>>,
    bytes: std::sync::atomic::AtomicU64,
}

/// What the cache may hold (the full room's shots need about 1.5 GB at 32³ subspaces).
const CACHE_BYTES: u64 = 4 << 30;

impl ShotCache {
    fn new(n: usize) -> ShotCache {
        ShotCache {
            shots: (0..n).map(|_| std::sync::OnceLock::new()).collect(),
            bytes: Default::default(),
        }
    }

    /// Bytes of the shots kept.
    pub fn bytes(&self) -> u64 {
        self.bytes.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Patch `i`'s shot.
    fn get(
        &self,
        os: &ObjectSpace,
        patches: &Patches,
        cube: &[(Vec3, f32)],
        i: usize,
        c: &mut Counters,
    ) -> std::sync::Arc<Shot> {
        use std::sync::atomic::Ordering;
        if let Some(s) = self.shots[i].get() {
            return s.clone();
        }
        let mut shot = Shot::default();
        execute_shot(os, patches, cube, i, &mut shot, c);
        shot.rays.shrink_to_fit();
        shot.segs.shrink_to_fit();
        let shot = std::sync::Arc::new(shot);
        if self.bytes.load(Ordering::Relaxed) + shot.bytes() <= CACHE_BYTES
            && self.shots[i].set(shot.clone()).is_ok()
        {
            self.bytes.fetch_add(shot.bytes(), Ordering::Relaxed);
        }
        shot
    }
}

impl Clone for ShotCache {
    /// A clone starts empty (the shots are a cache).
    fn clone(&self) -> Self {
        ShotCache::new(self.shots.len())
    }
}

impl std::fmt::Debug for ShotCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ShotCache({} bytes)", self.bytes())
    }
}

/// The outward normal of specular element `o` at `p`.
fn specular_normal(os: &ObjectSpace, patches: &Patches, o: usize, p: Vec3) -> Vec3 {
    match os.geometry.prims[patches.first_prim[o] as usize] {
        Prim::Sphere { center, .. } => (p - center).normalize_or_zero(),
        Prim::Cone { base, apex, .. } => {
            // The radial direction (exact for cylinders, which are what the room has).
            let a = (apex - base).normalize_or_zero();
            let v = p - base;
            (v - a * v.dot(a)).normalize_or_zero()
        }
        Prim::Triangle(t) => (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero(),
    }
}

/// Executes patch `i`'s shot: every hemicube ray and its reflections.
fn execute_shot(
    os: &ObjectSpace,
    patches: &Patches,
    cube: &[(Vec3, f32)],
    i: usize,
    shot: &mut Shot,
    c: &mut Counters,
) {
    shot.rays.clear();
    shot.segs.clear();
    let n = patches.normal[i];
    let t = patches.tangent[i];
    let b = n.cross(t);
    let o = patches.origin(i);
    let mut segs: Vec<Segment> = Vec::new();
    for &(d, ff) in cube {
        let dir = (t * d.x + b * d.y + n * d.z).normalize();
        let mut ray = Ray::new(o, dir, 0.0, f32::INFINITY);
        let mut fraction = ff;
        let mut root = true;
        for depth in 0..=MAX_REFLECTIONS {
            segs.clear();
            let h = os.execute(&ray, false, &mut segs, c);
            let mut next = None;
            let end = if !h.is_hit() {
                End::Lost { hit: false }
            } else {
                let j = h.object as usize;
                if patches.is_patch(j) {
                    if ray.dir.dot(patches.normal[j]) < 0.0 {
                        End::Deposit {
                            patch: j as u32,
                            gain: patches.rho[j] / patches.area[j],
                        }
                    } else {
                        End::Lost { hit: true }
                    }
                } else if patches.ks[j] > 0.0 && depth < MAX_REFLECTIONS {
                    let p = ray.at(h.t);
                    let mut sn = specular_normal(os, patches, j, p);
                    if sn.dot(ray.dir) > 0.0 {
                        sn = -sn;
                    }
                    let r = (ray.dir - sn * (2.0 * ray.dir.dot(sn))).normalize();
                    next = Some((Ray::new(p + sn * EPS, r, 0.0, f32::INFINITY), patches.ks[j]));
                    End::Reflect
                } else {
                    End::Lost { hit: true }
                }
            };
            let tail = match end {
                End::Deposit { .. } | End::Lost { hit: true } => TAIL_ICU,
                End::Reflect => TAIL_SRGU,
                End::Lost { hit: false } => TAIL_DDA,
            };
            let start = shot.segs.len() as u32;
            for (k, sg) in segs.iter().enumerate() {
                // A subspace's work is all its primitives' tests (no shadow rays here), which
                // the simulation reads from the subspace ([`ObjectSpace::subspace_work`]).
                debug_assert_eq!(sg.work, os.subspace_work(sg.subspace as usize));
                assert!(
                    sg.subspace <= SUBSPACE,
                    "too many subspaces for a segment word"
                );
                let mut w = sg.subspace;
                if k == 0 {
                    w |= FIRST;
                }
                if k + 1 == segs.len() {
                    w |= LAST | (tail << TAIL_SHIFT);
                }
                shot.segs.push(w);
            }
            shot.rays.push(ShotRay {
                seg_start: start,
                seg_count: segs.len() as u32,
                end,
                fraction,
                root,
            });
            match next {
                Some((r, ks)) => {
                    ray = r;
                    fraction *= ks;
                    root = false;
                }
                None => break,
            }
        }
    }
}

/// A radiosity solution: per object (zero for non-patches).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Solution {
    #[serde(skip)]
    pub radiosity: Vec<Vec3>,
    #[serde(skip)]
    pub unshot: Vec<Vec3>,
    pub shots: u64,
    /// Delta-radiosity rays, reflections included.
    pub rays: u64,
    pub subspace_visits: u64,
}

impl Solution {
    fn start(patches: &Patches) -> Solution {
        Solution {
            radiosity: patches.emission.clone(),
            unshot: patches.emission.clone(),
            ..Default::default()
        }
    }

    /// Largest relative difference of any patch's radiosity (any channel) to `other`'s,
    /// relative to the larger of the two; channels where both are 0 agree.
    pub fn max_relative_difference(&self, other: &Solution) -> f64 {
        let mut m = 0.0f64;
        for (a, b) in self.radiosity.iter().zip(&other.radiosity) {
            for k in 0..3 {
                let (x, y) = (a[k] as f64, b[k] as f64);
                let d = x.abs().max(y.abs());
                if d > 0.0 {
                    m = m.max((x - y).abs() / d);
                }
            }
        }
        m
    }

    /// Largest difference of any patch's radiosity (any channel) to `other`'s, relative to the
    /// larger of the two or to `floor` if that is larger: radiosities below the threshold are
    /// known only to within it.
    pub fn max_difference_above(&self, other: &Solution, floor: f32) -> f64 {
        let mut m = 0.0f64;
        for (a, b) in self.radiosity.iter().zip(&other.radiosity) {
            for k in 0..3 {
                let (x, y) = (a[k] as f64, b[k] as f64);
                let d = x.abs().max(y.abs()).max(floor as f64);
                m = m.max((x - y).abs() / d);
            }
        }
        m
    }

    /// Largest absolute difference of any patch's radiosity (any channel) to `other`'s.
    pub fn max_abs_difference(&self, other: &Solution) -> f64 {
        let mut m = 0.0f64;
        for (a, b) in self.radiosity.iter().zip(&other.radiosity) {
            m = m.max((*a - *b).abs().max_element() as f64);
        }
        m
    }

    /// Mean over patches and channels of |B − B_other| / max(B, B_other) (0-0 pairs skipped).
    pub fn mean_relative_difference(&self, other: &Solution) -> f64 {
        let (mut s, mut n) = (0.0f64, 0u64);
        for (a, b) in self.radiosity.iter().zip(&other.radiosity) {
            for k in 0..3 {
                let (x, y) = (a[k] as f64, b[k] as f64);
                let d = x.abs().max(y.abs());
                if d > 0.0 {
                    s += (x - y).abs() / d;
                    n += 1;
                }
            }
        }
        s / n.max(1) as f64
    }

    fn apply(&mut self, shot: &Shot, power: Vec3) {
        self.shots += 1;
        self.rays += shot.rays.len() as u64;
        self.subspace_visits += shot.segs.len() as u64;
        for r in &shot.rays {
            if let End::Deposit { patch, gain } = r.end {
                let add = gain * power * r.fraction;
                self.radiosity[patch as usize] += add;
                self.unshot[patch as usize] += add;
            }
        }
    }
}

/// Checks a threshold: above 0 and finite.
pub fn check_threshold(threshold: f32) -> Result<(), String> {
    if threshold > 0.0 && threshold.is_finite() {
        Ok(())
    } else {
        Err(format!(
            "radiosity threshold must be above 0, got {threshold}"
        ))
    }
}

/// The plain single-process progressive refinement: shoot the globally brightest patch until
/// none has unshot radiosity above `threshold`.
pub fn reference(os: &ObjectSpace, patches: &Patches, threshold: f32) -> Solution {
    let cube = hemicube();
    let mut s = Solution::start(patches);
    let mut c = Counters::default();
    loop {
        let mut best = None;
        let mut level = threshold;
        for (i, u) in s.unshot.iter().enumerate() {
            let u = u.max_element();
            if patches.is_patch(i) && u > level {
                (best, level) = (Some(i), u);
            }
        }
        let Some(i) = best else { break };
        let power = s.unshot[i] * patches.area[i];
        s.unshot[i] = Vec3::ZERO;
        let shot = patches.shots.get(os, patches, &cube, i, &mut c);
        s.apply(&shot, power);
    }
    s
}

/// What the machine's radiosity pass measured, and its solution.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RadiosityRun {
    /// Image time of the pass: the last event.
    pub clocks: u64,
    pub pes: u64,
    pub rp_blocks: u64,
    /// RP-block busy clocks, in all and on the busiest PE.
    pub busy: u64,
    pub busy_max_pe: u64,
    /// Ray packets handled by an RD (one per ray per subspace).
    pub events: u64,
    pub packets: u64,
    pub hops: u64,
    pub solution: Solution,
}

impl RadiosityRun {
    pub fn utilisation(&self) -> f64 {
        self.busy as f64 / (self.clocks.max(1) as f64 * (self.pes * self.rp_blocks) as f64)
    }
    pub fn imbalance(&self) -> f64 {
        self.busy_max_pe as f64 * self.pes as f64 / self.busy.max(1) as f64
    }
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Ev {
    /// PE's FRGU picks its next patch.
    Pick(u32),
    /// PE's FRGU sends root `ray` of shot `shot`.
    Emit { pe: u32, shot: u32, ray: u32 },
    /// Ray `ray` of shot `shot` reaches the RD of PE `pe`, owning its segment `seg`.
    Arrive {
        shot: u32,
        ray: u32,
        seg: u32,
        pe: u32,
    },
    /// …and its RP block is done with it; `next`: the PE of its next segment ([`NONE`]: it
    /// ended there). Events carry what the next one needs, so that a packet's step touches the
    /// shot's record once.
    Done {
        shot: u32,
        ray: u32,
        seg: u32,
        pe: u32,
        next: u32,
    },
}

const NONE: u32 = u32::MAX;

/// The torus's PE coordinates, for routing without divisions per packet.
struct Router {
    pes: [u32; 3],
    coords: Vec<[u32; 3]>,
}

impl Router {
    fn new(machine: &Machine) -> Router {
        Router {
            pes: machine.pes,
            coords: (0..machine.pe_count() as u32)
                .map(|p| machine.pe_coords(p))
                .collect(),
        }
    }

    /// [`Machine::route`]: hops, and the first hop's outgoing link.
    fn route(&self, from: u32, to: u32) -> (u32, usize) {
        let (a, b) = (self.coords[from as usize], self.coords[to as usize]);
        let mut hops = 0;
        let mut link = usize::MAX;
        for i in 0..3 {
            if a[i] == b[i] {
                continue;
            }
            let n = self.pes[i];
            let up = if b[i] > a[i] {
                b[i] - a[i]
            } else {
                b[i] + n - a[i]
            };
            let down = n - up;
            let (d, dir) = if up <= down { (up, 0) } else { (down, 1) };
            hops += d;
            if link == usize::MAX {
                link = 2 * i + dir;
            }
        }
        (hops, if link == usize::MAX { 0 } else { link })
    }
}

/// The radiosity pass on `machine` (subspace owners `owner`) until no delta-radiosity ray
/// remains and no PE has a patch above `threshold`.
pub fn simulate(
    os: &ObjectSpace,
    patches: &Patches,
    machine: &Machine,
    owner: &[u32],
    costs: &Costs,
    threshold: f32,
) -> RadiosityRun {
    let cube = hemicube();
    let pes = machine.pe_count();
    let rpb = machine.rp_blocks as usize;
    let router = Router::new(machine);
    // Per subspace: its PE and its tests' clocks (one load per packet step).
    let sub: Vec<(u32, u32)> = owner
        .iter()
        .enumerate()
        .map(|(s, &pe)| (pe, os.subspace_work(s)))
        .collect();
    let mut sol = Solution::start(patches);
    // Each patch's PE: the owner of the subspace holding its ray origin.
    let lattice = &os.subspaces.lattice;
    let mut pe_patches: Vec<Vec<u32>> = vec![Vec::new(); pes];
    let mut patch_pe = vec![u32::MAX; patches.area.len()];
    for (i, patch_pe) in patch_pe.iter_mut().enumerate() {
        if patches.is_patch(i) {
            let s = lattice.index(lattice.cell_of(patches.origin(i)));
            let pe = owner[s];
            *patch_pe = pe;
            pe_patches[pe as usize].push(i as u32);
        }
    }
    let mut run = RadiosityRun {
        pes: pes as u64,
        rp_blocks: rpb as u64,
        ..Default::default()
    };
    let mut heap = RadixHeap::default();
    let mut frgu_idle = vec![false; pes];
    for pe in 0..pes {
        heap.push(0, Ev::Pick(pe as u32));
    }
    // Shots in flight: (the shot, power, rays not yet finished); freed slots are reused.
    let mut shots: Vec<(std::sync::Arc<Shot>, Vec3, u32)> = Vec::new();
    let mut free: Vec<u32> = Vec::new();
    let mut rp_free = vec![0u64; pes * rpb];
    let mut busy = vec![0u64; pes];
    let mut link_free = vec![0u64; pes * 6];
    let mut c = Counters::default();
    let mut send = |from: u32, to: u32, t: u64, run: &mut RadiosityRun| -> u64 {
        let (hops, link) = router.route(from, to);
        let lf = &mut link_free[from as usize * 6 + link];
        let start = t.max(*lf);
        *lf = start + costs.hop as u64;
        run.packets += 1;
        run.hops += hops as u64;
        start + hops as u64 * costs.hop as u64
    };
    let mut last = 0u64;
    // An arrival at the current time is handled next without going through the heap: the heap
    // pops events of one time last-pushed first, so it would have come out next all the same.
    let mut now: Option<Ev> = None;
    loop {
        let (t, ev) = match now.take() {
            Some(e) => (last, e),
            None => match heap.pop() {
                Some(x) => x,
                None => break,
            },
        };
        last = t;
        let mut arrive = |at: u64, e: Ev, heap: &mut RadixHeap<Ev>| {
            if at == t {
                debug_assert!(now.is_none());
                now = Some(e);
            } else {
                heap.push(at, e);
            }
        };
        match ev {
            Ev::Pick(pe) => {
                let mut best = None;
                let mut level = threshold;
                for &i in &pe_patches[pe as usize] {
                    let u = sol.unshot[i as usize].max_element();
                    if u > level {
                        (best, level) = (Some(i as usize), u);
                    }
                }
                let Some(i) = best else {
                    frgu_idle[pe as usize] = true;
                    continue;
                };
                let power = sol.unshot[i] * patches.area[i];
                sol.unshot[i] = Vec3::ZERO;
                let shot = patches.shots.get(os, patches, &cube, i, &mut c);
                sol.shots += 1;
                sol.rays += shot.rays.len() as u64;
                sol.subspace_visits += shot.segs.len() as u64;
                let first = next_root(&shot, 0);
                let slot = match free.pop() {
                    Some(k) => {
                        shots[k as usize] = (shot, power, 0);
                        k
                    }
                    None => {
                        shots.push((shot, power, 0));
                        shots.len() as u32 - 1
                    }
                };
                let entry = &mut shots[slot as usize];
                entry.2 = entry.0.rays.len() as u32;
                heap.push(
                    t + HEMICUBE_SETUP,
                    Ev::Emit {
                        pe,
                        shot: slot,
                        ray: first,
                    },
                );
            }
            Ev::Emit { pe, shot, ray } => {
                let sh = &shots[shot as usize].0;
                let next = next_root(sh, ray + 1);
                if next < sh.rays.len() as u32 {
                    // FRGU → RD → RP is a pipeline: the FRGU hands its next ray on no sooner
                    // than one of its PE's RP blocks is free.
                    let p = pe as usize;
                    let rp_ready = rp_free[p * rpb..p * rpb + rpb].iter().copied().min();
                    heap.push(
                        (t + costs.primary as u64).max(rp_ready.unwrap_or(0)),
                        Ev::Emit {
                            pe,
                            shot,
                            ray: next,
                        },
                    );
                } else {
                    heap.push(t, Ev::Pick(pe));
                }
                let r = sh.rays[ray as usize];
                if r.seg_count == 0 {
                    let pending = &mut shots[shot as usize].2;
                    *pending -= 1;
                    if *pending == 0 {
                        free.push(shot);
                    }
                    continue;
                }
                let to = sub[(sh.segs[r.seg_start as usize] & SUBSPACE) as usize].0;
                let at = if to == pe {
                    t
                } else {
                    send(pe, to, t, &mut run)
                };
                arrive(
                    at,
                    Ev::Arrive {
                        shot,
                        ray,
                        seg: r.seg_start,
                        pe: to,
                    },
                    &mut heap,
                );
            }
            Ev::Arrive { shot, ray, seg, pe } => {
                run.events += 1;
                let segs = &shots[shot as usize].0.segs;
                let w = segs[seg as usize];
                let work = sub[(w & SUBSPACE) as usize].1;
                let (next, tail) = if w & LAST == 0 {
                    let next = sub[(segs[seg as usize + 1] & SUBSPACE) as usize].0;
                    let dda = if w & FIRST != 0 {
                        costs.dda_init
                    } else {
                        costs.dda
                    };
                    (next, dda + costs.packet)
                } else {
                    let tail = match (w & TAIL) >> TAIL_SHIFT {
                        TAIL_ICU => costs.intensity,
                        TAIL_SRGU => costs.secondary,
                        _ => costs.dda,
                    };
                    (NONE, tail)
                };
                let cost = work.saturating_add(tail) as u64;
                let p = pe as usize;
                let blocks = &mut rp_free[p * rpb..p * rpb + rpb];
                let mut b = 0;
                for (j, &f) in blocks.iter().enumerate().skip(1) {
                    if f < blocks[b] {
                        b = j;
                    }
                }
                let end = t.max(blocks[b]) + cost;
                blocks[b] = end;
                busy[p] += cost;
                heap.push(
                    end,
                    Ev::Done {
                        shot,
                        ray,
                        seg,
                        pe,
                        next,
                    },
                );
            }
            Ev::Done {
                shot,
                ray,
                seg,
                pe,
                next,
            } => {
                if next != NONE {
                    let at = if next == pe {
                        t
                    } else {
                        send(pe, next, t, &mut run)
                    };
                    arrive(
                        at,
                        Ev::Arrive {
                            shot,
                            ray,
                            seg: seg + 1,
                            pe: next,
                        },
                        &mut heap,
                    );
                    continue;
                }
                let (sh, power, pending) = &mut shots[shot as usize];
                let r = sh.rays[ray as usize];
                *pending -= 1;
                match r.end {
                    End::Deposit { patch, gain } => {
                        let j = patch as usize;
                        let add = gain * *power * r.fraction;
                        sol.radiosity[j] += add;
                        sol.unshot[j] += add;
                        let q = patch_pe[j] as usize;
                        if frgu_idle[q] && sol.unshot[j].max_element() > threshold {
                            frgu_idle[q] = false;
                            heap.push(t, Ev::Pick(q as u32));
                        }
                    }
                    End::Reflect => {
                        let child = sh.rays[ray as usize + 1];
                        if child.seg_count == 0 {
                            *pending -= 1;
                        } else {
                            let to = sub[(sh.segs[child.seg_start as usize] & SUBSPACE) as usize].0;
                            let at = if to == pe {
                                t
                            } else {
                                send(pe, to, t, &mut run)
                            };
                            arrive(
                                at,
                                Ev::Arrive {
                                    shot,
                                    ray: ray + 1,
                                    seg: child.seg_start,
                                    pe: to,
                                },
                                &mut heap,
                            );
                        }
                    }
                    End::Lost { .. } => {}
                }
                if *pending == 0 {
                    free.push(shot);
                }
            }
        }
    }
    run.clocks = last;
    run.busy = busy.iter().sum();
    run.busy_max_pe = busy.iter().copied().max().unwrap_or(0);
    run.solution = sol;
    run
}

/// The first root ray at or after `k` (reflections follow their root).
fn next_root(shot: &Shot, mut k: u32) -> u32 {
    while (k as usize) < shot.rays.len() && !shot.rays[k as usize].root {
        k += 1;
    }
    k
}

/// A monotone priority queue on clocks (a radix heap): pops in time order, events of the same
/// time last-pushed first; pushes never precede the last pop. Deterministic: the same pushes and
/// pops give the same order.
struct RadixHeap<T> {
    last: u64,
    buckets: Vec<Vec<(u64, T)>>,
}

impl<T> Default for RadixHeap<T> {
    fn default() -> Self {
        RadixHeap {
            last: 0,
            buckets: (0..65).map(|_| Vec::new()).collect(),
        }
    }
}

impl<T> RadixHeap<T> {
    fn bucket(last: u64, key: u64) -> usize {
        64 - (key ^ last).leading_zeros() as usize
    }

    fn push(&mut self, key: u64, v: T) {
        debug_assert!(key >= self.last);
        self.buckets[Self::bucket(self.last, key)].push((key, v));
    }

    fn pop(&mut self) -> Option<(u64, T)> {
        if self.buckets[0].is_empty() {
            let i = self.buckets.iter().position(|b| !b.is_empty())?;
            // Every entry of bucket i goes to a lower bucket: its allocation is kept for reuse
            // (taking it would reallocate the buckets on every redistribution).
            let mut b = std::mem::take(&mut self.buckets[i]);
            self.last = b.iter().map(|e| e.0).min()?;
            for (k, v) in b.drain(..) {
                self.buckets[Self::bucket(self.last, k)].push((k, v));
            }
            debug_assert!(self.buckets[i].is_empty());
            self.buckets[i] = b;
        }
        self.buckets[0].pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order every simulated clock depends on: time order, and on equal times the last
    /// pushed first (also across a redistribution of buckets).
    #[test]
    fn the_radix_heap_pops_in_time_order_last_pushed_first_on_ties() {
        let mut q = RadixHeap::default();
        for (t, v) in [(5u64, 1u32), (3, 2), (5, 3), (9, 4), (3, 5)] {
            q.push(t, v);
        }
        assert_eq!(q.pop(), Some((3, 5)));
        q.push(3, 6);
        q.push(4, 7);
        let order: Vec<(u64, u32)> = std::iter::from_fn(|| q.pop()).collect();
        assert_eq!(order, [(3, 6), (3, 2), (4, 7), (5, 3), (5, 1), (9, 4)]);
    }
}
