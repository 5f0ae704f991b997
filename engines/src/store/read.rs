//! Reading a store: its header, the bounding-box file as a forward stream, and the geometry
//! file with forward-only seeks (seed 000 §4.2.2, "G": geometry is read only when needed).

use super::blocks;
use super::io::{Codec, IoCounters, IoFile};
use super::write::bbox_checksum;
use super::{
    Layout, Surface, BBOX_FILE, BBOX_MAGIC, BBOX_RECORD, FILE_HEADER, GEOMETRY_FILE,
    GEOMETRY_MAGIC, HEADER_FILE, MATERIALS_FILE, MATERIALS_MAGIC, MATERIAL_RECORD, MAX_LIGHTS,
    MIN_GEOMETRY_RECORD, OBJECTS_FILE, OBJECTS_FILE_GZ, OBJECTS_FILE_ZST, OBJECTS_MAGIC, VERSION,
};
use crate::geometry::Prim;
use glam::{DVec3, Vec3};
use rtbench_scenes::validate;
use rtbench_scenes::{Light, Material, View};
use serde_json::Value;
use std::io;
use std::path::{Path, PathBuf};

/// `header.json`, parsed.
#[derive(Clone, Debug)]
pub struct StoreHeader {
    pub dir: PathBuf,
    pub name: String,
    pub objects: u64,
    pub primitives: u64,
    pub bounds: [Vec3; 2],
    pub background: DVec3,
    pub view: View,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    pub layout: Layout,
    /// How `objects.bin` (basic layout) or `bbox.bin` and `geometry.bin` (split layout: zstd
    /// blocks, [`super::blocks`]) are stored, and the size on disk of `objects.bin` or of
    /// `geometry.bin`'s data file.
    pub codec: Codec,
    pub stored_bytes: u64,
    /// The size on disk of `bbox.bin`'s data file (compressed split layout; else `bbox_bytes`).
    pub bbox_stored_bytes: u64,
    /// Sizes of `bbox.bin` and `geometry.bin`, as recorded (and checked against the files); in
    /// the basic layout `bbox_bytes` is 0 and `geometry_bytes` is the size of `objects.bin`.
    pub bbox_bytes: u64,
    pub geometry_bytes: u64,
}

fn bad(dir: &Path, what: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: not a scene store: {what}", dir.display()),
    )
}

