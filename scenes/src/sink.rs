//! Where a scene stream goes. A generator (or the NFF reader) calls a [`Sink`] once per record, in
//! file order, so a scene of any size can be written, counted or stored without being held.

use crate::model::{Bounds, Light, Material, Object, Scene, ShapeRef, View};
use glam::DVec3;
use serde::Serialize;

/// One call per NFF record, in the order the C program prints them.
pub trait Sink {
    fn background(&mut self, color: DVec3);
    fn view(&mut self, view: &View);
    fn light(&mut self, light: &Light);
    fn material(&mut self, material: &Material);
    fn shape(&mut self, shape: ShapeRef<'_>);
}

/// Collects a stream into a [`Scene`].
#[derive(Default)]
pub struct SceneCollector {
    pub scene: Scene,
}

impl Sink for SceneCollector {
    fn background(&mut self, color: DVec3) {
        self.scene.background = color;
    }
    fn view(&mut self, view: &View) {
        self.scene.view = view.clone();
    }
    fn light(&mut self, light: &Light) {
        self.scene.lights.push(light.clone());
    }
    fn material(&mut self, material: &Material) {
        self.scene.materials.push(material.clone());
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        if self.scene.materials.is_empty() {
            // NFF allows primitives before any `f`: they get the default material.
            self.scene.materials.push(Material::default());
        }
        let material = (self.scene.materials.len() - 1) as u32;
        self.scene.objects.push(Object {
            material,
            shape: shape.to_owned(),
        });
    }
}

/// Primitive counts, as `rtbench scene stats` reports them (docs/concepts.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    pub sphere: u64,
    pub cone: u64,
    pub polygon: u64,
    pub patch: u64,
    /// Triangles after fanning polygons and patches (n-gon → n − 2); curved primitives count
    /// only once tessellated (they are then patches in the stream).
    pub triangles: u64,
}

impl Counts {
    pub fn objects(&self) -> u64 {
        self.sphere + self.cone + self.polygon + self.patch
    }
}

/// Counts a stream and its bounds without holding it.
#[derive(Default)]
pub struct CountingSink {
    pub counts: Counts,
    pub lights: u64,
    pub materials: u64,
    pub bounds: Option<Bounds>,
}

impl Sink for CountingSink {
    fn background(&mut self, _: DVec3) {}
    fn view(&mut self, _: &View) {}
    fn light(&mut self, _: &Light) {
        self.lights += 1;
    }
    fn material(&mut self, _: &Material) {
        self.materials += 1;
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        let c = &mut self.counts;
        match shape {
            ShapeRef::Sphere { .. } => c.sphere += 1,
            ShapeRef::Cone { .. } => c.cone += 1,
            ShapeRef::Polygon(v) => {
                c.polygon += 1;
                c.triangles += v.len().saturating_sub(2) as u64;
            }
            ShapeRef::Patch { vertices, .. } => {
                c.patch += 1;
                c.triangles += vertices.len().saturating_sub(2) as u64;
            }
        }
        self.bounds
            .get_or_insert(Bounds::EMPTY)
            .union(&shape.bounds());
    }
}
