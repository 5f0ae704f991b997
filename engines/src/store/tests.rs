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
    // The table holds each distinct material once; every object's entry equals its own.
    assert!(h.materials.len() <= scene.materials.len());
    assert_eq!(h.background, scene.background);
    assert_eq!(h.bounds, [geometry.bounds_min, geometry.bounds_max]);

    let mut bb = BboxReader::open(&dir.0, h.objects, 4096).unwrap();
    let mut geo = GeometryReader::open(&dir.0, 4096).unwrap();
    let mut rec = ObjectRecord::default();
    let mut next_prim = 0;
    while let Some((id, b)) = bb.next_record().unwrap() {
        geo.read_at(b.offset, &mut rec).unwrap();
        let o = &scene.objects[id as usize];
        assert_eq!(
            h.materials[rec.material as usize],
            scene.materials[o.material as usize]
        );
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

/// A small store of `program` at `sf`, written into `dir`.
fn write_store(dir: &TempDir, program: Program, sf: u32) {
    let opts = Options {
        size_factor: sf,
        ..Options::standard(program)
    };
    let mut w = StoreWriter::create(&dir.0, "x").unwrap();
    spd::generate(program, &opts, &mut w).unwrap();
    w.finish().unwrap();
}

/// Opening and verifying, as the breadth-first engine does with `verify=full`.
fn open_and_verify(dir: &std::path::Path) -> std::io::Result<u64> {
    StoreHeader::read(dir)?.verify()
}

#[test]
fn every_bit_flip_is_refused() {
    let dir = TempDir::new("flips");
    write_store(&dir, Program::Tree, 2);
    assert!(open_and_verify(&dir.0).is_ok());
    // A seeded pseudo-random sequence, so that a failure reproduces.
    let mut rng = fastrand::Rng::with_seed(0x9e37_79b9_7f4a_7c15);
    let mut next = || rng.u64(..);
    for k in 0..300 {
        let name = [HEADER_FILE, BBOX_FILE, GEOMETRY_FILE, MATERIALS_FILE][k % 4];
        let path = dir.0.join(name);
        let orig = std::fs::read(&path).unwrap();
        let mut bytes = orig.clone();
        let bit = (next() % (bytes.len() as u64 * 8)) as usize;
        bytes[bit / 8] ^= 1 << (bit % 8);
        std::fs::write(&path, &bytes).unwrap();
        assert!(
            open_and_verify(&dir.0).is_err(),
            "flip of bit {bit} of {name} accepted"
        );
        std::fs::write(&path, &orig).unwrap();
    }
}

#[test]
fn record_lengths_are_checked_before_allocating() {
    let dir = TempDir::new("len");
    write_store(&dir, Program::Tetra, 1);
    let path = dir.0.join(GEOMETRY_FILE);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[16..20].copy_from_slice(&[0xf0, 0xff, 0xff, 0xff]);
    std::fs::write(&path, &bytes).unwrap();
    let mut geo = GeometryReader::open(&dir.0, 4096).unwrap();
    let e = geo
        .read_at(FILE_HEADER, &mut ObjectRecord::default())
        .unwrap_err();
    assert!(e.to_string().contains("does not fit the file"), "{e}");
}

#[test]
fn a_header_that_disagrees_with_the_files_is_refused() {
    let dir = TempDir::new("objects");
    write_store(&dir, Program::Tetra, 1);
    let path = dir.0.join(HEADER_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    // The reported case: "objects": 1, even with the checksum put right.
    let edited = text.replace("\"objects\": 4", "\"objects\": 1");
    assert_ne!(edited, text);
    std::fs::write(&path, &edited).unwrap();
    let crc = crc32fast::hash(edited.as_bytes()).to_le_bytes();
    for name in [BBOX_FILE, GEOMETRY_FILE] {
        let p = dir.0.join(name);
        let mut b = std::fs::read(&p).unwrap();
        b[12..16].copy_from_slice(&crc);
        std::fs::write(&p, &b).unwrap();
    }
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    assert!(e.contains("bbox_bytes"), "{e}");
}

/// A gzip or zstd file reads back what was written, through forward seeks (decompress and
/// discard) and rewinds (the stream again), counting compressed bytes on disk and uncompressed
/// ones through the codec.
#[test]
fn gzip_files_seek_forward_and_rewind() {
    compressed_files_seek_forward_and_rewind(Codec::Gzip(6));
}

#[test]
fn zstd_files_seek_forward_and_rewind() {
    compressed_files_seek_forward_and_rewind(Codec::Zstd(3));
}

fn compressed_files_seek_forward_and_rewind(codec: Codec) {
    let dir = TempDir::new(&format!("{}-io", codec.name()));
    std::fs::create_dir_all(&dir.0).unwrap();
    let path = dir.0.join("x.z");
    let data: Vec<u8> = (0..200_000u32)
        .flat_map(|i| (i % 251).to_le_bytes())
        .collect();
    let mut w = IoFile::create_codec(&path, 4096, codec).unwrap();
    w.write_all(&data).unwrap();
    let wio = w.finish().unwrap();
    assert_eq!(wio.codec_bytes, data.len() as u64);
    assert_eq!(wio.bytes_written, std::fs::metadata(&path).unwrap().len());
    assert!(wio.bytes_written * 4 < data.len() as u64);
    let mut r = IoFile::open_codec(&path, 4096, codec).unwrap();
    let mut b = [0u8; 8];
    for at in [0u64, 100, 50_000, 700_000, 12, 799_992] {
        r.seek_to(at).unwrap();
        r.read_exact(&mut b).unwrap();
        assert_eq!(&b[..], &data[at as usize..at as usize + 8], "{at}");
    }
    r.seek_to(data.len() as u64).unwrap();
    assert!(r.read_exact(&mut b).is_err());
    // One rewind: 12 after 700_000.
    assert_eq!(r.io.seeks, 1);
    assert!(r.io.codec_bytes >= data.len() as u64);
    assert!(r.io.bytes_read < r.io.codec_bytes);
}

/// A compressed basic store reads back object by object as the plain one does; a truncated or
/// corrupted one fails with an error (never a panic).
#[test]
fn compressed_basic_store_round_trips_and_refuses_damage() {
    compressed_store_round_trips_and_refuses_damage(Codec::Gzip(6));
}

#[test]
fn zstd_basic_store_round_trips_and_refuses_damage() {
    compressed_store_round_trips_and_refuses_damage(Codec::Zstd(3));
}

fn compressed_store_round_trips_and_refuses_damage(codec: Codec) {
    let program = Program::Mount;
    let opts = Options {
        size_factor: 3,
        ..Options::standard(program)
    };
    let scene = generate_scene(program, &opts).unwrap();
    let plain = TempDir::new("basic-plain");
    let gz = TempDir::new(&format!("basic-{}", codec.name()));
    StoreWriter::create_layout(&plain.0, "x", Layout::Basic)
        .unwrap()
        .write_scene(&scene)
        .unwrap();
    StoreWriter::create_with(&gz.0, "x", Layout::Basic, codec)
        .unwrap()
        .write_scene(&scene)
        .unwrap();
    let (hp, hg) = (
        StoreHeader::read(&plain.0).unwrap(),
        StoreHeader::read(&gz.0).unwrap(),
    );
    assert_eq!(hg.codec.name(), codec.name());
    assert_eq!(hp.geometry_bytes, hg.geometry_bytes);
    assert!(hg.stored_bytes < hp.stored_bytes);
    assert!(hg.verify().unwrap() < hp.verify().unwrap());
    let read_all = |h: &StoreHeader| {
        let mut r = SceneReader::open(h, 4096, false).unwrap();
        let mut rec = ObjectRecord::default();
        let mut out = Vec::new();
        while let Some((id, b, _)) = r.next(&mut rec).unwrap() {
            out.push((id, b.lo, b.hi, rec.clone()));
        }
        out
    };
    assert_eq!(read_all(&hp), read_all(&hg));
    // A split store is compressed as zstd blocks (store::blocks), never as one gzip stream.
    assert_eq!(
        StoreWriter::create_with(&gz.0.join("s"), "x", Layout::Split, codec).is_err(),
        matches!(codec, Codec::Gzip(_))
    );
    // header.json edited (a light moved): header.crc no longer vouches for it; without
    // header.crc the store is refused too.
    let hj = gz.0.join(HEADER_FILE);
    let text = std::fs::read_to_string(&hj).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let x = v["lights"][0]["position"][0].as_f64().unwrap();
    v["lights"][0]["position"][0] = serde_json::json!(x + 1.0);
    let moved = serde_json::to_string_pretty(&v).unwrap();
    std::fs::write(&hj, &moved).unwrap();
    let e = StoreHeader::read(&gz.0).unwrap_err().to_string();
    assert!(e.contains("header.crc"), "{e}");
    std::fs::write(&hj, &text).unwrap();
    StoreHeader::read(&gz.0).unwrap();
    let crc = std::fs::read(gz.0.join(HEADER_CRC_FILE)).unwrap();
    std::fs::remove_file(gz.0.join(HEADER_CRC_FILE)).unwrap();
    assert!(StoreHeader::read(&gz.0).is_err());
    std::fs::write(gz.0.join(HEADER_CRC_FILE), crc).unwrap();
    // Truncated: the size no longer matches the header.
    let f = gz.0.join(codec.objects_file());
    let bytes = std::fs::read(&f).unwrap();
    std::fs::write(&f, &bytes[..bytes.len() / 2]).unwrap();
    assert!(StoreHeader::read(&gz.0).is_err());
    // Corrupted in the middle, size kept: the codec or a record checksum refuses it.
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0xff;
    std::fs::write(&f, &bad).unwrap();
    let h = StoreHeader::read(&gz.0).unwrap();
    assert!(h.verify().is_err());
    // Damaged in the codec's own trailer (gzip's CRC-32 and length; zstd's frame checksum):
    // the records all read, and the codec still refuses the stream.
    let mut bad = bytes.clone();
    let end = bad.len() - 2;
    bad[end] ^= 0xff;
    std::fs::write(&f, &bad).unwrap();
    let h = StoreHeader::read(&gz.0).unwrap();
    assert!(h.verify().is_err());
}

/// A stream of `n` objects, each after its own material emission (cycling through `colors`
/// distinct colours, as SPD's rings emits one per ring): what made format 2's header.json grow
/// with the object count.
fn write_many(dir: &TempDir, n: u32, colors: u32) {
    use rtbench_scenes::{Material, Sink};
    let mut w = StoreWriter::create_layout(&dir.0, "many", Layout::Basic).unwrap();
    Sink::light(
        &mut w,
        &rtbench_scenes::Light {
            position: glam::DVec3::new(0.0, 0.0, 10.0),
            color: None,
        },
    );
    for i in 0..n {
        let c = (i % colors) as f64 / colors as f64;
        Sink::material(
            &mut w,
            &Material {
                color: glam::DVec3::new(c, 0.5, 1.0 - c),
                kd: 0.5,
                ks: 0.2,
                shine: 8.0,
                t: 0.0,
                ior: 1.0,
            },
        );
        let x = i as f64;
        Sink::shape(
            &mut w,
            rtbench_scenes::ShapeRef::Sphere {
                center: glam::DVec3::new(x, 0.0, 0.0),
                radius: 0.4,
            },
        );
    }
    w.finish().unwrap();
}

/// header.json stays small and bounded however many objects (and material emissions) the scene
/// has: 200,000 objects give a header within a few bytes (digits) of 10 objects', and the
/// material table holds the distinct materials only.
#[test]
fn header_size_does_not_grow_with_the_object_count() {
    let (small, large) = (TempDir::new("few"), TempDir::new("many"));
    write_many(&small, 10, 6);
    write_many(&large, 200_000, 6);
    let size = |d: &TempDir| std::fs::metadata(d.0.join(HEADER_FILE)).unwrap().len();
    let (a, b) = (size(&small), size(&large));
    assert!(b < 4096, "header.json of 200,000 objects: {b} bytes");
    assert!(
        b <= a + 64,
        "header.json: {a} bytes for 10 objects, {b} for 200,000"
    );
    let h = StoreHeader::read(&large.0).unwrap();
    assert_eq!(h.objects, 200_000);
    assert_eq!(h.materials.len(), 6);
    assert_eq!(
        std::fs::metadata(large.0.join(MATERIALS_FILE))
            .unwrap()
            .len(),
        FILE_HEADER + 6 * MATERIAL_RECORD as u64
    );
    h.verify().unwrap();
    // Distinct materials per object (gears: one per gear) go to materials.bin, not the header.
    let distinct = TempDir::new("distinct");
    write_many(&distinct, 50_000, 50_000);
    assert!(size(&distinct) <= a + 64);
    assert_eq!(
        StoreHeader::read(&distinct.0).unwrap().materials.len(),
        50_000
    );
}

/// A store of format 2 (materials in header.json) is refused with one line naming both formats
/// and the way out, whether its header is small enough to parse or too large to read.
#[test]
fn an_old_format_store_is_refused_with_the_way_out() {
    let dir = TempDir::new("old");
    write_store(&dir, Program::Tetra, 1);
    let path = dir.0.join(HEADER_FILE);
    let text = std::fs::read_to_string(&path).unwrap();
    let old = text.replace(&format!("\"version\": {VERSION}"), "\"version\": 2");
    assert_ne!(old, text);
    std::fs::write(&path, &old).unwrap();
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    let want =
        format!("store format 2, this rtbench reads {VERSION}: rebuild with `rtbench scene store`");
    assert!(e.ends_with(&want), "{e}");
    assert_eq!(e.lines().count(), 1);
    // Too large to read (format 2's rings80: 187 MB): the version comes from bbox.bin.
    let mut big = old.into_bytes();
    big.resize(5 << 20, b' ');
    std::fs::write(&path, &big).unwrap();
    for name in [BBOX_FILE, GEOMETRY_FILE] {
        let p = dir.0.join(name);
        let mut b = std::fs::read(&p).unwrap();
        b[8..12].copy_from_slice(&2u32.to_le_bytes());
        std::fs::write(&p, &b).unwrap();
    }
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    assert!(e.ends_with(&want), "{e}");
    // Too large and of this format: the size is what is wrong.
    for name in [BBOX_FILE, GEOMETRY_FILE] {
        let p = dir.0.join(name);
        let mut b = std::fs::read(&p).unwrap();
        b[8..12].copy_from_slice(&VERSION.to_le_bytes());
        std::fs::write(&p, &b).unwrap();
    }
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    assert!(e.contains("at most"), "{e}");
}

/// materials.bin is vouched for by header.json: a changed byte or a shortened file is refused.
#[test]
fn a_damaged_material_table_is_refused() {
    let dir = TempDir::new("mats");
    write_store(&dir, Program::Gears, 1);
    let path = dir.0.join(MATERIALS_FILE);
    let orig = std::fs::read(&path).unwrap();
    let mut b = orig.clone();
    let last = b.len() - 3;
    b[last] ^= 1;
    std::fs::write(&path, &b).unwrap();
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    std::fs::write(&path, &orig[..orig.len() - 64]).unwrap();
    let e = StoreHeader::read(&dir.0).unwrap_err().to_string();
    assert!(e.contains("materials.bin has"), "{e}");
    std::fs::write(&path, &orig).unwrap();
    StoreHeader::read(&dir.0).unwrap().verify().unwrap();
}

/// Every object of a store as read back: (id, box, record).
fn read_all(dir: &std::path::Path) -> Vec<(u32, glam::Vec3, glam::Vec3, ObjectRecord)> {
    let h = StoreHeader::read(dir).unwrap();
    let mut r = SceneReader::open(&h, 4096, false).unwrap();
    let mut rec = ObjectRecord::default();
    let mut out = Vec::new();
    while let Some((id, b, _)) = r.next(&mut rec).unwrap() {
        out.push((id, b.lo, b.hi, rec.clone()));
    }
    out
}

#[test]
fn a_store_written_in_segments_across_stops_equals_one_written_at_once() {
    use std::time::Duration;
    let program = Program::Rings;
    let opts = Options {
        size_factor: 2,
        ..Options::standard(program)
    };
    for (layout, codec) in [
        (Layout::Split, Codec::None),
        (Layout::Basic, Codec::None),
        (Layout::Basic, Codec::Gzip(1)),
        (Layout::Split, Codec::Zstd(3)),
    ] {
        let tag = format!("seg-{}-{}", layout.name(), codec.name());
        let once = TempDir::new(&format!("{tag}-once"));
        let mut w = StoreWriter::create_with(&once.0, "rings2", layout, codec).unwrap();
        spd::generate(program, &opts, &mut w).unwrap();
        w.finish().unwrap();
        let objects = StoreHeader::read(&once.0).unwrap().objects;

        let seg = TempDir::new(&tag);
        let mut w = SegmentedWriter::start(&seg.0, "rings2", layout, codec, 37)
            .unwrap()
            .with_budget(Duration::ZERO);
        spd::generate(program, &opts, &mut w).unwrap();
        assert!(matches!(w.finish().unwrap(), Outcome::Stopped));
        assert!(
            StoreHeader::read(&seg.0).is_err(),
            "no header while being written"
        );
        let mut runs = 1;
        loop {
            // A process that died mid-segment leaves bytes after the checkpoint: cut off.
            let log = SegmentLog::read(&seg.0).unwrap().unwrap();
            assert_eq!(log.state.objects, 37 * log.done.len() as u64, "{tag}");
            let files: &[&str] = match (layout, codec) {
                // A block and part of its index entry written after the checkpoint.
                (Layout::Split, Codec::Zstd(_)) => {
                    &["geometry.bin.zst", GEOMETRY_INDEX, BBOX_INDEX]
                }
                (Layout::Split, _) => &[GEOMETRY_FILE],
                (_, Codec::None) => &[OBJECTS_FILE],
                _ => &[OBJECTS_FILE_GZ],
            };
            for file in files {
                let mut f = std::fs::OpenOptions::new()
                    .append(true)
                    .open(seg.0.join(file))
                    .unwrap();
                std::io::Write::write_all(&mut f, b"half a segment").unwrap();
            }
            assert!(
                SegmentedWriter::resume(&seg.0, "rings3").is_err(),
                "another scene"
            );
            let mut w = SegmentedWriter::resume(&seg.0, "rings2")
                .unwrap()
                .with_budget(Duration::ZERO);
            spd::generate(program, &opts, &mut w).unwrap();
            runs += 1;
            match w.finish().unwrap() {
                Outcome::Stopped => continue,
                Outcome::Finished(_) => break,
            }
        }
        // 301 objects in segments of 37: 8 full segments (a stop after each), the 9th short.
        assert_eq!(objects, 301);
        assert_eq!(runs, 9, "{tag}");
        assert!(!seg.0.join(SEGMENTS_FILE).exists());
        assert_eq!(read_all(&seg.0), read_all(&once.0), "{tag}");
        let (a, b) = (
            StoreHeader::read(&seg.0).unwrap(),
            StoreHeader::read(&once.0).unwrap(),
        );
        assert_eq!(
            (
                a.objects,
                a.primitives,
                a.bounds,
                a.view.clone(),
                a.materials.clone()
            ),
            (
                b.objects,
                b.primitives,
                b.bounds,
                b.view.clone(),
                b.materials.clone()
            )
        );
        // Bytes read by a full check: equal uncompressed; compressed, one member per segment.
        let (va, vb) = (a.verify().unwrap(), b.verify().unwrap());
        if codec == Codec::None {
            assert_eq!(va, vb, "{tag}");
            for f in std::fs::read_dir(&once.0).unwrap() {
                let name = f.unwrap().file_name();
                assert_eq!(
                    std::fs::read(seg.0.join(&name)).unwrap(),
                    std::fs::read(once.0.join(&name)).unwrap(),
                    "{tag}: {name:?}"
                );
            }
        } else {
            // One gzip member per segment (and the file header's): larger than one member.
            assert!(a.stored_bytes > b.stored_bytes);
            assert!(va > vb, "{tag}: {va} {vb}");
        }
    }
}