impl StoreHeader {
    pub fn read(dir: &Path) -> io::Result<StoreHeader> {
        let path = dir.join(HEADER_FILE);
        let text = match read_bounded(&path, MAX_HEADER_BYTES) {
            Ok(t) => t,
            // Format 2 kept the materials in header.json, one per object on some scenes: an
            // old store's header can pass the limit. Its binary files say which format it is.
            Err(e) => match data_file_version(dir) {
                Some(n) if n != VERSION => return Err(old_format(dir, n)),
                _ => return Err(e),
            },
        };
        let crc = crc32fast::hash(text.as_bytes());
        let v: Value = serde_json::from_str(&text).map_err(|e| bad(dir, e))?;
        if v["format"] != "rtbench-store" {
            return Err(bad(dir, "header.json has no \"format\": \"rtbench-store\""));
        }
        match v["version"].as_u64() {
            Some(n) if n == VERSION as u64 => {}
            Some(n) => return Err(old_format(dir, n)),
            None => return Err(bad(dir, format!("version {}", v["version"]))),
        }
        let num = |v: &Value, k: &str| -> io::Result<f64> {
            v[k].as_f64()
                .ok_or_else(|| bad(dir, format!("'{k}' is not a number")))
        };
        let d3 = |v: &Value| -> io::Result<DVec3> {
            let a = v
                .as_array()
                .filter(|a| a.len() == 3)
                .ok_or_else(|| bad(dir, "expected [x, y, z]"))?;
            let f = |i: usize| {
                a[i].as_f64()
                    .ok_or_else(|| bad(dir, "non-numeric coordinate"))
            };
            Ok(DVec3::new(f(0)?, f(1)?, f(2)?))
        };
        let vw = &v["view"];
        let res = vw["resolution"]
            .as_array()
            .filter(|a| a.len() == 2)
            .ok_or_else(|| bad(dir, "view.resolution"))?;
        let view = View {
            from: d3(&vw["from"])?,
            at: d3(&vw["at"])?,
            up: d3(&vw["up"])?,
            angle: num(vw, "angle")?,
            hither: num(vw, "hither")?,
            resolution: [
                res[0]
                    .as_u64()
                    .and_then(|r| u32::try_from(r).ok())
                    .ok_or_else(|| bad(dir, "view.resolution"))?,
                res[1]
                    .as_u64()
                    .and_then(|r| u32::try_from(r).ok())
                    .ok_or_else(|| bad(dir, "view.resolution"))?,
            ],
        };
        let mut lights = Vec::new();
        let light_list = v["lights"].as_array();
        if light_list.map_or(0, |l| l.len()) > MAX_LIGHTS {
            return Err(bad(
                dir,
                format!("header.json: more than {MAX_LIGHTS} lights"),
            ));
        }
        for l in light_list.into_iter().flatten() {
            lights.push(Light {
                position: d3(&l["position"])?,
                color: if l["color"].is_null() {
                    None
                } else {
                    Some(d3(&l["color"])?)
                },
            });
        }
        let b = d3(&v["bounds"][0])?.as_vec3();
        let c = d3(&v["bounds"][1])?.as_vec3();
        let count = |k: &str| -> io::Result<u64> {
            v[k].as_u64()
                .ok_or_else(|| bad(dir, format!("'{k}' is not a whole number")))
        };
        let objects = count("objects")?;
        let material_count = count("materials")?;
        if objects > 0 && material_count == 0 {
            return Err(bad(dir, "header.json: objects but no materials"));
        }
        let materials = read_materials(
            dir,
            material_count,
            count("materials_bytes")?,
            count("materials_crc")?,
        )?;
        let layout = match v["layout"].as_str() {
            None if v["layout"].is_null() => Layout::Split,
            Some("split") => Layout::Split,
            Some("basic") => Layout::Basic,
            _ => return Err(bad(dir, format!("unknown layout {}", v["layout"]))),
        };
        let (bbox_bytes, geometry_bytes) = match layout {
            Layout::Split => (count("bbox_bytes")?, count("geometry_bytes")?),
            Layout::Basic => (0, count("objects_bytes")?),
        };
        let codec = match (v["compression"].as_str(), layout) {
            (None, _) if v["compression"].is_null() => Codec::None,
            (Some(name), Layout::Basic) if Codec::from_header(name).is_some() => {
                Codec::from_header(name).unwrap_or_default()
            }
            (Some("zstd"), Layout::Split)
                if v["block_bytes"].as_u64() == Some(super::blocks::BLOCK_BYTES as u64) =>
            {
                Codec::Zstd(3)
            }
            _ => {
                return Err(bad(
                    dir,
                    format!(
                        "compression {} (gzip or zstd in the basic layout, zstd blocks of {} bytes in the split one)",
                        v["compression"],
                        super::blocks::BLOCK_BYTES
                    ),
                ))
            }
        };
        let stored_bytes = match codec {
            Codec::None => geometry_bytes,
            Codec::Gzip(_) | Codec::Zstd(_) => count("stored_bytes")?,
        };
        let bbox_stored_bytes = match (codec, layout) {
            (Codec::None, _) | (_, Layout::Basic) => bbox_bytes,
            _ => count("bbox_stored_bytes")?,
        };
        let h = StoreHeader {
            dir: dir.to_path_buf(),
            name: v["name"].as_str().unwrap_or("").to_string(),
            objects,
            primitives: count("primitives")?,
            bounds: [b, c],
            background: d3(&v["background"])?,
            view,
            lights,
            materials,
            layout,
            codec,
            stored_bytes,
            bbox_stored_bytes,
            bbox_bytes,
            geometry_bytes,
        };
        h.check(crc)?;
        Ok(h)
    }

