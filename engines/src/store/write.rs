//! Writing a store: a [`Sink`] that encodes each object as it streams by (seed 000 §3
//! preprocessing, "convert all scene data to a binary format, each object with its AABB"). It
//! holds one object at a time, the lights and the materials, never the scene.

use super::io::{Codec, IoCounters, IoFile};
use super::{
    Layout, Surface, BBOX_FILE, BBOX_INDEX, BBOX_MAGIC, GEOMETRY_FILE, GEOMETRY_INDEX,
    GEOMETRY_MAGIC, HEADER_FILE, MATERIALS_FILE, MATERIALS_MAGIC, MATERIAL_RECORD, MAX_LIGHTS,
    OBJECTS_FILE, OBJECTS_MAGIC, VERSION,
};
use crate::geometry::{prims_of, Prim};
use glam::{DVec3, Vec3};
use rtbench_scenes::{Light, Material, Scene, ShapeRef, Sink, View};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::HashMap;
use std::io;
use std::path::{Path, PathBuf};

/// One binary file at a checkpoint: its size on disk and the length of its (uncompressed) stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileState {
    pub stored: u64,
    pub written: u64,
}

/// Where a store being written stood at its last checkpoint ([`StoreWriter::checkpoint`]):
/// counts, the bounds so far (as f32 bits: an empty box is ±infinity, which JSON cannot hold)
/// and each binary file's state.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct WriteState {
    pub objects: u64,
    pub primitives: u64,
    pub lo_bits: [u32; 3],
    pub hi_bits: [u32; 3],
    /// `bbox.bin` (split layout only).
    pub bbox: Option<FileState>,
    /// `geometry.bin` (split) or `objects.bin[.gz]` (basic).
    pub geometry: FileState,
}

/// Buffer of each file being written.
const WRITE_BUFFER: usize = 1 << 16;

/// Streams a scene into a store directory. Call [`StoreWriter::finish`] at the end; the first
/// I/O error is kept and returned there (a `Sink` cannot fail mid-stream).
pub struct StoreWriter {
    dir: PathBuf,
    name: String,
    layout: Layout,
    codec: Codec,
    /// `bbox.bin` (split layout; `None` in the basic layout).
    bbox: Option<IoFile>,
    /// `geometry.bin` (split), or `objects.bin` holding each box and its geometry (basic).
    geometry: IoFile,
    error: Option<io::Error>,
    view: View,
    background: DVec3,
    lights: Vec<Light>,
    /// The scene's distinct materials, in order of first use (what `materials.bin` holds), and
    /// each one's index by its bits: generators emit a material per object or per group (SPD's
    /// rings one per ring, of six colours), so the table stays as small as the scene's palette.
    materials: Vec<Material>,
    material_ids: HashMap<[u64; 8], u32>,
    /// The table index of the material the next shape takes (the last one emitted).
    current_material: Option<u32>,
    objects: u64,
    prims_total: u64,
    lo: Vec3,
    hi: Vec3,
    // Scratch, reused per object.
    prims: Vec<Prim>,
    tris: Vec<[usize; 3]>,
    record: Vec<u8>,
}

/// The layouts a codec can store: gzip only the basic one (a split store's files are read with
/// seeks, so they are compressed as zstd blocks, and there is no gzip block format here).
fn check_codec(layout: Layout, codec: Codec) -> io::Result<()> {
    match (layout, codec) {
        (Layout::Split, Codec::Gzip(_)) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "a split store is compressed with zstd (blocks) only, not gzip",
        )),
        _ => Ok(()),
    }
}

/// `bbox.bin` or `geometry.bin` of a split store: plain, or as zstd blocks (`NAME.zst` and its
/// index) under `Codec::Zstd`; new, or taken up at a checkpoint's `state`.
fn split_file(
    dir: &Path,
    name: &str,
    codec: Codec,
    state: Option<&FileState>,
) -> io::Result<IoFile> {
    match (codec, state) {
        (Codec::Zstd(level), None) => {
            IoFile::create_blocks(&dir.join(super::blocks::data_name(name)), level)
        }
        (Codec::Zstd(level), Some(s)) => IoFile::append_blocks(
            &dir.join(super::blocks::data_name(name)),
            level,
            s.stored,
            s.written,
        ),
        (_, None) => IoFile::create(&dir.join(name), WRITE_BUFFER),
        (_, Some(s)) => IoFile::append_codec(
            &dir.join(name),
            WRITE_BUFFER,
            Codec::None,
            s.stored,
            s.written,
        ),
    }
}

