//! Byte sizes as settings take them (`block=32MiB`, `memory=1GiB`).

use std::str::FromStr;

/// A byte size: `33554432`, `32MiB`, `64KiB`, `1GiB` (also `MB`, `KB`, `GB` as powers of 10).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bytes(pub u64);

impl FromStr for Bytes {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let split = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
        let (num, unit) = s.split_at(split);
        let n: u64 = num
            .parse()
            .map_err(|_| "expected a size such as 32MiB".to_string())?;
        let k: u64 = match unit {
            "" | "B" => 1,
            "KiB" => 1 << 10,
            "MiB" => 1 << 20,
            "GiB" => 1 << 30,
            "KB" => 1000,
            "MB" => 1_000_000,
            "GB" => 1_000_000_000,
            _ => {
                return Err(format!(
                    "unknown unit '{unit}' (B, KiB, MiB, GiB, KB, MB, GB)"
                ))
            }
        };
        match n.checked_mul(k) {
            Some(0) => Err("must be above 0".into()),
            Some(v) => Ok(Bytes(v)),
            None => Err("too large".into()),
        }
    }
}