    /// The header against the scene rules and against the files: their sizes, and the checksum of
    /// header.json that each file's header carries.
    fn check(&self, crc: u32) -> io::Result<()> {
        let dir = &self.dir;
        let rule = |r: Result<(), String>| r.map_err(|e| bad(dir, format!("header.json: {e}")));
        rule(validate::check_view(&self.view))?;
        rule(validate::check_background(self.background))?;
        for l in &self.lights {
            rule(validate::check_light(l))?;
        }
        for m in &self.materials {
            rule(validate::check_material(m))?;
        }
        if self.objects > u32::MAX as u64 {
            return Err(bad(
                dir,
                format!("{} objects (at most 2^32 − 1)", self.objects),
            ));
        }
        let want_bbox = FILE_HEADER + self.objects * BBOX_RECORD as u64;
        if self.layout == Layout::Split && self.bbox_bytes != want_bbox {
            return Err(bad(
                dir,
                format!(
                    "header.json: bbox_bytes {} for {} objects (expected {want_bbox})",
                    self.bbox_bytes, self.objects
                ),
            ));
        }
        if self.objects > 0 && !(self.bounds[0].is_finite() && self.bounds[1].is_finite()) {
            return Err(bad(dir, "header.json: bounds are not finite"));
        }
        if self.layout == Layout::Split && self.codec != Codec::None {
            return self.check_blocks(crc);
        }
        let files: &[(&str, u64)] = match self.layout {
            Layout::Split => &[
                (BBOX_FILE, self.bbox_bytes),
                (GEOMETRY_FILE, self.geometry_bytes),
            ],
            Layout::Basic if self.codec == Codec::None => &[(OBJECTS_FILE, self.geometry_bytes)],
            Layout::Basic => &[(self.codec.objects_file(), self.stored_bytes)],
        };
        let compressed = self.codec != Codec::None;
        if compressed {
            self.check_header_crc(crc)?;
        }
        for &(name, want) in files {
            let path = dir.join(name);
            let mut f = std::fs::File::open(&path)
                .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
            let size = f.metadata()?.len();
            if size != want {
                return Err(bad(
                    dir,
                    format!("{name} has {size} bytes, header.json says {want}"),
                ));
            }
            if compressed {
                // Checked through the codec as it is read (gzip CRC-32, record checksums).
                continue;
            }
            let mut h = [0u8; FILE_HEADER as usize];
            std::io::Read::read_exact(&mut f, &mut h)
                .map_err(|_| bad(dir, format!("{name} is shorter than its header")))?;
            if u32::from_le_bytes(h[12..16].try_into().unwrap()) != crc {
                return Err(bad(
                    dir,
                    format!("{name} does not match header.json (checksum)"),
                ));
            }
        }
        Ok(())
    }

    /// `header.crc` of a compressed basic store against header.json (module docs of `store`).
    fn check_header_crc(&self, crc: u32) -> io::Result<()> {
        let path = self.dir.join(super::HEADER_CRC_FILE);
        let h = read_bounded_bytes(&path, FILE_HEADER).map_err(|e| {
            bad(
                &self.dir,
                format!(
                    "{}: {} (a compressed store's header.json must be vouched for: write the store again)",
                    super::HEADER_CRC_FILE,
                    e.kind().to_string().to_lowercase()
                ),
            )
        })?;
        if h.len() as u64 != FILE_HEADER || &h[..8] != super::HEADER_CRC_MAGIC {
            return Err(bad(
                &self.dir,
                format!("{} is not a header checksum", super::HEADER_CRC_FILE),
            ));
        }
        if u32::from_le_bytes(h[12..16].try_into().unwrap()) != crc {
            return Err(bad(
                &self.dir,
                "header.json does not match header.crc (checksum): it was changed after writing",
            ));
        }
        Ok(())
    }

    /// The files of a compressed split store: each data file's size, its index against it and
    /// against the uncompressed size header.json records, and the index's header against
    /// header.json's checksum.
    fn check_blocks(&self, crc: u32) -> io::Result<()> {
        let files = [
            (BBOX_FILE, self.bbox_bytes, self.bbox_stored_bytes),
            (GEOMETRY_FILE, self.geometry_bytes, self.stored_bytes),
        ];
        for (name, bytes, stored) in files {
            let data = self.dir.join(blocks::data_name(name));
            let size = std::fs::metadata(&data)
                .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", data.display())))?
                .len();
            if size != stored {
                return Err(bad(
                    &self.dir,
                    format!(
                        "{} has {size} bytes, header.json says {stored}",
                        blocks::data_name(name)
                    ),
                ));
            }
            let ix = blocks::BlockIndex::read(&blocks::index_path(&data), stored)
                .map_err(|e| bad(&self.dir, e))?;
            if ix.total != bytes {
                return Err(bad(
                    &self.dir,
                    format!(
                        "{name}'s blocks hold {} bytes, header.json says {bytes}",
                        ix.total
                    ),
                ));
            }
            if ix.header_crc != crc {
                return Err(bad(
                    &self.dir,
                    format!("{name}'s block index does not match header.json (checksum)"),
                ));
            }
        }
        Ok(())
    }

    /// Bytes of the store's record files on disk (compressed where they are; block indexes
    /// not counted).
    pub fn disk_bytes(&self) -> u64 {
        self.stored_bytes + self.bbox_stored_bytes
    }

