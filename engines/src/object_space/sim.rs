//! The discrete-event simulation of the (Mπ)² machine (003 §3.2, §4.2.1), in clocks, replaying
//! a [`Trace`].
//!
//! Units and their costs (Table 4, [`Costs`]):
//! - FRGU, one per PE: makes the initial rays whose first subspace the PE owns, one after the
//!   other (4379 clocks each; a root ray starting inside the grid, as the SPD workload's
//!   secondary and shadow rays do, costs a secondary ray's 1818).
//! - RD: gives each arriving ray packet at once to the PE's least-loaded ray-processing (RP)
//!   block, the one whose queued work ends first (lowest index on a tie). Each RP block works
//!   its packets in arrival order.
//! - RP block, per packet (one ray in one subspace): the ray–primitive tests of the subspace
//!   (the trace's `work`); then either the hit's intensity (ICU, 349) and secondary rays (SRGU,
//!   1818 each), which 003 runs side by side so the longer of the two counts, or the next
//!   subspace by 3D-DDA (3151 on the ray's first step, 1106 after) and a ray packet (164).
//! - NIU and links: a packet for a subspace of another PE goes out on the link towards it,
//!   each link sending one packet at a time (164 clocks a hop); a subspace of the same PE goes
//!   back to its RD at no transmission cost.
//! - Intensity packets go to the frame buffer ([`super::framebuffer`]); the PEs do not wait.
//!
//! The image time is when the last RP block and the frame buffer are both done. Events are
//! ordered by (time, ray, segment), which is unique, so a run is deterministic.

use super::config::{Costs, FrameBuffer};
use super::framebuffer::{self, Emission, FrameBufferStats};
use super::machine::Machine;
use super::trace::{Trace, NO_PIXEL};
use serde::Serialize;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// What one simulated run measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SimResult {
    /// Simulated image time: the last RP block and the frame buffer done.
    pub clocks: u64,
    /// When the last RP block finished.
    pub pe_clocks: u64,
    /// Clocks the RP blocks were busy, in all and on the busiest PE.
    pub busy: u64,
    pub busy_max_pe: u64,
    pub pes: u64,
    pub rp_blocks: u64,
    /// Ray packets handled by RD/RP (one per ray per subspace visited).
    pub events: u64,
    /// Ray packets sent to another PE, and the hops they made.
    pub packets: u64,
    pub hops: u64,
    pub frame_buffer: FrameBufferStats,
}

impl SimResult {
    /// Busy share of all RP blocks over the image time.
    pub fn utilisation(&self) -> f64 {
        self.busy as f64 / (self.clocks.max(1) as f64 * (self.pes * self.rp_blocks) as f64)
    }

    /// Busiest PE's busy clocks over the mean PE's (1: perfectly even).
    pub fn imbalance(&self) -> f64 {
        self.busy_max_pe as f64 * self.pes as f64 / self.busy.max(1) as f64
    }
}

/// Simulates `trace` on `machine`; `owner[s]` is the PE of subspace s, `width` the image width
/// (pixels index the frame buffer row by row).
pub fn simulate(
    trace: &Trace,
    machine: &Machine,
    owner: &[u32],
    costs: &Costs,
    frame_buffer: FrameBuffer,
    width: u32,
) -> SimResult {
    let pes = machine.pe_count();
    let rpb = machine.rp_blocks as usize;
    let mut rp_free = vec![0u64; pes * rpb];
    let mut busy = vec![0u64; pes];
    let mut frgu = vec![0u64; pes];
    let mut link_free = vec![0u64; pes * 6];
    let mut heap: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::new();
    let mut r = SimResult {
        pes: pes as u64,
        rp_blocks: rpb as u64,
        ..Default::default()
    };
    let mut emissions: Vec<Emission> = Vec::new();

    for (i, ray) in trace.rays.iter().enumerate() {
        if ray.root && ray.seg_count > 0 {
            let pe = owner[trace.segs[ray.seg_start as usize].subspace as usize] as usize;
            frgu[pe] += if ray.initial {
                costs.primary
            } else {
                costs.secondary
            } as u64;
            heap.push(Reverse((frgu[pe], i as u32, 0)));
        }
    }

    let mut send = |from: u32, to: u32, t: u64, r: &mut SimResult| -> u64 {
        let (hops, link) = machine.route(from, to);
        let lf = &mut link_free[from as usize * 6 + link];
        let start = t.max(*lf);
        *lf = start + costs.hop as u64;
        r.packets += 1;
        r.hops += hops as u64;
        start + hops as u64 * costs.hop as u64
    };

    while let Some(Reverse((t, ri, s))) = heap.pop() {
        r.events += 1;
        let ray = &trace.rays[ri as usize];
        let segs = trace.segments(ray);
        let seg = segs[s as usize];
        let pe = owner[seg.subspace as usize];
        let last = s + 1 == ray.seg_count;
        let dda = if s == 0 { costs.dda_init } else { costs.dda };
        let tail = if !last {
            dda + costs.packet
        } else if ray.hit {
            let icu = if ray.pixel != NO_PIXEL {
                costs.intensity
            } else {
                0
            };
            icu.max(costs.secondary * ray.children)
        } else {
            // The DDA finds no next subspace: the ray leaves the space and vanishes.
            dda
        };
        let cost = (seg.work + tail) as u64;
        // The RD: least-loaded RP block of this PE.
        let blocks = &mut rp_free[pe as usize * rpb..(pe as usize + 1) * rpb];
        let mut best = 0;
        for (k, &f) in blocks.iter().enumerate().skip(1) {
            if f < blocks[best] {
                best = k;
            }
        }
        let end = t.max(blocks[best]) + cost;
        blocks[best] = end;
        busy[pe as usize] += cost;
        r.pe_clocks = r.pe_clocks.max(end);

        if !last {
            let next = owner[segs[s as usize + 1].subspace as usize];
            let at = if next == pe {
                end
            } else {
                send(pe, next, end, &mut r)
            };
            heap.push(Reverse((at, ri, s + 1)));
            continue;
        }
        if !ray.hit {
            continue;
        }
        if ray.pixel != NO_PIXEL {
            emissions.push(Emission {
                time: end,
                pe,
                pixel: ray.pixel,
            });
        }
        for c in ray.first_child..ray.first_child + ray.children {
            let child = &trace.rays[c as usize];
            if child.seg_count == 0 {
                continue;
            }
            let next = owner[trace.segs[child.seg_start as usize].subspace as usize];
            let at = if next == pe {
                end
            } else {
                send(pe, next, end, &mut r)
            };
            heap.push(Reverse((at, c, 0)));
        }
    }
    r.busy = busy.iter().sum();
    r.busy_max_pe = busy.iter().copied().max().unwrap_or(0);
    r.frame_buffer = framebuffer::simulate(&mut emissions, pes as u32, costs, frame_buffer, width);
    r.clocks = r.pe_clocks.max(r.frame_buffer.finish);
    r
}
