//! The compressed split layout ([`super::blocks`]) answers byte for byte as the plain one:
//! records, forward seeks of bbox records and geometry records, the hierarchy's subtree skips
//! and the engine's answers and counters; damage is refused in one line.

use super::tests::TempDir;
use super::*;
use crate::breadth_first::config::BreadthFirstConfig;
use crate::breadth_first::BreadthFirst;
use crate::test_support::{answers, kv, rays_around, spd};
use crate::{Counters, Settings};
use rtbench_scenes::spd::Program;

/// A plain and a zstd-compressed split store of the same scene.
fn pair(program: Program, sf: u32, tag: &str) -> (crate::BuildInput, TempDir, TempDir) {
    let input = spd(program, sf);
    let plain = TempDir::new(&format!("blk-{tag}-plain"));
    let zst = TempDir::new(&format!("blk-{tag}-zst"));
    StoreWriter::create(&plain.0, "x")
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    StoreWriter::create_with(&zst.0, "x", Layout::Split, Codec::Zstd(3))
        .unwrap()
        .write_scene(&input.scene)
        .unwrap();
    (input, plain, zst)
}

#[test]
fn a_compressed_split_store_reads_and_seeks_as_the_plain_one() {
    let (_, plain, zst) = pair(Program::Mount, 6, "seek");
    let (hp, hz) = (
        StoreHeader::read(&plain.0).unwrap(),
        StoreHeader::read(&zst.0).unwrap(),
    );
    assert_eq!(hz.codec, Codec::Zstd(3));
    assert!(!zst.0.join(BBOX_FILE).exists() && zst.0.join("bbox.bin.zst").exists());
    assert_eq!(
        (hp.objects, hp.bbox_bytes, hp.geometry_bytes),
        (hz.objects, hz.bbox_bytes, hz.geometry_bytes)
    );
    // More than one block in each file, and smaller on disk.
    assert!(hz.geometry_bytes > 2 * blocks::BLOCK_BYTES as u64);
    assert!(
        hz.disk_bytes() < hp.disk_bytes(),
        "{} {}",
        hz.disk_bytes(),
        hp.disk_bytes()
    );
    assert_eq!(hp.verify().unwrap() > 0, hz.verify().unwrap() > 0);
    // Forward seeks with strides from one record to past a block, then a rewind, twice.
    let mut bp = BboxReader::open(&plain.0, hp.objects, 4096).unwrap();
    let mut bz = BboxReader::open(&zst.0, hz.objects, 4096).unwrap();
    let mut gp = GeometryReader::open(&plain.0, 4096).unwrap();
    let mut gz = GeometryReader::open(&zst.0, 4096).unwrap();
    let (mut rp, mut rz) = (ObjectRecord::default(), ObjectRecord::default());
    for sweep in 0..2 {
        let mut id = 0u64;
        let mut stride = 1u64;
        while id < hp.objects {
            bp.seek_record(id).unwrap();
            bz.seek_record(id).unwrap();
            let (a, b) = (bp.next_record().unwrap(), bz.next_record().unwrap());
            assert_eq!(a, b, "sweep {sweep} record {id}");
            let (_, rec) = a.unwrap();
            gp.read_at(rec.offset, &mut rp).unwrap();
            gz.read_at(rec.offset, &mut rz).unwrap();
            assert_eq!(rp, rz, "sweep {sweep} geometry of {id}");
            id += stride;
            stride = stride * 7 % 9001 + 1;
        }
        // Past the last record: nothing.
        bz.seek_record(hz.objects).unwrap();
        assert!(bz.next_record().unwrap().is_none());
        for r in [&mut bp, &mut bz] {
            r.rewind().unwrap();
        }
        gp.rewind().unwrap();
        gz.rewind().unwrap();
    }
    // A seek decompresses one block: far fewer bytes through the codec than the file.
    let io = bz.file.io;
    assert!(
        io.seeks > 0 && io.bytes_read < hz.bbox_stored_bytes * 3,
        "{io:?}"
    );
}

