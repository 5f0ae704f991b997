//! `rtbench scene list | gen | store | stats`.

use crate::error::{input, Result};
use crate::output::{print_json, write_atomic};
use crate::source::Source;
use rtbench_engines::store::{Codec, Layout, StoreHeader, StoreWriter};
use rtbench_scenes::Sink;
use std::io::Write;

use rtbench_scenes::nff::NffWriter;
use rtbench_scenes::spd::Program;
use rtbench_scenes::CountingSink;
use serde_json::json;
use std::path::Path;

pub fn list(as_json: bool) -> Result<()> {
    // The room is seed 003's stand-in scene (`room` = room8, `roomN` at N patches per metre).
    let room_ppm = rtbench_scenes::room::DEFAULT_PPM;
    let room_objects = {
        let mut c = CountingSink::default();
        rtbench_scenes::room::generate(room_ppm, &mut c)
            .map(|()| c.counts.sphere + c.counts.cone + c.counts.polygon + c.counts.patch)
            .ok()
    };
    let room_about = "seed 003's room stand-in (Yamauchi 1997, Table 6): walls, furniture, two \
                      light panels, mirror quadrics; roomN for N patches per metre";
    let files = "OBJ, PLY, glTF/GLB and NFF files are scenes too: give their path wherever a \
                 program name goes (--scene, --scenes, scene stats|gen|store)";
    if as_json {
        let mut v: Vec<_> = Program::ALL
            .iter()
            .map(|p| {
                json!({"name": p.name(), "standard_sf": p.standard_sf(),
                       "objects_at_standard_sf": p.object_count(p.standard_sf()),
                       "description": p.description()})
            })
            .collect();
        v.push(
            json!({"name": "room", "standard_sf": null, "patches_per_metre": room_ppm,
                      "objects_at_standard_sf": room_objects, "description": room_about}),
        );
        // Still a list of scenes (the contract); the note on files is for people.
        print_json(&json!(v));
    } else {
        println!(
            "{:<10} {:>4} {:>10}  description",
            "program", "sf", "objects"
        );
        for p in Program::ALL {
            let n = p
                .object_count(p.standard_sf())
                .map(|n| n.to_string())
                .unwrap_or_else(|| "?".into());
            println!(
                "{:<10} {:>4} {:>10}  {}",
                p.name(),
                p.standard_sf(),
                n,
                p.description()
            );
        }
        let n = room_objects.map_or_else(|| "?".into(), |n| n.to_string());
        println!("{:<10} {:>4} {:>10}  {room_about}", "room", "-", n);
        println!("\n{files}.");
    }
    Ok(())
}

/// `--max-bytes`: bytes, at least 1.
pub fn max_bytes(s: &str) -> Result<u64> {
    match super::runs::parse_bytes(s) {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(input(format!(
            "--max-bytes '{s}': expected bytes, e.g. 512M or 8GiB"
        ))),
    }
}

/// Refuses up front a program's scene whose output the census puts over `max`.
pub fn check_output_bound(
    src: &Source,
    max: u64,
    what: &str,
    per_object: u64,
    per_vertex: u64,
) -> Result<()> {
    let Source::Program(p, o) = src else {
        return Ok(());
    };
    let c = crate::workload::footprint::Census::of(*p, o);
    let at_least = c
        .objects
        .saturating_mul(per_object)
        .saturating_add(c.vertices.saturating_mul(per_vertex));
    if at_least > max {
        return Err(input(format!(
            "{}: {} objects make about {:.1} GB of {what}, past --max-bytes {max} (raise it to write them)",
            src.label(),
            c.objects,
            at_least as f64 / 1e9
        )));
    }
    Ok(())
}

/// A writer that fails once more than `max` bytes went through it.
struct Bounded<W> {
    inner: W,
    written: u64,
    max: u64,
}

impl<W: Write> Write for Bounded<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.written + buf.len() as u64 > self.max {
            return Err(std::io::Error::other(format!(
                "past --max-bytes {} (raise it to write more)",
                self.max
            )));
        }
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Lower bounds of NFF bytes per object and per polygon vertex (a sphere line; a vertex line).
const NFF_PER_OBJECT: u64 = 24;
const NFF_PER_VERTEX: u64 = 20;

pub fn gen(src: &Source, out: Option<&Path>, max: u64) -> Result<()> {
    check_output_bound(src, max, "NFF", NFF_PER_OBJECT, NFF_PER_VERTEX)?;
    match out {
        None => {
            let stdout = std::io::stdout();
            let mut w = NffWriter::new(Bounded {
                inner: std::io::BufWriter::with_capacity(1 << 20, stdout.lock()),
                written: 0,
                max,
            });
            src.stream(&mut w)?;
            w.finish()
                .map_err(|e| input(format!("stdout: cannot write: {e}")))?;
        }
        Some(path) => {
            let start = std::time::Instant::now();
            let mut result = Ok(());
            let mut bytes = 0;
            write_atomic(path, |f| {
                let mut w = NffWriter::new(Bounded {
                    inner: f,
                    written: 0,
                    max,
                });
                result = src.stream(&mut w);
                bytes = w.bytes();
                w.finish().map(|_| ())
            })?;
            result?;
            let secs = start.elapsed().as_secs_f64();
            eprintln!(
                "wrote {} ({:.1} MB) in {:.2} s, {:.1} MB/s, peak RSS {:.1} MiB",
                path.display(),
                bytes as f64 / 1e6,
                secs,
                bytes as f64 / 1e6 / secs.max(1e-9),
                crate::measure::rss::peak_rss_bytes().unwrap_or(0) as f64 / 1048576.0
            );
        }
    }
    Ok(())
}

