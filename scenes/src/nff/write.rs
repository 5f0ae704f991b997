//! NFF writer: prints records exactly as SPD's libpr*.c do for `OUTPUT_NFF` (`%g` numbers).

use super::cfmt::write_g;
use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use glam::DVec3;
use std::io::{self, Write};

/// A [`Sink`] that prints NFF. Output is buffered per record; the first I/O error stops
/// writing and is returned by [`NffWriter::finish`].
pub struct NffWriter<W: Write> {
    out: W,
    line: Vec<u8>,
    error: Option<io::Error>,
    bytes: u64,
}

impl<W: Write> NffWriter<W> {
    pub fn new(out: W) -> Self {
        NffWriter {
            out,
            line: Vec::with_capacity(256),
            error: None,
            bytes: 0,
        }
    }

    /// Bytes written so far.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Flushes and returns the writer, or the first I/O error met.
    pub fn finish(mut self) -> io::Result<W> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.out.flush()?;
        Ok(self.out)
    }

    fn num(&mut self, x: f64) {
        write_g(&mut self.line, x);
    }

    fn vec3(&mut self, v: DVec3) {
        self.num(v.x);
        self.line.push(b' ');
        self.num(v.y);
        self.line.push(b' ');
        self.num(v.z);
    }

    fn flush_line(&mut self) {
        if self.error.is_none() {
            if let Err(e) = self.out.write_all(&self.line) {
                self.error = Some(e);
            } else {
                self.bytes += self.line.len() as u64;
            }
        }
        self.line.clear();
    }
}

impl<W: Write> Sink for NffWriter<W> {
    fn background(&mut self, color: DVec3) {
        self.line.extend_from_slice(b"b ");
        self.vec3(color);
        self.line.push(b'\n');
        self.flush_line();
    }

    fn view(&mut self, v: &View) {
        self.line.extend_from_slice(b"v\nfrom ");
        self.vec3(v.from);
        self.line.extend_from_slice(b"\nat ");
        self.vec3(v.at);
        self.line.extend_from_slice(b"\nup ");
        self.vec3(v.up);
        self.line.extend_from_slice(b"\nangle ");
        self.num(v.angle);
        self.line.extend_from_slice(b"\nhither ");
        self.num(v.hither);
        let _ = writeln!(
            self.line,
            "\nresolution {} {}",
            v.resolution[0], v.resolution[1]
        );
        self.flush_line();
    }

    fn light(&mut self, l: &Light) {
        self.line.extend_from_slice(b"l ");
        self.vec3(l.position);
        if let Some(c) = l.color {
            self.line.push(b' ');
            self.vec3(c);
        }
        self.line.push(b'\n');
        self.flush_line();
    }

    fn material(&mut self, m: &Material) {
        self.line.extend_from_slice(b"f ");
        self.vec3(m.color);
        for x in [m.kd, m.ks, m.shine, m.t, m.ior] {
            self.line.push(b' ');
            self.num(x);
        }
        self.line.push(b'\n');
        self.flush_line();
    }

    fn shape(&mut self, shape: ShapeRef<'_>) {
        match shape {
            ShapeRef::Sphere { center, radius } => {
                self.line.extend_from_slice(b"s ");
                self.vec3(center);
                self.line.push(b' ');
                self.num(radius);
                self.line.push(b'\n');
            }
            ShapeRef::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                self.line.extend_from_slice(b"c ");
                self.vec3(base);
                self.line.push(b' ');
                self.num(base_radius);
                self.line.push(b' ');
                self.vec3(apex);
                self.line.push(b' ');
                self.num(apex_radius);
                self.line.push(b'\n');
            }
            ShapeRef::Polygon(v) => {
                let _ = writeln!(self.line, "p {}", v.len());
                for p in v {
                    self.vec3(*p);
                    self.line.push(b'\n');
                }
            }
            ShapeRef::Patch { vertices, normals } => {
                let _ = writeln!(self.line, "pp {}", vertices.len());
                for (p, n) in vertices.iter().zip(normals) {
                    self.vec3(*p);
                    self.line.push(b' ');
                    self.vec3(*n);
                    self.line.push(b'\n');
                }
            }
        }
        self.flush_line();
    }
}
