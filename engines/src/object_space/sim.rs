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
//! - Intensity packets go to the frame buffer: with unbounded queues ([`simulate`]) the PEs do
//!   not wait and the frame buffer is simulated after them ([`super::framebuffer`]); with finite
//!   queues ([`simulate_path`], [`super::fbpath`]) an RP block whose packet finds its PE's queue
//!   full waits until it is taken, and its queued work with it.
//!
//! The image time is when the last RP block and the frame buffer are both done. Events are
//! ordered by (time, ray, segment, kind), which is unique, so a run is deterministic.

use super::config::{Costs, FrameBuffer};
use super::fbpath::{FbPath, Path};
use super::framebuffer::{self, Emission, FrameBufferStats};
use super::machine::Machine;
use super::trace::{Trace, NO_PIXEL};
use serde::Serialize;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

/// What one simulated run measured.
#[derive(Clone, Debug, Default, PartialEq, Serialize, serde::Deserialize)]
pub struct SimResult {
    /// Simulated image time: the last RP block and the frame buffer done.
    pub clocks: u64,
    /// When the last RP block finished.
    pub pe_clocks: u64,
    /// When the busiest FRGU had made its last initial ray.
    pub frgu_clocks: u64,
    /// Clocks RP blocks waited for room in their PE's frame-buffer queue, in all and on the
    /// block that waited longest (finite queues only).
    pub fb_stall: u64,
    pub fb_stall_max: u64,
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

/// What a heap entry stands for. Arrivals wait in the heap; a ray's completion in an RP block
/// waits in that block's FIFO (completions there come in the order the work was queued), and
/// only each FIFO's head, and each FRGU's next initial ray, is in the heap: the heap stays as
/// small as the machine, not as the rays in flight.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Source {
    /// A ray packet reaching the RD of the PE owning its subspace (from a link or its own PE).
    Arrival,
    /// The head of RP block `b`'s FIFO of completions.
    Done(u32),
    /// The next initial ray of PE `p`'s FRGU.
    Frgu(u32),
    /// Frame-buffer station `s` finishes a service ([`super::fbpath`]).
    Fb(u32),
}

type Event = (u64, u32, u32, Source);

/// Queues an arrival: as the next event when it precedes everything queued, else in the heap.
fn arrive(e: Event, heap: &mut BinaryHeap<Reverse<Event>>, next_event: &mut Option<Event>) {
    if next_event.is_none() && heap.peek().is_none_or(|Reverse(top)| e < *top) {
        *next_event = Some(e);
    } else {
        heap.push(Reverse(e));
    }
}

/// One segment as the event loop needs it, made in one pass before the loop so that an event
/// touches one place in memory: the owning PE (top bit: the ray's last segment) and the clocks
/// of the whole packet's work in its RP block.
#[derive(Clone, Copy)]
struct Step {
    pe: u32,
    cost: u32,
}

const LAST: u32 = 1 << 31;
const NONE: u32 = u32::MAX;

fn steps(trace: &Trace, owner: &[u32], costs: &Costs) -> Vec<Step> {
    let mut v = Vec::with_capacity(trace.segs.len());
    for ray in &trace.rays {
        let n = ray.seg_count;
        for (s, seg) in trace.segments(ray).iter().enumerate() {
            let last = s as u32 + 1 == n;
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
            v.push(Step {
                pe: owner[seg.subspace as usize] | if last { LAST } else { 0 },
                cost: seg.work.saturating_add(tail),
            });
        }
    }
    v
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
    let queue = match frame_buffer {
        FrameBuffer::WriteBuffer { .. } => u32::MAX,
        _ => 0,
    };
    simulate_path(
        trace,
        machine,
        owner,
        costs,
        FbPath {
            kind: frame_buffer,
            queue,
        },
        width,
    )
}

