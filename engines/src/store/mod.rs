//! The on-disk scene store of the breadth-first engine (seed 000 §4.2.1, "S"): a scene written
//! by streaming from its generator, never held, as three files in one directory.
//!
//! - `header.json`: format version, name, camera, background, lights (at most [`MAX_LIGHTS`]),
//!   object and primitive counts, the bounds of the prepared primitives, the byte sizes of the
//!   binary files (`bbox_bytes`, `geometry_bytes`), and the material table's count, size and
//!   CRC-32 (`materials`, `materials_bytes`, `materials_crc`). Bounded (at most
//!   `MAX_HEADER_BYTES`) whatever the object count: no per-object and no per-material data.
//! - `materials.bin`: 16-byte header (magic `RTMATS\0\0`, u32 version, u32 count), then one
//!   64-byte record per *distinct* material, in order of first use: 8 × f64 (color r g b, kd, ks,
//!   shine, t, ior). The writer shares one entry among bit-equal materials, so the table is the
//!   scene's palette (rings: 7 entries, where the generator emits one material per ring; gears:
//!   one per gear). Each geometry record's material index points into it. Written before
//!   header.json, whose `materials_crc` vouches for its bytes.
//! - `bbox.bin`: 16-byte header, then one 36-byte record per object in stream order: its
//!   bounding box (6 × f32: min x y z, max x y z, of its prepared `f32` primitives), the byte
//!   offset (u64) of its record in `geometry.bin`, and a CRC-32 (u32) of the object id (u64)
//!   followed by the record's first 32 bytes.
//! - `geometry.bin`: 16-byte header, then one variable-size record per object, in the same
//!   order: u32 record bytes (this field and the checksum included), u32 material index, the
//!   [`Surface`] (u8 kind, then f32s), u32 primitive count, each prepared primitive (u8 kind,
//!   then its f32s: sphere 4, cone 8, triangle 9), and a CRC-32 (u32) of all the record's bytes
//!   before it.
//! - Each binary file's header: the magic (`RTBBOX\0\0`, `RTGEOM\0\0`), u32 version, and the
//!   CRC-32 (u32) of `header.json`'s bytes, which ties the header to the files.
//!
//! The *basic* layout (seed 000 chapter 3, the thesis's `sray` before Chapter 4's "S") holds the
//! same records in one file, `objects.bin` (magic `RTOBJS\0\0`): per object its 36-byte box record
//! (whose offset field points at the geometry record right after it) followed by its geometry
//! record, so the file is read whole and in order on every sweep. `header.json` then says
//! `"layout": "basic"` and gives `objects_bytes` in place of `bbox_bytes` and `geometry_bytes`.
//! A basic store may be gzip-compressed (seed 000 §3.4, Table 3.3): `objects.bin.gz` holds the
//! same bytes, `header.json` adds `"compression": "gzip"` and `stored_bytes` (the compressed
//! size; `objects_bytes` stays the uncompressed one, and record offsets are uncompressed
//! offsets). Or zstd-compressed: `objects.bin.zst`, `"compression": "zstd"` (zstd is offered
//! beside the thesis's gzip: it compresses several times faster).
//! The compressed file's header cannot carry the checksum of `header.json` (it is written,
//! compressed, before the header is known), so `header.crc` does: 16 bytes, magic `RTHCRC\0\0`,
//! u32 version, the CRC-32 of `header.json`, written right after it; a compressed basic store
//! without it is refused. The codec's own checksum (gzip's CRC-32; zstd's frame checksum) and
//! the records' checksums guard the data's bytes.
//! [`SceneReader`] reads either layout as one stream of (id, box, geometry when read).
//!
//! A store too large to write in one sitting is written in segments ([`segments`]): while it
//! is being written its directory holds `segments.json` and no `header.json`.
//!
//! A split store may carry a bounding-box hierarchy (`bbox-K.bin`, `hierarchy.json`; seed 000
//! §4.2.2 "B"): see [`hierarchy`].
//!
//! All numbers little-endian; CRC-32 is IEEE's (crate `crc32fast`). Reading checks what it can
//! before trusting it: [`StoreHeader::read`] the header's checksum, the files' sizes against the
//! header and the object count against the size of `bbox.bin`, and every value against the scene
//! rules (`rtbench_scenes::validate`); each record read is checked against its checksum, and a
//! record length is checked against the file before anything is allocated for it;
//! [`StoreHeader::verify`] reads the whole store once and checks every record, that the records
//! tile `geometry.bin` exactly and that counts and bounds agree with the header.
//!
//! The object id is the record order (0-based), which is also the scene's object index: hits
//! name the same object in-memory and from the store. The primitives are exactly what
//! [`crate::geometry::prims_of`] makes (same triangulation), so the breadth-first engine tests
//! the same `f32` triangles as every other engine.

