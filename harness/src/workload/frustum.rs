//! How many objects a view sees: the view frustum of the SPD camera ([`super::camera`]) and a
//! [`Sink`] that counts the objects whose bounding box reaches into it, streamed from the
//! generator without a store. Seed 000 §4.4 (Table 4.3) traces `rings368m`, rings368 under
//! another view in which "about 1,000,000 of the 10^9 objects (0.1%)" are in view; the thesis
//! does not give that camera, so ours lives in `data/views/rings368m.json` with the counts this
//! module measured.
//!
//! "In view" is the box test: a box is out when all its corners lie outside one plane of the
//! frustum (the four sides through the image's corner rays, and the plane through the eye
//! facing forward). A box that straddles a frustum edge from outside is counted in, so the count
//! is an upper bound on the objects a ray can reach, as a uniform grid sees it.

use super::camera::Camera;
use glam::Vec3;
use rtbench_engines::geometry::{prims_of, Prim};
use rtbench_scenes::{Light, Material, ShapeRef, Sink, View};

pub struct Frustum {
    eye: Vec3,
    /// Inward normals of the five planes through the eye.
    normals: [Vec3; 5],
}

impl Frustum {
    /// The frustum of the eye rays of a `size`×`size` image (its corner rays span `size`
    /// pixel spacings, as [`Camera::corner_ray`] shoots them).
    pub fn new(view: &View, size: u32) -> Frustum {
        let cam = Camera::new(view);
        let corner = |i, j| cam.corner_ray(i, j, size).dir;
        // Top-left, top-right, bottom-right, bottom-left.
        let c = [
            corner(0, 0),
            corner(size, 0),
            corner(size, size),
            corner(0, size),
        ];
        let forward = (c[0] + c[1] + c[2] + c[3]).normalize();
        let mut normals = [forward; 5];
        for k in 0..4 {
            let n = c[k].cross(c[(k + 1) % 4]).normalize();
            normals[k] = if n.dot(forward) < 0.0 { -n } else { n };
        }
        Frustum {
            eye: cam.eye,
            normals,
        }
    }

    /// Whether the box `lo..hi` reaches into the frustum (see the module's doc).
    pub fn sees(&self, lo: Vec3, hi: Vec3) -> bool {
        self.normals.iter().all(|n| {
            // The corner farthest along n: if even it is outside, the box is.
            let p = Vec3::select(n.cmpge(Vec3::ZERO), hi, lo);
            n.dot(p - self.eye) >= 0.0
        })
    }
}

/// Counts the objects of a stream and those in view.
pub struct ViewCount {
    frustum: Frustum,
    pub objects: u64,
    pub in_view: u64,
    prims: Vec<Prim>,
    tris: Vec<[usize; 3]>,
}

impl ViewCount {
    pub fn new(view: &View, size: u32) -> ViewCount {
        ViewCount {
            frustum: Frustum::new(view, size),
            objects: 0,
            in_view: 0,
            prims: Vec::new(),
            tris: Vec::new(),
        }
    }
}

impl Sink for ViewCount {
    fn background(&mut self, _: glam::DVec3) {}
    fn view(&mut self, _: &View) {}
    fn light(&mut self, _: &Light) {}
    fn material(&mut self, _: &Material) {}
    fn shape(&mut self, shape: ShapeRef<'_>) {
        self.prims.clear();
        prims_of(shape, &mut self.prims, &mut self.tris);
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in &self.prims {
            let (a, b) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        self.objects += 1;
        if !self.prims.is_empty() && self.frustum.sees(lo, hi) {
            self.in_view += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn view(angle: f64) -> View {
        View {
            from: DVec3::ZERO,
            at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            angle,
            hither: 0.0,
            resolution: [512, 512],
        }
    }

    #[test]
    fn boxes_in_front_inside_the_angle_are_seen() {
        let f = Frustum::new(&view(90.0), 512);
        let unit = |c: Vec3| (c - Vec3::splat(0.1), c + Vec3::splat(0.1));
        let seen = |c: Vec3| {
            let (lo, hi) = unit(c);
            f.sees(lo, hi)
        };
        assert!(seen(Vec3::new(0.0, 0.0, -5.0)));
        // At 90°, the side planes are x = ±z (a hair wider: corner rays span 512/511).
        assert!(seen(Vec3::new(4.8, 0.0, -5.0)));
        assert!(!seen(Vec3::new(5.5, 0.0, -5.0)));
        assert!(!seen(Vec3::new(0.0, -5.5, -5.0)));
        assert!(!seen(Vec3::new(0.0, 0.0, 5.0)), "behind the eye");
        // A box straddling a side plane is in.
        assert!(f.sees(Vec3::new(4.0, -0.1, -5.1), Vec3::new(6.0, 0.1, -4.9)));
        // Narrower: the same box off-axis is out.
        let narrow = Frustum::new(&view(10.0), 512);
        assert!(!narrow.sees(Vec3::new(1.9, -0.1, -5.1), Vec3::new(2.1, 0.1, -4.9)));
        assert!(narrow.sees(Vec3::new(0.3, -0.1, -5.1), Vec3::new(0.4, 0.1, -4.9)));
    }
}
