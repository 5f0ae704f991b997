//! The grid switches of the `breadth-first` engine (seed 000 §4.3): which grid, and its
//! resolution rule's constants.

use crate::engine::{EngineError, Settings};

/// Which grid rays are registered in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridKind {
    /// The basic method's in-memory grid, ⌊n^(1/3) + 0.5⌋ cells per axis, coarsened to fit half
    /// the memory budget (`grid=cuberoot`, the default; Ch.3).
    CubeRoot,
    /// An in-memory single-level grid at Klimaszewski's resolution capped at `cap` cells per axis
    /// (`grid=single`, cap 128: the thesis's "-l" curves of Figs 4.4–4.7 and Table 4.2's base).
    Single { cap: u32 },
    /// The high-resolution grid of §4.3: voxel flags on disk, made subspace by subspace, read in
    /// X-slab blocks (Algorithm 4.6), rays registered in a two-level grid (`grid=two-level`).
    TwoLevel(TwoLevelConfig),
}

/// The constants of the high-resolution grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoLevelConfig {
    /// R_u and R_l, the per-axis maxima of the upper and lower grids (thesis: 256 and 4).
    pub upper: u32,
    pub lower: u32,
    /// A cap on Klimaszewski's R before the rule (`cap=N`; none by default).
    pub cap: Option<u32>,
    /// Lower grids in the pool (`pool=N`); `None`: what 1/16 of the memory budget holds.
    pub pool: Option<u64>,
    /// Bytes of one X-slab block in memory (`block=`); `None`: 1/8 of the memory budget.
    pub block: Option<u64>,
    /// Voxels per side of a cubic preprocessing subspace (`subspace=N`); `None`: what 1/4 of
    /// the memory budget holds.
    pub subspace: Option<u32>,
    /// Rebuild the on-disk grid at preprocessing (`hrgrid=build`, the default, counted in
    /// preprocessing) or open the one a previous run left in the store (`hrgrid=reuse`).
    pub reuse: bool,
    /// `hrgrid=resume`: build as `build` does, keeping a record after each subspace, and take
    /// up an interrupted or finished build of the same grid with its recorded seconds
    /// ([`super::disk_grid::DiskGrid::build`]).
    pub resume: bool,
    /// `hrgrid_subspaces=K`: build only the first K subspaces of the on-disk grid and leave the
    /// rest empty: a timing model of a build longer than one sitting (rings368's basic build is 27
    /// sweeps of a 35 GB store). The answers are then not the scene's, so it needs `max_passes`
    /// (whose runs claim no image) and `hrgrid=build`, and the partial grid is removed from the
    /// store once opened, so that no later run can take it.
    pub max_subspaces: Option<u64>,
}

fn bad(key: &str, value: &str, reason: &str) -> EngineError {
    EngineError::BadValue {
        engine: "breadth-first".into(),
        key: key.into(),
        value: value.into(),
        reason: reason.into(),
    }
}

fn positive(s: &mut Settings, key: &'static str, default: u32) -> Result<u32, EngineError> {
    let v: u32 = s.get(key, default)?;
    if v == 0 {
        return Err(bad(key, "0", "at least 1"));
    }
    Ok(v)
}

