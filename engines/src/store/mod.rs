//! The on-disk scene store of the breadth-first engine (seed 000 §4.2.1, "S"): a scene written
//! by streaming from its generator, never held, as three files in one directory.
//!
//! - `header.json`: format version, name, camera, background, lights, materials, object and
//!   primitive counts, and the bounds of the prepared primitives. Small: no per-object data.
//! - `bbox.bin`: 16-byte header (`RTBBOX\0\0`, u32 version, u32 record size = 32), then one
//!   record per object in stream order: its bounding box (6 × f32: min x y z, max x y z, of
//!   its prepared `f32` primitives) and the byte offset (u64) of its record in `geometry.bin`.
//! - `geometry.bin`: 16-byte header (`RTGEOM\0\0`, u32 version, u32 0), then one variable-size
//!   record per object, in the same order: u32 record bytes (this field included), u32
//!   material index, the [`Surface`] (u8 kind, then f32s), u32 primitive count, and each
//!   prepared primitive (u8 kind, then its f32s: sphere 4, cone 8, triangle 9).
//!
//! All numbers little-endian. The object id is the record order (0-based), which is also the
//! scene's object index: hits name the same object in-memory and from the store. The
//! primitives are exactly what [`crate::geometry::prims_of`] makes (same triangulation), so the
//! breadth-first engine tests the same `f32` triangles as every other engine.

mod io;
mod read;
mod surface;
mod write;

pub use io::{IoCounters, IoFile};
pub use read::{BboxReader, BboxRecord, GeometryReader, ObjectRecord, StoreHeader};
pub use surface::Surface;
pub use write::StoreWriter;

/// Format version written in all three files; readers refuse any other.
pub const VERSION: u32 = 1;
pub const BBOX_MAGIC: &[u8; 8] = b"RTBBOX\0\0";
pub const GEOMETRY_MAGIC: &[u8; 8] = b"RTGEOM\0\0";
/// Bytes of a bbox record: 6 × f32 + u64.
pub const BBOX_RECORD: usize = 32;
/// Bytes of each file's header.
pub const FILE_HEADER: u64 = 16;

pub const HEADER_FILE: &str = "header.json";
pub const BBOX_FILE: &str = "bbox.bin";
pub const GEOMETRY_FILE: &str = "geometry.bin";

#[cfg(test)]
mod tests;
