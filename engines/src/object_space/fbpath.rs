//! The frame-buffer path with finite queues, coupled to the PEs (003 §3.4, §4.3.2): an
//! intensity packet must find room in its PE's output queue, or the RP block that made it waits
//! (back-pressure), so a saturated frame buffer slows the PEs and the CFBS or a write buffer can
//! shorten the image time.
//!
//! Stations, each a FIFO server with an input queue of [`FbPath::queue`] entries (003 gives no
//! queue sizes; the capacity is a setting) and blocking after service (a finished item waits in
//! its server until the next station has room):
//! - per PE, its link to the first stage (T_C1 = 8 clocks a packet);
//! - direct: the GFB, one server shared by all PEs (14 clocks a packet);
//! - CFBS (m-ary): FBCs as in [`super::framebuffer`] (2-way LRU, 4×4-pixel blocks, 1/128 of the
//!   GFB; hit 12, miss 7 + 4 × dirty pixels), an evicted block going up its cache's link (T_Ci =
//!   64) to the next stage, the last stage being the GFB (12 a block);
//! - write buffer (m-ary, 003's third case, "details not given"): the same tree with FIFO
//!   buffers in place of the FBCs, which add nothing up: each packet is passed on (T_C1 = 8)
//!   and reaches the GFB (14 a packet). A buffer holds [`FbPath::queue`] packets, as the caches'
//!   input queues do, so the two differ only in accumulating.
//!
//! The end-of-frame flush of the caches is counted, not timed (as in [`super::framebuffer`]).

use super::config::{Costs, FrameBuffer};
use super::framebuffer::FrameBufferStats;
use std::collections::VecDeque;

/// The frame-buffer path's shape and its queues' capacity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FbPath {
    pub kind: FrameBuffer,
    /// Entries in each station's input queue (at least 1).
    pub queue: u32,
}

/// One item on the path: a packet (one pixel) or a cache block (its dirty pixels).
#[derive(Clone, Copy, Debug)]
struct Item {
    block: u32,
    mask: u16,
    /// When the packet left its RP block (blocks: when they left their cache).
    born: u64,
    /// A packet rather than a cache block.
    packet: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    /// A link: passes the item on after `cost` clocks.
    Link { cost: u64 },
    /// A frame-buffer cache of stage `stage` (1 = first).
    Cache { stage: u32 },
    /// A write buffer: passes each packet on.
    Buffer,
    /// The global frame buffer, the sink.
    Gfb,
}

/// Who waits for room in a station's queue.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Waiter {
    Station(u32),
    /// An RP block (global index) holding a packet of its PE.
    Block(u32),
}

struct Station {
    kind: Kind,
    /// Where finished items go (none for the GFB, and for a cache its up-link).
    dest: u32,
    queue: VecDeque<Item>,
    serving: Option<Item>,
    /// A finished item waiting for room at `dest`.
    blocked: Option<Item>,
    waiting: VecDeque<(Waiter, Item)>,
    /// Cache ways: (block, dirty mask, last use); empty for other kinds.
    ways: Vec<(u32, u16, u64)>,
    clock: u64,
}

const NO_DEST: u32 = u32::MAX;
const EMPTY: u32 = u32::MAX;

/// The path's state during a run.
pub struct Path {
    stations: Vec<Station>,
    width: u32,
    sets: usize,
    costs: Costs,
    /// Station events due: (time, station) — the caller schedules them.
    pub due: Vec<(u64, u32)>,
    /// RP blocks whose packet has been taken, at the time: the caller resumes them.
    pub resumed: Vec<(u64, u32)>,
    pub stats: FrameBufferStats,
    latency_sum: u64,
    last_emit: Vec<u64>,
    interval: (u64, f64, f64),
}

