//! Where intensity packets go (003 §3.4): straight to the global frame buffer (GFB), or through
//! the cached frame buffer system (CFBS), an m-ary tree of frame-buffer caches (FBCs).
//!
//! A packet (a pixel's intensity from one interaction, 7 bytes) leaves its PE on its own link
//! (T_C1 = 8 clocks). Without caches it is added into the GFB, one shared server (14 clocks).
//! With the CFBS, m PEs share a first-stage FBC, m of those a second-stage one, and so on; an
//! m-ary n-stage tree over N PEs has n = ⌈log_m N⌉ stages, the last being the GFB itself (so
//! m ≥ N is no cache at all, as 003's m = 1024 for 1024 PEs). Each FBC holds 1/128 of the GFB
//! in 4×4-pixel blocks, 2-way set-associative with LRU (Table 5). Values are only ever added,
//! so a miss needs no fill: the block is allocated empty. A hit adds (12 clocks); a miss
//! allocates, evicting the least recently used block of the set when both ways are taken and
//! writing it up the tree (7 + 4 × its dirty pixels clocks, and T_Ci = 64 clocks on the link
//! above). The GFB takes blocks as an always-hitting cache (12 clocks). At the end the caches'
//! blocks are flushed to the GFB; the flush is counted, not timed.
//!
//! Nothing waits for the frame buffer, so it is simulated after the PEs, stage by stage: each
//! link and cache is a FIFO server fed only from below, which makes this exact.

use super::config::{Costs, FrameBuffer};
use serde::Serialize;

/// One intensity packet leaving a PE.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Emission {
    pub time: u64,
    pub pe: u32,
    pub pixel: u32,
}

/// What the frame buffer saw.
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct FrameBufferStats {
    pub packets: u64,
    /// First-stage FBC hits and misses (0 without caches).
    pub hits: u64,
    pub misses: u64,
    /// Blocks written up from one stage to the next, and left in the caches at the end.
    pub blocks_up: u64,
    pub flushed_blocks: u64,
    /// Clocks from a packet leaving its PE to its being added (in the first FBC, or the GFB).
    pub latency_mean: f64,
    pub latency_max: u64,
    /// When the last packet or block was added.
    pub finish: u64,
    /// Intervals between one PE's successive packets, pooled over PEs: mean and variance.
    pub interval_mean: f64,
    pub interval_var: f64,
}

impl FrameBufferStats {
    pub fn hit_rate(&self) -> f64 {
        self.hits as f64 / (self.hits + self.misses).max(1) as f64
    }
}

/// A block on its way up, or a packet (one dirty pixel) on its way in.
#[derive(Clone, Copy)]
struct Item {
    time: u64,
    src: u32,
    block: u32,
    mask: u16,
    /// Index of the packet (first stage) for its latency.
    packet: u32,
}

/// One FBC: `sets` × 2 ways of (block, dirty mask, last use).
struct Cache {
    ways: Vec<(u32, u16, u64)>,
    free: u64,
    clock: u64,
}

const EMPTY: u32 = u32::MAX;

