//! What every scene must satisfy before an engine sees it, whatever its source (NFF, SPD
//! program, scene store): one set of rules, so that no engine is handed a scene it traces
//! differently from the others or not at all.
//!
//! - Every coordinate (vertices, centres, cone ends, lights, the camera) is finite and at most
//!   [`MAX_COORD`] in absolute value. Engines trace in `f32`: at 1e6 a unit is still resolved to
//!   1/16, products of two coordinates (1e12) and the squares the sphere test takes stay far from
//!   `f32`'s 3.4e38, and the grids and BVHs of every engine build on such bounds.
//! - Sphere radii are from [`MIN_RADIUS`] to [`MAX_COORD`] (zero gave NaN normals, negative ones
//!   engine-dependent hits); cone radii are from 0 to [`MAX_COORD`], not both 0, and the cone's
//!   ends are apart.
//! - The view is usable: `from` ≠ `at`, `up` not zero nor parallel to the line of sight,
//!   0 < angle < 180 degrees, hither ≥ 0 (an up of zero, or an angle of 0, 180 or more, rendered
//!   blank or mirrored images).
//! - Material and colour numbers are finite.

use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use glam::DVec3;

/// Largest absolute coordinate accepted.
pub const MAX_COORD: f64 = 1e6;
/// Smallest sphere radius accepted.
pub const MIN_RADIUS: f64 = 1e-12;

fn point(p: DVec3, what: &str) -> Result<(), String> {
    if !p.is_finite() || p.abs().max_element() > MAX_COORD {
        return Err(format!(
            "{what} ({} {} {}) is outside the coordinate range ±{MAX_COORD:e}",
            p.x, p.y, p.z
        ));
    }
    Ok(())
}

fn finite(p: DVec3, what: &str) -> Result<(), String> {
    if !p.is_finite() {
        return Err(format!("{what} is not finite"));
    }
    Ok(())
}

/// The view is usable (see the module's rules).
pub fn check_view(v: &View) -> Result<(), String> {
    point(v.from, "view 'from'")?;
    point(v.at, "view 'at'")?;
    finite(v.up, "view 'up'")?;
    let dir = v.at - v.from;
    if dir.length_squared() == 0.0 {
        return Err("view 'from' and 'at' are the same point".into());
    }
    let up = v.up;
    if up.length_squared() == 0.0 {
        return Err("view 'up' is the zero vector".into());
    }
    // Parallel (or nearly: the camera's right vector would be lost in rounding).
    if dir.normalize().cross(up.normalize()).length() < 1e-6 {
        return Err(format!(
            "view 'up' ({} {} {}) is parallel to the line of sight",
            up.x, up.y, up.z
        ));
    }
    if !(v.angle > 0.0 && v.angle < 180.0) {
        return Err(format!(
            "view angle {} must be between 0 and 180 degrees (exclusive)",
            v.angle
        ));
    }
    if !(v.hither >= 0.0 && v.hither.is_finite()) {
        return Err(format!("view hither {} must be 0 or more", v.hither));
    }
    if v.resolution[0] == 0 || v.resolution[1] == 0 {
        return Err("view resolution must be at least 1 by 1".into());
    }
    Ok(())
}

pub fn check_light(l: &Light) -> Result<(), String> {
    point(l.position, "light position")?;
    if let Some(c) = l.color {
        finite(c, "light colour")?;
    }
    Ok(())
}

pub fn check_material(m: &Material) -> Result<(), String> {
    finite(m.color, "material colour")?;
    for (x, what) in [
        (m.kd, "Kd"),
        (m.ks, "Ks"),
        (m.shine, "Shine"),
        (m.t, "T"),
        (m.ior, "index of refraction"),
    ] {
        if !x.is_finite() {
            return Err(format!("material {what} is not finite"));
        }
    }
    Ok(())
}

pub fn check_background(c: DVec3) -> Result<(), String> {
    finite(c, "background colour")
}

fn radius(r: f64, min: f64, what: &str) -> Result<(), String> {
    if !(r >= min && r <= MAX_COORD) {
        return Err(format!("{what} {r} must be from {min:e} to {MAX_COORD:e}"));
    }
    Ok(())
}