#[test]
fn the_engine_answers_the_same_from_a_compressed_split_store() {
    let (input, plain, zst) = pair(Program::Rings, 3, "engine");
    let r = rays_around(&input.geometry, 800, 7);
    for sets in [
        // `rays`, not `memory`: the compressed readers hold more than `buffer`, so a budget
        // would hold fewer rays and make other passes.
        vec![("rays", "150")],
        vec![("hierarchy", "on"), ("bh_s", "2"), ("rays", "150")],
        vec![("lazy", "off")],
        vec![("grid", "two-level"), ("hierarchy", "on")],
    ] {
        let open = |dir: &std::path::Path| {
            let s = Settings::new("breadth-first", kv(&sets));
            BreadthFirst::open(dir, BreadthFirstConfig::from_settings(s).unwrap()).unwrap()
        };
        let (ep, ez) = (open(&plain.0), open(&zst.0));
        let (mut cp, mut cz) = (Counters::default(), Counters::default());
        assert_eq!(
            answers(&ep, &r, &mut cp),
            answers(&ez, &r, &mut cz),
            "{sets:?}"
        );
        // The same algorithm: every count but the disk's is equal.
        let strip = |c: &Counters| {
            let mut c = c.clone();
            c.extra.retain(|k, _| !k.starts_with("io_"));
            c
        };
        assert_eq!(strip(&cp), strip(&cz), "{sets:?}");
        // Read through the blocks (rings3's files are a block or two: after preprocessing the
        // sweeps may find theirs cached), and the readers' memory counted.
        use crate::Engine;
        let (sp, sz) = (ep.build_stats(), ez.build_stats());
        assert!(sz["preprocess_codec_bytes"] > 0.0, "{sets:?}");
        assert!(
            sz["store_reader_bytes"] > sp["store_reader_bytes"],
            "{sets:?}"
        );
    }
}

#[test]
fn a_damaged_compressed_split_store_is_refused_in_one_line() {
    let (_, _plain, zst) = pair(Program::Mount, 6, "damage");
    let d = &zst.0;
    let read = || -> std::io::Result<u64> { StoreHeader::read(d)?.verify() };
    read().unwrap();
    let files = [
        "bbox.bin.zst",
        "geometry.bin.zst",
        BBOX_INDEX,
        GEOMETRY_INDEX,
    ];
    for name in files {
        let p = d.join(name);
        let good = std::fs::read(&p).unwrap();
        // A flipped byte at several places (frame checksum, index checksum, header crc).
        for at in [3usize, good.len() / 2, good.len() - 2] {
            let mut bad = good.clone();
            bad[at] ^= 0x10;
            std::fs::write(&p, &bad).unwrap();
            let e = read()
                .err()
                .unwrap_or_else(|| panic!("{name}@{at} accepted"))
                .to_string();
            assert!(!e.contains('\n') && !e.is_empty(), "{e}");
        }
        // Truncated.
        std::fs::write(&p, &good[..good.len() - 5]).unwrap();
        let e = read()
            .err()
            .unwrap_or_else(|| panic!("{name} truncated accepted"))
            .to_string();
        assert!(!e.contains('\n'), "{e}");
        std::fs::write(&p, &good).unwrap();
    }
    // An index that disagrees: two entries of the geometry index swapped (checksums intact).
    let p = d.join(GEOMETRY_INDEX);
    let good = std::fs::read(&p).unwrap();
    assert!(good.len() >= 16 + 2 * blocks::INDEX_ENTRY, "one block only");
    {
        let mut bad = good.clone();
        let (a, b) = (16, 16 + blocks::INDEX_ENTRY);
        let first: Vec<u8> = bad[a..b].to_vec();
        bad.copy_within(b..b + blocks::INDEX_ENTRY, a);
        bad[b..b + blocks::INDEX_ENTRY].copy_from_slice(&first);
        std::fs::write(&p, &bad).unwrap();
        let e = read().err().unwrap().to_string();
        assert!(e.contains("disagrees"), "{e}");
        std::fs::write(&p, &good).unwrap();
    }
    read().unwrap();
    // gzip is not a split store's codec.
    let other = TempDir::new("blk-gzip");
    assert!(StoreWriter::create_with(&other.0, "x", Layout::Split, Codec::Gzip(1)).is_err());
}
