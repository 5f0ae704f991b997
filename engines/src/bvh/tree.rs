//! The build tree: what every builder produces and [`super::node::flatten`] turns into the
//! traversal layout. Nodes hold their own box (001 §1.2's generic node); an inner node has 2 to
//! `MAX_WIDTH` children, a leaf a range of the primitive order.

use crate::geometry::aabb::Aabb;
use crate::geometry::Geometry;
use glam::Vec3;

/// Widest node any builder makes: 8 for the engines (bvh8), 16 for 001's statistics
/// ([`super::tree_statistics`]).
pub const MAX_WIDTH: usize = 16;

/// Depth at which the SAH builders stop minimising cost and split at the object median (a tree
/// of at most 2^27 primitives then ends within 27 more levels), so every tree is at most
/// [`MAX_DEPTH`] deep and traversal can use a fixed-size stack.
pub const SAH_MEDIAN_DEPTH: usize = 64;
/// Deepest leaf of any tree (root = depth 0, 001 §1.2).
pub const MAX_DEPTH: usize = SAH_MEDIAN_DEPTH + 28;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BuildKind {
    /// `count` primitives: `order[first..first + count]`.
    Leaf { first: u32, count: u32 },
    /// Children, by index into `BuildTree::nodes`, in the first `len` slots.
    Inner { children: [u32; MAX_WIDTH], len: u8 },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildNode {
    pub bounds: Aabb,
    pub kind: BuildKind,
}

/// A tree over primitive indices. `nodes[0]` is the root.
#[derive(Clone, Debug, Default)]
pub struct BuildTree {
    pub nodes: Vec<BuildNode>,
    /// Primitive indices (into `Geometry::prims`) in leaf order.
    pub order: Vec<u32>,
}

impl BuildTree {
    /// Appends a node and gives its index.
    pub fn push(&mut self, bounds: Aabb, kind: BuildKind) -> u32 {
        self.nodes.push(BuildNode { bounds, kind });
        (self.nodes.len() - 1) as u32
    }

    /// Appends the nodes of a tree built on its own (children numbered from its node 0),
    /// renumbered by where they land, copied on `threads` threads ([`extend_par`]); gives where
    /// its node 0 landed. Copying a subtree built on another thread (hundreds of thousands of
    /// nodes) was a pass on one thread alone. Its leaves' first positions are moved on by
    /// `first_shift` (a subtree with an order of its own; 0 for one that shares this tree's).
    pub fn append_shifted(&mut self, sub: &[BuildNode], first_shift: u32, threads: usize) -> u32 {
        let at = self.nodes.len() as u32;
        let threads = if sub.len() < 2 * PARALLEL_MIN {
            1
        } else {
            threads
        };
        extend_par(&mut self.nodes, sub.len(), threads, |i| {
            let mut node = sub[i];
            match &mut node.kind {
                BuildKind::Inner { children, len } => {
                    for c in &mut children[..*len as usize] {
                        *c += at;
                    }
                }
                BuildKind::Leaf { first, .. } => *first += first_shift,
            }
            node
        });
        at
    }

    /// An inner node's children.
    pub fn children(&self, node: u32) -> &[u32] {
        match &self.nodes[node as usize].kind {
            BuildKind::Inner { children, len } => &children[..*len as usize],
            BuildKind::Leaf { .. } => &[],
        }
    }

    /// Checks the invariants every builder must keep: each primitive in exactly one leaf, each
    /// box enclosing its children, arity within `width`, depth within [`MAX_DEPTH`].
    pub fn validate(&self, prims: &BuildPrims, width: usize) -> Result<(), String> {
        self.check(prims, width, false)
    }

    /// [`BuildTree::validate`] for a tree with spatial splits (`build_sah::spatial`): a
    /// primitive may be in several leaves, and a leaf then bounds only its part, so only a
    /// primitive in one leaf must lie inside that leaf's box.
    pub fn validate_shared(&self, prims: &BuildPrims, width: usize) -> Result<(), String> {
        self.check(prims, width, true)
    }

    fn check(&self, prims: &BuildPrims, width: usize, shared: bool) -> Result<(), String> {
        let mut leaves = vec![0u32; prims.bounds.len()];
        for &p in &self.order {
            leaves[p as usize] += 1;
        }
        let mut seen = vec![false; prims.bounds.len()];
        let mut stack = vec![(0u32, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            if depth > MAX_DEPTH {
                return Err(format!("node {i} at depth {depth} > {MAX_DEPTH}"));
            }
            let n = &self.nodes[i as usize];
            match n.kind {
                BuildKind::Leaf { first, count } => {
                    if count == 0 {
                        return Err(format!("leaf {i} is empty"));
                    }
                    for &p in &self.order[first as usize..(first + count) as usize] {
                        if std::mem::replace(&mut seen[p as usize], true) && !shared {
                            return Err(format!("primitive {p} in two leaves"));
                        }
                        if leaves[p as usize] == 1
                            && n.bounds.union(&prims.bounds[p as usize]) != n.bounds
                        {
                            return Err(format!("leaf {i} does not enclose primitive {p}"));
                        }
                    }
                }
                BuildKind::Inner { children, len } => {
                    if !(2..=width).contains(&(len as usize)) {
                        return Err(format!("node {i} has {len} children (width {width})"));
                    }
                    for &c in &children[..len as usize] {
                        let cb = self.nodes[c as usize].bounds;
                        if n.bounds.union(&cb) != n.bounds {
                            return Err(format!("node {i} does not enclose child {c}"));
                        }
                        stack.push((c, depth + 1));
                    }
                }
            }
        }
        match seen.iter().position(|s| !s) {
            Some(p) => Err(format!("primitive {p} in no leaf")),
            None => Ok(()),
        }
    }
}

/// Fewer primitives than this per thread are boxed on one thread: starting a thread costs
/// more than boxing a few thousand.
pub const PARALLEL_MIN: usize = 4096;

/// Appends the `n` items `make(0)`, …, `make(n − 1)` to `v`, made on `threads` threads, each
/// writing a contiguous part straight into the vector's spare capacity: no pass on one thread
/// fills the vector first, and each thread takes the page faults of its own part (a fresh
/// process's build of balls4 tessellated took 7,000 faults in its first pass alone). One thread makes them all in order on the calling thread.
pub fn extend_par<T: Send, F: Fn(usize) -> T + Sync>(
    v: &mut Vec<T>,
    n: usize,
    threads: usize,
    make: F,
) {
    if threads <= 1 {
        v.extend((0..n).map(make));
        return;
    }
    let len = v.len();
    v.reserve(n);
    let part = n.div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (k, chunk) in v.spare_capacity_mut()[..n].chunks_mut(part).enumerate() {
            let make = &make;
            scope.spawn(move || {
                for (j, slot) in chunk.iter_mut().enumerate() {
                    slot.write(make(k * part + j));
                }
            });
        }
    });
    // SAFETY: the parts cover the n slots after `len` and every thread wrote each slot of its
    // part; the scope joined them all (a panic in one propagates out of the scope before this
    // line, and the vector keeps its old length).
    unsafe { v.set_len(len + n) };
}

