//! rayshade-ss's memory as seed 000 counted it (Table 3.2: "memory used by rayshade-ss", the
//! x-axis of Figs. 3.5–3.7), rebuilt from Rayshade 4.0's own data structures on the machine the
//! thesis ran (i386, 32-bit pointers, `double` Float aligned to 4 in structs, glibc `malloc`
//! chunks of n + 4 bytes rounded up to 8, at least 16):
//!
//! - every object is a primitive struct (`Sphere` 40 B, `Polygon` 44 B plus its vertex array,
//!   `Cone` 224 B with its own `Trans`, a phong `Triangle` 220 B plus 3 vertex normals) allocated
//!   by the parser, followed by its `Geom` (96 B: name, methods, the per-object bounding box
//!   `bounds[2][3]`, the mailbox `counter`, surface, links);
//! - the grid (`GridConvert`): an x array of pointers, per x a y array, per (x, y) a z array of
//!   list heads (`GeomList *`), then for every (object, voxel its box overlaps) a `GeomList`
//!   node of 8 B (`engrid`), allocated object by object, voxels x-major as `engrid` loops.
//!
//! The same image gives the pages a query touches ([`PageMap`], for Mattson's model), and the
//! pages the preprocessing touches (parsing = allocating the objects, bounding them, allocating
//! the voxels, inserting every object). SPD's rayshade output writes a polygon as `polygon` (one
//! object) and splits a polygonal patch into `triangle`s with normals (one object each).

use rtbench_engines::geometry::Geometry;
use rtbench_engines::grid::paging::{PageMap, PAGE};
use rtbench_engines::grid::Grid;
use rtbench_scenes::{Scene, Shape};

/// Rayshade 4.0 struct sizes on i386 (bytes).
const GEOM: u64 = 96;
const SPHERE: u64 = 40;
const POLYGON: u64 = 44;
const CONE: u64 = 224;
const TRIANGLE: u64 = 220;
const VECTOR: u64 = 24;
const POINTER: u64 = 4;
const LIST_NODE: u64 = 8;

/// What glibc's `malloc(n)` takes on a 32-bit machine: n + 4 bytes of header, rounded to 8.
pub fn chunk(n: u64) -> u64 {
    (n + 4).div_ceil(8).max(2) * 8
}

/// Bytes of one scene object: its primitive struct(s) and `Geom`(s); and where, inside that,
/// the (first) `Geom` starts.
fn object_bytes(shape: &Shape) -> (u64, u64) {
    match shape {
        Shape::Sphere { .. } => (chunk(SPHERE) + chunk(GEOM), chunk(SPHERE)),
        Shape::Cone { .. } => (chunk(CONE) + chunk(GEOM), chunk(CONE)),
        Shape::Polygon(v) => {
            let prim = chunk(POLYGON) + chunk(VECTOR * v.len() as u64);
            (prim + chunk(GEOM), prim)
        }
        Shape::Patch { vertices, .. } => {
            let one = chunk(TRIANGLE) + chunk(3 * VECTOR);
            (
                vertices.len().saturating_sub(2) as u64 * (one + chunk(GEOM)),
                one,
            )
        }
    }
}

/// Table 3.2's account, per part.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct Account {
    pub objects: u64,
    /// Of `objects`: the per-object bounding boxes (`Geom::bounds`, 48 B each).
    pub boxes: u64,
    pub voxel_arrays: u64,
    pub list_nodes: u64,
    pub node_bytes: u64,
    pub total: u64,
}

/// rayshade-ss's memory image of one scene and its grid.
pub struct RayshadeImage {
    obj_base: Vec<u64>,
    geom_off: Vec<u32>,
    prim_object: Vec<u32>,
    res: [u64; 3],
    cells_base: u64,
    y_stride: u64,
    z_stride: u64,
    nodes_base: u64,
    /// For each entry of the grid's reference list: its `GeomList` node's allocation number.
    node_of_ref: Vec<u32>,
    /// The nodes in allocation order: (object, Rayshade voxel number x·ry·rz + y·rz + z).
    nodes: Vec<(u32, u64)>,
    pub account: Account,
}

