//! What one `rtbench reproduce` invocation was and cost: the exact command, the commit, the date and
//! the machine (so that a result of record says how to regenerate it and where it was measured), and
//! wall and CPU seconds and the load average at its start and end, kept in every reproduction's JSON
//! (`invocation`) and stated under its document.
//!
//! Why: a time measured beside other work is only recognisable as such afterwards by CPU / wall
//! well under 100 % per thread, or by the load. The out-of-core ids keep both per run; the others
//! (Chapter 3's tables, 001–003) kept neither before. With `--resume` it is this invocation's
//! share of the work: rows loaded from the checkpoint cost nothing here.

use super::grid_runs::{cpu_share, load_average};
use super::Output;
use serde_json::{json, Value};
use std::time::Instant;

pub struct Invocation {
    t: Instant,
    cpu0: f64,
    load: String,
    started_at: String,
}

/// The command line as typed, the program named `rtbench` (a path to the binary says nothing to
/// a reader of the document); arguments with spaces or quotes are quoted for a POSIX shell.
pub fn command_line(args: impl IntoIterator<Item = String>) -> String {
    let mut words = vec!["rtbench".to_string()];
    words.extend(args.into_iter().skip(1).map(|a| {
        if !a.is_empty()
            && a.chars()
                .all(|c| c.is_ascii_alphanumeric() || "-_./:=,+@%".contains(c))
        {
            a
        } else {
            format!("'{}'", a.replace('\'', "'\\''"))
        }
    }));
    words.join(" ")
}

/// The machine in one line: CPU model, logical cores, memory, OS.
fn machine(env: &rtbench_reports::Environment) -> String {
    format!(
        "{}, {} logical cores, {:.1} GiB, {}",
        if env.cpu_model.is_empty() {
            "unknown CPU"
        } else {
            &env.cpu_model
        },
        env.cores_logical,
        env.memory_bytes as f64 / (1u64 << 30) as f64,
        env.os
    )
}

impl Invocation {
    pub fn start() -> Invocation {
        Invocation {
            t: Instant::now(),
            cpu0: crate::measure::clock::process_cpu_seconds(),
            load: load_average(),
            started_at: crate::measure::environment::now_utc(),
        }
    }

    /// Adds the figures to `o`'s JSON and a sentence to its document.
    pub fn stamp(self, o: &mut Output, resumed: bool) {
        let wall_s = self.t.elapsed().as_secs_f64();
        let cpu_s = crate::measure::clock::process_cpu_seconds() - self.cpu0;
        let end = load_average();
        let env = crate::measure::environment::capture();
        let command = command_line(std::env::args());
        let commit = format!(
            "{}{}",
            env.git_commit,
            if env.git_dirty {
                " (with uncommitted changes)"
            } else {
                ""
            }
        );
        let machine = machine(&env);
        if let Value::Object(m) = &mut o.result {
            m.insert(
                "invocation".into(),
                json!({"command": command, "commit": env.git_commit, "dirty": env.git_dirty,
                       "date": self.started_at, "machine": machine, "rustc": env.rustc,
                       "wall_s": wall_s, "cpu_s": cpu_s, "load_average_start": self.load,
                       "load_average_end": end, "resumed": resumed}),
            );
        }
        // A resumed run measured only what its saved steps lacked: the date, commit and machine
        // are this invocation's, the loaded rows' are those of the invocations that saved them.
        o.doc.paragraph(if resumed {
            format!(
                "Regenerate: `{command}`. Written on {}, commit {commit}, {machine}, from the steps saved in the output folder's `.partial/` (rows loaded from them were measured by earlier invocations).",
                self.started_at
            )
        } else {
            format!(
                "Regenerate: `{command}`. Measured on {}, commit {commit}, {machine}.",
                self.started_at
            )
        });
        o.doc.paragraph(format!(
            "This invocation: {wall_s:.1} s wall, {cpu_s:.1} s CPU over all threads (CPU / wall {}); load average {} at its start, {end} at its end{}.",
            cpu_share(cpu_s, wall_s),
            self.load,
            if resumed { " (resumed: rows taken from the checkpoint cost nothing here)" } else { "" },
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rtbench_reports::Document;

    // Beside the whole unit suite with output captured this test is reported failed with no panic
    // message, though every assertion's value holds when written out; the cause is not found yet.
    // So it runs on its own: scripts/test.sh (and with it CI) runs it after the workspace's tests.
    #[test]
    #[ignore = "runs alone: scripts/test.sh runs it with --ignored after the workspace tests"]
    fn an_invocation_keeps_its_cpu_and_wall_seconds() {
        let inv = Invocation::start();
        // Burn some CPU so that the figures cannot both be zero.
        let mut x = 0u64;
        let t = Instant::now();
        while t.elapsed().as_millis() < 30 {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(std::hint::black_box(1));
        }
        std::hint::black_box(x);
        let mut o = Output::new(json!({"id": "x"}), Vec::new(), Document::new("x"));
        inv.stamp(&mut o, false);
        let v = &o.result["invocation"];
        assert!(v["wall_s"].as_f64().unwrap() >= 0.03, "{v}");
        assert!(v["cpu_s"].as_f64().unwrap() > 0.0, "{v}");
        assert_eq!(v["resumed"], false);
        let md = o.doc.to_markdown();
        assert!(md.contains("This invocation: "));
        assert!(md.contains("Regenerate: `rtbench "), "{md}");
        assert!(v["command"].as_str().unwrap().starts_with("rtbench"), "{v}");
        assert!(!v["commit"].as_str().unwrap().is_empty(), "{v}");
    }

    #[test]
    fn a_command_line_is_quoted_for_the_shell() {
        let args = [
            "/x/target/release/rtbench",
            "reproduce",
            "spd-stats",
            "--out",
            "a b",
            "--set",
            "k=it's",
        ];
        assert_eq!(
            command_line(args.iter().map(|s| s.to_string())),
            "rtbench reproduce spd-stats --out 'a b' --set 'k=it'\\''s'"
        );
    }
}