fn f32s(out: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

fn v3(out: &mut Vec<u8>, v: Vec3) {
    f32s(out, &v.to_array());
}

/// The checksum of bbox record `id` (its first 32 bytes, `rec`).
pub(super) fn bbox_checksum(id: u64, rec: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(&id.to_le_bytes());
    h.update(rec);
    h.finalize()
}

/// The 16-byte header of a binary file of the store.
fn file_header(magic: &[u8; 8], extra: u32) -> [u8; 16] {
    let mut h = [0u8; 16];
    h[..8].copy_from_slice(magic);
    h[8..12].copy_from_slice(&VERSION.to_le_bytes());
    h[12..].copy_from_slice(&extra.to_le_bytes());
    h
}

impl StoreWriter {
    /// Creates `dir` (and parents) and the two binary files of the split layout in it.
    pub fn create(dir: &Path, name: &str) -> io::Result<StoreWriter> {
        Self::create_layout(dir, name, Layout::Split)
    }

    /// Creates `dir` (and parents) and the binary files of `layout` in it.
    pub fn create_layout(dir: &Path, name: &str, layout: Layout) -> io::Result<StoreWriter> {
        Self::create_with(dir, name, layout, Codec::None)
    }

    /// As [`StoreWriter::create_layout`], its files stored through `codec`: the basic layout's
    /// `objects.bin` as one gzip or zstd stream (it is read strictly forward), the split
    /// layout's two files as zstd blocks with an index ([`super::blocks`]: they are read with
    /// seeks).
    pub fn create_with(
        dir: &Path,
        name: &str,
        layout: Layout,
        codec: Codec,
    ) -> io::Result<StoreWriter> {
        check_codec(layout, codec)?;
        std::fs::create_dir_all(dir)?;
        // The header's checksum goes in at `finish`, when header.json is written.
        let (bbox, geometry) = match layout {
            Layout::Split => {
                let mut bbox = split_file(dir, BBOX_FILE, codec, None)?;
                let mut geometry = split_file(dir, GEOMETRY_FILE, codec, None)?;
                bbox.write_all(&file_header(BBOX_MAGIC, 0))?;
                geometry.write_all(&file_header(GEOMETRY_MAGIC, 0))?;
                (Some(bbox), geometry)
            }
            Layout::Basic => {
                let mut objects =
                    IoFile::create_codec(&dir.join(codec.objects_file()), WRITE_BUFFER, codec)?;
                objects.write_all(&file_header(OBJECTS_MAGIC, 0))?;
                (None, objects)
            }
        };
        Ok(Self::create_with_files(
            dir, name, layout, codec, bbox, geometry,
        ))
    }

    fn create_with_files(
        dir: &Path,
        name: &str,
        layout: Layout,
        codec: Codec,
        bbox: Option<IoFile>,
        geometry: IoFile,
    ) -> StoreWriter {
        StoreWriter {
            dir: dir.to_path_buf(),
            name: name.to_string(),
            layout,
            codec,
            bbox,
            geometry,
            error: None,
            view: View::default(),
            background: DVec3::ZERO,
            lights: Vec::new(),
            materials: Vec::new(),
            material_ids: HashMap::new(),
            current_material: None,
            objects: 0,
            prims_total: 0,
            lo: Vec3::INFINITY,
            hi: Vec3::NEG_INFINITY,
            prims: Vec::new(),
            tris: Vec::new(),
            record: Vec::new(),
        }
    }

    /// Objects written so far.
    pub fn objects(&self) -> u64 {
        self.objects
    }

    /// Bytes of records written so far (uncompressed streams, file headers included).
    pub fn written(&self) -> u64 {
        self.bbox.as_ref().map_or(0, |b| b.written()) + self.geometry.written()
    }

    /// Makes the store written so far durable and complete up to the last object
    /// ([`IoFile::checkpoint`] on every binary file: a gzip member ends) and returns where it
    /// stands, for [`StoreWriter::resume`] in another process. The first error of the stream is
    /// returned here.
    pub fn checkpoint(&mut self) -> io::Result<WriteState> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let bbox = match self.bbox.as_mut() {
            Some(b) => Some(FileState {
                stored: b.checkpoint()?,
                written: b.written(),
            }),
            None => None,
        };
        let geometry = FileState {
            stored: self.geometry.checkpoint()?,
            written: self.geometry.written(),
        };
        Ok(WriteState {
            objects: self.objects,
            primitives: self.prims_total,
            lo_bits: self.lo.to_array().map(f32::to_bits),
            hi_bits: self.hi.to_array().map(f32::to_bits),
            bbox,
            geometry,
        })
    }

    /// Takes up a store that [`StoreWriter::checkpoint`] left at `state` in `dir` (same name,
    /// layout and codec): the files are cut back to the checkpoint and appended to. The caller
    /// streams the scene again from its start and passes the first `state.objects` shapes by
    /// (they are on disk); lights, view and materials are taken again from that stream, and the
    /// material table comes out the same because it is built in order of first use.
    pub fn resume(
        dir: &Path,
        name: &str,
        layout: Layout,
        codec: Codec,
        state: &WriteState,
    ) -> io::Result<StoreWriter> {
        check_codec(layout, codec)?;
        let (bbox, geometry) = match (layout, &state.bbox) {
            (Layout::Split, Some(b)) => (
                Some(split_file(dir, BBOX_FILE, codec, Some(b))?),
                split_file(dir, GEOMETRY_FILE, codec, Some(&state.geometry))?,
            ),
            (Layout::Basic, None) => {
                let file = codec.objects_file();
                (
                    None,
                    IoFile::append_codec(
                        &dir.join(file),
                        WRITE_BUFFER,
                        codec,
                        state.geometry.stored,
                        state.geometry.written,
                    )?,
                )
            }
            _ => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!("{}: the checkpoint is of another layout", dir.display()),
                ))
            }
        };
        let mut w = StoreWriter::create_with_files(dir, name, layout, codec, bbox, geometry);
        w.objects = state.objects;
        w.prims_total = state.primitives;
        w.lo = Vec3::from_array(state.lo_bits.map(f32::from_bits));
        w.hi = Vec3::from_array(state.hi_bits.map(f32::from_bits));
        Ok(w)
    }

    /// Writes a scene already in memory (the breadth-first engine built from a `BuildInput`):
    /// each object keeps its own material index.
    pub fn write_scene(mut self, scene: &Scene) -> io::Result<IoCounters> {
        self.background = scene.background;
        self.view = scene.view.clone();
        for l in &scene.lights {
            self.add_light(l)?;
        }
        let ids: Vec<u32> = scene
            .materials
            .iter()
            .map(|m| self.material_id(m))
            .collect();
        for o in &scene.objects {
            let id = ids.get(o.material as usize).copied().ok_or_else(|| {
                io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("an object names material {} of {}", o.material, ids.len()),
                )
            })?;
            self.write_object(id, o.shape.as_ref())?;
        }
        self.finish()
    }

    /// The table index of `m`, adding it on first use. Bit-equal materials share one entry,
    /// so shading reads the same values as from the scene's own list.
    fn material_id(&mut self, m: &Material) -> u32 {
        let key = material_bits(m);
        if let Some(&id) = self.material_ids.get(&key) {
            return id;
        }
        let id = self.materials.len() as u32;
        self.materials.push(m.clone());
        self.material_ids.insert(key, id);
        id
    }

    fn add_light(&mut self, l: &Light) -> io::Result<()> {
        if self.lights.len() >= MAX_LIGHTS {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("more than {MAX_LIGHTS} lights (a store's header.json holds at most {MAX_LIGHTS})"),
            ));
        }
        self.lights.push(l.clone());
        Ok(())
    }

    fn write_object(&mut self, material: u32, shape: ShapeRef<'_>) -> io::Result<()> {
        self.prims.clear();
        prims_of(shape, &mut self.prims, &mut self.tris);
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in &self.prims {
            let (a, b) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        let r = &mut self.record;
        r.clear();
        r.extend_from_slice(&[0; 4]);
        r.extend_from_slice(&material.to_le_bytes());
        encode_surface(r, &Surface::of(shape));
        r.extend_from_slice(&(self.prims.len() as u32).to_le_bytes());
        for p in &self.prims {
            encode_prim(r, p);
        }
        let len = u32::try_from(r.len() + 4)
            .map_err(|_| io::Error::other("an object's record passes 4 GiB"))?;
        r[..4].copy_from_slice(&len.to_le_bytes());
        let crc = crc32fast::hash(r);
        r.extend_from_slice(&crc.to_le_bytes());
        // Basic layout: the box record, then the geometry record right after it.
        let offset = match self.bbox {
            Some(_) => self.geometry.written(),
            None => self.geometry.written() + super::BBOX_RECORD as u64,
        };
        let mut b = Vec::with_capacity(super::BBOX_RECORD);
        v3(&mut b, lo);
        v3(&mut b, hi);
        b.extend_from_slice(&offset.to_le_bytes());
        let crc = bbox_checksum(self.objects, &b);
        b.extend_from_slice(&crc.to_le_bytes());
        match self.bbox.as_mut() {
            Some(bbox) => {
                self.geometry.write_all(r)?;
                bbox.write_all(&b)?;
            }
            None => {
                self.geometry.write_all(&b)?;
                self.geometry.write_all(r)?;
            }
        }
        if !self.prims.is_empty() {
            self.lo = self.lo.min(lo);
            self.hi = self.hi.max(hi);
        }
        self.objects += 1;
        self.prims_total += self.prims.len() as u64;
        Ok(())
    }

    /// Flushes the binary files and writes `header.json`. Returns the bytes and calls made.
    pub fn finish(self) -> io::Result<IoCounters> {
        if let Some(e) = self.error {
            return Err(e);
        }
        let bbox_bytes = self.bbox.as_ref().map_or(0, |b| b.written());
        let geometry_bytes = self.geometry.written();
        let mut io = self.geometry.finish()?;
        let stored_bytes = io.bytes_written;
        if let Some(b) = self.bbox {
            io.add(&b.finish()?);
        }
        let (materials_bytes, materials_crc) = write_materials(&self.dir, &self.materials)?;
        io.bytes_written += materials_bytes;
        io.write_calls += 1;
        let v = &self.view;
        let d3 = |v: DVec3| json!([v.x, v.y, v.z]);
        let mut header = json!({
            "format": "rtbench-store",
            "version": VERSION,
            "name": self.name,
            "objects": self.objects,
            "primitives": self.prims_total,
            "bounds": [self.lo.to_array(), self.hi.to_array()],
            "background": d3(self.background),
            "view": {"from": d3(v.from), "at": d3(v.at), "up": d3(v.up), "angle": v.angle,
                     "hither": v.hither, "resolution": v.resolution},
            "lights": self.lights.iter().map(|l| json!({
                "position": d3(l.position), "color": l.color.map(d3)})).collect::<Vec<_>>(),
            "materials": self.materials.len(),
            "materials_bytes": materials_bytes,
            "materials_crc": materials_crc,
        });
        let split_zstd = self.layout == Layout::Split && self.codec != Codec::None;
        match self.layout {
            Layout::Split => {
                header["bbox_bytes"] = json!(bbox_bytes);
                header["geometry_bytes"] = json!(geometry_bytes);
                if split_zstd {
                    // The data files' sizes (the counters also hold the indexes').
                    let size = |n: &str| {
                        std::fs::metadata(self.dir.join(super::blocks::data_name(n)))
                            .map(|m| m.len())
                    };
                    header["compression"] = json!(self.codec.name());
                    header["block_bytes"] = json!(super::blocks::BLOCK_BYTES);
                    header["bbox_stored_bytes"] = json!(size(BBOX_FILE)?);
                    header["stored_bytes"] = json!(size(GEOMETRY_FILE)?);
                }
            }
            Layout::Basic => {
                header["layout"] = json!("basic");
                header["objects_bytes"] = json!(geometry_bytes);
                if self.codec != Codec::None {
                    header["compression"] = json!(self.codec.name());
                    header["stored_bytes"] = json!(stored_bytes);
                }
            }
        }
        let text = serde_json::to_string_pretty(&header).map_err(io::Error::other)?;
        std::fs::write(self.dir.join(HEADER_FILE), &text)?;
        io.bytes_written += text.len() as u64;
        io.write_calls += 1;
        // Tie the header to the files: its checksum in both files' headers.
        let crc = crc32fast::hash(text.as_bytes()).to_le_bytes();
        let files: &[&str] = match self.layout {
            // The indexes' headers carry it: the data files are written compressed.
            Layout::Split if split_zstd => &[BBOX_INDEX, GEOMETRY_INDEX],
            Layout::Split => &[BBOX_FILE, GEOMETRY_FILE],
            Layout::Basic if self.codec == Codec::None => &[OBJECTS_FILE],
            // Written compressed: its header cannot be patched in place; header.crc holds it.
            Layout::Basic => {
                let path = self.dir.join(super::HEADER_CRC_FILE);
                let h = file_header(super::HEADER_CRC_MAGIC, u32::from_le_bytes(crc));
                std::fs::write(&path, h)?;
                std::fs::File::open(&path)?.sync_all()?;
                io.bytes_written += h.len() as u64;
                io.write_calls += 1;
                &[]
            }
        };
        for name in files {
            use std::os::unix::fs::FileExt;
            let f = std::fs::OpenOptions::new()
                .write(true)
                .open(self.dir.join(name))?;
            f.write_all_at(&crc, 12)?;
            f.sync_data()?;
            io.bytes_written += 4;
            io.write_calls += 1;
        }
        Ok(io)
    }
}