    /// Reads the whole store once (its own buffers, outside any engine's I/O counters) and checks
    /// every record: its checksum and values, that the geometry records tile `geometry.bin` in
    /// object order, that each box is its primitives' box, and that the object and primitive
    /// counts and the bounds are the header's. Returns the bytes read.
    pub fn verify(&self) -> io::Result<u64> {
        let mut scene = SceneReader::open(self, 1 << 16, false)?;
        let mut rec = ObjectRecord::default();
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let mut next = FILE_HEADER;
        let mut prims = 0u64;
        let gap = match self.layout {
            Layout::Split => 0,
            Layout::Basic => BBOX_RECORD as u64,
        };
        while let Some((id, b, _)) = scene.next(&mut rec)? {
            next += gap;
            if b.offset != next {
                return Err(bad(
                    &self.dir,
                    format!("bbox record {id}: offset {} (expected {next})", b.offset),
                ));
            }
            next = scene.position();
            let (mut a, mut c) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for p in &rec.prims {
                let (pa, pc) = p.bounds();
                a = a.min(pa);
                c = c.max(pc);
            }
            if (a, c) != (b.lo, b.hi) {
                return Err(bad(
                    &self.dir,
                    format!("bbox record {id} is not its primitives' box"),
                ));
            }
            if (rec.material as usize) >= self.materials.len() {
                return Err(bad(
                    &self.dir,
                    format!(
                        "object {id} names material {} of {}",
                        rec.material,
                        self.materials.len()
                    ),
                ));
            }
            if !rec.prims.is_empty() {
                lo = lo.min(a);
                hi = hi.max(c);
            }
            prims += rec.prims.len() as u64;
        }
        if next != self.geometry_bytes {
            return Err(bad(
                &self.dir,
                format!(
                    "geometry records end at {next}, the file at {}",
                    self.geometry_bytes
                ),
            ));
        }
        if prims != self.primitives || (prims > 0 && [lo, hi] != self.bounds) {
            return Err(bad(
                &self.dir,
                "header.json's primitive count or bounds differ from the records",
            ));
        }
        Ok(scene.io().bytes_read)
    }
}

/// Largest header.json read. It holds no per-object or per-material data, and at most
/// [`MAX_LIGHTS`] lights (about 250 bytes each in pretty JSON), so 4 MiB bounds it whatever the
/// scene's size.
const MAX_HEADER_BYTES: u64 = 4 << 20;

/// The one-line refusal of a store of another format.
fn old_format(dir: &Path, n: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "{}: store format {n}, this rtbench reads {VERSION}: rebuild with `rtbench scene store`",
            dir.display()
        ),
    )
}

/// The format version in the header of the store's main binary file (bbox.bin, objects.bin or
/// objects.bin.gz), when there is one with one of the store's magics.
fn data_file_version(dir: &Path) -> Option<u32> {
    let files = [
        (BBOX_FILE, Codec::None),
        (OBJECTS_FILE, Codec::None),
        (OBJECTS_FILE_GZ, Codec::Gzip(6)),
        (OBJECTS_FILE_ZST, Codec::Zstd(3)),
    ];
    for (name, codec) in files {
        let path = dir.join(name);
        if !path.is_file() {
            continue;
        }
        let mut f = IoFile::open_codec(&path, 64, codec).ok()?;
        let mut h = [0u8; FILE_HEADER as usize];
        f.read_exact(&mut h).ok()?;
        if [BBOX_MAGIC, OBJECTS_MAGIC].iter().any(|m| h[..8] == m[..]) {
            return Some(u32::from_le_bytes(h[8..12].try_into().unwrap()));
        }
    }
    None
}

