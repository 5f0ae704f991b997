//! Tree statistics of 001's tables and figures (§2.2; thesis Figs. 3.12–3.19): node counts,
//! leaf depths, 001's modelled memory, and the bytes actually used.
//!
//! Conventions (001 §1.2, §1.3, §1.6):
//! - Depth: root = 0, +1 per edge; a leaf's depth is its parent's + 1 (a leaf root: 0).
//! - Internal nodes: the wide nodes. Leaves: the used child slots that hold primitives. Empty
//!   nodes: unused slots (001 counts them as "a kind of leaf").
//! - Modelled memory, Eq. 3.1–3.3: `N_i·(28 + 4B) + N_l·32` bytes. Whether 001 counts empty
//!   nodes in N_l is unclear, so both are given (`model_bytes` without, `model_bytes_with_empty`
//!   with). Average leaf depth likewise, with and without empty slots.
//! - SAH cost of the finished tree: `Σ_inner A/A_root · len · T_AABB + Σ_leaf A/A_root · n ·
//!   T_tri` (001 Eq. 3.4 summed over the tree; the root box is not counted).

use super::config::{T_AABB, T_TRI};
use super::node::{is_leaf, leaf_range, WideNode};
use crate::geometry::aabb::Aabb;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreeStats {
    pub width: usize,
    pub internal_nodes: u64,
    pub leaf_nodes: u64,
    pub empty_nodes: u64,
    pub primitives: u64,
    pub avg_leaf_depth: f64,
    pub avg_leaf_depth_with_empty: f64,
    pub max_leaf_depth: u64,
    pub sah_cost: f64,
    /// Bytes of the node array (the layout traversal reads).
    pub node_bytes: u64,
}

impl TreeStats {
    /// 001 Eq. 3.1: bytes of one internal node of branching factor B.
    pub fn internal_node_model_bytes(width: usize) -> u64 {
        28 + 4 * width as u64
    }

    /// 001 Eq. 3.3, empty nodes not counted as leaves.
    pub fn model_bytes(&self) -> u64 {
        self.internal_nodes * Self::internal_node_model_bytes(self.width) + self.leaf_nodes * 32
    }

    /// 001 Eq. 3.3, empty nodes counted as leaves.
    pub fn model_bytes_with_empty(&self) -> u64 {
        self.model_bytes() + self.empty_nodes * 32
    }

    /// The statistics as `build_stats` entries.
    pub fn insert_into(&self, m: &mut BTreeMap<String, f64>) {
        let mut put = |k: &str, v: f64| {
            m.insert(k.to_string(), v);
        };
        put("width", self.width as f64);
        put("internal_nodes", self.internal_nodes as f64);
        put("leaf_nodes", self.leaf_nodes as f64);
        put("empty_nodes", self.empty_nodes as f64);
        put(
            "total_nodes",
            (self.internal_nodes + self.leaf_nodes + self.empty_nodes) as f64,
        );
        put(
            "avg_leaf_prims",
            self.primitives as f64 / self.leaf_nodes.max(1) as f64,
        );
        put("avg_leaf_depth", self.avg_leaf_depth);
        put("avg_leaf_depth_with_empty", self.avg_leaf_depth_with_empty);
        put("max_leaf_depth", self.max_leaf_depth as f64);
        put("sah_cost", self.sah_cost);
        put("model_bytes", self.model_bytes() as f64);
        put(
            "model_bytes_with_empty",
            self.model_bytes_with_empty() as f64,
        );
        put("node_bytes", self.node_bytes as f64);
    }
}

/// Statistics of a flattened tree whose root is `root` (box `root_bounds`).
pub fn tree_stats<const N: usize>(
    nodes: &[WideNode<N>],
    root: u32,
    root_bounds: &Aabb,
) -> TreeStats {
    let mut s = TreeStats {
        width: N,
        node_bytes: std::mem::size_of_val(nodes) as u64,
        ..Default::default()
    };
    let root_area = root_bounds.half_area();
    let rel = |b: &Aabb| {
        if root_area > 0.0 {
            (b.half_area() / root_area) as f64
        } else {
            1.0
        }
    };
    let (mut depth_sum, mut empty_depth_sum) = (0u64, 0u64);
    if is_leaf(root) {
        let (_, count) = leaf_range(root);
        s.leaf_nodes = 1;
        s.primitives = count as u64;
        s.sah_cost = count as f64 * T_TRI as f64;
    } else {
        let mut stack = vec![(root, 0u64, 1.0f64)];
        while let Some((i, depth, area)) = stack.pop() {
            let node = &nodes[i as usize];
            let len = node.len as usize;
            s.internal_nodes += 1;
            s.sah_cost += area * len as f64 * T_AABB as f64;
            s.empty_nodes += (N - len) as u64;
            empty_depth_sum += (N - len) as u64 * (depth + 1);
            for slot in 0..len {
                let c = node.child[slot];
                let a = rel(&node.child_bounds(slot));
                if is_leaf(c) {
                    let (_, count) = leaf_range(c);
                    s.leaf_nodes += 1;
                    s.primitives += count as u64;
                    s.sah_cost += a * count as f64 * T_TRI as f64;
                    depth_sum += depth + 1;
                    s.max_leaf_depth = s.max_leaf_depth.max(depth + 1);
                } else {
                    stack.push((c, depth + 1, a));
                }
            }
        }
    }
    s.avg_leaf_depth = depth_sum as f64 / s.leaf_nodes.max(1) as f64;
    s.avg_leaf_depth_with_empty =
        (depth_sum + empty_depth_sum) as f64 / (s.leaf_nodes + s.empty_nodes).max(1) as f64;
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_3_3_internal_node_bytes() {
        // 001 Table 3.3: 36, 44, 52, 60, 68, 76, 84, 92 bytes for B = 2 … 16.
        let got: Vec<u64> = (1..=8)
            .map(|k| TreeStats::internal_node_model_bytes(2 * k))
            .collect();
        assert_eq!(got, vec![36, 44, 52, 60, 68, 76, 84, 92]);
    }
}
