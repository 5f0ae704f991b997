//! Models the tables use in place of a measurement or beside it: the paging model of thrashing
//! (Mattson's stack algorithm), page replacement policies, Rayshade's memory account, and the
//! object-space machine's pass of Yamauchi et al. 1997.

pub mod paging;
pub mod pass_003;
pub mod rayshade_memory;
pub mod replacement;