pub fn check_shape(s: ShapeRef<'_>) -> Result<(), String> {
    match s {
        ShapeRef::Sphere { center, radius: r } => {
            point(center, "sphere centre")?;
            radius(r, MIN_RADIUS, "sphere radius")
        }
        ShapeRef::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => {
            point(base, "cone base")?;
            point(apex, "cone apex")?;
            radius(base_radius, 0.0, "cone base radius")?;
            radius(apex_radius, 0.0, "cone apex radius")?;
            if base_radius == 0.0 && apex_radius == 0.0 {
                return Err("cone has both radii 0".into());
            }
            if base.as_vec3() == apex.as_vec3() {
                return Err("cone base and apex are the same point".into());
            }
            Ok(())
        }
        ShapeRef::Polygon(v) => {
            for p in v {
                point(*p, "polygon vertex")?;
            }
            Ok(())
        }
        ShapeRef::Patch { vertices, normals } => {
            for p in vertices {
                point(*p, "patch vertex")?;
            }
            for n in normals {
                finite(*n, "patch normal")?;
            }
            Ok(())
        }
    }
}

/// A [`Sink`] that passes on only valid records and keeps the first refusal (with the 0-based
/// index of the object it concerns, when it is an object). Sources that cannot fail per record
/// (SPD programs) stream through it; the NFF reader checks per record itself, to name the line.
pub struct Validating<'a> {
    pub inner: &'a mut dyn Sink,
    pub error: Option<String>,
    objects: u64,
}

impl<'a> Validating<'a> {
    pub fn new(inner: &'a mut dyn Sink) -> Validating<'a> {
        Validating {
            inner,
            error: None,
            objects: 0,
        }
    }

    fn keep(&mut self, r: Result<(), String>) -> bool {
        if self.error.is_some() {
            return false;
        }
        match r {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }

    /// The first refusal, if any.
    pub fn finish(self) -> Result<(), String> {
        self.error.map_or(Ok(()), Err)
    }
}

impl Sink for Validating<'_> {
    fn background(&mut self, color: DVec3) {
        if self.keep(check_background(color)) {
            self.inner.background(color);
        }
    }
    fn view(&mut self, view: &View) {
        if self.keep(check_view(view)) {
            self.inner.view(view);
        }
    }
    fn light(&mut self, light: &Light) {
        if self.keep(check_light(light)) {
            self.inner.light(light);
        }
    }
    fn material(&mut self, material: &Material) {
        if self.keep(check_material(material)) {
            self.inner.material(material);
        }
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        let n = self.objects;
        self.objects += 1;
        let r = check_shape(shape).map_err(|e| format!("object {n}: {e}"));
        if self.keep(r) {
            self.inner.shape(shape);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view() -> View {
        View {
            from: DVec3::new(0.0, 0.0, -5.0),
            ..View::default()
        }
    }

    #[test]
    fn views() {
        assert!(check_view(&view()).is_ok());
        for (up, angle) in [
            (DVec3::ZERO, 45.0),
            (DVec3::Z, 45.0),
            (DVec3::Y, 0.0),
            (DVec3::Y, 180.0),
            (DVec3::Y, 360.0),
            (DVec3::Y, -10.0),
        ] {
            let v = View {
                up,
                angle,
                ..view()
            };
            assert!(check_view(&v).is_err(), "{up} {angle}");
        }
    }

    #[test]
    fn shapes() {
        let s = |r: f64, c: f64| ShapeRef::Sphere {
            center: DVec3::splat(c),
            radius: r,
        };
        assert!(check_shape(s(1.0, 0.0)).is_ok());
        assert!(check_shape(s(0.0, 0.0)).is_err());
        assert!(check_shape(s(-1.0, 0.0)).is_err());
        assert!(check_shape(s(1.0, 1e30)).is_err());
        assert!(check_shape(s(1.0, 1e300)).is_err());
        assert!(check_shape(s(f64::NAN, 0.0)).is_err());
        let cone = |rb: f64, ra: f64, apex: DVec3| ShapeRef::Cone {
            base: DVec3::ZERO,
            base_radius: rb,
            apex,
            apex_radius: ra,
        };
        assert!(check_shape(cone(1.0, 0.0, DVec3::Y)).is_ok());
        assert!(check_shape(cone(0.0, 0.0, DVec3::Y)).is_err());
        assert!(check_shape(cone(1.0, 1.0, DVec3::ZERO)).is_err());
        assert!(check_shape(cone(-1.0, 1.0, DVec3::Y)).is_err());
    }
}