/// `materials.bin`: its size against header.json's count and size, its bytes against the CRC-32
/// header.json records, then each material against the scene rules.
fn read_materials(dir: &Path, count: u64, bytes: u64, crc: u64) -> io::Result<Vec<Material>> {
    let want = count
        .checked_mul(MATERIAL_RECORD as u64)
        .and_then(|b| b.checked_add(FILE_HEADER))
        .filter(|_| count <= u32::MAX as u64)
        .ok_or_else(|| bad(dir, format!("header.json: {count} materials")))?;
    if bytes != want {
        return Err(bad(
            dir,
            format!("header.json: materials_bytes {bytes} for {count} materials (expected {want})"),
        ));
    }
    let path = dir.join(MATERIALS_FILE);
    let file = std::fs::File::open(&path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    let size = file.metadata()?.len();
    let mut f = io::BufReader::with_capacity(1 << 16, file);
    if size != bytes {
        return Err(bad(
            dir,
            format!("{MATERIALS_FILE} has {size} bytes, header.json says {bytes}"),
        ));
    }
    let mut hasher = crc32fast::Hasher::new();
    let mut h = [0u8; FILE_HEADER as usize];
    io::Read::read_exact(&mut f, &mut h)?;
    hasher.update(&h);
    let mut materials = Vec::with_capacity(count as usize);
    let mut r = [0u8; MATERIAL_RECORD];
    for _ in 0..count {
        io::Read::read_exact(&mut f, &mut r)?;
        hasher.update(&r);
        let x = |i: usize| f64::from_le_bytes(r[i * 8..i * 8 + 8].try_into().unwrap());
        materials.push(Material {
            color: DVec3::new(x(0), x(1), x(2)),
            kd: x(3),
            ks: x(4),
            shine: x(5),
            t: x(6),
            ior: x(7),
        });
    }
    if hasher.finalize() as u64 != crc {
        return Err(bad(
            dir,
            format!("{MATERIALS_FILE} does not match header.json (checksum)"),
        ));
    }
    if &h[..8] != MATERIALS_MAGIC
        || u32::from_le_bytes(h[8..12].try_into().unwrap()) != VERSION
        || u32::from_le_bytes(h[12..16].try_into().unwrap()) as u64 != count
    {
        return Err(bad(
            dir,
            format!("{MATERIALS_FILE}: wrong magic, version or count"),
        ));
    }
    Ok(materials)
}

/// A text file of at most `max` bytes, its size checked before reading.
fn read_bounded(path: &Path, max: u64) -> io::Result<String> {
    let shown = |e: io::Error| io::Error::new(e.kind(), format!("{}: {e}", path.display()));
    let f = std::fs::File::open(path).map_err(shown)?;
    let size = f.metadata().map_err(shown)?.len();
    if size > max {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}: {size} bytes (at most {max})", path.display()),
        ));
    }
    let mut text = String::new();
    std::io::Read::read_to_string(&mut std::io::Read::take(f, max), &mut text).map_err(shown)?;
    Ok(text)
}

/// At most `max` bytes of `path`.
fn read_bounded_bytes(path: &Path, max: u64) -> io::Result<Vec<u8>> {
    let f = std::fs::File::open(path)?;
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut std::io::Read::take(f, max + 1), &mut out)?;
    Ok(out)
}

fn check_file_header(f: &mut IoFile, magic: &[u8; 8], path: &Path) -> io::Result<()> {
    let mut h = [0u8; FILE_HEADER as usize];
    f.read_exact(&mut h).map_err(|e| match e.kind() {
        io::ErrorKind::UnexpectedEof => bad(path, "file shorter than its header"),
        // A compressed file whose stream is damaged before the first record.
        _ => bad(path, format!("unreadable header: {e}")),
    })?;
    if &h[..8] != magic {
        return Err(bad(path, "wrong magic"));
    }
    let version = u32::from_le_bytes(h[8..12].try_into().unwrap());
    if version != VERSION {
        return Err(bad(path, format!("version {version}")));
    }
    Ok(())
}

/// `bbox.bin` or `geometry.bin` of a split store, as it is stored: as zstd blocks when
/// `NAME.zst` is there (its buffer is then one block, [`super::blocks`]), else plain.
fn open_split_file(dir: &Path, name: &str, buffer: usize) -> io::Result<(IoFile, PathBuf)> {
    let z = dir.join(blocks::data_name(name));
    if z.exists() {
        Ok((IoFile::open_blocks(&z)?, z))
    } else {
        let path = dir.join(name);
        Ok((IoFile::open(&path, buffer)?, path))
    }
}

/// One record of the bounding-box file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BboxRecord {
    pub lo: Vec3,
    pub hi: Vec3,
    pub offset: u64,
}

/// The bounding-box file, read forward, record by record; [`BboxReader::rewind`] for the next
/// sweep.
pub struct BboxReader {
    pub file: IoFile,
    next_id: u64,
    objects: u64,
}

impl BboxReader {
    pub fn open(dir: &Path, objects: u64, buffer: usize) -> io::Result<BboxReader> {
        let (mut file, path) = open_split_file(dir, BBOX_FILE, buffer)?;
        let want = FILE_HEADER + objects * BBOX_RECORD as u64;
        if file.block_total().is_some_and(|t| t != want) {
            return Err(bad(
                &path,
                format!(
                    "{} bytes in blocks for {objects} objects (expected {want})",
                    file.block_total().unwrap_or(0)
                ),
            ));
        }
        check_file_header(&mut file, BBOX_MAGIC, &path)?;
        Ok(BboxReader {
            file,
            next_id: 0,
            objects,
        })
    }

    pub fn rewind(&mut self) -> io::Result<()> {
        self.file.seek_to(FILE_HEADER)?;
        self.next_id = 0;
        Ok(())
    }