/// A material's values as bits (color x y z, kd, ks, shine, t, ior): the key under which
/// bit-equal materials share a table entry, and the record of `materials.bin`.
fn material_bits(m: &Material) -> [u64; 8] {
    [
        m.color.x, m.color.y, m.color.z, m.kd, m.ks, m.shine, m.t, m.ior,
    ]
    .map(f64::to_bits)
}

/// Writes `materials.bin` (its header, then one record per material); returns its size and
/// CRC-32, which header.json records (the file is written first, so the header vouches for it).
fn write_materials(dir: &Path, materials: &[Material]) -> io::Result<(u64, u32)> {
    let count = u32::try_from(materials.len())
        .map_err(|_| io::Error::other("more than 2^32 − 1 distinct materials"))?;
    let mut bytes = Vec::with_capacity(16 + materials.len() * MATERIAL_RECORD);
    bytes.extend_from_slice(&file_header(MATERIALS_MAGIC, count));
    for m in materials {
        for b in material_bits(m) {
            bytes.extend_from_slice(&b.to_le_bytes());
        }
    }
    let path = dir.join(MATERIALS_FILE);
    let f = std::fs::File::create(&path)?;
    std::io::Write::write_all(&mut &f, &bytes)?;
    f.sync_data()?;
    Ok((bytes.len() as u64, crc32fast::hash(&bytes)))
}