/// [`simulate`] with the frame-buffer path's queues of `path.queue` entries (0: unbounded, the
/// frame buffer simulated after the PEs).
pub fn simulate_path(
    trace: &Trace,
    machine: &Machine,
    owner: &[u32],
    costs: &Costs,
    path: FbPath,
    width: u32,
) -> SimResult {
    let pes = machine.pe_count();
    let queue = path.queue;
    let mut fb = (queue > 0).then(|| Path::new(path, pes as u32, costs, width));
    // Per RP block: waiting since (for room for its head's packet), and whether the head's
    // packet has been taken.
    let mut stalled_at = vec![u64::MAX; pes * machine.rp_blocks as usize];
    let mut emitted = vec![false; pes * machine.rp_blocks as usize];
    let rpb = machine.rp_blocks as usize;
    let steps = steps(trace, owner, costs);
    let mut rp_free = vec![0u64; pes * rpb];
    // Per RP block: (end, ray, segment, PE of the ray's next segment or NONE).
    let mut fifo: Vec<VecDeque<(u64, u32, u32, u32)>> = vec![VecDeque::new(); pes * rpb];
    let mut busy = vec![0u64; pes];
    let mut link_free = vec![0u64; pes * 6];
    // Entries (time, ray, global segment index, source): unique, so the order is total.
    let mut heap: BinaryHeap<Reverse<Event>> = BinaryHeap::new();
    let mut r = SimResult {
        pes: pes as u64,
        rp_blocks: rpb as u64,
        ..Default::default()
    };
    let mut emissions: Vec<Emission> = Vec::new();

    // Each FRGU's initial rays, in ray order.
    let mut roots: Vec<Vec<u32>> = vec![Vec::new(); pes];
    for (i, ray) in trace.rays.iter().enumerate() {
        if ray.root && ray.seg_count > 0 {
            let pe = steps[ray.seg_start as usize].pe & !LAST;
            roots[pe as usize].push(i as u32);
        }
    }
    let gen_cost = |ri: u32| -> u64 {
        if trace.rays[ri as usize].initial {
            costs.primary as u64
        } else {
            costs.secondary as u64
        }
    };
    let mut frgu_next = vec![0usize; pes];
    let mut frgu_time = vec![0u64; pes];
    for (pe, list) in roots.iter().enumerate() {
        if let Some(&ri) = list.first() {
            frgu_time[pe] = gen_cost(ri);
            let k = trace.rays[ri as usize].seg_start;
            heap.push(Reverse((frgu_time[pe], ri, k, Source::Frgu(pe as u32))));
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

    // An arrival that comes before everything in the heap is handled next without going
    // through it (most often a ray stepping to a subspace of the same PE): the order of events
    // is the heap's all the same.
    let mut next_event: Option<Event> = None;
    while let Some((t, ri, k, src)) = next_event.take().or_else(|| heap.pop().map(|Reverse(e)| e)) {
        match src {
            Source::Frgu(p) => {
                let p = p as usize;
                frgu_next[p] += 1;
                if let Some(&next) = roots[p].get(frgu_next[p]) {
                    frgu_time[p] += gen_cost(next);
                    let kn = trace.rays[next as usize].seg_start;
                    heap.push(Reverse((frgu_time[p], next, kn, Source::Frgu(p as u32))));
                }
            }
            Source::Fb(st) => {
                let f = fb.as_mut().expect("frame-buffer events need the path");
                f.done(st, t, queue);
                drain(
                    f,
                    &mut heap,
                    &mut fifo,
                    &mut rp_free,
                    &mut stalled_at,
                    &mut emitted,
                    &mut r,
                );
                continue;
            }
            Source::Done(b) => {
                let ray = &trace.rays[ri as usize];
                let bu = b as usize;
                // An intensity packet must find room in its PE's queue, else the block waits.
                if let Some(f) = fb.as_mut() {
                    let last = fifo[bu].front().expect("a FIFO head is in the heap").3 == NONE;
                    if last && ray.hit && ray.pixel != NO_PIXEL && !emitted[bu] {
                        let pe = b / rpb as u32;
                        if f.emit(pe, b, ray.pixel, t, queue) {
                            emitted[bu] = true;
                        } else {
                            stalled_at[bu] = t;
                        }
                        drain(
                            f,
                            &mut heap,
                            &mut fifo,
                            &mut rp_free,
                            &mut stalled_at,
                            &mut emitted,
                            &mut r,
                        );
                        if !emitted[bu] {
                            continue;
                        }
                    }
                }
                emitted[bu] = false;
                let q = &mut fifo[bu];
                let (_, _, _, next) = q.pop_front().expect("a FIFO head is in the heap");
                if let Some(&(te, rn, kn, _)) = q.front() {
                    heap.push(Reverse((te, rn, kn, Source::Done(b))));
                }
                let pe = b / rpb as u32;
                // The ray leaves the RP block: on to its next subspace, or its hit's results.
                if next != NONE {
                    let at = if next == pe {
                        t
                    } else {
                        send(pe, next, t, &mut r)
                    };
                    arrive((at, ri, k + 1, Source::Arrival), &mut heap, &mut next_event);
                    continue;
                }
                if !ray.hit {
                    continue;
                }
                if ray.pixel != NO_PIXEL && fb.is_none() {
                    emissions.push(Emission {
                        time: t,
                        pe,
                        pixel: ray.pixel,
                    });
                }
                for c in ray.first_child..ray.first_child + ray.children {
                    let child = &trace.rays[c as usize];
                    if child.seg_count == 0 {
                        continue;
                    }
                    let kc = child.seg_start;
                    let next = steps[kc as usize].pe & !LAST;
                    let at = if next == pe {
                        t
                    } else {
                        send(pe, next, t, &mut r)
                    };
                    arrive((at, c, kc, Source::Arrival), &mut heap, &mut next_event);
                }
                continue;
            }
            Source::Arrival => {}
        }
        // An arrival (or a ray the FRGU has just made): the RD dispatches it to the PE's
        // least-loaded RP block.
        r.events += 1;
        let step = steps[k as usize];
        let pe = step.pe & !LAST;
        let next = if step.pe & LAST != 0 {
            NONE
        } else {
            steps[k as usize + 1].pe & !LAST
        };
        let cost = step.cost as u64;
        let base = pe as usize * rpb;
        let blocks = &mut rp_free[base..base + rpb];
        let mut best = 0;
        for (j, &f) in blocks.iter().enumerate().skip(1) {
            if f < blocks[best] {
                best = j;
            }
        }
        let end = t.max(blocks[best]) + cost;
        blocks[best] = end;
        busy[pe as usize] += cost;
        r.pe_clocks = r.pe_clocks.max(end);
        let b = base + best;
        if fifo[b].is_empty() {
            heap.push(Reverse((end, ri, k, Source::Done(b as u32))));
        }
        fifo[b].push_back((end, ri, k, next));
    }
    r.frgu_clocks = frgu_time.iter().copied().max().unwrap_or(0);
    r.busy = busy.iter().sum();
    r.busy_max_pe = busy.iter().copied().max().unwrap_or(0);
    r.pe_clocks = r.pe_clocks.max(rp_free.iter().copied().max().unwrap_or(0));
    r.frame_buffer = match fb {
        Some(f) => f.finish(),
        None => framebuffer::simulate(&mut emissions, pes as u32, costs, path.kind, width),
    };
    r.clocks = r.pe_clocks.max(r.frame_buffer.finish);
    r
}

/// After a call into the frame-buffer path: schedules its stations' events and resumes the RP
/// blocks whose packets it took, their queued work shifted by the wait.
fn drain(
    f: &mut Path,
    heap: &mut BinaryHeap<Reverse<Event>>,
    fifo: &mut [VecDeque<(u64, u32, u32, u32)>],
    rp_free: &mut [u64],
    stalled_at: &mut [u64],
    emitted: &mut [bool],
    r: &mut SimResult,
) {
    for (t, s) in f.due.drain(..) {
        heap.push(Reverse((t, u32::MAX, s, Source::Fb(s))));
    }
    for (t, b) in f.resumed.drain(..) {
        let bu = b as usize;
        let d = t - stalled_at[bu];
        stalled_at[bu] = u64::MAX;
        emitted[bu] = true;
        r.fb_stall += d;
        r.fb_stall_max = r.fb_stall_max.max(d);
        for e in fifo[bu].iter_mut() {
            e.0 += d;
        }
        rp_free[bu] += d;
        let &(te, rn, kn, _) = fifo[bu].front().expect("a waiting block has its head");
        heap.push(Reverse((te, rn, kn, Source::Done(b))));
    }
}
