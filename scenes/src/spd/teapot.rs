//! teapot: the Utah teapot's 32 bicubic Bézier patches, each evaluated on an SF×SF grid and
//! split into triangle patches with normals, on an SF×SF checkerboard (SPD 3.14 `teapot.c`, Eric
//! Haines). Two lights.
//!
//! The lid knob and the bottom meet at cusps (all four control points of a patch edge at the
//! axis): the triangle with two vertices there is degenerate and is not output, and a vertex
//! alone at a cusp gets the normal (0, 0, ±1). That drops SF triangles from each of those
//! 8 patches, so there are 64·SF² − 8·SF patches and SF² squares — also at SF 1, which the C
//! warns is "not supported" (it prints the same 56 patches the formula gives).
//!
//! Only triangle patches and polygons are emitted, so the tessellated (`-t`) output is the same
//! as the curved one.

use super::vec::{self, Coord3, Coord4, Matrix};
use super::Output;

/// `NUM_PATCHES` with `BOTTOM` defined (as distributed): the 28 Newell patches plus the bottom.
const NUM_PATCHES: usize = 32;

/// `check_for_cusp`: `false` when two or more vertices are at the axis (degenerate triangle);
/// a single vertex at the axis gets the normal (0, 0, 1) at the lid and (0, 0, -1) at the bottom.
fn check_for_cusp(vert: &[Coord3; 3], norm: &mut [Coord3; 3]) -> bool {
    let mut count = 0;
    let mut nv = 0;
    // The C scans from the last vertex down, so `nv` ends as the lowest index at the cusp.
    for i in (0..vert.len()).rev() {
        if vert[i][0].abs() <= 0.0001 && vert[i][1].abs() <= 0.0001 {
            count += 1;
            nv = i;
        }
    }
    if count > 1 {
        return false;
    }
    if count == 1 {
        // above the middle of the teapot: the lid
        norm[nv] = if vert[nv][2] > 1.5 {
            [0.0, 0.0, 1.0]
        } else {
            [0.0, 0.0, -1.0]
        };
    }
    true
}

/// `DOT4`.
fn dot4(a: &Coord4, b: &Coord4) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// `points_from_basis`: the surface point and normal at each (s, t), from the power basis
/// `[s³ s² s 1] · MGMᵀ · [t³ t² t 1]` and its partial derivatives.
fn points_from_basis(
    s: &[f64; 3],
    t: &[f64; 3],
    mgm: &[Matrix; 3],
    vert: &mut [Coord3; 3],
    norm: &mut [Coord3; 3],
) {
    for num_vert in 0..3 {
        let sxyz = s[num_vert];
        let txyz = t[num_vert];

        // power vectors and their derivatives, filled from the end as the C does
        let (mut sp, mut tp, mut dsp, mut dtp) = ([0.0; 4], [0.0; 4], [0.0; 4], [0.0; 4]);
        let (mut sval, mut tval) = (1.0, 1.0);
        let (mut dsval, mut dtval) = (0.0, 0.0);
        for p in (0..4).rev() {
            sp[p] = sval;
            tp[p] = tval;
            sval *= sxyz;
            tval *= txyz;
            if p == 3 {
                dsp[p] = 0.0;
                dtp[p] = 0.0;
                dsval = 1.0;
                dtval = 1.0;
            } else {
                dsp[p] = dsval * (3 - p) as f64;
                dtp[p] = dtval * (3 - p) as f64;
                dsval *= sxyz;
                dtval *= txyz;
            }
        }

        let (mut sdir, mut tdir) = ([0.0; 3], [0.0; 3]);
        for i in 0..3 {
            let tcoord = vec::transform_coord(&sp, &mgm[i]);
            vert[num_vert][i] = dot4(&tcoord, &tp);
            // s and t tangents
            let tcoord = vec::transform_coord(&dsp, &mgm[i]);
            sdir[i] = dot4(&tcoord, &tp);
            let tcoord = vec::transform_coord(&sp, &mgm[i]);
            tdir[i] = dot4(&tcoord, &dtp);
        }

        norm[num_vert] = vec::cross(&tdir, &sdir);
        vec::normalize_vector(&mut norm[num_vert]);
    }
}

