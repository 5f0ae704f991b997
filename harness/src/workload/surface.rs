//! What shading needs at a hit, per scene object: the shading normal (sphere, cone, polygon,
//! smooth patch) and the material. Built once per scene in `f32`; the per-object values are the
//! store's [`Surface`], so the out-of-core workload shades from the same definition.

use glam::Vec3;
use rtbench_engines::store::Surface;
use rtbench_engines::Hit;
use rtbench_scenes::Scene;

pub struct Surfaces {
    shapes: Vec<Surface>,
    pub material: Vec<u32>,
}

impl Surfaces {
    pub fn new(scene: &Scene) -> Surfaces {
        Surfaces {
            shapes: scene
                .objects
                .iter()
                .map(|o| Surface::of(o.shape.as_ref()))
                .collect(),
            material: scene.objects.iter().map(|o| o.material).collect(),
        }
    }

    /// (shading normal, geometric normal) at point `p` of the hit (see [`Surface::normals`]).
    pub fn normals(&self, hit: &Hit, p: Vec3) -> (Vec3, Vec3) {
        self.shapes[hit.object as usize].normals(hit, p)
    }
}