    /// Moves forward to object `id` (one seek at most): the bounding-box hierarchy skips a
    /// subtree so (seed 000 §4.2.2, "B"), and shading reaches a hit object so (Algorithm 4.4).
    pub fn seek_record(&mut self, id: u64) -> io::Result<()> {
        if id > self.objects {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("bbox record {id} past the last ({})", self.objects),
            ));
        }
        self.file.seek_to(FILE_HEADER + id * BBOX_RECORD as u64)?;
        self.next_id = id;
        Ok(())
    }

    /// The next (object id, record), or `None` after the last.
    pub fn next_record(&mut self) -> io::Result<Option<(u32, BboxRecord)>> {
        if self.next_id == self.objects {
            return Ok(None);
        }
        let mut b = [0u8; BBOX_RECORD];
        self.file.read_exact(&mut b)?;
        let rec = decode_bbox(self.next_id, &b)?;
        let id = self.next_id as u32;
        self.next_id += 1;
        Ok(Some((id, rec)))
    }
}

/// One object's record of the geometry file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectRecord {
    pub material: u32,
    pub surface: Option<Surface>,
    pub prims: Vec<Prim>,
}

/// The geometry file, read at increasing offsets only (a backward offset is a caller's bug and
/// is refused); the buffer makes near records cost no system call.
pub struct GeometryReader {
    pub file: IoFile,
    scratch: Vec<u8>,
    /// The file's size: no record length past it is believed.
    size: u64,
}

impl GeometryReader {
    pub fn open(dir: &Path, buffer: usize) -> io::Result<GeometryReader> {
        let (mut file, path) = open_split_file(dir, GEOMETRY_FILE, buffer)?;
        let size = match file.block_total() {
            Some(t) => t,
            None => std::fs::metadata(&path)?.len(),
        };
        check_file_header(&mut file, GEOMETRY_MAGIC, &path)?;
        Ok(GeometryReader {
            file,
            scratch: Vec::new(),
            size,
        })
    }

    /// Back to the start, for the next sweep (the only backward move).
    pub fn rewind(&mut self) -> io::Result<()> {
        self.file.seek_to(FILE_HEADER)
    }

    /// Reads the record at `offset` into `out`.
    pub fn read_at(&mut self, offset: u64, out: &mut ObjectRecord) -> io::Result<()> {
        if offset < self.file.position() {
            return Err(io::Error::other(format!(
                "geometry read at {offset} behind the position {}: not forward-only",
                self.file.position()
            )));
        }
        self.file.seek_to(offset)?;
        read_geometry(&mut self.file, self.size, &mut self.scratch, out)
    }
}

/// Reads the geometry record at the file's position into `out`, checking its length against
/// `size` (the file's) before allocating, and its checksum.
fn read_geometry(
    file: &mut IoFile,
    size: u64,
    scratch: &mut Vec<u8>,
    out: &mut ObjectRecord,
) -> io::Result<()> {
    let offset = file.position();
    let mut len = [0u8; 4];
    file.read_exact(&mut len)?;
    let len_bytes = len;
    let len = u32::from_le_bytes(len) as usize;
    // Checked before anything is allocated for it: a corrupt length asked for gigabytes.
    if len < MIN_GEOMETRY_RECORD || offset.saturating_add(len as u64) > size {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "geometry record at {offset}: length {len} does not fit the file ({size} bytes)"
            ),
        ));
    }
    scratch.resize(len - 4, 0);
    file.read_exact(scratch)?;
    let (body, crc) = scratch.split_at(len - 8);
    let mut h = crc32fast::Hasher::new();
    h.update(&len_bytes);
    h.update(body);
    if h.finalize() != u32::from_le_bytes(crc.try_into().unwrap()) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("geometry record at {offset}: checksum mismatch"),
        ));
    }
    decode_record(body, out).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("geometry record at {offset} is malformed"),
        )
    })
}

/// A bounding-box record from its 36 bytes, checked against its checksum.
fn decode_bbox(id: u64, b: &[u8; BBOX_RECORD]) -> io::Result<BboxRecord> {
    let crc = u32::from_le_bytes(b[32..36].try_into().unwrap());
    if bbox_checksum(id, &b[..32]) != crc {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("bbox record {id}: checksum mismatch"),
        ));
    }
    let f = |i: usize| f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    Ok(BboxRecord {
        lo: Vec3::new(f(0), f(1), f(2)),
        hi: Vec3::new(f(3), f(4), f(5)),
        offset: u64::from_le_bytes(b[24..32].try_into().unwrap()),
    })
}

/// `objects.bin` of the basic layout: each object's box record and geometry record, read
/// together, forward, record by record (seed 000 Algorithms 3.4–3.6: "read object").
pub struct BasicReader {
    pub file: IoFile,
    scratch: Vec<u8>,
    size: u64,
    next_id: u64,
    objects: u64,
}