impl Path {
    pub fn new(path: FbPath, pes: u32, costs: &Costs, width: u32) -> Path {
        let mut stations: Vec<Station> = Vec::new();
        let new = |kind, dest| Station {
            kind,
            dest,
            queue: VecDeque::new(),
            serving: None,
            blocked: None,
            waiting: VecDeque::new(),
            ways: Vec::new(),
            clock: 0,
        };
        let blocks = width.div_ceil(4) as u64 * width.div_ceil(4) as u64;
        let sets = (blocks / 128 / 2).max(1) as usize;
        // Stations 0..pes: the PEs' links. Then stage by stage; the GFB last.
        for _ in 0..pes {
            stations.push(new(
                Kind::Link {
                    cost: costs.fb_link as u64,
                },
                NO_DEST,
            ));
        }
        let m = match path.kind {
            FrameBuffer::Direct => None,
            FrameBuffer::Cached { m } | FrameBuffer::WriteBuffer { m } => Some(m as u64),
        };
        // Nodes of the stage below (the PEs' links first) and their count.
        let (mut below, mut below_n) = (0u32, pes as u64);
        if let Some(m) = m {
            while below_n > m {
                let n = below_n.div_ceil(m);
                let first = stations.len() as u32;
                let stage = if below == 0 { 1 } else { 2 };
                for _ in 0..n {
                    let kind = match path.kind {
                        FrameBuffer::WriteBuffer { .. } => Kind::Buffer,
                        _ => Kind::Cache { stage },
                    };
                    let mut s = new(kind, NO_DEST);
                    if kind != Kind::Buffer {
                        s.ways = vec![(EMPTY, 0, 0); sets * 2];
                    }
                    stations.push(s);
                }
                for b in 0..below_n as u32 {
                    stations[(below + b) as usize].dest = first + (b as u64 / m) as u32;
                }
                // A cache's evictions (or a buffer's packets) go up its own link.
                let up_first = stations.len() as u32;
                for k in 0..n as u32 {
                    let cost = match path.kind {
                        FrameBuffer::WriteBuffer { .. } => costs.fb_link,
                        _ => costs.fb_block_link,
                    } as u64;
                    stations.push(new(Kind::Link { cost }, NO_DEST));
                    stations[(first + k) as usize].dest = up_first + k;
                }
                below = up_first;
                below_n = n;
            }
        }
        let gfb = stations.len() as u32;
        stations.push(new(Kind::Gfb, NO_DEST));
        for b in 0..below_n as u32 {
            stations[(below + b) as usize].dest = gfb;
        }
        Path {
            stations,
            width,
            sets,
            costs: *costs,
            due: Vec::new(),
            resumed: Vec::new(),
            stats: FrameBufferStats::default(),
            latency_sum: 0,
            last_emit: vec![u64::MAX; pes as usize],
            interval: (0, 0.0, 0.0),
        }
    }

    fn item(&self, pixel: u32, t: u64) -> Item {
        let (x, y) = (pixel % self.width, pixel / self.width);
        Item {
            block: (y / 4) * self.width.div_ceil(4) + x / 4,
            mask: 1 << ((y % 4) * 4 + x % 4),
            born: t,
            packet: true,
        }
    }

    /// RP block `block` of PE `pe` emits a packet for `pixel` at `t`: true when its PE's queue
    /// took it; else the block waits and is listed in [`Path::resumed`] when it is taken.
    pub fn emit(&mut self, pe: u32, block: u32, pixel: u32, t: u64, queue: u32) -> bool {
        let it = self.item(pixel, t);
        let s = &mut self.stations[pe as usize];
        if s.queue.len() < queue as usize && s.waiting.is_empty() {
            self.record_emission(pe, t);
            self.accept(pe, it, t, queue);
            true
        } else {
            s.waiting.push_back((Waiter::Block(block), it));
            false
        }
    }

    fn record_emission(&mut self, pe: u32, t: u64) {
        self.stats.packets += 1;
        let l = &mut self.last_emit[pe as usize];
        if *l != u64::MAX {
            let d = (t - *l) as f64;
            self.interval.0 += 1;
            self.interval.1 += d;
            self.interval.2 += d * d;
        }
        *l = t;
    }

    /// Puts `it` in station `s`'s queue (there is room) and starts it if idle.
    fn accept(&mut self, s: u32, it: Item, t: u64, queue: u32) {
        self.stations[s as usize].queue.push_back(it);
        self.start(s, t, queue);
    }

