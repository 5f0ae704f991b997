//! `rtbench engines`: every engine, and whether it can run here (with the reason if not).

use crate::error::Result;
use crate::output::print_json;
use serde_json::json;

pub fn list(as_json: bool) -> Result<()> {
    let engines = rtbench_engines::registry();
    if as_json {
        let v: Vec<_> = engines
            .iter()
            .map(|e| {
                let avail = (e.available)();
                let mut o = json!({"name": e.name, "available": avail.is_ok(), "description": e.description});
                if let Err(reason) = avail {
                    o["reason"] = json!(reason);
                }
                o
            })
            .collect();
        print_json(&json!(v));
    } else {
        for e in &engines {
            match (e.available)() {
                Ok(()) => println!("{:<14} yes  {}", e.name, e.description),
                Err(r) => println!("{:<14} no   {} (unavailable: {r})", e.name, e.description),
            }
        }
    }
    Ok(())
}
