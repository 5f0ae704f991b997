//! The scene model: exactly the records of NFF, nothing more (docs/concepts.md).
//!
//! Primitives stay what the SPD says they are: sphere, open cone/cylinder, polygon (convex or
//! concave), triangle patch with vertex normals. Coordinates are `f64`, as the C generators
//! compute them; engines convert to `f32` when they build.

use glam::DVec3;
use serde::Serialize;

/// The `v` block of an NFF file.
#[derive(Clone, Debug, PartialEq)]
pub struct View {
    pub from: DVec3,
    pub at: DVec3,
    pub up: DVec3,
    /// Full field of view in degrees.
    pub angle: f64,
    pub hither: f64,
    pub resolution: [u32; 2],
}

impl Default for View {
    fn default() -> Self {
        View {
            from: DVec3::new(0.0, 0.0, 1.0),
            at: DVec3::ZERO,
            up: DVec3::Y,
            angle: 45.0,
            hither: 1e-3,
            resolution: [512, 512],
        }
    }
}

/// An `l` record: a positional light, optionally coloured.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub position: DVec3,
    pub color: Option<DVec3>,
}

/// An `f` record: `r g b Kd Ks Shine T index_of_refraction`.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub color: DVec3,
    pub kd: f64,
    pub ks: f64,
    pub shine: f64,
    pub t: f64,
    pub ior: f64,
}

impl Material {
    /// The material of SPD's `lib_output_color`: the Phong exponent is derived from the highlight
    /// half-angle `ang` in degrees (libpr1.c). `ka` and `ks_spec` do not reach NFF.
    pub fn from_spd(color: DVec3, kd: f64, ks: f64, ang: f64, kt: f64, ior: f64) -> Material {
        let ang_radians = std::f64::consts::PI * ang / 180.0;
        let shine = if ang_radians <= 0.0 {
            100000.0
        } else if ang_radians >= std::f64::consts::PI / 2.0 {
            1.0
        } else {
            0.5f64.ln() / ang_radians.cos().ln()
        };
        Material {
            color,
            kd,
            ks,
            shine,
            t: kt,
            ior,
        }
    }
}

impl Default for Material {
    fn default() -> Self {
        Material {
            color: DVec3::ONE,
            kd: 1.0,
            ks: 0.0,
            shine: 1.0,
            t: 0.0,
            ior: 1.0,
        }
    }
}

/// A primitive as a stream hands it out: borrowed vertex lists, no allocation per record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeRef<'a> {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    /// Open cone or cylinder: no caps.
    Cone {
        base: DVec3,
        base_radius: f64,
        apex: DVec3,
        apex_radius: f64,
    },
    Polygon(&'a [DVec3]),
    /// A polygonal patch with one normal per vertex (`pp`).
    Patch {
        vertices: &'a [DVec3],
        normals: &'a [DVec3],
    },
}

/// An owned primitive, as a [`Scene`] holds it.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    Cone {
        base: DVec3,
        base_radius: f64,
        apex: DVec3,
        apex_radius: f64,
    },
    Polygon(Vec<DVec3>),
    Patch {
        vertices: Vec<DVec3>,
        normals: Vec<DVec3>,
    },
}

impl Shape {
    /// Axis-aligned bounds (see [`ShapeRef::bounds`]).
    pub fn bounds(&self) -> Bounds {
        self.as_ref().bounds()
    }

    pub fn as_ref(&self) -> ShapeRef<'_> {
        match self {
            Shape::Sphere { center, radius } => ShapeRef::Sphere {
                center: *center,
                radius: *radius,
            },
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => ShapeRef::Cone {
                base: *base,
                base_radius: *base_radius,
                apex: *apex,
                apex_radius: *apex_radius,
            },
            Shape::Polygon(v) => ShapeRef::Polygon(v),
            Shape::Patch { vertices, normals } => ShapeRef::Patch { vertices, normals },
        }
    }
}

impl ShapeRef<'_> {
    pub fn to_owned(&self) -> Shape {
        match *self {
            ShapeRef::Sphere { center, radius } => Shape::Sphere { center, radius },
            ShapeRef::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            },
            ShapeRef::Polygon(v) => Shape::Polygon(v.to_vec()),
            ShapeRef::Patch { vertices, normals } => Shape::Patch {
                vertices: vertices.to_vec(),
                normals: normals.to_vec(),
            },
        }
    }

    /// Axis-aligned bounds of the primitive (conservative for cones: the boxes of both end discs).
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        match *self {
            ShapeRef::Sphere { center, radius } => {
                b.grow(center - DVec3::splat(radius.abs()));
                b.grow(center + DVec3::splat(radius.abs()));
            }
            ShapeRef::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                let axis = (apex - base).normalize_or_zero();
                // Extent of a disc of radius r with normal `axis` along each world axis: r·sqrt(1 − a_i²).
                let e = (DVec3::ONE - axis * axis).max(DVec3::ZERO);
                let e = DVec3::new(e.x.sqrt(), e.y.sqrt(), e.z.sqrt());
                for (c, r) in [(base, base_radius.abs()), (apex, apex_radius.abs())] {
                    b.grow(c - e * r);
                    b.grow(c + e * r);
                }
            }
            ShapeRef::Polygon(v) | ShapeRef::Patch { vertices: v, .. } => {
                for p in v {
                    b.grow(*p);
                }
            }
        }
        b
    }
}

/// One primitive with the index of the material (`f` record) in force when it was emitted.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    pub material: u32,
    pub shape: Shape,
}

/// Axis-aligned box. `EMPTY` has min = +inf, max = −inf.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
    };

    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&mut self, o: &Bounds) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    pub fn extent(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }
}

/// A whole scene in memory: collected from a generator's stream or read from NFF.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Program and size factor when generated, the file name when read.
    pub name: String,
    pub view: View,
    pub background: DVec3,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub objects: Vec<Object>,
}

impl Scene {
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for o in &self.objects {
            b.union(&o.shape.as_ref().bounds());
        }
        b
    }
}