impl BasicReader {
    pub fn open(dir: &Path, objects: u64, buffer: usize) -> io::Result<BasicReader> {
        let size = std::fs::metadata(dir.join(OBJECTS_FILE))?.len();
        Self::open_codec(dir, objects, buffer, Codec::None, size)
    }

    /// `objects.bin` (or `objects.bin.gz`) holding `size` uncompressed bytes.
    pub fn open_codec(
        dir: &Path,
        objects: u64,
        buffer: usize,
        codec: Codec,
        size: u64,
    ) -> io::Result<BasicReader> {
        let path = dir.join(codec.objects_file());
        let mut file = IoFile::open_codec(&path, buffer, codec)?;
        check_file_header(&mut file, OBJECTS_MAGIC, &path)?;
        Ok(BasicReader {
            file,
            scratch: Vec::new(),
            size,
            next_id: 0,
            objects,
        })
    }

    pub fn rewind(&mut self) -> io::Result<()> {
        self.file.seek_to(FILE_HEADER)?;
        self.next_id = 0;
        Ok(())
    }

    /// The next object: its id and box, its geometry in `out`; `None` after the last.
    pub fn next_record(&mut self, out: &mut ObjectRecord) -> io::Result<Option<(u32, BboxRecord)>> {
        if self.next_id == self.objects {
            return Ok(None);
        }
        let mut b = [0u8; BBOX_RECORD];
        self.file.read_exact(&mut b)?;
        let rec = decode_bbox(self.next_id, &b)?;
        if rec.offset != self.file.position() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "object record {}: geometry offset {} (expected {})",
                    self.next_id,
                    rec.offset,
                    self.file.position()
                ),
            ));
        }
        read_geometry(&mut self.file, self.size, &mut self.scratch, out)?;
        let id = self.next_id as u32;
        self.next_id += 1;
        Ok(Some((id, rec)))
    }
}

/// A store's objects as one forward stream, whatever its layout: (id, box, and whether the
/// geometry was read with it). Split layout with `lazy` reads geometry only on
/// [`SceneReader::load`] (seed 000 §4.2.2, "G"); without `lazy`, and always in the basic layout,
/// every object's geometry is read as the stream passes it.
pub enum SceneReader {
    Split {
        bbox: BboxReader,
        geometry: GeometryReader,
        lazy: bool,
    },
    Basic(BasicReader),
}

impl SceneReader {
    pub fn open(h: &StoreHeader, buffer: usize, lazy: bool) -> io::Result<SceneReader> {
        Ok(match h.layout {
            Layout::Split => SceneReader::Split {
                bbox: BboxReader::open(&h.dir, h.objects, buffer)?,
                geometry: GeometryReader::open(&h.dir, buffer)?,
                lazy,
            },
            Layout::Basic => SceneReader::Basic(BasicReader::open_codec(
                &h.dir,
                h.objects,
                buffer,
                h.codec,
                h.geometry_bytes,
            )?),
        })
    }

    pub fn rewind(&mut self) -> io::Result<()> {
        match self {
            SceneReader::Split { bbox, geometry, .. } => {
                bbox.rewind()?;
                geometry.rewind()
            }
            SceneReader::Basic(b) => b.rewind(),
        }
    }

    /// The next object; `out` holds its geometry when the flag is true.
    pub fn next(&mut self, out: &mut ObjectRecord) -> io::Result<Option<(u32, BboxRecord, bool)>> {
        match self {
            SceneReader::Split {
                bbox,
                geometry,
                lazy,
            } => {
                let Some((id, b)) = bbox.next_record()? else {
                    return Ok(None);
                };
                if !*lazy {
                    geometry.read_at(b.offset, out)?;
                }
                Ok(Some((id, b, !*lazy)))
            }
            SceneReader::Basic(r) => Ok(r.next_record(out)?.map(|(id, b)| (id, b, true))),
        }
    }

    /// Moves the stream to object `id` (not behind the stream): in the split layout one seek in
    /// the bounding-box file, in the basic layout the records before it are read and passed
    /// (a store of the basic layout has no index).
    pub fn skip_to(&mut self, id: u32, out: &mut ObjectRecord) -> io::Result<()> {
        match self {
            SceneReader::Split { bbox, .. } => {
                if (id as u64) < bbox.next_id {
                    return Err(io::Error::other(format!(
                        "object {id} behind the stream (at {})",
                        bbox.next_id
                    )));
                }
                bbox.seek_record(id as u64)
            }
            SceneReader::Basic(r) => {
                while r.next_id < id as u64 {
                    if r.next_record(out)?.is_none() {
                        break;
                    }
                }
                Ok(())
            }
        }
    }