pub(super) fn encode_surface(r: &mut Vec<u8>, s: &Surface) {
    match *s {
        Surface::Sphere { center, radius } => {
            r.push(0);
            v3(r, center);
            f32s(r, &[radius]);
        }
        Surface::Cone { base, rb, apex, ra } => {
            r.push(1);
            v3(r, base);
            f32s(r, &[rb]);
            v3(r, apex);
            f32s(r, &[ra]);
        }
        Surface::Flat { normal } => {
            r.push(2);
            v3(r, normal);
        }
        Surface::Smooth { normals, flat } => {
            r.push(3);
            for n in normals {
                v3(r, n);
            }
            v3(r, flat);
        }
    }
}

pub(super) fn encode_prim(r: &mut Vec<u8>, p: &Prim) {
    match *p {
        Prim::Sphere { center, radius } => {
            r.push(0);
            v3(r, center);
            f32s(r, &[radius]);
        }
        Prim::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => {
            r.push(1);
            v3(r, base);
            f32s(r, &[base_radius]);
            v3(r, apex);
            f32s(r, &[apex_radius]);
        }
        Prim::Triangle(t) => {
            r.push(2);
            for v in t {
                v3(r, v);
            }
        }
    }
}

impl Sink for StoreWriter {
    fn background(&mut self, color: DVec3) {
        self.background = color;
    }
    fn view(&mut self, view: &View) {
        self.view = view.clone();
    }
    fn light(&mut self, light: &Light) {
        if self.error.is_none() {
            if let Err(e) = self.add_light(light) {
                self.error = Some(e);
            }
        }
    }
    fn material(&mut self, material: &Material) {
        self.current_material = Some(self.material_id(material));
    }
    fn shape(&mut self, shape: ShapeRef<'_>) {
        // NFF allows primitives before any `f`: they get the default material (as
        // `SceneCollector` does).
        let material = match self.current_material {
            Some(m) => m,
            None => {
                let m = self.material_id(&Material::default());
                self.current_material = Some(m);
                m
            }
        };
        if self.error.is_none() {
            if let Err(e) = self.write_object(material, shape) {
                self.error = Some(e);
            }
        }
    }
}
