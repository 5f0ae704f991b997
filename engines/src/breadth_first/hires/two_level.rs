//! The two-level grid rays are registered in (seed 000 §4.3.3): an upper grid, and a bounded
//! pool of lower grids of `lower`³ voxels given to the upper voxels holding the most
//! registrations; the rest are registered directly in their upper voxel with their full voxel
//! coordinates, which every box then checks against its own voxel range.
//!
//! Like Jevans and Wyvill's hierarchical grid, but holding rays, not objects. Memory is bounded
//! in the worst case (upper grid + pool + registrations), and it works because only a few upper
//! voxels hold many rays. With `lower` = 1 it is the single-level grid of the rule's first case.

use std::cell::Cell;

/// An upper voxel with no registration.
pub const NONE: u32 = u32::MAX;
/// Tag of an upper voxel's entry naming a lower grid (else the head of its direct list).
const LOWER: u32 = 1 << 31;

/// One registration: a link of a lower voxel's or an upper voxel's list.
#[derive(Clone, Copy)]
pub struct Reg {
    pub slot: u32,
    pub next: u32,
    /// The voxel in the effective (upper × lower) grid.
    pub voxel: [u32; 3],
}

pub fn reg_bytes() -> u64 {
    std::mem::size_of::<Reg>() as u64
}

/// What the registrations of the calls counted.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    /// Registrations in a lower grid, and sent directly to their upper voxel.
    pub lower: u64,
    pub direct: u64,
    /// Lower grids in use, summed over passes.
    pub grids_used: u64,
    /// Registrations (direct) whose voxel a box's range check turned away.
    pub direct_misses: u64,
}

pub struct TwoLevel {
    pub upper_res: [u32; 3],
    pub lower: u32,
    /// Lower grids at most.
    pub pool: usize,
    /// Per upper voxel: [`NONE`], the head of its direct list, or `LOWER | grid`.
    upper: Vec<u32>,
    lower_heads: Vec<u32>,
    pub regs: Vec<Reg>,
    touched: Vec<u32>,
    used: usize,
    pub tally: Tally,
    misses: Cell<u64>,
}

impl TwoLevel {
    pub fn new(upper_res: [u32; 3], lower: u32, pool: usize) -> TwoLevel {
        let n = upper_res.iter().map(|&r| r as usize).product();
        TwoLevel {
            upper_res,
            lower,
            pool: if lower == 1 { 0 } else { pool },
            upper: vec![NONE; n],
            lower_heads: Vec::new(),
            regs: Vec::new(),
            touched: Vec::new(),
            used: 0,
            tally: Tally::default(),
            misses: Cell::new(0),
        }
    }

    /// Bytes of the upper grid and of the full pool.
    pub fn bytes(upper_res: [u32; 3], lower: u32, pool: u64) -> u64 {
        let upper: u64 = upper_res.iter().map(|&r| r as u64).product();
        4 * upper
            + if lower == 1 {
                0
            } else {
                4 * pool * (lower as u64).pow(3)
            }
    }

    #[inline]
    fn upper_of(&self, v: [u32; 3]) -> (usize, [u32; 3]) {
        let u = v.map(|c| c / self.lower);
        let r = self.upper_res;
        (
            u[0] as usize + r[0] as usize * (u[1] as usize + r[1] as usize * u[2] as usize),
            u,
        )
    }

    #[inline]
    fn lower_index(&self, grid: u32, v: [u32; 3], u: [u32; 3]) -> usize {
        let l = self.lower as usize;
        let p = [0, 1, 2].map(|i| (v[i] - u[i] * self.lower) as usize);
        grid as usize * l * l * l + p[0] + l * (p[1] + l * p[2])
    }

    /// Registers the candidates (slot, voxel) of one pass: count them per upper voxel, give the
    /// pool's lower grids to the upper voxels with the most, in decreasing order, then link
    /// each into its lower voxel's list or, without a lower grid, its upper voxel's.
    pub fn register(&mut self, cands: &[(u32, [u32; 3])]) {
        for &(_, v) in cands {
            let (u, _) = self.upper_of(v);
            if self.upper[u] == NONE {
                self.upper[u] = 0;
                self.touched.push(u as u32);
            }
            self.upper[u] += 1;
        }
        let mut order: Vec<(u32, u32)> = self
            .touched
            .iter()
            .map(|&u| (self.upper[u as usize], u))
            .collect();
        for &(_, u) in &order {
            self.upper[u as usize] = NONE;
        }
        if self.pool > 0 {
            // Decreasing count; ties by upper voxel, so the assignment is deterministic.
            order.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
            self.used = order.len().min(self.pool);
            let cells = (self.lower as usize).pow(3);
            if self.lower_heads.len() < self.used * cells {
                self.lower_heads.resize(self.used * cells, NONE);
            }
            for (g, &(_, u)) in order.iter().take(self.used).enumerate() {
                self.upper[u as usize] = LOWER | g as u32;
            }
        }
        for &(slot, voxel) in cands {
            let (u, uc) = self.upper_of(voxel);
            let e = self.upper[u];
            let at = self.regs.len() as u32;
            if e != NONE && e & LOWER != 0 {
                let li = self.lower_index(e & !LOWER, voxel, uc);
                self.regs.push(Reg {
                    slot,
                    next: self.lower_heads[li],
                    voxel,
                });
                self.lower_heads[li] = at;
                self.tally.lower += 1;
            } else {
                self.regs.push(Reg {
                    slot,
                    next: e,
                    voxel,
                });
                self.upper[u] = at;
                self.tally.direct += 1;
            }
        }
        self.tally.grids_used += self.used as u64;
    }

