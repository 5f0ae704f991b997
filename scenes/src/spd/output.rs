//! The SPD library's output layer (`lib_output_*` of libpr1.c, libpr2.c, libpr3.c, libply.c and the
//! transform stack of libtx.c), for the NFF format only. Generators call these exactly where the C
//! programs call the `lib_` functions; the records that NFF would print go to a [`Sink`].
//!
//! With `OUTPUT_PATCHES` (`-t`), curved primitives are tessellated here (see `tessellate.rs`);
//! plain polygons are printed as they are, as the C library does.

use super::tessellate;
use super::vec::{self, Coord3, Coord4, Matrix};
use crate::model::{Light, Material, ShapeRef, View};
use crate::sink::Sink;
use glam::DVec3;

/// SPD's `EPSILON2` (def.h, non-Mac value 1e-6): adjacent polygon vertices closer than this
/// are merged. (1e-7 / 1e-15 are the Mac-only values of def.h.)
pub const EPSILON2: f64 = vec::EPSILON2;
/// SPD's `EPSILON` (def.h, non-Mac value 1e-8), the `lib_tx_active` tolerance.
pub const EPSILON: f64 = vec::EPSILON;

/// `OUTPUT_CURVES` (true curves, `-r 1` default) or `OUTPUT_PATCHES` (`-t`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveFormat {
    Curves,
    Patches,
}

pub(crate) fn d3(c: &[f64]) -> DVec3 {
    DVec3::new(c[0], c[1], c[2])
}

/// The state the C library keeps in globals: output format, polygonalization, transform stack.
pub struct Output<'s> {
    sink: &'s mut dyn Sink,
    /// The format the generator asked for (`output_format` in the C programs).
    pub curve_format: CurveFormat,
    /// `gU_resolution`, `gV_resolution` (OUTPUT_RESOLUTION = 3 by default, `-t N` sets both).
    pub u_resolution: u32,
    pub v_resolution: u32,
    current_tx: Matrix,
    tx_stack: Vec<Matrix>,
    // Scratch buffers, so a polygon costs no allocation.
    verts: Vec<DVec3>,
    norms: Vec<DVec3>,
    scratch: Vec<Coord3>,
}

