//! NFF, the Neutral File Format of the SPD (docs/concepts.md).

pub mod cfmt;
pub mod read;
pub mod write;

pub use read::{read_nff, read_nff_file, NffError};
pub use write::NffWriter;
