//! Reading a store: its header, the bounding-box file as a forward stream, and the geometry
//! file with forward-only seeks (seed 000 §4.2.2, "G": geometry is read only when needed).

use super::io::IoFile;
use super::{
    Surface, BBOX_FILE, BBOX_MAGIC, BBOX_RECORD, FILE_HEADER, GEOMETRY_FILE, GEOMETRY_MAGIC,
    HEADER_FILE, VERSION,
};
use crate::geometry::Prim;
use glam::{DVec3, Vec3};
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
        let text = std::fs::read_to_string(&path)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        let v: Value = serde_json::from_str(&text).map_err(|e| bad(dir, e))?;
        if v["format"] != "rtbench-store" {
            return Err(bad(dir, "header.json has no \"format\": \"rtbench-store\""));
        }
        if v["version"].as_u64() != Some(VERSION as u64) {
            return Err(bad(
                dir,
                format!("version {} (this rtbench reads {VERSION})", v["version"]),
            ));
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
                res[0].as_u64().unwrap_or(512) as u32,
                res[1].as_u64().unwrap_or(512) as u32,
            ],
        };
        let mut lights = Vec::new();
        for l in v["lights"].as_array().into_iter().flatten() {
            lights.push(Light {
                position: d3(&l["position"])?,
                color: if l["color"].is_null() {
                    None
                } else {
                    Some(d3(&l["color"])?)
                },
            });
        }
        let mut materials = Vec::new();
        for m in v["materials"].as_array().into_iter().flatten() {
            materials.push(Material {
                color: d3(&m["color"])?,
                kd: num(m, "kd")?,
                ks: num(m, "ks")?,
                shine: num(m, "shine")?,
                t: num(m, "t")?,
                ior: num(m, "ior")?,
            });
        }
        let b = d3(&v["bounds"][0])?.as_vec3();
        let c = d3(&v["bounds"][1])?.as_vec3();
        Ok(StoreHeader {
            dir: dir.to_path_buf(),
            name: v["name"].as_str().unwrap_or("").to_string(),
            objects: num(&v, "objects")? as u64,
            primitives: num(&v, "primitives")? as u64,
            bounds: [b, c],
            background: d3(&v["background"])?,
            view,
            lights,
            materials,
        })
    }
}

fn check_file_header(f: &mut IoFile, magic: &[u8; 8], path: &Path) -> io::Result<()> {
    let mut h = [0u8; FILE_HEADER as usize];
    f.read_exact(&mut h)
        .map_err(|_| bad(path, "file shorter than its header"))?;
    if &h[..8] != magic {
        return Err(bad(path, "wrong magic"));
    }
    let version = u32::from_le_bytes(h[8..12].try_into().unwrap());
    if version != VERSION {
        return Err(bad(path, format!("version {version}")));
    }
    Ok(())
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
        let path = dir.join(BBOX_FILE);
        let mut file = IoFile::open(&path, buffer)?;
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

    /// The next (object id, record), or `None` after the last.
    pub fn next_record(&mut self) -> io::Result<Option<(u32, BboxRecord)>> {
        if self.next_id == self.objects {
            return Ok(None);
        }
        let mut b = [0u8; BBOX_RECORD];
        self.file.read_exact(&mut b)?;
        let f = |i: usize| f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
        let id = self.next_id as u32;
        self.next_id += 1;
        Ok(Some((
            id,
            BboxRecord {
                lo: Vec3::new(f(0), f(1), f(2)),
                hi: Vec3::new(f(3), f(4), f(5)),
                offset: u64::from_le_bytes(b[24..32].try_into().unwrap()),
            },
        )))
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
}

impl GeometryReader {
    pub fn open(dir: &Path, buffer: usize) -> io::Result<GeometryReader> {
        let path = dir.join(GEOMETRY_FILE);
        let mut file = IoFile::open(&path, buffer)?;
        check_file_header(&mut file, GEOMETRY_MAGIC, &path)?;
        Ok(GeometryReader {
            file,
            scratch: Vec::new(),
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
        let mut len = [0u8; 4];
        self.file.read_exact(&mut len)?;
        let len = u32::from_le_bytes(len) as usize;
        if len < 13 {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                "geometry record too short",
            ));
        }
        self.scratch.resize(len - 4, 0);
        self.file.read_exact(&mut self.scratch)?;
        decode_record(&self.scratch, out).ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("geometry record at {offset} is malformed"),
            )
        })
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
    c.0.is_empty().then_some(())
}
