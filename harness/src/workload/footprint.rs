//! How much memory a generated scene takes once held, with an engine's structure built over it,
//! known before it is generated: one estimate for every command that holds a scene (render,
//! check, tree-stats), covering the size factor, the tessellation resolution and each engine.
//!
//! The scene is counted, not guessed: the program runs into a counting sink at the largest size
//! factor up to the one asked whose scene has at most [`COUNT_OBJECTS`] objects, untessellated,
//! and the counts are scaled by the object count at the size factor asked. Tessellation is then
//! applied by its own formulas (`scenes/src/spd/tessellate.rs`: a sphere is 6 faces of RES × RES
//! quads, 12 RES² triangles; a cone 4 RES strips of 2 triangles, 8 RES), each triangle one
//! object of the scene.

use rtbench_scenes::spd::{self, Options, Program};
use rtbench_scenes::{Light, Material, ShapeRef, Sink, View};

/// Most objects the counting pass generates (a few milliseconds).
const COUNT_OBJECTS: u64 = 20_000;

/// Bytes the scene holds per object (the shape, its material index, the prepared `f32`
/// primitive and its bounds), and per polygon vertex (position and normal, f64).
const SCENE_PER_OBJECT: u64 = 160;
const SCENE_PER_VERTEX: u64 = 48;

/// Bytes an engine holds per primitive it builds over, beyond the scene, at its peak (structure,
/// build scratch, its copy of the primitives): peak RSS less the reference engine's on balls SF 2
/// tessellated at 40 (1.75 million triangles) and on gears SF 8 (293,000 triangles), rounded up.
/// With [`SCENE_PER_OBJECT`] and [`SCENE_PER_VERTEX`] the estimate comes out 10–20 % above the
/// peak RSS measured there.
fn per_primitive(engine: &str) -> u64 {
    match engine.split(':').next().unwrap_or(engine) {
        "reference" => 16,
        "grid" | "breadth-first" => 64,
        "bvh2" | "bvh4" | "bvh8" => 96,
        "embree" => 160,
        "obvhs" => 256,
        _ => 256,
    }
}

/// What a scene holds (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Census {
    pub objects: u64,
    pub spheres: u64,
    pub cones: u64,
    pub triangles: u64,
    pub vertices: u64,
}

impl Sink for Census {
    fn background(&mut self, _: glam::DVec3) {}
    fn view(&mut self, _: &View) {}
    fn light(&mut self, _: &Light) {}
    fn material(&mut self, _: &Material) {}
    fn shape(&mut self, shape: ShapeRef<'_>) {
        self.objects += 1;
        match shape {
            ShapeRef::Sphere { .. } => self.spheres += 1,
            ShapeRef::Cone { .. } => self.cones += 1,
            ShapeRef::Polygon(v) | ShapeRef::Patch { vertices: v, .. } => {
                self.triangles += v.len().saturating_sub(2) as u64;
                self.vertices += v.len() as u64;
            }
        }
    }
}

impl Census {
    /// The counts of `program` at `opts` (module docs).
    pub fn of(program: Program, opts: &Options) -> Census {
        let objects = program.object_count(opts.size_factor).unwrap_or(u64::MAX);
        let mut counted_sf = 1;
        for sf in 1..=opts.size_factor {
            match program.object_count(sf) {
                Some(n) if n <= COUNT_OBJECTS => counted_sf = sf,
                _ => break,
            }
        }
        let small = Options {
            size_factor: counted_sf,
            tessellate: None,
            ..*opts
        };
        let mut c = Census::default();
        if spd::generate(program, &small, &mut c).is_err() || c.objects == 0 {
            // The real generation reports the error; count one primitive per object meanwhile.
            c = Census {
                objects: 1,
                triangles: 1,
                vertices: 3,
                ..Census::default()
            };
        }
        let scale = objects as f64 / c.objects as f64;
        let up = |n: u64| (n as f64 * scale).min(u64::MAX as f64) as u64;
        let mut out = Census {
            objects,
            spheres: up(c.spheres),
            cones: up(c.cones),
            triangles: up(c.triangles),
            vertices: up(c.vertices),
        };
        if let Some(res) = opts.tessellate {
            let r = res as u64;
            let tris = out
                .spheres
                .saturating_mul(12u64.saturating_mul(r).saturating_mul(r))
                .saturating_add(out.cones.saturating_mul(8u64.saturating_mul(r)));
            out.objects = out
                .objects
                .saturating_sub(out.spheres + out.cones)
                .saturating_add(tris);
            out.triangles = out.triangles.saturating_add(tris);
            out.vertices = out.vertices.saturating_add(tris.saturating_mul(3));
            out.spheres = 0;
            out.cones = 0;
        }
        out
    }

    /// Triangles, spheres and cones: what an engine builds over.
    pub fn primitives(&self) -> u64 {
        self.triangles
            .saturating_add(self.spheres)
            .saturating_add(self.cones)
    }

    /// Bytes of the scene held with the structures of `engines` (all at once) over it.
    pub fn bytes(&self, engines: &[&str]) -> u64 {
        let scene = self
            .objects
            .saturating_mul(SCENE_PER_OBJECT)
            .saturating_add(self.vertices.saturating_mul(SCENE_PER_VERTEX));
        engines.iter().fold(scene, |acc, e| {
            acc.saturating_add(self.primitives().saturating_mul(per_primitive(e)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn census(p: Program, sf: u32, tess: Option<u32>) -> Census {
        let o = Options {
            size_factor: sf,
            tessellate: tess,
            ..Options::standard(p)
        };
        Census::of(p, &o)
    }

    #[test]
    fn counts_follow_the_size_factor_and_the_resolution() {
        // balls sf 1: 10 spheres and the floor polygon (SPD).
        let b = census(Program::Balls, 1, None);
        assert_eq!((b.objects, b.spheres, b.triangles), (11, 10, 2));
        // Tessellated at 1000: 12 million triangles a sphere.
        let t = census(Program::Balls, 1, Some(1000));
        assert_eq!(t.triangles, 2 + 10 * 12_000_000);
        assert!(t.bytes(&["bvh4"]) > 30 << 30, "{}", t.bytes(&["bvh4"]));
        // Scaled past what is counted: the object count is SPD's, the shares the small scene's.
        let g = census(Program::Gears, 40, None);
        assert_eq!(g.objects, Program::Gears.object_count(40).unwrap());
        assert!(g.triangles > g.objects, "{g:?}");
        for e in [
            "bvh4",
            "embree",
            "grid",
            "obvhs",
            "reference",
            "breadth-first",
        ] {
            assert!(g.bytes(&[e]) > g.objects * SCENE_PER_OBJECT, "{e}");
            assert!(g.bytes(&[e, "embree"]) > g.bytes(&[e]), "{e}");
        }
    }
}