impl<'s> Output<'s> {
    pub fn new(sink: &'s mut dyn Sink, curve_format: CurveFormat, resolution: u32) -> Output<'s> {
        Output {
            sink,
            curve_format,
            u_resolution: resolution,
            v_resolution: resolution,
            current_tx: vec::identity_matrix(),
            tx_stack: Vec::new(),
            verts: Vec::new(),
            norms: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// `lib_set_polygonalization`.
    pub fn set_polygonalization(&mut self, u: u32, v: u32) {
        self.u_resolution = u;
        self.v_resolution = v;
    }

    /// `lib_output_background_color`.
    pub fn background(&mut self, color: Coord3) {
        self.sink.background(d3(&color));
    }

    /// `lib_output_viewpoint` (aspect is not printed by NFF).
    #[allow(clippy::too_many_arguments)]
    pub fn viewpoint(
        &mut self,
        from: Coord3,
        at: Coord3,
        up: Coord3,
        fov_angle: f64,
        _aspect: f64,
        hither: f64,
        resx: u32,
        resy: u32,
    ) {
        self.sink.view(&View {
            from: d3(&from),
            at: d3(&at),
            up: d3(&up),
            angle: fov_angle,
            hither,
            resolution: [resx, resy],
        });
    }

    /// `lib_output_light`: `center[3]` is the intensity, which NFF does not print. A light is
    /// moved by the current transform (as a vector, as libpr1.c does).
    pub fn light(&mut self, center: Coord4) {
        let mut p = [center[0], center[1], center[2]];
        if self.tx_active() {
            p = vec::transform_vector(&p, &self.current_tx);
        }
        self.sink.light(&Light {
            position: d3(&p),
            color: None,
        });
    }

    /// `lib_output_color(name, color, ka, kd, ks, ks_spec, ang, kt, ior)`.
    #[allow(clippy::too_many_arguments)]
    pub fn color(
        &mut self,
        color: Coord3,
        _ka: f64,
        kd: f64,
        ks: f64,
        _ks_spec: f64,
        ang: f64,
        kt: f64,
        ior: f64,
    ) {
        self.sink
            .material(&Material::from_spd(d3(&color), kd, ks, ang, kt, ior));
    }

    /// `lib_output_sphere`: `center[3]` is the radius.
    pub fn sphere(&mut self, center: Coord4) {
        match self.curve_format {
            CurveFormat::Curves => {
                let mut c = center;
                if self.tx_active() {
                    // "This assumes uniform scaling" (libpr2.c): the radius is scaled by |Sx|.
                    let p = vec::transform_point(&c[..3], &self.current_tx);
                    let scale = vec::tx_unwind_scale_x(&self.current_tx);
                    c = [p[0], p[1], p[2], c[3] * scale.abs()];
                }
                self.sink.shape(ShapeRef::Sphere {
                    center: d3(&c),
                    radius: c[3],
                });
            }
            CurveFormat::Patches => tessellate::sphere(self, center),
        }
    }

    /// `lib_output_cylcone`: `[3]` of each end is its radius.
    pub fn cylcone(&mut self, base: Coord4, apex: Coord4) {
        match self.curve_format {
            CurveFormat::Curves => {
                let (mut b, mut a) = (base, apex);
                if self.tx_active() {
                    let scale = vec::tx_unwind_scale_x(&self.current_tx).abs();
                    let pb = vec::transform_point(&b[..3], &self.current_tx);
                    let pa = vec::transform_point(&a[..3], &self.current_tx);
                    b = [pb[0], pb[1], pb[2], b[3] * scale];
                    a = [pa[0], pa[1], pa[2], a[3] * scale];
                }
                self.sink.shape(ShapeRef::Cone {
                    base: d3(&b),
                    base_radius: b[3],
                    apex: d3(&a),
                    apex_radius: a[3],
                });
            }
            CurveFormat::Patches => tessellate::cylcone(self, base, apex),
        }
    }

    /// `lib_output_polygon`: merges adjacent vertices closer than EPSILON2, drops polygons left
    /// with fewer than three vertices, applies the current transform.
    pub fn polygon(&mut self, vert: &[Coord3]) {
        let mut v = std::mem::take(&mut self.scratch);
        v.clear();
        v.extend_from_slice(vert);
        self.polygon_in_place(&mut v);
        self.scratch = v;
    }

    /// `lib_output_polygon` exactly as the C runs it on the caller's array: degenerate edges
    /// are removed by shifting the later vertices down in `vert`, and the surviving vertices are
    /// transformed in place. Returns the remaining vertex count (`tot_vert`); the polygon is
    /// printed only if that is at least 3. Callers that reuse their array after the call (as
    /// `lib_output_polygon_height` does) see what the C callers see.
    pub fn polygon_in_place(&mut self, vert: &mut [Coord3]) -> usize {
        let mut tot = vert.len();
        let mut i = 0;
        while i < tot {
            let mut x = vec::sub3(&vert[i], &vert[(i + 1) % tot]);
            if vec::normalize_vector(&mut x) < EPSILON2 {
                for j in i..tot - 1 {
                    vert[j] = vert[j + 1];
                }
                tot -= 1;
            } else {
                i += 1;
            }
        }
        if tot < 3 {
            return tot;
        }
        if self.tx_active() {
            let m = self.current_tx;
            for p in vert[..tot].iter_mut() {
                *p = vec::transform_point(p, &m);
            }
        }
        self.emit_polygon(&vert[..tot]);
        tot
    }

    /// `lib_output_height` (libpr3.c), which for NFF is `lib_output_polygon_height` (libply.c)
    /// whatever the curve format: a `height` x `width` grid of samples `y0 + data[i][j]` over
    /// `x0..x1` (columns `j`) and `z0..z1` (rows `i`), as two triangles per cell. Rows are
    /// pulled in order through `fill_row(i, row)` so the grid is never held whole.
    #[allow(clippy::too_many_arguments)]
    pub fn height(
        &mut self,
        height: usize,
        width: usize,
        fill_row: &mut dyn FnMut(usize, &mut [f32]),
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
        z0: f64,
        z1: f64,
    ) {
        tessellate::height(self, height, width, fill_row, x0, x1, y0, y1, z0, z1);
    }

    /// `lib_output_polypatch`: split into triangles (libply.c `split_polygon`), each printed as
    /// `pp 3`.
    pub fn polypatch(&mut self, vert: &[Coord3], norm: &[Coord3]) {
        tessellate::split_polygon(self, vert, norm);
    }

    /// Emits one triangle patch as the C library prints it (after transforms). Used by the
    /// tessellation code.
    pub(crate) fn emit_patch(&mut self, vert: &[Coord3], norm: &[Coord3]) {
        let mut v = std::mem::take(&mut self.verts);
        let mut n = std::mem::take(&mut self.norms);
        v.clear();
        n.clear();
        v.extend(vert.iter().map(|p| d3(p)));
        n.extend(norm.iter().map(|p| d3(p)));
        self.sink.shape(ShapeRef::Patch {
            vertices: &v,
            normals: &n,
        });
        self.verts = v;
        self.norms = n;
    }

    /// Emits a polygon record as printed (no vertex merging, no transform). Used by the
    /// tessellation code where the C library prints `p` directly.
    pub(crate) fn emit_polygon(&mut self, vert: &[Coord3]) {
        let mut v = std::mem::take(&mut self.verts);
        v.clear();
        v.extend(vert.iter().map(|p| d3(p)));
        self.sink.shape(ShapeRef::Polygon(&v));
        self.verts = v;
    }

    // ----- transform stack (libtx.c) -----

    /// `lib_tx_active`: any element of the current transform differs from the identity by more
    /// than EPSILON.
    pub fn tx_active(&self) -> bool {
        for i in 0..4 {
            for j in 0..4 {
                let id = if i == j { 1.0 } else { 0.0 };
                if (self.current_tx[i][j] - id).abs() > EPSILON {
                    return true;
                }
            }
        }
        false
    }

    pub fn current_tx(&self) -> &Matrix {
        &self.current_tx
    }

    /// `lib_tx_push`.
    pub fn tx_push(&mut self) {
        self.tx_stack.push(self.current_tx);
    }

    /// `lib_tx_pop` (popping an empty stack is ignored, as in C, which only complains).
    pub fn tx_pop(&mut self) {
        if let Some(m) = self.tx_stack.pop() {
            self.current_tx = m;
        }
    }

    /// `lib_tx_rotate`: current = R · current.
    pub fn tx_rotate(&mut self, axis: usize, angle: f64) {
        let r = vec::rotate_matrix(axis, angle);
        self.current_tx = vec::matrix_multiply(&r, &self.current_tx);
    }

    /// `lib_tx_scale`: current = S · current.
    pub fn tx_scale(&mut self, v: Coord3) {
        let s = vec::scale_matrix(&v);
        self.current_tx = vec::matrix_multiply(&s, &self.current_tx);
    }

    /// `lib_tx_translate`: current = T · current.
    pub fn tx_translate(&mut self, v: Coord3) {
        let t = vec::translate_matrix(&v);
        self.current_tx = vec::matrix_multiply(&t, &self.current_tx);
    }
}