/// `output_teapot`: every patch by brute-force evaluation ("forward differencing would be
/// faster, but this is compact & simple").
fn output_teapot(out: &mut Output<'_>, size_factor: u32) {
    // Bézier basis
    const MS: Matrix = [
        [-1.0, 3.0, -3.0, 1.0],
        [3.0, -6.0, 3.0, 0.0],
        [-3.0, 3.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0],
    ];

    out.color([1.0, 0.5, 0.1], 0.0, 0.75, 0.25, 0.25, 37.0, 0.0, 0.0);

    let mst = vec::transpose_matrix(&MS);
    let sf = size_factor as f64;
    let n = size_factor as u64;
    let mut vert = [[0.0; 3]; 3];
    let mut norm = [[0.0; 3]; 3];

    for patch in PATCHES.iter() {
        // M · G · Mᵀ for x, y, z
        let mut mgm = [[[0.0; 4]; 4]; 3];
        for (i, m) in mgm.iter_mut().enumerate() {
            let mut g = [[0.0; 4]; 4];
            for r in 0..4 {
                for c in 0..4 {
                    g[r][c] = VERTS[patch[r][c] as usize][i];
                }
            }
            let tmtx = vec::matrix_multiply(&MS, &g);
            *m = vec::matrix_multiply(&tmtx, &mst);
        }

        for sstep in 0..n {
            for tstep in 0..n {
                for num_tri in 0..2 {
                    let (mut s, mut t) = ([0.0; 3], [0.0; 3]);
                    for num_vert in 0..3 {
                        // quad corners 0..3; triangles (0,1,2) and (2,3,0)
                        let num_tri_vert = (num_vert + num_tri * 2) % 4;
                        // add 1 to sstep at corners 2 and 3, to tstep at corners 1 and 2
                        let ds = u64::from(num_tri_vert / 2 != 0);
                        let dt = u64::from(num_tri_vert % 3 != 0);
                        s[num_vert] = (sstep + ds) as f64 / sf;
                        t[num_vert] = (tstep + dt) as f64 / sf;
                    }
                    points_from_basis(&s, &t, &mgm, &mut vert, &mut norm);
                    // don't output degenerate polygons
                    if check_for_cusp(&vert, &mut norm) {
                        out.polypatch(&vert, &norm);
                    }
                }
            }
        }
    }
}

/// `loc_to_square`: checkerboard square (sstep, tstep) of an SF×SF board spanning [-4, 4]².
fn loc_to_square(sstep: u64, tstep: u64, sf: f64) -> [Coord3; 4] {
    let mut vert = [[0.0; 3]; 4];
    for (i, v) in vert.iter_mut().enumerate() {
        // vertices 0 and 3 are x.low, 1 and 2 x.high; 0 and 1 are y.low, 2 and 3 y.high
        let xs = sstep + u64::from(i % 3 != 0);
        let ys = tstep + u64::from(i / 2 != 0);
        *v = [
            4.0 * (2.0 * xs as f64 / sf - 1.0),
            4.0 * (2.0 * ys as f64 / sf - 1.0),
            0.0,
        ];
    }
    vert
}

/// `output_checkerboard`: the white squares, then the grey ones.
fn output_checkerboard(out: &mut Output<'_>, size_factor: u32) {
    let sf = size_factor as f64;
    let n = size_factor as u64;
    for (color, parity) in [([1.0, 1.0, 1.0], 1), ([0.5, 0.5, 0.5], 0)] {
        out.color(color, 0.0, 0.5, 0.5, 0.5, 30.0, 0.0, 0.0);
        for sstep in 0..n {
            for tstep in 0..n {
                if (sstep + tstep) % 2 == parity {
                    out.polygon(&loc_to_square(sstep, tstep, sf));
                }
            }
        }
    }
}