/// Lower bounds of store bytes per object (box record, geometry record) and per vertex.
pub const STORE_PER_OBJECT: u64 = 36 + 17;
pub const STORE_PER_VERTEX: u64 = 12;

/// A store being written that stops taking objects once its records pass `max` bytes.
pub struct CappedStore<'a, S: Sink> {
    pub w: &'a mut S,
    pub max: u64,
    pub over: bool,
}

impl<S: Sink + StoreBytes> Sink for CappedStore<'_, S> {
    fn background(&mut self, c: glam::DVec3) {
        self.w.background(c)
    }
    fn view(&mut self, v: &rtbench_scenes::View) {
        self.w.view(v)
    }
    fn light(&mut self, l: &rtbench_scenes::Light) {
        self.w.light(l)
    }
    fn material(&mut self, m: &rtbench_scenes::Material) {
        self.w.material(m)
    }
    fn shape(&mut self, s: rtbench_scenes::ShapeRef<'_>) {
        if self.over || self.w.record_bytes() > self.max {
            self.over = true;
            return;
        }
        self.w.shape(s)
    }
}

/// Bytes of records a store writer has taken so far.
pub trait StoreBytes {
    fn record_bytes(&self) -> u64;
}

impl StoreBytes for StoreWriter {
    fn record_bytes(&self) -> u64 {
        self.written()
    }
}

/// `rtbench scene store`: streams the scene into a store directory (seed 000's "S"; format in
/// `rtbench_engines::store`). Written into a temporary directory `.NAME.tmp-…` beside `out` and
/// renamed when complete, so a failure (bad input, full disk) leaves nothing behind.
pub fn store(
    src: &Source,
    out: &Path,
    layout: &str,
    compress: &str,
    hierarchy: bool,
    max: u64,
    as_json: bool,
) -> Result<()> {
    check_output_bound(
        src,
        max,
        "store records",
        STORE_PER_OBJECT,
        STORE_PER_VERTEX,
    )?;
    let layout: Layout = layout
        .parse()
        .map_err(|e| input(format!("--layout {layout}: {e}")))?;
    let codec = crate::workload::out_of_core::parse_codec(compress)
        .map_err(|e| input(format!("--compress {compress}: {e}")))?;
    if matches!(codec, Codec::Gzip(_)) && layout == Layout::Split {
        return Err(input(format!(
            "--compress {compress}: a split store is read with seeks, so it is compressed as zstd blocks: use --compress zstd[:LEVEL] or --layout basic"
        )));
    }
    if hierarchy && layout != Layout::Split {
        return Err(input(
            "--hierarchy: the bounding-box hierarchy indexes bbox.bin, so it needs --layout split",
        ));
    }
    let start = std::time::Instant::now();
    if out.exists()
        && std::fs::read_dir(out)
            .map(|mut d| d.next().is_some())
            .unwrap_or(true)
    {
        return Err(input(format!(
            "{}: exists and is not an empty directory",
            out.display()
        )));
    }
    let name = out
        .file_name()
        .ok_or_else(|| input(format!("{}: not a directory name", out.display())))?;
    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent)
        .map_err(|e| input(format!("{}: cannot write: {e}", out.display())))?;
    // Removed when this returns early (an error) or on a signal; kept and renamed when whole.
    let tmp_dir = tempfile::Builder::new()
        .prefix(&format!(".{}.tmp-", name.to_string_lossy()))
        .tempdir_in(parent)
        .map_err(|e| input(format!("{}: cannot write: {e}", out.display())))?;
    let tmp = tmp_dir.path().to_path_buf();
    let cleanup = |e: String| {
        let _ = std::fs::remove_dir_all(&tmp);
        input(e)
    };
    let _interrupted = crate::output::interrupt::remove_dir_on_signal(&tmp);
    let mut w = StoreWriter::create_with(&tmp, &src.label(), layout, codec)
        .map_err(|e| cleanup(format!("{}: cannot write: {e}", out.display())))?;
    let mut capped = CappedStore {
        w: &mut w,
        max,
        over: false,
    };
    if let Err(e) = src.stream(&mut capped) {
        let _ = std::fs::remove_dir_all(&tmp);
        return Err(e);
    }
    if capped.over {
        drop(w);
        return Err(cleanup(format!(
            "{}: the store passed --max-bytes {max} (raise it to write more)",
            out.display()
        )));
    }
    let mut io = w
        .finish()
        .map_err(|e| cleanup(format!("{}: cannot write: {e}", out.display())))?;
    let mut levels = Vec::new();
    if hierarchy {
        let built = StoreHeader::read(&tmp)
            .and_then(|h| {
                let c = rtbench_engines::store::Constants::thesis(&h.name);
                rtbench_engines::store::Hierarchy::build(&h, c, 1 << 16)
            })
            .map_err(|e| {
                cleanup(format!(
                    "{}: cannot build the hierarchy: {e}",
                    out.display()
                ))
            })?;
        io.add(&built.io);
        levels = built.levels;
    }
    if out.exists() {
        let _ = std::fs::remove_dir(out);
    }
    let tmp = tmp_dir.keep();
    std::fs::rename(&tmp, out)
        .map_err(|e| cleanup(format!("{}: cannot rename into place: {e}", out.display())))?;
    let header = StoreHeader::read(out).map_err(|e| input(e.to_string()))?;
    if header.objects == 0 {
        let _ = std::fs::remove_dir_all(out);
        return Err(input(format!("{}: the scene has no objects", src.label())));
    }
    let secs = start.elapsed().as_secs_f64();
    let v = json!({
        "store": out.display().to_string(),
        "layout": layout.name(),
        "compression": codec.name(),
        "objects_bytes": header.geometry_bytes + header.bbox_bytes,
        "stored_bytes": header.disk_bytes(),
        "scene": src.label(),
        "objects": header.objects,
        "primitives": header.primitives,
        "hierarchy_levels": levels,
        "bytes_written": io.bytes_written,
        "write_calls": io.write_calls,
        "time_s": secs,
        "peak_rss_bytes": crate::measure::rss::peak_rss_bytes(),
    });
    if as_json {
        print_json(&v);
    } else {
        eprintln!(
            "wrote {} ({} objects, {} primitives, {:.1} MB) in {:.2} s, peak RSS {:.1} MiB",
            out.display(),
            header.objects,
            header.primitives,
            io.bytes_written as f64 / 1e6,
            secs,
            crate::measure::rss::peak_rss_bytes().unwrap_or(0) as f64 / 1048576.0
        );
    }
    Ok(())
}

