//! `rtbench env [--json]`: every `RTBENCH_*` variable rtbench reads, its value in this
//! environment, the forms it accepts and what it does.

use crate::error::Result;
use crate::measure::vars::VARS;
use crate::output::print_json;
use serde_json::json;

pub fn list(as_json: bool) -> Result<()> {
    let value = |name: &str| std::env::var_os(name).map(|v| v.to_string_lossy().into_owned());
    if as_json {
        let rows: Vec<_> = VARS
            .iter()
            .map(|v| {
                let val = value(v.name);
                let accepted = val.as_deref().map(|x| v.accepts(x));
                json!({"name": v.name, "value": val, "accepted": accepted, "forms": v.forms, "about": v.about})
            })
            .collect();
        print_json(&json!(rows));
        return Ok(());
    }
    println!("| variable | value | accepts | does |");
    println!("|---|---|---|---|");
    for v in VARS {
        println!(
            "| {} | {} | {} | {} |",
            v.name,
            match value(v.name) {
                None => "(unset)".to_string(),
                Some(x) if v.accepts(&x) => x,
                Some(x) => format!("{x} (not accepted: every other command stops with exit 2)"),
            },
            v.forms,
            v.about
        );
    }
    Ok(())
}
