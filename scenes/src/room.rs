//! `room`: a room-like scene in the spirit of seed 003's single test scene (Yamauchi 1997,
//! Table 6, Fig. 25: 18,859 patches in 32,768 subspaces; the image and its description are
//! lost). This is a documented stand-in (fidelity `substituted`), not a claim to be 003's
//! scene: only its parameters are known, so each choice below is ours, with its reason.
//!
//! | parameter | value | why |
//! |---|---|---|
//! | room | 8 m wide (x), 4 m high (y up), 8 m deep (z) | a room; with 32³ subspaces a subspace is 0.25 × 0.125 × 0.25 m |
//! | axes: y up, the eye looking along +z | 003 laid its PEs parallel to the screen (§4.2.1 on Table 6; §2.3: "so block and distributed already spread the primary rays over the PEs"). A 2D machine's torus axes are eq. (8)'s (X, Y) and eq. (10)'s (X + Z, Y): Z is the axis left out or folded, so the screen is parallel to the torus only when the eye looks along Z, and every allocation then gives the front face's subspaces (X, Y, 0) to all N_x × N_y PEs. The skew still spreads what 003 motivates it by: upright walls at a fixed X or Z. The price: the floor and ceiling (fixed Y) lie on one PE row each under 2D distributed and skewed allocation |
//! | front wall | open (z = 0), eye outside at z = −6 | as in a Cornell box: primary rays enter the subspace grid through its front face, so the FRGUs of the PEs owning that face make them (an eye inside the room would put every primary ray on one PE's FRGU) |
//! | patch size | 1/`ppm` m, `ppm` = patches per metre (default 8: 0.125 m) | at 8, walls, floor, ceiling, lights and furniture give 18,910 patches, 003's 18,859 to 0.3% (ppm 1: 427, 2: 1,325, 4: 4,888) |
//! | furniture | a table with legs, two bookcases with shelves, a sofa, two chairs, a pillar, a low cabinet: boxes meshed into patches on all visible faces | occluders and upright coherent objects, so subspaces are unevenly loaded as in a furnished room |
//! | specular quadrics | three mirror spheres and one mirror cylinder (k_s 0.9, k_d 0) | 003: specular elements (smooth quadrics) are not meshed; delta-radiosity rays reflect off them |
//! | lights | two 1 m × 1 m emitting panels just below the ceiling, meshed like the rest | 003's lights are patches that start with unshot radiosity |
//! | materials | white walls and ceiling, red left wall, green right wall, wooden floor and furniture | colour bleeding shows the radiosity in the image |
//!
//! The emitting material is [`LIGHT`] (its emission is [`LIGHT_EMISSION`]); [`emission`] gives
//! each material's emission from a scene's materials. Polygons are emitted counter-clockwise seen
//! from their lit side, so a polygon's normal (first edge × second edge) points into the room.
//! `ppm` = 0 is refused: a room of 0 patches.

use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use glam::DVec3;

/// The default resolution: patches per metre.
pub const DEFAULT_PPM: u32 = 8;
/// Room extent in the frame it is modelled in (width, depth, height: the floor spans the first
/// two); [`turn`] gives the scene's frame, y up and the eye looking along +z.
pub const SIZE: DVec3 = DVec3::new(8.0, 8.0, 4.0);

/// The modelling frame (floor x-y, z up, front at y = 0) to the scene's (y up, front at z = 0):
/// a proper rotation (determinant +1), so polygons keep their winding and facing, and a shift
/// keeping x in [0, 8]. Why the scene's frame is y up: see the module doc (003's PEs parallel to
/// the screen).
pub fn turn(p: DVec3) -> DVec3 {
    DVec3::new(SIZE.x - p.x, p.z, p.y)
}

/// [`turn`] for directions.
fn turn_dir(v: DVec3) -> DVec3 {
    DVec3::new(-v.x, v.z, v.y)
}
/// Emission of the light panels' material (radiosity units; RGB).
pub const LIGHT_EMISSION: DVec3 = DVec3::new(12.0, 12.0, 10.0);

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum RoomError {
    #[error("room: patches per metre must be at least 1 (0 gives a room of 0 patches)")]
    NoPatches,
    #[error("room: patches per metre must be at most 64, got {0}")]
    TooMany(u32),
}

/// The light panels' material: the one emitting material.
pub const LIGHT: Material = Material {
    color: DVec3::new(0.8, 0.8, 0.8),
    kd: 1.0,
    ks: 0.0,
    shine: 1.0,
    t: 0.0,
    ior: 1.0,
};

const fn diffuse(r: f64, g: f64, b: f64) -> Material {
    Material {
        color: DVec3::new(r, g, b),
        kd: 1.0,
        ks: 0.0,
        shine: 1.0,
        t: 0.0,
        ior: 1.0,
    }
}