/// What builders read of each primitive: its box and the box's centre (001 §1.2: the centre of
/// the primitive's box, not its barycentre, orders and splits primitives).
#[derive(Clone, Debug, Default)]
pub struct BuildPrims {
    pub bounds: Vec<Aabb>,
    pub centroid: Vec<Vec3>,
}

impl BuildPrims {
    pub fn new(g: &Geometry) -> BuildPrims {
        let bounds: Vec<Aabb> = g
            .prims
            .iter()
            .map(|p| {
                let (lo, hi) = p.bounds();
                Aabb::new(lo, hi)
            })
            .collect();
        let centroid = bounds.iter().map(|b| b.centre()).collect();
        BuildPrims { bounds, centroid }
    }

    pub fn len(&self) -> usize {
        self.bounds.len()
    }

    pub fn is_empty(&self) -> bool {
        self.bounds.is_empty()
    }

    /// Union of the boxes of `ids`.
    pub fn bounds_of(&self, ids: &[u32]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &i in ids {
            b.grow(&self.bounds[i as usize]);
        }
        b
    }

    /// Bounds of the centres of `ids`.
    pub fn centroid_bounds_of(&self, ids: &[u32]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &i in ids {
            b.grow_point(self.centroid[i as usize]);
        }
        b
    }

    /// Sort key of primitive `i` on `axis`: its centre, ties broken by index so that every
    /// builder is deterministic.
    #[inline]
    pub fn key(&self, i: u32, axis: usize) -> (f32, u32) {
        (self.centroid[i as usize][axis], i)
    }

    #[inline]
    pub fn cmp(&self, a: u32, b: u32, axis: usize) -> std::cmp::Ordering {
        let (ka, kb) = (self.key(a, axis), self.key(b, axis));
        ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1))
    }
}