/// teapot.c `main` after option parsing. (At SF 1 the C also prints a warning to stderr that
/// the size is not supported; the output is still well formed.)
pub fn generate(out: &mut Output<'_>, size_factor: u32) {
    // UNC sky blue
    out.background([0.078, 0.361, 0.753]);
    out.viewpoint(
        [4.86, 7.2, 5.4],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        45.0,
        1.0,
        1.0,
        512,
        512,
    );

    // NFF lights are not scaled (lscale = 1 for OUTPUT_NFF).
    out.light([-3.1, 9.8, 12.1, 1.0]);
    out.light([11.3, 5.1, 8.8, 1.0]);

    output_checkerboard(out, size_factor);
    output_teapot(out, size_factor);
}

/// 64·SF² − 8·SF triangle patches (8 cusp patches lose SF degenerate triangles each) plus SF²
/// squares: 65·SF² − 8·SF.
pub fn object_count(size_factor: u64) -> Option<u64> {
    let sf = size_factor;
    if sf == 0 {
        return Some(0);
    }
    // sf · (65·sf − 8): no intermediate larger than the result
    sf.checked_mul(sf.checked_mul(65)? - 8)
}

// Newell's teapot data as teapot.c has it: the control-point indices of each patch (4 rows of 4)
// and the 290 control points (with the duplicates and unused points noted in teapot.c).
const PATCHES: [[[u16; 4]; 4]; NUM_PATCHES] = [
    [[0, 1, 2, 3], [4, 5, 6, 7], [8, 9, 10, 11], [12, 13, 14, 15]],
    [
        [3, 16, 17, 18],
        [7, 19, 20, 21],
        [11, 22, 23, 24],
        [15, 25, 26, 27],
    ],
    [
        [18, 28, 29, 30],
        [21, 31, 32, 33],
        [24, 34, 35, 36],
        [27, 37, 38, 39],
    ],
    [
        [30, 40, 41, 0],
        [33, 42, 43, 4],
        [36, 44, 45, 8],
        [39, 46, 47, 12],
    ],
    [
        [12, 13, 14, 15],
        [48, 49, 50, 51],
        [52, 53, 54, 55],
        [56, 57, 58, 59],
    ],
    [
        [15, 25, 26, 27],
        [51, 60, 61, 62],
        [55, 63, 64, 65],
        [59, 66, 67, 68],
    ],
    [
        [27, 37, 38, 39],
        [62, 69, 70, 71],
        [65, 72, 73, 74],
        [68, 75, 76, 77],
    ],
    [
        [39, 46, 47, 12],
        [71, 78, 79, 48],
        [74, 80, 81, 52],
        [77, 82, 83, 56],
    ],
    [
        [56, 57, 58, 59],
        [84, 85, 86, 87],
        [88, 89, 90, 91],
        [92, 93, 94, 95],
    ],
    [
        [59, 66, 67, 68],
        [87, 96, 97, 98],
        [91, 99, 100, 101],
        [95, 102, 103, 104],
    ],
    [
        [68, 75, 76, 77],
        [98, 105, 106, 107],
        [101, 108, 109, 110],
        [104, 111, 112, 113],
    ],
    [
        [77, 82, 83, 56],
        [107, 114, 115, 84],
        [110, 116, 117, 88],
        [113, 118, 119, 92],
    ],
    [
        [120, 121, 122, 123],
        [124, 125, 126, 127],
        [128, 129, 130, 131],
        [132, 133, 134, 135],
    ],
    [
        [123, 136, 137, 120],
        [127, 138, 139, 124],
        [131, 140, 141, 128],
        [135, 142, 143, 132],
    ],
    [
        [132, 133, 134, 135],
        [144, 145, 146, 147],
        [148, 149, 150, 151],
        [68, 152, 153, 154],
    ],
    [
        [135, 142, 143, 132],
        [147, 155, 156, 144],
        [151, 157, 158, 148],
        [154, 159, 160, 68],
    ],
    [
        [161, 162, 163, 164],
        [165, 166, 167, 168],
        [169, 170, 171, 172],
        [173, 174, 175, 176],
    ],
    [
        [164, 177, 178, 161],
        [168, 179, 180, 165],
        [172, 181, 182, 169],
        [176, 183, 184, 173],
    ],
    [
        [173, 174, 175, 176],
        [185, 186, 187, 188],
        [189, 190, 191, 192],
        [193, 194, 195, 196],
    ],
    [
        [176, 183, 184, 173],
        [188, 197, 198, 185],
        [192, 199, 200, 189],
        [196, 201, 202, 193],
    ],
    [
        [203, 203, 203, 203],
        [204, 205, 206, 207],
        [208, 208, 208, 208],
        [209, 210, 211, 212],
    ],
    [
        [203, 203, 203, 203],
        [207, 213, 214, 215],
        [208, 208, 208, 208],
        [212, 216, 217, 218],
    ],
    [
        [203, 203, 203, 203],
        [215, 219, 220, 221],
        [208, 208, 208, 208],
        [218, 222, 223, 224],
    ],
    [
        [203, 203, 203, 203],
        [221, 225, 226, 204],
        [208, 208, 208, 208],
        [224, 227, 228, 209],
    ],
    [
        [209, 210, 211, 212],
        [229, 230, 231, 232],
        [233, 234, 235, 236],
        [237, 238, 239, 240],
    ],
    [
        [212, 216, 217, 218],
        [232, 241, 242, 243],
        [236, 244, 245, 246],
        [240, 247, 248, 249],
    ],
    [
        [218, 222, 223, 224],
        [243, 250, 251, 252],
        [246, 253, 254, 255],
        [249, 256, 257, 258],
    ],
    [
        [224, 227, 228, 209],
        [252, 259, 260, 229],
        [255, 261, 262, 233],
        [258, 263, 264, 237],
    ],
    [
        [265, 265, 265, 265],
        [266, 267, 268, 269],
        [270, 271, 272, 273],
        [92, 119, 118, 113],
    ],
    [
        [265, 265, 265, 265],
        [269, 274, 275, 276],
        [273, 277, 278, 279],
        [113, 112, 111, 104],
    ],
    [
        [265, 265, 265, 265],
        [276, 280, 281, 282],
        [279, 283, 284, 285],
        [104, 103, 102, 95],
    ],
    [
        [265, 265, 265, 265],
        [282, 286, 287, 266],
        [285, 288, 289, 270],
        [95, 94, 93, 92],
    ],
];
const VERTS: [Coord3; 290] = [
    [1.4, 0.0, 2.4],
    [1.4, -0.784, 2.4],
    [0.784, -1.4, 2.4],
    [0.0, -1.4, 2.4],
    [1.3375, 0.0, 2.53125],
    [1.3375, -0.749, 2.53125],
    [0.749, -1.3375, 2.53125],
    [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125],
    [1.4375, -0.805, 2.53125],
    [0.805, -1.4375, 2.53125],
    [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4],
    [1.5, -0.84, 2.4],
    [0.84, -1.5, 2.4],
    [0.0, -1.5, 2.4],
    [-0.784, -1.4, 2.4],
    [-1.4, -0.784, 2.4],
    [-1.4, 0.0, 2.4],
    [-0.749, -1.3375, 2.53125],
    [-1.3375, -0.749, 2.53125],
    [-1.3375, 0.0, 2.53125],
    [-0.805, -1.4375, 2.53125],
    [-1.4375, -0.805, 2.53125],
    [-1.4375, 0.0, 2.53125],
    [-0.84, -1.5, 2.4],
    [-1.5, -0.84, 2.4],
    [-1.5, 0.0, 2.4],
    [-1.4, 0.784, 2.4],
    [-0.784, 1.4, 2.4],
    [0.0, 1.4, 2.4],
    [-1.3375, 0.749, 2.53125],
    [-0.749, 1.3375, 2.53125],
    [0.0, 1.3375, 2.53125],
    [-1.4375, 0.805, 2.53125],
    [-0.805, 1.4375, 2.53125],
    [0.0, 1.4375, 2.53125],
    [-1.5, 0.84, 2.4],
    [-0.84, 1.5, 2.4],
    [0.0, 1.5, 2.4],
    [0.784, 1.4, 2.4],
    [1.4, 0.784, 2.4],
    [0.749, 1.3375, 2.53125],
    [1.3375, 0.749, 2.53125],
    [0.805, 1.4375, 2.53125],
    [1.4375, 0.805, 2.53125],
    [0.84, 1.5, 2.4],
    [1.5, 0.84, 2.4],
    [1.75, 0.0, 1.875],
    [1.75, -0.98, 1.875],
    [0.98, -1.75, 1.875],
    [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35],
    [2.0, -1.12, 1.35],
    [1.12, -2.0, 1.35],
    [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9],
    [2.0, -1.12, 0.9],
    [1.12, -2.0, 0.9],
    [0.0, -2.0, 0.9],
    [-0.98, -1.75, 1.875],
    [-1.75, -0.98, 1.875],
    [-1.75, 0.0, 1.875],
    [-1.12, -2.0, 1.35],
    [-2.0, -1.12, 1.35],
    [-2.0, 0.0, 1.35],
    [-1.12, -2.0, 0.9],
    [-2.0, -1.12, 0.9],
    [-2.0, 0.0, 0.9],
    [-1.75, 0.98, 1.875],
    [-0.98, 1.75, 1.875],
    [0.0, 1.75, 1.875],
    [-2.0, 1.12, 1.35],
    [-1.12, 2.0, 1.35],
    [0.0, 2.0, 1.35],
    [-2.0, 1.12, 0.9],
    [-1.12, 2.0, 0.9],
    [0.0, 2.0, 0.9],
    [0.98, 1.75, 1.875],
    [1.75, 0.98, 1.875],
    [1.12, 2.0, 1.35],
    [2.0, 1.12, 1.35],
    [1.12, 2.0, 0.9],
    [2.0, 1.12, 0.9],
    [2.0, 0.0, 0.45],
    [2.0, -1.12, 0.45],
    [1.12, -2.0, 0.45],
    [0.0, -2.0, 0.45],
    [1.5, 0.0, 0.225],
    [1.5, -0.84, 0.225],
    [0.84, -1.5, 0.225],
    [0.0, -1.5, 0.225],
    [1.5, 0.0, 0.15],
    [1.5, -0.84, 0.15],
    [0.84, -1.5, 0.15],
    [0.0, -1.5, 0.15],
    [-1.12, -2.0, 0.45],
    [-2.0, -1.12, 0.45],
    [-2.0, 0.0, 0.45],
    [-0.84, -1.5, 0.225],
    [-1.5, -0.84, 0.225],
    [-1.5, 0.0, 0.225],
    [-0.84, -1.5, 0.15],
    [-1.5, -0.84, 0.15],
    [-1.5, 0.0, 0.15],
    [-2.0, 1.12, 0.45],
    [-1.12, 2.0, 0.45],
    [0.0, 2.0, 0.45],
    [-1.5, 0.84, 0.225],
    [-0.84, 1.5, 0.225],
    [0.0, 1.5, 0.225],
    [-1.5, 0.84, 0.15],
    [-0.84, 1.5, 0.15],
    [0.0, 1.5, 0.15],
    [1.12, 2.0, 0.45],
    [2.0, 1.12, 0.45],
    [0.84, 1.5, 0.225],
    [1.5, 0.84, 0.225],
    [0.84, 1.5, 0.15],
    [1.5, 0.84, 0.15],
    [-1.6, 0.0, 2.025],
    [-1.6, -0.3, 2.025],
    [-1.5, -0.3, 2.25],
    [-1.5, 0.0, 2.25],
    [-2.3, 0.0, 2.025],
    [-2.3, -0.3, 2.025],
    [-2.5, -0.3, 2.25],
    [-2.5, 0.0, 2.25],
    [-2.7, 0.0, 2.025],
    [-2.7, -0.3, 2.025],
    [-3.0, -0.3, 2.25],
    [-3.0, 0.0, 2.25],
    [-2.7, 0.0, 1.8],
    [-2.7, -0.3, 1.8],
    [-3.0, -0.3, 1.8],
    [-3.0, 0.0, 1.8],
    [-1.5, 0.3, 2.25],
    [-1.6, 0.3, 2.025],
    [-2.5, 0.3, 2.25],
    [-2.3, 0.3, 2.025],
    [-3.0, 0.3, 2.25],
    [-2.7, 0.3, 2.025],
    [-3.0, 0.3, 1.8],
    [-2.7, 0.3, 1.8],
    [-2.7, 0.0, 1.575],
    [-2.7, -0.3, 1.575],
    [-3.0, -0.3, 1.35],
    [-3.0, 0.0, 1.35],
    [-2.5, 0.0, 1.125],
    [-2.5, -0.3, 1.125],
    [-2.65, -0.3, 0.9375],
    [-2.65, 0.0, 0.9375],
    [-2.0, -0.3, 0.9],
    [-1.9, -0.3, 0.6],
    [-1.9, 0.0, 0.6],
    [-3.0, 0.3, 1.35],
    [-2.7, 0.3, 1.575],
    [-2.65, 0.3, 0.9375],
    [-2.5, 0.3, 1.125],
    [-1.9, 0.3, 0.6],
    [-2.0, 0.3, 0.9],
    [1.7, 0.0, 1.425],
    [1.7, -0.66, 1.425],
    [1.7, -0.66, 0.6],
    [1.7, 0.0, 0.6],
    [2.6, 0.0, 1.425],
    [2.6, -0.66, 1.425],
    [3.1, -0.66, 0.825],
    [3.1, 0.0, 0.825],
    [2.3, 0.0, 2.1],
    [2.3, -0.25, 2.1],
    [2.4, -0.25, 2.025],
    [2.4, 0.0, 2.025],
    [2.7, 0.0, 2.4],
    [2.7, -0.25, 2.4],
    [3.3, -0.25, 2.4],
    [3.3, 0.0, 2.4],
    [1.7, 0.66, 0.6],
    [1.7, 0.66, 1.425],
    [3.1, 0.66, 0.825],
    [2.6, 0.66, 1.425],
    [2.4, 0.25, 2.025],
    [2.3, 0.25, 2.1],
    [3.3, 0.25, 2.4],
    [2.7, 0.25, 2.4],
    [2.8, 0.0, 2.475],
    [2.8, -0.25, 2.475],
    [3.525, -0.25, 2.49375],
    [3.525, 0.0, 2.49375],
    [2.9, 0.0, 2.475],
    [2.9, -0.15, 2.475],
    [3.45, -0.15, 2.5125],
    [3.45, 0.0, 2.5125],
    [2.8, 0.0, 2.4],
    [2.8, -0.15, 2.4],
    [3.2, -0.15, 2.4],
    [3.2, 0.0, 2.4],
    [3.525, 0.25, 2.49375],
    [2.8, 0.25, 2.475],
    [3.45, 0.15, 2.5125],
    [2.9, 0.15, 2.475],
    [3.2, 0.15, 2.4],
    [2.8, 0.15, 2.4],
    [0.0, 0.0, 3.15],
    [0.8, 0.0, 3.15],
    [0.8, -0.45, 3.15],
    [0.45, -0.8, 3.15],
    [0.0, -0.8, 3.15],
    [0.0, 0.0, 2.85],
    [0.2, 0.0, 2.7],
    [0.2, -0.112, 2.7],
    [0.112, -0.2, 2.7],
    [0.0, -0.2, 2.7],
    [-0.45, -0.8, 3.15],
    [-0.8, -0.45, 3.15],
    [-0.8, 0.0, 3.15],
    [-0.112, -0.2, 2.7],
    [-0.2, -0.112, 2.7],
    [-0.2, 0.0, 2.7],
    [-0.8, 0.45, 3.15],
    [-0.45, 0.8, 3.15],
    [0.0, 0.8, 3.15],
    [-0.2, 0.112, 2.7],
    [-0.112, 0.2, 2.7],
    [0.0, 0.2, 2.7],
    [0.45, 0.8, 3.15],
    [0.8, 0.45, 3.15],
    [0.112, 0.2, 2.7],
    [0.2, 0.112, 2.7],
    [0.4, 0.0, 2.55],
    [0.4, -0.224, 2.55],
    [0.224, -0.4, 2.55],
    [0.0, -0.4, 2.55],
    [1.3, 0.0, 2.55],
    [1.3, -0.728, 2.55],
    [0.728, -1.3, 2.55],
    [0.0, -1.3, 2.55],
    [1.3, 0.0, 2.4],
    [1.3, -0.728, 2.4],
    [0.728, -1.3, 2.4],
    [0.0, -1.3, 2.4],
    [-0.224, -0.4, 2.55],
    [-0.4, -0.224, 2.55],
    [-0.4, 0.0, 2.55],
    [-0.728, -1.3, 2.55],
    [-1.3, -0.728, 2.55],
    [-1.3, 0.0, 2.55],
    [-0.728, -1.3, 2.4],
    [-1.3, -0.728, 2.4],
    [-1.3, 0.0, 2.4],
    [-0.4, 0.224, 2.55],
    [-0.224, 0.4, 2.55],
    [0.0, 0.4, 2.55],
    [-1.3, 0.728, 2.55],
    [-0.728, 1.3, 2.55],
    [0.0, 1.3, 2.55],
    [-1.3, 0.728, 2.4],
    [-0.728, 1.3, 2.4],
    [0.0, 1.3, 2.4],
    [0.224, 0.4, 2.55],
    [0.4, 0.224, 2.55],
    [0.728, 1.3, 2.55],
    [1.3, 0.728, 2.55],
    [0.728, 1.3, 2.4],
    [1.3, 0.728, 2.4],
    [0.0, 0.0, 0.0],
    [1.425, 0.0, 0.0],
    [1.425, 0.798, 0.0],
    [0.798, 1.425, 0.0],
    [0.0, 1.425, 0.0],
    [1.5, 0.0, 0.075],
    [1.5, 0.84, 0.075],
    [0.84, 1.5, 0.075],
    [0.0, 1.5, 0.075],
    [-0.798, 1.425, 0.0],
    [-1.425, 0.798, 0.0],
    [-1.425, 0.0, 0.0],
    [-0.84, 1.5, 0.075],
    [-1.5, 0.84, 0.075],
    [-1.5, 0.0, 0.075],
    [-1.425, -0.798, 0.0],
    [-0.798, -1.425, 0.0],
    [0.0, -1.425, 0.0],
    [-1.5, -0.84, 0.075],
    [-0.84, -1.5, 0.075],
    [0.0, -1.5, 0.075],
    [0.798, -1.425, 0.0],
    [1.425, -0.798, 0.0],
    [0.84, -1.5, 0.075],
    [1.5, -0.84, 0.075],
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sink::CountingSink;
    use crate::spd::{CurveFormat, DEFAULT_RESOLUTION};

    fn count(sf: u32, format: CurveFormat) -> CountingSink {
        let mut sink = CountingSink::default();
        let mut out = Output::new(&mut sink, format, DEFAULT_RESOLUTION);
        generate(&mut out, sf);
        sink
    }

    #[test]
    fn object_count_standard() {
        assert_eq!(object_count(12), Some(9_264));
        assert_eq!(object_count(1), Some(57));
        assert_eq!(object_count(u64::MAX / 64), None);
    }

    #[test]
    fn stream_matches_object_count() {
        for sf in [1u32, 2, 3, 5, 12] {
            let s = count(sf, CurveFormat::Curves);
            let n = sf as u64;
            assert_eq!(s.counts.objects(), object_count(n).unwrap(), "sf {sf}");
            assert_eq!(s.counts.polygon, n * n);
            assert_eq!(s.counts.patch, 64 * n * n - 8 * n);
        }
    }

    #[test]
    fn tessellated_is_the_same() {
        let a = count(3, CurveFormat::Curves);
        let b = count(3, CurveFormat::Patches);
        assert_eq!(a.counts, b.counts);
    }
}
