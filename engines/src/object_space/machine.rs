//! The (Mπ)² machine's shape: processing elements (PEs) on a 1D, 2D or 3D torus, and which PE
//! owns each subspace (003 §3.3.2, static load balancing).

use std::str::FromStr;

/// How subspaces are given to PEs. (X, Y, Z) is a subspace, S its axis counts, N the PEs per
/// axis; the torus makes every `mod` wrap without an edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Allocation {
    /// Eq. (7): PE = (⌊X / ⌈S_x/N_x⌉⌋, …): neighbouring subspaces stay together.
    Block,
    /// Eq. (8): PE = (X mod N_x, Y mod N_y, Z mod N_z): neighbours on neighbouring PEs.
    Distributed,
    /// Eqs. (9), (10): 1D PE = (X + Y + Z) mod N_x; 2D PE = ((X + Z) mod N_x, Y mod N_y). The
    /// axes with no PE dimension are folded in, so an upright column (Z is up in the SPD) is
    /// spread over PEs.
    Skewed,
}

impl FromStr for Allocation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "block" => Ok(Allocation::Block),
            "distributed" => Ok(Allocation::Distributed),
            "skewed" => Ok(Allocation::Skewed),
            _ => Err("expected block, distributed or skewed".into()),
        }
    }
}

impl Allocation {
    pub fn name(self) -> &'static str {
        match self {
            Allocation::Block => "block",
            Allocation::Distributed => "distributed",
            Allocation::Skewed => "skewed",
        }
    }
}

/// The machine: PEs per torus axis (1 on the axes a lower-dimensional machine lacks), its
/// dimension, the allocation, and the ray-processing blocks in each PE.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Machine {
    pub pes: [u32; 3],
    pub dims: u8,
    pub allocation: Allocation,
    pub rp_blocks: u32,
}

impl Machine {
    pub fn pe_count(&self) -> usize {
        self.pes.iter().map(|&n| n as usize).product()
    }

    /// `NxM…` as on the command line.
    pub fn pes_label(&self) -> String {
        self.pes[..self.dims as usize]
            .iter()
            .map(|n| n.to_string())
            .collect::<Vec<_>>()
            .join("x")
    }

    /// The torus coordinates of the PE owning subspace `c` of a grid of `s` subspaces per axis.
    pub fn owner_coords(&self, c: [u32; 3], s: [u32; 3]) -> [u32; 3] {
        let n = self.pes;
        match self.allocation {
            Allocation::Block => [0, 1, 2].map(|i| c[i] / s[i].div_ceil(n[i])),
            Allocation::Distributed => [0, 1, 2].map(|i| c[i] % n[i]),
            Allocation::Skewed => match self.dims {
                1 => [(c[0] + c[1] + c[2]) % n[0], 0, 0],
                _ => [(c[0] + c[2]) % n[0], c[1] % n[1], 0],
            },
        }
    }

    pub fn pe_index(&self, p: [u32; 3]) -> u32 {
        p[0] + self.pes[0] * (p[1] + self.pes[1] * p[2])
    }

    pub fn pe_coords(&self, pe: u32) -> [u32; 3] {
        let (nx, ny) = (self.pes[0], self.pes[1]);
        [pe % nx, (pe / nx) % ny, pe / (nx * ny)]
    }

    /// The owning PE of every subspace, by linear subspace index (x fastest).
    pub fn owner_map(&self, s: [u32; 3]) -> Vec<u32> {
        let mut v = Vec::with_capacity((s[0] * s[1] * s[2]) as usize);
        for z in 0..s[2] {
            for y in 0..s[1] {
                for x in 0..s[0] {
                    v.push(self.pe_index(self.owner_coords([x, y, z], s)));
                }
            }
        }
        v
    }

    /// Hops between two PEs on the torus (shortest way round each axis), and the outgoing link
    /// of `from` the first hop takes: 2·axis, +1 when going down.
    pub fn route(&self, from: u32, to: u32) -> (u32, usize) {
        let (a, b) = (self.pe_coords(from), self.pe_coords(to));
        let mut hops = 0;
        let mut link = usize::MAX;
        for i in 0..3 {
            let n = self.pes[i];
            let up = (b[i] + n - a[i]) % n;
            let down = n - up;
            if up == 0 {
                continue;
            }
            let (d, dir) = if up <= down { (up, 0) } else { (down, 1) };
            hops += d;
            if link == usize::MAX {
                link = 2 * i + dir;
            }
        }
        (hops, if link == usize::MAX { 0 } else { link })
    }
}