impl GridKind {
    /// Reads `grid`, `cap`, `upper`, `lower`, `pool`, `block`, `subspace`, `hrgrid`.
    pub fn from_settings(s: &mut Settings) -> Result<GridKind, EngineError> {
        let kind: String = s.get("grid", "cuberoot".to_string())?;
        let cap: u32 = s.get("cap", 0u32)?;
        let upper = positive(s, "upper", 256)?;
        let lower = positive(s, "lower", 4)?;
        let pool: u64 = s.get("pool", 0u64)?;
        let block = s.get("block", super::super::config::Bytes(1))?.0;
        let subspace: u32 = s.get("subspace", 0u32)?;
        let hrgrid: String = s.get("hrgrid", "build".to_string())?;
        let max_subspaces: u64 = s.get("hrgrid_subspaces", 0u64)?;
        let (reuse, resume) = match hrgrid.as_str() {
            "build" => (false, false),
            "reuse" => (true, false),
            "resume" => (false, true),
            v => return Err(bad("hrgrid", v, "build, reuse or resume")),
        };
        if max_subspaces > 0 && (reuse || resume) {
            return Err(bad(
                "hrgrid_subspaces",
                &max_subspaces.to_string(),
                "a partial grid is a timing model: it needs hrgrid=build",
            ));
        }
        if upper > 4096 || lower > 64 {
            return Err(bad(
                "upper",
                &format!("{upper}/{lower}"),
                "upper ≤ 4096 and lower ≤ 64 cells per axis",
            ));
        }
        Ok(match kind.as_str() {
            "cuberoot" => GridKind::CubeRoot,
            "single" => GridKind::Single {
                cap: if cap == 0 { 128 } else { cap },
            },
            "two-level" => GridKind::TwoLevel(TwoLevelConfig {
                upper,
                lower,
                cap: (cap > 0).then_some(cap),
                pool: (pool > 0).then_some(pool),
                block: (block > 1).then_some(block),
                subspace: (subspace > 0).then_some(subspace),
                reuse,
                resume,
                max_subspaces: (max_subspaces > 0).then_some(max_subspaces),
            }),
            v => return Err(bad("grid", v, "cuberoot, single or two-level")),
        })
    }
}

/// The grid the resolution rule of §4.3.3 picks: effective cells per axis `res`, an upper grid
/// of `upper` cells per axis and lower grids of `lower`³ (1: a single-level grid).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    pub res: [u32; 3],
    pub upper: [u32; 3],
    pub lower: u32,
}

/// Seed 000 §4.3.3: R the largest per-axis resolution of Klimaszewski's method; R ≤ R_u → one
/// level; otherwise R_l = min(R_l, ⌈R/R_u⌉), then R_u = min(R_u, ⌈R/R_l⌉). Each axis's upper
/// count is its Klimaszewski resolution over R_l, rounded up and capped at R_u, so the grid's
/// shape follows Klimaszewski's and its effective resolution is at most R_u·R_l.
pub fn plan(klim: [u32; 3], c: &TwoLevelConfig) -> Plan {
    let klim = klim.map(|r| c.cap.map_or(r, |cap| r.min(cap)).max(1));
    let r = klim.into_iter().max().unwrap_or(1);
    if r <= c.upper {
        return Plan {
            res: klim,
            upper: klim,
            lower: 1,
        };
    }
    let lower = c.lower.min(r.div_ceil(c.upper));
    let ru = c.upper.min(r.div_ceil(lower));
    let upper = klim.map(|k| k.div_ceil(lower).min(ru));
    Plan {
        res: upper.map(|u| u * lower),
        upper,
        lower,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(upper: u32, lower: u32) -> TwoLevelConfig {
        TwoLevelConfig {
            upper,
            lower,
            cap: None,
            pool: None,
            block: None,
            subspace: None,
            reuse: false,
            resume: false,
            max_subspaces: None,
        }
    }

    #[test]
    fn the_rule_of_4_3_3() {
        // R ≤ R_u: one level.
        assert_eq!(plan([100, 50, 7], &cfg(256, 4)).lower, 1);
        // R = 1000: R_l = min(4, ⌈1000/256⌉ = 4) = 4, R_u = min(256, 250) = 250.
        let p = plan([1000, 500, 10], &cfg(256, 4));
        assert_eq!(p.lower, 4);
        assert_eq!(p.upper, [250, 125, 3]);
        assert_eq!(p.res, [1000, 500, 12]);
        // Table 4.2's 64/2 and 32/4 at R = 300: effective 128 per axis.
        assert_eq!(plan([300, 300, 300], &cfg(64, 2)).res, [128; 3]);
        assert_eq!(plan([300, 300, 300], &cfg(32, 4)).res, [128; 3]);
        // R = 300 with 256/4: R_l = 2, R_u = 150.
        assert_eq!(plan([300, 20, 20], &cfg(256, 4)).upper, [150, 10, 10]);
    }
}