pub mod blocks;
pub mod hierarchy;
mod io;
mod read;
pub mod segments;
mod surface;
mod write;

pub use hierarchy::{Constants, Hierarchy, LevelReader, NodeRecord};
pub use io::{Codec, IoCounters, IoFile};
pub use read::{
    BasicReader, BboxReader, BboxRecord, GeometryReader, ObjectRecord, SceneReader, StoreHeader,
};
pub use segments::{Outcome, SegmentLog, SegmentedWriter, SEGMENTS_FILE};
pub use surface::Surface;
pub use write::{FileState, StoreWriter, WriteState};

/// Writes `bytes` to `path` whole or not at all: into a temporary file beside it (`tempfile`),
/// synced, then renamed over it, so a reader or a resumed run never sees half a record.
pub(crate) fn write_atomic(path: &std::path::Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_data()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Format version written in every file; readers refuse any other (2: checksums; 3: the material
/// table moved out of header.json into `materials.bin`, so that the header stays small at 10^9
/// objects).
pub const VERSION: u32 = 3;
pub const BBOX_MAGIC: &[u8; 8] = b"RTBBOX\0\0";
pub const GEOMETRY_MAGIC: &[u8; 8] = b"RTGEOM\0\0";
/// Bytes of a bbox record: 6 × f32 + u64 + u32 checksum.
pub const BBOX_RECORD: usize = 36;
/// Smallest geometry record: length, material, a surface kind byte, the primitive count and the
/// checksum.
pub const MIN_GEOMETRY_RECORD: usize = 17;
/// Bytes of each file's header.
pub const FILE_HEADER: u64 = 16;

pub const OBJECTS_MAGIC: &[u8; 8] = b"RTOBJS\0\0";
pub const MATERIALS_MAGIC: &[u8; 8] = b"RTMATS\0\0";
pub const HEADER_CRC_MAGIC: &[u8; 8] = b"RTHCRC\0\0";
/// Bytes of a material record: 8 × f64.
pub const MATERIAL_RECORD: usize = 64;
/// Most lights a store holds (they stay in header.json, whose size this bounds).
pub const MAX_LIGHTS: usize = 4096;

/// How a store lays its records out on disk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// `objects.bin`: each object's box and geometry together, one sequential file (Ch.3).
    Basic,
    /// `bbox.bin` and `geometry.bin` apart (Ch.4's "S").
    Split,
}

impl Layout {
    pub fn name(self) -> &'static str {
        match self {
            Layout::Basic => "basic",
            Layout::Split => "split",
        }
    }
}

impl std::str::FromStr for Layout {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "basic" => Ok(Layout::Basic),
            "split" => Ok(Layout::Split),
            _ => Err("expected basic or split".into()),
        }
    }
}

pub const HEADER_FILE: &str = "header.json";
pub const OBJECTS_FILE: &str = "objects.bin";
/// `objects.bin` gzip-compressed (basic layout only: it is read strictly forward, §3.4).
pub const OBJECTS_FILE_GZ: &str = "objects.bin.gz";
/// `objects.bin` zstd-compressed (the same, beside the thesis's gzip).
pub const OBJECTS_FILE_ZST: &str = "objects.bin.zst";
pub const BBOX_FILE: &str = "bbox.bin";
pub const GEOMETRY_FILE: &str = "geometry.bin";
/// The block indexes of a compressed split store ([`blocks`]; the data files are
/// `bbox.bin.zst` and `geometry.bin.zst`).
pub const BBOX_INDEX: &str = "bbox.bin.idx";
pub const GEOMETRY_INDEX: &str = "geometry.bin.idx";
pub const MATERIALS_FILE: &str = "materials.bin";
/// The checksum of `header.json` of a compressed basic store (module docs).
pub const HEADER_CRC_FILE: &str = "header.crc";

#[cfg(test)]
mod blocks_tests;
#[cfg(test)]
pub(crate) mod tests;