const WHITE: Material = diffuse(0.75, 0.75, 0.75);
const RED: Material = diffuse(0.75, 0.2, 0.2);
const GREEN: Material = diffuse(0.2, 0.65, 0.25);
const FLOOR: Material = diffuse(0.55, 0.42, 0.3);
const WOOD: Material = diffuse(0.5, 0.33, 0.18);
const FABRIC: Material = diffuse(0.25, 0.3, 0.55);
const MIRROR: Material = Material {
    color: DVec3::new(0.9, 0.9, 0.9),
    kd: 0.0,
    ks: 0.9,
    shine: 200.0,
    t: 0.0,
    ior: 1.0,
};

/// Emission of every material of a scene: [`LIGHT_EMISSION`] for [`LIGHT`], zero otherwise.
pub fn emission(materials: &[Material]) -> Vec<DVec3> {
    materials
        .iter()
        .map(|m| {
            if *m == LIGHT {
                LIGHT_EMISSION
            } else {
                DVec3::ZERO
            }
        })
        .collect()
}

/// Patches the room has at `ppm` patches per metre (what [`generate`] emits as polygons).
pub fn patch_count(ppm: u32) -> Result<u64, RoomError> {
    let mut c = crate::sink::CountingSink::default();
    generate(ppm, &mut c)?;
    Ok(c.counts.polygon)
}

struct Mesher<'a> {
    sink: &'a mut dyn Sink,
    ppm: f64,
    current: Option<Material>,
}

impl Mesher<'_> {
    fn material(&mut self, m: Material) {
        if self.current.as_ref() != Some(&m) {
            self.sink.material(&m);
            self.current = Some(m);
        }
    }

    /// The rectangle `o`, `o + u`, `o + u + v`, `o + v` cut into patches of at most 1/ppm a side;
    /// its normal is u × v.
    fn rect(&mut self, o: DVec3, u: DVec3, v: DVec3) {
        let (o, u, v) = (turn(o), turn_dir(u), turn_dir(v));
        let nu = ((u.length() * self.ppm).ceil() as u32).max(1);
        let nv = ((v.length() * self.ppm).ceil() as u32).max(1);
        let (du, dv) = (u / nu as f64, v / nv as f64);
        for j in 0..nv {
            for i in 0..nu {
                let p = o + du * i as f64 + dv * j as f64;
                let quad = [p, p + du, p + du + dv, p + dv];
                self.sink.shape(ShapeRef::Polygon(&quad));
            }
        }
    }

    /// A box's faces, outward; `bottom`: also the face at `a.z`.
    fn cuboid(&mut self, a: DVec3, b: DVec3, bottom: bool) {
        let d = b - a;
        let (x, y, z) = (
            DVec3::new(d.x, 0.0, 0.0),
            DVec3::new(0.0, d.y, 0.0),
            DVec3::new(0.0, 0.0, d.z),
        );
        self.rect(DVec3::new(b.x, a.y, a.z), y, z);
        self.rect(a, z, y);
        self.rect(DVec3::new(a.x, b.y, a.z), z, x);
        self.rect(a, x, z);
        self.rect(DVec3::new(a.x, a.y, b.z), x, y);
        if bottom {
            self.rect(a, y, x);
        }
    }
}