pub fn simulate(
    em: &mut [Emission],
    pes: u32,
    costs: &Costs,
    fb: FrameBuffer,
    width: u32,
) -> FrameBufferStats {
    em.sort_unstable();
    let mut st = FrameBufferStats {
        packets: em.len() as u64,
        ..Default::default()
    };
    intervals(em, pes, &mut st);
    if em.is_empty() {
        return st;
    }
    let bw = width.div_ceil(4);
    let to_item = |(i, e): (usize, &Emission)| {
        let (x, y) = (e.pixel % width, e.pixel / width);
        Item {
            time: e.time,
            src: e.pe,
            block: (y / 4) * bw + x / 4,
            mask: 1 << ((y % 4) * 4 + x % 4),
            packet: i as u32,
        }
    };
    let mut items: Vec<Item> = em.iter().enumerate().map(to_item).collect();
    // The first links (C_1), one per PE.
    through_links(&mut items, pes as usize, costs.fb_link as u64);
    let stages = match fb {
        // Unbounded write buffers add nothing up and never hold a PE: every packet reaches the
        // GFB as if direct (with finite queues they are simulated in [`super::fbpath`]).
        FrameBuffer::Direct | FrameBuffer::WriteBuffer { .. } => 1,
        FrameBuffer::Cached { m } => {
            let mut n = 1u32;
            let mut reach = m as u64;
            while reach < pes as u64 {
                reach *= m as u64;
                n += 1;
            }
            n
        }
    };
    let mut latency = vec![0u64; em.len()];
    let m = match fb {
        FrameBuffer::Cached { m } => m,
        FrameBuffer::Direct | FrameBuffer::WriteBuffer { .. } => pes.max(1),
    };
    let total_blocks = bw as u64 * width.div_ceil(4) as u64;
    let sets = ((total_blocks / 128 / 2).max(1)) as usize;
    let mut group = 1u64;
    for stage in 1..stages {
        group *= m as u64;
        let ncache = (pes as u64).div_ceil(group) as usize;
        let mut caches: Vec<Cache> = (0..ncache)
            .map(|_| Cache {
                ways: vec![(EMPTY, 0, 0); sets * 2],
                free: 0,
                clock: 0,
            })
            .collect();
        let mut up = Vec::new();
        for it in &items {
            // `src` is a PE at stage 1, a cache of the stage below afterwards.
            let c = &mut caches[(it.src as u64 / m as u64) as usize];
            let start = it.time.max(c.free);
            c.clock += 1;
            let set = (it.block as usize % sets) * 2;
            let (a, b) = (c.ways[set], c.ways[set + 1]);
            let service = if a.0 == it.block || b.0 == it.block {
                let w = if a.0 == it.block { set } else { set + 1 };
                c.ways[w].1 |= it.mask;
                c.ways[w].2 = c.clock;
                if stage == 1 {
                    st.hits += 1;
                }
                costs.fb_hit as u64
            } else {
                if stage == 1 {
                    st.misses += 1;
                }
                let w = if a.0 == EMPTY {
                    set
                } else if b.0 == EMPTY || b.2 < a.2 {
                    set + 1
                } else {
                    set
                };
                let victim = c.ways[w];
                c.ways[w] = (it.block, it.mask, c.clock);
                if victim.0 == EMPTY {
                    costs.fb_miss as u64
                } else {
                    let dirty = victim.1.count_ones() as u64;
                    up.push(Item {
                        time: start + costs.fb_miss as u64 + costs.fb_dirty as u64 * dirty,
                        src: (it.src as u64 / m as u64) as u32,
                        block: victim.0,
                        mask: victim.1,
                        packet: u32::MAX,
                    });
                    costs.fb_miss as u64 + costs.fb_dirty as u64 * dirty
                }
            };
            c.free = start + service;
            st.finish = st.finish.max(c.free);
            if stage == 1 {
                latency[it.packet as usize] = c.free - em[it.packet as usize].time;
            }
        }
        st.flushed_blocks += caches
            .iter()
            .map(|c| c.ways.iter().filter(|w| w.0 != EMPTY).count() as u64)
            .sum::<u64>();
        st.blocks_up += up.len() as u64;
        items = up;
        through_links(&mut items, ncache, costs.fb_block_link as u64);
    }
    // The GFB: one server; direct packets cost its access time, blocks from a cache a hit.
    let service = if stages == 1 {
        costs.gfb as u64
    } else {
        costs.fb_hit as u64
    };
    let mut free = 0u64;
    for it in &items {
        free = it.time.max(free) + service;
        if stages == 1 {
            latency[it.packet as usize] = free - em[it.packet as usize].time;
        }
    }
    st.finish = st.finish.max(free);
    st.latency_max = latency.iter().copied().max().unwrap_or(0);
    st.latency_mean = latency.iter().sum::<u64>() as f64 / latency.len() as f64;
    st
}

/// Passes `items` through one FIFO link per source (`cost` clocks each), then orders them by
/// arrival (source, then order of sending, on a tie).
fn through_links(items: &mut [Item], sources: usize, cost: u64) {
    items.sort_by_key(|i| (i.time, i.src));
    let mut free = vec![0u64; sources];
    for it in items.iter_mut() {
        let f = &mut free[it.src as usize];
        *f = it.time.max(*f) + cost;
        it.time = *f;
    }
    items.sort_by_key(|i| (i.time, i.src));
}

/// Pooled mean and variance of the intervals between each PE's successive packets.
fn intervals(em: &[Emission], pes: u32, st: &mut FrameBufferStats) {
    let mut last = vec![u64::MAX; pes as usize];
    let (mut n, mut sum, mut sum2) = (0u64, 0f64, 0f64);
    for e in em {
        let l = &mut last[e.pe as usize];
        if *l != u64::MAX {
            let d = (e.time - *l) as f64;
            n += 1;
            sum += d;
            sum2 += d * d;
        }
        *l = e.time;
    }
    if n > 0 {
        st.interval_mean = sum / n as f64;
        st.interval_var = (sum2 / n as f64 - st.interval_mean * st.interval_mean).max(0.0);
    }
}