    /// Empties the grid for the next pass.
    pub fn clear(&mut self) {
        for &u in &self.touched {
            self.upper[u as usize] = NONE;
        }
        let cells = (self.lower as usize).pow(3);
        self.lower_heads[..self.used * cells].fill(NONE);
        self.touched.clear();
        self.regs.clear();
        self.used = 0;
        self.tally.direct_misses += self.misses.take();
    }

    /// Calls `f(slot)` for each registration in the voxels `a..=z` (inclusive, effective grid),
    /// until it returns `Ok(true)`; returns whether it did.
    pub fn for_each<E>(
        &self,
        a: [u32; 3],
        z: [u32; 3],
        mut f: impl FnMut(u32) -> Result<bool, E>,
    ) -> Result<bool, E> {
        let inside = |v: [u32; 3]| (0..3).all(|i| v[i] >= a[i] && v[i] <= z[i]);
        let ua = a.map(|c| c / self.lower);
        let uz = z.map(|c| c / self.lower);
        let uppers: u64 = (0..3).map(|i| (uz[i] - ua[i] + 1) as u64).product();
        if uppers > self.regs.len() as u64 {
            // A box wider than the registrations: test them all.
            for reg in &self.regs {
                if inside(reg.voxel) && f(reg.slot)? {
                    return Ok(true);
                }
            }
            return Ok(false);
        }
        let l = self.lower;
        let mut misses = 0;
        for uzc in ua[2]..=uz[2] {
            for uy in ua[1]..=uz[1] {
                for ux in ua[0]..=uz[0] {
                    let uc = [ux, uy, uzc];
                    let (u, _) = self.upper_of(uc.map(|c| c * l));
                    let e = self.upper[u];
                    if e == NONE {
                        continue;
                    }
                    if e & LOWER != 0 {
                        let lo = [0, 1, 2].map(|i| a[i].max(uc[i] * l) - uc[i] * l);
                        let hi = [0, 1, 2].map(|i| z[i].min(uc[i] * l + l - 1) - uc[i] * l);
                        for pz in lo[2]..=hi[2] {
                            for py in lo[1]..=hi[1] {
                                for px in lo[0]..=hi[0] {
                                    let v = [0, 1, 2].map(|i| uc[i] * l + [px, py, pz][i]);
                                    let mut r =
                                        self.lower_heads[self.lower_index(e & !LOWER, v, uc)];
                                    while r != NONE {
                                        let reg = self.regs[r as usize];
                                        r = reg.next;
                                        if f(reg.slot)? {
                                            return Ok(true);
                                        }
                                    }
                                }
                            }
                        }
                    } else {
                        let mut r = e;
                        while r != NONE {
                            let reg = self.regs[r as usize];
                            r = reg.next;
                            if !inside(reg.voxel) {
                                misses += 1;
                                continue;
                            }
                            if f(reg.slot)? {
                                self.misses.set(self.misses.get() + misses);
                                return Ok(true);
                            }
                        }
                    }
                }
            }
        }
        self.misses.set(self.misses.get() + misses);
        Ok(false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every registration is found exactly where it was made, whatever the pool's size.
    #[test]
    fn lower_grids_and_direct_registrations_agree() {
        let cands: Vec<(u32, [u32; 3])> = (0..200u32)
            .map(|i| (i, [(i * 7) % 16, (i * 3) % 16, (i / 13) % 16]))
            .collect();
        for pool in [0, 1, 3, 1000] {
            let mut g = TwoLevel::new([4; 3], 4, pool);
            g.register(&cands);
            assert_eq!(g.tally.lower + g.tally.direct, 200);
            if pool == 0 {
                assert_eq!(g.tally.lower, 0);
            }
            if pool >= 64 {
                assert_eq!(g.tally.direct, 0);
            }
            for (a, z) in [([0; 3], [15; 3]), ([2, 5, 1], [9, 5, 14]), ([3; 3], [3; 3])] {
                let mut got = Vec::new();
                g.for_each(a, z, |s| {
                    got.push(s);
                    Ok::<bool, ()>(false)
                })
                .unwrap();
                got.sort_unstable();
                let want: Vec<u32> = cands
                    .iter()
                    .filter(|(_, v)| (0..3).all(|i| v[i] >= a[i] && v[i] <= z[i]))
                    .map(|c| c.0)
                    .collect();
                assert_eq!(got, want, "pool {pool}, box {a:?}..{z:?}");
            }
            g.clear();
            assert!(g.regs.is_empty());
            let mut n = 0;
            g.for_each([0; 3], [15; 3], |_| {
                n += 1;
                Ok::<bool, ()>(false)
            })
            .unwrap();
            assert_eq!(n, 0);
        }
    }
}