/// Streams the room at `ppm` patches per metre into `sink`.
pub fn generate(ppm: u32, sink: &mut dyn Sink) -> Result<(), RoomError> {
    if ppm == 0 {
        return Err(RoomError::NoPatches);
    }
    if ppm > 64 {
        return Err(RoomError::TooMany(ppm));
    }
    sink.background(DVec3::ZERO);
    sink.view(&View {
        from: turn(DVec3::new(4.0, -6.0, 2.2)),
        at: turn(DVec3::new(4.0, 4.0, 1.6)),
        up: turn_dir(DVec3::Z),
        angle: 50.0,
        hither: 1e-3,
        resolution: [512, 512],
    });
    // For renderers that light locally (the NFF view of the scene): the panels' centres.
    for c in [DVec3::new(2.5, 4.5, 3.9), DVec3::new(5.5, 4.5, 3.9)] {
        sink.light(&Light {
            position: turn(c),
            color: None,
        });
    }
    let s = SIZE;
    let (x, y, z) = (
        DVec3::new(s.x, 0.0, 0.0),
        DVec3::new(0.0, s.y, 0.0),
        DVec3::new(0.0, 0.0, s.z),
    );
    let mut m = Mesher {
        sink,
        ppm: ppm as f64,
        current: None,
    };
    // The shell, facing in: floor, ceiling, back wall, left (red), right (green).
    m.material(FLOOR);
    m.rect(DVec3::ZERO, x, y);
    m.material(WHITE);
    m.rect(z, y, x);
    m.rect(y, x, z);
    m.material(RED);
    m.rect(DVec3::ZERO, y, z);
    m.material(GREEN);
    m.rect(x, z, y);
    // Lights: two panels facing down, 2 cm below the ceiling.
    m.material(LIGHT);
    for (cx, cy) in [(2.5, 4.5), (5.5, 4.5)] {
        let o = DVec3::new(cx - 0.5, cy - 0.5, s.z - 0.02);
        m.rect(o, DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
    }
    // Furniture.
    let v = DVec3::new;
    m.material(WOOD);
    // Table: a top with its underside, four legs.
    m.cuboid(v(3.0, 3.5, 0.7), v(5.0, 4.5, 0.76), true);
    for (lx, ly) in [(3.05, 3.55), (4.85, 3.55), (3.05, 4.35), (4.85, 4.35)] {
        m.cuboid(v(lx, ly, 0.0), v(lx + 0.1, ly + 0.1, 0.7), false);
    }
    // Two bookcases against the back wall, each with four shelves.
    for bx in [0.5, 5.3] {
        m.cuboid(v(bx, 7.5, 0.0), v(bx + 2.0, 8.0, 2.0), false);
        for k in 1..=3 {
            let h = 0.5 * k as f64;
            m.cuboid(v(bx - 0.02, 7.2, h), v(bx + 2.02, 7.5, h + 0.04), false);
        }
    }
    // A low cabinet against the left wall.
    m.cuboid(v(0.0, 2.2, 0.0), v(0.5, 3.8, 0.9), false);
    // Chairs: seat and back.
    for cx in [3.4, 4.2] {
        m.cuboid(v(cx, 2.7, 0.0), v(cx + 0.45, 3.15, 0.45), false);
        m.cuboid(v(cx, 2.62, 0.45), v(cx + 0.45, 2.7, 1.0), false);
    }
    // A pillar from floor to ceiling.
    m.cuboid(v(6.6, 6.0, 0.0), v(7.0, 6.4, s.z), false);
    m.material(FABRIC);
    // A sofa: seat, back and arms.
    m.cuboid(v(5.6, 1.6, 0.0), v(7.6, 2.5, 0.45), false);
    m.cuboid(v(5.6, 2.5, 0.0), v(7.6, 2.75, 0.95), false);
    for ax in [5.4, 7.6] {
        m.cuboid(v(ax, 1.6, 0.0), v(ax + 0.2, 2.75, 0.65), false);
    }
    // Specular quadrics: three mirror spheres, one mirror column.
    m.material(MIRROR);
    for (c, r) in [
        (v(4.0, 4.0, 0.96), 0.2),
        (v(1.6, 2.2, 0.5), 0.5),
        (v(2.0, 5.8, 0.35), 0.35),
    ] {
        m.sink.shape(ShapeRef::Sphere {
            center: turn(c),
            radius: r,
        });
    }
    m.sink.shape(ShapeRef::Cone {
        base: turn(v(1.2, 6.2, 0.0)),
        base_radius: 0.15,
        apex: turn(v(1.2, 6.2, s.z)),
        apex_radius: 0.15,
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::{CountingSink, SceneCollector};

    #[test]
    fn the_default_room_has_about_003s_patch_count() {
        let n = patch_count(DEFAULT_PPM).unwrap();
        // 003, Table 6: 18,859 patches.
        assert!((n as f64 / 18859.0 - 1.0).abs() < 0.005, "{n} patches");
        let mut c = CountingSink::default();
        generate(DEFAULT_PPM, &mut c).unwrap();
        assert_eq!((c.counts.sphere, c.counts.cone), (3, 1));
    }

    #[test]
    fn zero_patches_is_refused_and_sizes_grow_with_ppm() {
        assert_eq!(patch_count(0), Err(RoomError::NoPatches));
        assert!(patch_count(65).is_err());
        assert!(patch_count(1).unwrap() < patch_count(2).unwrap());
    }

    #[test]
    fn polygons_face_into_the_room_and_lights_emit() {
        let mut c = SceneCollector::default();
        generate(2, &mut c).unwrap();
        let s = c.scene;
        let em = emission(&s.materials);
        // The eye looks along +z, y up, into the open front at z = 0 (003: PEs parallel to the
        // screen; see the module doc).
        let dir = (s.view.at - s.view.from).normalize();
        assert!(dir.z > 0.99 && s.view.from.z < 0.0 && s.view.up == DVec3::Y);
        let mut lights = 0;
        for o in &s.objects {
            if let crate::model::Shape::Polygon(v) = &o.shape {
                assert!(v.iter().all(|p| p.z >= 0.0 && p.y >= 0.0 && p.x >= 0.0));
                let n = (v[1] - v[0]).cross(v[3] - v[0]).normalize();
                let centre = (v[0] + v[2]) / 2.0;
                // Shell patches face the room's centre (y up, the red wall at x = 8).
                if centre.y == 0.0 {
                    assert!(n.y > 0.99, "the floor faces up");
                }
                if centre.x == SIZE.x && s.materials[o.material as usize] == RED {
                    assert!(n.x < -0.99);
                }
                if em[o.material as usize] != DVec3::ZERO {
                    assert!(n.y < -0.99, "lights face down");
                    lights += 1;
                }
            }
        }
        assert_eq!(lights, 2 * 2 * 2);
    }
}
