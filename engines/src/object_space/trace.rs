//! What executing rays through the subspaces leaves for the timing simulation: every ray's
//! subspace visits (segments) with the intersection work done in each, how it ended, and the
//! rays it spawned.
//!
//! The simulation is execution-driven (003 §4.2.1): the intersections are real, and they decide
//! which subspaces a ray visits, where it stops and what it spawns. None of that depends on
//! timing, so the execution is done once and the record is replayed by [`super::sim`] for as
//! many machine configurations as wanted; the replay is exactly what an interleaved execution
//! would have timed.

/// One ray's visit to one subspace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    pub subspace: u32,
    /// Clocks of the ray–primitive tests made in this subspace (Table 4's per-test cost by
    /// primitive kind, summed).
    pub work: u32,
}

/// One traced ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TracedRay {
    /// `segs[seg_start .. seg_start + seg_count]` of the trace; no segment: the ray misses the
    /// grid and costs nothing.
    pub seg_start: u32,
    pub seg_count: u32,
    /// Rays this ray spawned at its hit: `rays[first_child .. first_child + children]`.
    pub first_child: u32,
    pub children: u32,
    /// Pixel its intensity packet goes to ([`NO_PIXEL`]: none is sent).
    pub pixel: u32,
    /// Not spawned by another traced ray: made by the FRGU of the PE owning its first subspace.
    pub root: bool,
    /// A root generated as an initial ray (Table 4: 4379 clocks) rather than as a secondary ray
    /// (1818): its origin lies outside the subspace grid (the eye).
    pub initial: bool,
    /// Ended at a hit (closest hit) or a blocker (any hit), not by leaving the grid.
    pub hit: bool,
}

/// Marks a ray that sends no intensity packet.
pub const NO_PIXEL: u32 = u32::MAX;

/// The rays of one simulated run, parents before their children.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    pub rays: Vec<TracedRay>,
    pub segs: Vec<Segment>,
}

impl Trace {
    pub fn segments(&self, r: &TracedRay) -> &[Segment] {
        &self.segs[r.seg_start as usize..(r.seg_start + r.seg_count) as usize]
    }
}