pub fn stats(src: &Source, as_json: bool) -> Result<()> {
    let mut c = CountingSink::default();
    src.stream(&mut c)?;
    if c.counts.objects() == 0 {
        return Err(input(format!("{}: the scene has no objects", src.label())));
    }
    let bounds = c
        .bounds
        .map(|b| json!([[b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z]]));
    let program = match src {
        Source::Program(p, _) => json!(p.name()),
        Source::File(f) => json!(f.display().to_string()),
        Source::Room(ppm) => json!(format!("room{ppm}")),
    };
    let v = json!({
        "program": program,
        "sf": src.size_factor(),
        "counts": c.counts,
        "objects": c.counts.objects(),
        "lights": c.lights,
        "materials": c.materials,
        "bounds": bounds,
        // Shows that counting streamed: a materialised scene would show here.
        "peak_rss_bytes": crate::measure::rss::peak_rss_bytes(),
    });
    if as_json {
        print_json(&v);
    } else {
        let k = &c.counts;
        println!("scene      {}", src.label());
        println!("objects    {}", k.objects());
        println!(
            "  spheres  {}\n  cones    {}\n  polygons {}\n  patches  {}",
            k.sphere, k.cone, k.polygon, k.patch
        );
        println!("triangles  {}", k.triangles);
        println!("lights     {}", c.lights);
        if let Some(b) = c.bounds {
            println!(
                "bounds     [{} {} {}] .. [{} {} {}]",
                b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
            );
        }
    }
    Ok(())
}

/// `rtbench scene stats … --view FILE`: the objects and those whose box reaches into the view's
/// frustum ([`crate::workload::frustum`]), streamed from the generator.
pub fn view_stats(src: &Source, file: &Path, as_json: bool) -> Result<()> {
    let vf = crate::workload::view_file::ViewFile::read(file)?;
    let start = std::time::Instant::now();
    let mut c = crate::workload::frustum::ViewCount::new(&vf.view, 512);
    src.stream(&mut c)?;
    if c.objects == 0 {
        return Err(input(format!("{}: the scene has no objects", src.label())));
    }
    let v = json!({
        "scene": src.label(),
        "view": file.display().to_string(),
        "objects": c.objects,
        "objects_in_view": c.in_view,
        "fraction_in_view": c.in_view as f64 / c.objects as f64,
        "time_s": start.elapsed().as_secs_f64(),
    });
    if as_json {
        print_json(&v);
    } else {
        println!(
            "{}: {} of {} objects in view ({:.4}%) under {}",
            src.label(),
            c.in_view,
            c.objects,
            100.0 * c.in_view as f64 / c.objects as f64,
            file.display()
        );
    }
    Ok(())
}
