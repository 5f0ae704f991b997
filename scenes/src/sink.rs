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

/// Primitive counts, as `rtbench scene stats` reports them (../shared/CLI.md).
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

/// Sends every record to two sinks.
pub struct Tee<'a, A: Sink + ?Sized, B: Sink + ?Sized>(pub &'a mut A, pub &'a mut B);

impl<A: Sink + ?Sized, B: Sink + ?Sized> Sink for Tee<'_, A, B> {
    fn background(&mut self, color: DVec3) {
        self.0.background(color);
        self.1.background(color);
    }
    fn view(&mut self, view: &View) {
        self.0.view(view);
        self.1.view(view);
    }
    fn light(&mut self, light: &Light) {
        self.0.light(light);
        self.1.light(light);
    }
    fn material(&mut self, material: &Material) {
        self.0.material(material);
        self.1.material(material);
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        self.0.shape(shape);
        self.1.shape(shape);
    }
}

/// Replays a scene in memory into a sink (e.g. to write it as NFF).
pub fn replay(scene: &Scene, sink: &mut dyn Sink) {
    sink.background(scene.background);
    sink.view(&scene.view);
    for l in &scene.lights {
        sink.light(l);
    }
    let mut current = None;
    for o in &scene.objects {
        if current != Some(o.material) {
            sink.material(&scene.materials[o.material as usize]);
            current = Some(o.material);
        }
        sink.shape(o.shape.as_ref());
    }
}
