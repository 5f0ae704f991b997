//! The store round-trips: what streams in comes back, object by object, equal to the in-memory
//! scene's prepared geometry, surfaces, materials, camera and lights.

use super::*;
use crate::geometry::Geometry;
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{self, Options, Program};
use std::path::PathBuf;

/// A fresh directory under the system's temp dir, removed on drop.
pub(crate) struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let d = std::env::temp_dir().join(format!(
            "rtbench-store-test-{tag}-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        TempDir(d)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn round_trip(program: Program, sf: u32) {
    let opts = Options {
        size_factor: sf,
        ..Options::standard(program)
    };
    let scene = generate_scene(program, &opts).unwrap();
    let geometry = Geometry::from_scene(&scene);
    let dir = TempDir::new(program.name());
    let mut w = StoreWriter::create(&dir.0, "x").unwrap();
    spd::generate(program, &opts, &mut w).unwrap();
    let io = w.finish().unwrap();
    assert!(io.bytes_written > 0);

    let h = StoreHeader::read(&dir.0).unwrap();
    assert_eq!(h.objects as usize, scene.objects.len());
    assert_eq!(h.primitives as usize, geometry.prims.len());
    assert_eq!(h.view, scene.view);
    assert_eq!(h.lights, scene.lights);
    assert_eq!(h.materials, scene.materials);
    assert_eq!(h.background, scene.background);
    assert_eq!(h.bounds, [geometry.bounds_min, geometry.bounds_max]);

    let mut bb = BboxReader::open(&dir.0, h.objects, 4096).unwrap();
    let mut geo = GeometryReader::open(&dir.0, 4096).unwrap();
    let mut rec = ObjectRecord::default();
    let mut next_prim = 0;
    while let Some((id, b)) = bb.next_record().unwrap() {
        geo.read_at(b.offset, &mut rec).unwrap();
        let o = &scene.objects[id as usize];
        assert_eq!(rec.material, o.material);
        assert_eq!(rec.surface, Some(Surface::of(o.shape.as_ref())));
        let n = rec.prims.len();
        assert_eq!(&rec.prims[..], &geometry.prims[next_prim..next_prim + n]);
        assert!(geometry.prim_object[next_prim..next_prim + n]
            .iter()
            .all(|&p| p == id));
        let (mut lo, mut hi) = (glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY);
        for p in &rec.prims {
            let (a, c) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(c);
        }
        assert_eq!((b.lo, b.hi), (lo, hi));
        next_prim += n;
    }
    assert_eq!(next_prim, geometry.prims.len());
    // A second sweep after rewinding reads the same first record; a backward read is refused.
    bb.rewind().unwrap();
    let first = bb.next_record().unwrap().unwrap();
    assert_eq!(first.0, 0);
    assert!(geo.read_at(first.1.offset, &mut rec).is_err());
    geo.rewind().unwrap();
    geo.read_at(first.1.offset, &mut rec).unwrap();
}

#[test]
fn round_trips_every_primitive_kind() {
    round_trip(Program::Gears, 1); // concave polygons
    round_trip(Program::Tree, 2); // cones and spheres
    round_trip(Program::Teapot, 2); // patches with normals
}

#[test]
fn refuses_what_is_not_a_store() {
    let dir = TempDir::new("bad");
    std::fs::create_dir_all(&dir.0).unwrap();
    assert!(StoreHeader::read(&dir.0).is_err());
    std::fs::write(dir.0.join(BBOX_FILE), b"RTGEOM\0\0\x01\0\0\0\0\0\0\0").unwrap();
    assert!(BboxReader::open(&dir.0, 0, 64).is_err());
}