    /// Starts station `s`'s next service if it is idle and has work; taking an item from the
    /// queue makes room, given to the first waiter.
    fn start(&mut self, s: u32, t: u64, queue: u32) {
        let st = &mut self.stations[s as usize];
        if st.serving.is_some() || st.blocked.is_some() {
            return;
        }
        let Some(it) = st.queue.pop_front() else {
            return;
        };
        let service = match st.kind {
            Kind::Link { cost } => cost,
            Kind::Buffer => 1,
            Kind::Gfb => {
                if it.packet {
                    self.costs.gfb as u64
                } else {
                    self.costs.fb_hit as u64
                }
            }
            Kind::Cache { stage } => {
                let st = &mut self.stations[s as usize];
                st.clock += 1;
                let set = (it.block as usize % self.sets) * 2;
                let (a, b) = (st.ways[set], st.ways[set + 1]);
                if a.0 == it.block || b.0 == it.block {
                    let w = if a.0 == it.block { set } else { set + 1 };
                    st.ways[w].1 |= it.mask;
                    st.ways[w].2 = st.clock;
                    if stage == 1 {
                        self.stats.hits += 1;
                    }
                    self.costs.fb_hit as u64
                } else {
                    if stage == 1 {
                        self.stats.misses += 1;
                    }
                    let w = if a.0 == EMPTY {
                        set
                    } else if b.0 == EMPTY || b.2 < a.2 {
                        set + 1
                    } else {
                        set
                    };
                    let victim = st.ways[w];
                    st.ways[w] = (it.block, it.mask, st.clock);
                    let dirty = if victim.0 == EMPTY {
                        0
                    } else {
                        victim.1.count_ones() as u64
                    };
                    let cost = self.costs.fb_miss as u64 + self.costs.fb_dirty as u64 * dirty;
                    // The cache's output this time: the victim block, if any, else nothing.
                    st.serving = Some(Item {
                        block: victim.0,
                        mask: victim.1,
                        born: t + cost,
                        packet: false,
                    });
                    if stage == 1 {
                        self.latency_sum += t + cost - it.born;
                        self.stats.latency_max = self.stats.latency_max.max(t + cost - it.born);
                    }
                    self.due.push((t + cost, s));
                    self.admit(s, t, queue);
                    return;
                }
            }
        };
        let st = &mut self.stations[s as usize];
        // A packet's latency: until it is added, in a first-stage cache or in the GFB.
        let added =
            matches!(st.kind, Kind::Cache { stage: 1 }) || (st.kind == Kind::Gfb && it.packet);
        // A hit leaves nothing to pass on.
        st.serving = Some(if matches!(st.kind, Kind::Cache { .. }) {
            Item {
                block: EMPTY,
                mask: 0,
                born: t,
                packet: false,
            }
        } else {
            it
        });
        if added {
            self.latency_sum += t + service - it.born;
            self.stats.latency_max = self.stats.latency_max.max(t + service - it.born);
        }
        self.due.push((t + service, s));
        self.admit(s, t, queue);
    }

    /// Station `s`'s queue has room: the first waiter moves in.
    fn admit(&mut self, s: u32, t: u64, queue: u32) {
        let st = &mut self.stations[s as usize];
        if st.queue.len() >= queue as usize {
            return;
        }
        let Some((w, it)) = st.waiting.pop_front() else {
            return;
        };
        st.queue.push_back(it);
        match w {
            Waiter::Block(b) => {
                // The packet leaves its RP block now.
                self.record_emission(s, t);
                self.resumed.push((t, b));
            }
            Waiter::Station(u) => {
                self.stations[u as usize].blocked = None;
                self.start(u, t, queue);
            }
        }
        self.start(s, t, queue);
    }

    /// Station `s` finishes its service at `t`.
    pub fn done(&mut self, s: u32, t: u64, queue: u32) {
        let st = &mut self.stations[s as usize];
        let it = st.serving.take().expect("a station event has a service");
        self.stats.finish = self.stats.finish.max(t);
        let passes_on = it.block != EMPTY && st.kind != Kind::Gfb;
        if passes_on {
            let d = st.dest;
            if matches!(st.kind, Kind::Cache { .. }) {
                self.stats.blocks_up += 1;
            }
            let ds = &mut self.stations[d as usize];
            if ds.queue.len() < queue as usize && ds.waiting.is_empty() {
                self.accept(d, it, t, queue);
            } else {
                ds.waiting.push_back((Waiter::Station(s), it));
                self.stations[s as usize].blocked = Some(it);
                return;
            }
        }
        self.start(s, t, queue);
    }

    /// The statistics at the end: latency, intervals, blocks left in the caches.
    pub fn finish(mut self) -> FrameBufferStats {
        self.stats.latency_mean = self.latency_sum as f64 / self.stats.packets.max(1) as f64;
        self.stats.flushed_blocks = self
            .stations
            .iter()
            .map(|s| s.ways.iter().filter(|w| w.0 != EMPTY).count() as u64)
            .sum();
        let (n, s, s2) = self.interval;
        if n > 0 {
            self.stats.interval_mean = s / n as f64;
            self.stats.interval_var = (s2 / n as f64 - self.stats.interval_mean.powi(2)).max(0.0);
        }
        self.stats
    }
}