    /// Drops the store's files from the page cache (`cache=cold`).
    pub fn drop_cache(&self) {
        match self {
            SceneReader::Split { bbox, geometry, .. } => {
                bbox.file.drop_cache();
                geometry.file.drop_cache();
            }
            SceneReader::Basic(b) => b.file.drop_cache(),
        }
    }

    /// Reads the geometry of the object `next` just gave without it (forward only).
    pub fn load(&mut self, b: &BboxRecord, out: &mut ObjectRecord) -> io::Result<()> {
        match self {
            SceneReader::Split { geometry, .. } => geometry.read_at(b.offset, out),
            SceneReader::Basic(_) => Ok(()),
        }
    }

    /// Position in the geometry file (split) or in `objects.bin` (basic).
    pub fn position(&self) -> u64 {
        match self {
            SceneReader::Split { geometry, .. } => geometry.file.position(),
            SceneReader::Basic(b) => b.file.position(),
        }
    }

    /// Bytes the reader holds in memory: its file buffers, and for a compressed split store
    /// each file's compressed block and block index.
    pub fn held_bytes(&self) -> u64 {
        match self {
            SceneReader::Split { bbox, geometry, .. } => {
                bbox.file.held_bytes() + geometry.file.held_bytes()
            }
            SceneReader::Basic(b) => b.file.held_bytes(),
        }
    }

    /// The I/O made so far.
    pub fn io(&self) -> IoCounters {
        match self {
            SceneReader::Split { bbox, geometry, .. } => {
                let mut io = bbox.file.io;
                io.add(&geometry.file.io);
                io
            }
            SceneReader::Basic(b) => b.file.io,
        }
    }

    /// The I/O made so far, the counters then zeroed.
    pub fn take_io(&mut self) -> IoCounters {
        let io = self.io();
        match self {
            SceneReader::Split { bbox, geometry, .. } => {
                bbox.file.io = IoCounters::default();
                geometry.file.io = IoCounters::default();
            }
            SceneReader::Basic(b) => b.file.io = IoCounters::default(),
        }
        io
    }
}

/// A little-endian cursor over a record.
struct Cursor<'a>(&'a [u8]);

impl Cursor<'_> {
    fn u8(&mut self) -> Option<u8> {
        let (b, rest) = self.0.split_first()?;
        self.0 = rest;
        Some(*b)
    }
    fn u32(&mut self) -> Option<u32> {
        let b = self.0.get(..4)?;
        self.0 = &self.0[4..];
        Some(u32::from_le_bytes(b.try_into().ok()?))
    }
    fn f32(&mut self) -> Option<f32> {
        self.u32().map(f32::from_bits)
    }
    fn v3(&mut self) -> Option<Vec3> {
        Some(Vec3::new(self.f32()?, self.f32()?, self.f32()?))
    }
}

fn decode_record(b: &[u8], out: &mut ObjectRecord) -> Option<()> {
    let mut c = Cursor(b);
    out.material = c.u32()?;
    out.surface = Some(match c.u8()? {
        0 => Surface::Sphere {
            center: c.v3()?,
            radius: c.f32()?,
        },
        1 => Surface::Cone {
            base: c.v3()?,
            rb: c.f32()?,
            apex: c.v3()?,
            ra: c.f32()?,
        },
        2 => Surface::Flat { normal: c.v3()? },
        3 => Surface::Smooth {
            normals: [c.v3()?, c.v3()?, c.v3()?],
            flat: c.v3()?,
        },
        _ => return None,
    });
    let n = c.u32()?;
    out.prims.clear();
    for _ in 0..n {
        out.prims.push(match c.u8()? {
            0 => Prim::Sphere {
                center: c.v3()?,
                radius: c.f32()?,
            },
            1 => Prim::Cone {
                base: c.v3()?,
                base_radius: c.f32()?,
                apex: c.v3()?,
                apex_radius: c.f32()?,
            },
            2 => Prim::Triangle([c.v3()?, c.v3()?, c.v3()?]),
            _ => return None,
        });
    }
    // The scene rules (rtbench_scenes::validate), on what was stored.
    let max = validate::MAX_COORD as f32;
    let point = |p: Vec3| p.is_finite() && p.abs().max_element() <= max;
    let ok = out.prims.iter().all(|p| match *p {
        Prim::Sphere { center, radius } => point(center) && radius > 0.0 && radius <= max,
        Prim::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => {
            point(base)
                && point(apex)
                && (0.0..=max).contains(&base_radius)
                && (0.0..=max).contains(&apex_radius)
        }
        Prim::Triangle(t) => t.iter().all(|&v| point(v)),
    });
    (ok && c.0.is_empty()).then_some(())
}