impl RayshadeImage {
    /// Lays out `scene` and `grid` (rss-r, bounding-box insertion, sized on objects) as
    /// rayshade-ss allocates them.
    pub fn new(scene: &Scene, geometry: &Geometry, grid: &Grid) -> RayshadeImage {
        let mut obj_base = Vec::with_capacity(scene.objects.len());
        let mut geom_off = Vec::with_capacity(scene.objects.len());
        let mut at = 0u64;
        let mut boxes = 0u64;
        for o in &scene.objects {
            let (bytes, off) = object_bytes(&o.shape);
            obj_base.push(at);
            geom_off.push(off as u32);
            at += bytes;
            boxes += 48
                * match &o.shape {
                    Shape::Patch { vertices, .. } => vertices.len().saturating_sub(2) as u64,
                    _ => 1,
                };
        }
        let objects = at;
        let cells = grid.cells();
        let r = cells.lattice.res;
        let res = [r[0] as u64, r[1] as u64, r[2] as u64];
        let cells_base = objects;
        let x_array = chunk(POINTER * res[0]);
        let z_stride = chunk(POINTER * res[2]);
        let y_stride = chunk(POINTER * res[1]) + res[1] * z_stride;
        let voxel_arrays = x_array + res[0] * y_stride;
        // Nodes: one per (object, voxel), allocated object by object, voxels in engrid's order.
        let mut pairs: Vec<(u32, u64, u32)> = Vec::with_capacity(cells.refs.len());
        for c in 0..cells.offsets.len().saturating_sub(1) {
            let (a, b) = (cells.offsets[c] as usize, cells.offsets[c + 1] as usize);
            let c = c as u64;
            let (x, y, z) = (c % res[0], (c / res[0]) % res[1], c / (res[0] * res[1]));
            let rs = (x * res[1] + y) * res[2] + z;
            for i in a..b {
                let o = geometry.prim_object[cells.refs[i] as usize];
                pairs.push((o, rs, i as u32));
            }
        }
        pairs.sort_unstable();
        let mut node_of_ref = vec![0u32; cells.refs.len()];
        let mut nodes: Vec<(u32, u64)> = Vec::new();
        for &(o, rs, i) in &pairs {
            if nodes.last() != Some(&(o, rs)) {
                nodes.push((o, rs));
            }
            node_of_ref[i as usize] = (nodes.len() - 1) as u32;
        }
        let node_bytes = nodes.len() as u64 * chunk(LIST_NODE);
        let nodes_base = cells_base + voxel_arrays;
        RayshadeImage {
            obj_base,
            geom_off,
            prim_object: geometry.prim_object.clone(),
            res,
            cells_base,
            y_stride,
            z_stride,
            nodes_base,
            node_of_ref,
            account: Account {
                objects,
                boxes,
                voxel_arrays,
                list_nodes: nodes.len() as u64,
                node_bytes,
                total: objects + voxel_arrays + node_bytes,
            },
            nodes,
        }
    }

    /// Pages of the whole image.
    pub fn pages(&self) -> u64 {
        self.account.total.div_ceil(PAGE) + 1
    }

    fn geom_page(&self, object: u32) -> u64 {
        (self.obj_base[object as usize] + self.geom_off[object as usize] as u64) / PAGE
    }

    /// The list head of Rayshade voxel `rs` (x·ry·rz + y·rz + z).
    fn voxel_page(&self, rs: u64) -> u64 {
        let z = rs % self.res[2];
        let xy = rs / self.res[2];
        let (x, y) = (xy / self.res[1], xy % self.res[1]);
        let x_array = chunk(POINTER * self.res[0]);
        let at = self.cells_base
            + x_array
            + x * self.y_stride
            + chunk(POINTER * self.res[1])
            + y * self.z_stride
            + z * POINTER;
        at / PAGE
    }

    /// The preprocessing's page stream: the parser allocating every object (each page of it
    /// written), the bounding pass over the objects, the voxel arrays allocated (calloc), then
    /// `engrid` per object: its `Geom` (bounds), then per voxel the list head and the new node.
    pub fn preprocess_accesses(&self, out: &mut dyn FnMut(u64)) {
        let n = self.obj_base.len();
        for i in 0..n {
            let a = self.obj_base[i] / PAGE;
            let end = if i + 1 < n {
                self.obj_base[i + 1]
            } else {
                self.cells_base
            };
            for p in a..=(end.saturating_sub(1) / PAGE).max(a) {
                out(p);
            }
        }
        for i in 0..n {
            out(self.geom_page(i as u32));
        }
        for p in self.cells_base / PAGE..=(self.nodes_base.saturating_sub(1) / PAGE) {
            out(p);
        }
        let mut k = 0usize;
        for o in 0..n as u32 {
            out(self.geom_page(o));
            while k < self.nodes.len() && self.nodes[k].0 == o {
                out(self.voxel_page(self.nodes[k].1));
                out((self.nodes_base + k as u64 * chunk(LIST_NODE)) / PAGE);
                k += 1;
            }
        }
    }
}

impl PageMap for RayshadeImage {
    fn cell(&self, cell: usize) -> u64 {
        let c = cell as u64;
        let (x, y, z) = (
            c % self.res[0],
            (c / self.res[0]) % self.res[1],
            c / (self.res[0] * self.res[1]),
        );
        self.voxel_page((x * self.res[1] + y) * self.res[2] + z)
    }
    fn reference(&self, index: u64) -> u64 {
        (self.nodes_base + self.node_of_ref[index as usize] as u64 * chunk(LIST_NODE)) / PAGE
    }
    fn mailbox(&self, prim: u32) -> u64 {
        self.geom_page(self.prim_object[prim as usize])
    }
    fn prim(&self, prim: u32) -> u64 {
        self.obj_base[self.prim_object[prim as usize] as usize] / PAGE
    }
    fn object(&self, prim: u32) -> u64 {
        self.geom_page(self.prim_object[prim as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn malloc_chunks_as_glibc_on_i386() {
        assert_eq!(chunk(0), 16);
        assert_eq!(chunk(8), 16);
        assert_eq!(chunk(12), 16);
        assert_eq!(chunk(13), 24);
        assert_eq!(chunk(96), 104);
        assert_eq!(chunk(40), 48);
    }

    #[test]
    fn a_sphere_is_its_struct_and_its_geom() {
        let s = Shape::Sphere {
            center: glam::DVec3::ZERO,
            radius: 1.0,
        };
        assert_eq!(object_bytes(&s), (48 + 104, 48));
        let tri = Shape::Polygon(vec![glam::DVec3::ZERO; 3]);
        // Polygon 44 → 48, three vertices 72 → 80, Geom 104.
        assert_eq!(object_bytes(&tri), (48 + 80 + 104, 128));
    }
}
